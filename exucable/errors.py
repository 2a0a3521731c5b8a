"""Error types. User errors (bad input) derive from :class:`ExucableError`; the CLI
prints their message without a traceback and exits with status 2."""

__all__ = ["ExucableError", "ScenarioError", "GeometryError", "ModelError", "SolverError", "OutputError",
           "LogError"]


class ExucableError(Exception):
    """Base class of every error caused by the user's input or a failed run.

    Subclasses whose constructor takes other arguments than the message keep those arguments, so
    that an error raised in a worker process (a sweep's or a benchmark's pool) is pickled back to
    the parent as the same error instead of failing to unpickle (which hangs the pool).
    """

    def __reduce__(self):
        return type(self), getattr(self, "_init_args", self.args)


class ScenarioError(ExucableError):
    """A scenario file is malformed or non-physical.

    Parameters
    ----------
    key : str
        Dotted key of the offending field, e.g. ``"conduit.path[2].radius"``.
    message : str
        What is wrong and what is allowed.
    """

    def __init__(self, key: str, message: str):
        self._init_args = (key, message)
        self.key = key
        self.message = message
        super().__init__(f"{key}: {message}" if key else message)


class GeometryError(ExucableError):
    """A conduit route cannot be built (e.g. a fillet that does not fit).

    ``key`` names the offending input relative to the conduit table, e.g.
    ``"points[3]"`` or ``"path[1].radius"``, so the scenario layer can prefix it.
    """

    def __init__(self, key: str, message: str):
        self._init_args = (key, message)
        self.key = key
        self.message = message
        super().__init__(f"{key}: {message}" if key else message)


class ModelError(ExucableError):
    """The scenario is valid on its own but cannot be modelled (e.g. a cable longer
    than its conduit, elements too long to resolve the bends)."""

    def __init__(self, key: str, message: str):
        self._init_args = (key, message)
        self.key = key
        self.message = message
        super().__init__(f"{key}: {message}" if key else message)


class SolverError(ExucableError):
    """The time integration failed; ``time_s`` is the simulated time where it happened."""

    def __init__(self, message: str, time_s: float | None = None):
        self._init_args = (message, time_s)
        self.time_s = time_s
        super().__init__(message if time_s is None else f"{message} (at simulated time t = {time_s:.6g} s)")


class OutputError(ExucableError):
    """An output path cannot be used: a file where a directory should be, no permission, a
    directory another run is writing into, or a write that failed (disk full).

    Parameters
    ----------
    path : str or os.PathLike
        The output path concerned.
    message : str
        What is wrong and what to do.
    """

    def __init__(self, path, message: str):
        self._init_args = (str(path), message)
        self.path = str(path)
        self.message = message
        super().__init__(f"{self.path}: {message}")


class LogError(ExucableError):
    """A tension recorder's log cannot be read or fitted (``exucable fit``).

    ``key`` names the offending column, row or flag, e.g. ``"column 'tension'"``, ``"row 12"`` or
    ``"--tare"``.
    """

    def __init__(self, key: str, message: str):
        self._init_args = (key, message)
        self.key = key
        self.message = message
        super().__init__(f"{key}: {message}" if key else message)
