"""The Python face of exucable: build a scenario like the physical system, run it, read numbers.

::

    import exucable as xc
    route = (xc.Route(inner_radius=3.5e-3)              # start and heading default to the origin, +x
             .straight(1.0).bend(90, radius=0.5, turn="left").straight(1.0))
    sc = xc.Scenario(route=route,
                     cable=xc.Cable(radius=2.5e-3, density=1000.0, youngs_modulus=1e9),
                     contact=xc.Contact(friction=0.2), pull=xc.Pull(speed=0.1, back_tension=150.0),
                     gravity=None, solver=xc.Solver(end_time=0.5))
    res = xc.run(sc)
    res.pull_force_N, res.pull_force_uncertainty_N, res.status

The part constructors take the scenario file's key names (``scenarios/README.md``) and run the
same checks as the file, raising the same :class:`~exucable.errors.ScenarioError` naming the
dotted key. Nothing here imports Exudyn until :func:`run` is called.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from .scenario.specs import (
    CableSpec,
    ConduitSpec,
    ContactSpec,
    GravitySpec,
    OutputSpec,
    PullSpec,
    Scenario,
    SolverSpec,
    conduit_from_spec,
    coerce_value,
    FIELD_BY_KEY,
    parse_conduit,
    quantities_to_si,
)
from .output.summary import RunSummary
from .scenario.fields import REQUIRED, fields_of

if TYPE_CHECKING:  # for the annotation only: Exudyn is imported when a run is asked for
    from .model.build import Model

__all__ = ["Route", "Cable", "Contact", "Pull", "Gravity", "Solver", "Output", "run", "vary", "Result", "History",
           "TensionProfile"]


# --------------------------------------------------------------------------------------------- parts


def _keys_doc(section: str) -> str:
    """The Parameters section of a part constructor, from the field table."""
    lines = ["Parameters", "----------"]
    for f in fields_of(section):
        unit = f" [{f.readme_unit}]" if f.readme_unit else ""
        if f.default is REQUIRED:
            default = "required"
        elif f.default_doc:
            default = f"default {f.default_doc}"
        elif f.default is None:
            default = "optional"
        else:
            default = f"default {f.default!r}"
        lines.append(f"{f.name} : {f.kind}, {default}")
        lines.append(f"    {f.rule}{unit}".replace("`", ""))
    return "\n".join(lines)


def _part(section: str, spec_cls, summary: str):
    def make(**keys):
        # quantities read as in a file: a number in SI, or a string with its unit ("2.5 mm")
        return spec_cls.from_keys(**quantities_to_si({section: keys}, "si")[section])

    make.__name__ = make.__qualname__ = section.capitalize()
    make.__doc__ = (f"{summary}\n\nTakes the ``[{section}]`` keys of a scenario file, read as in a file (SI "
                    "numbers, or strings with a unit such as ``\"2.5 mm\"``); returns a validated "
                    f":class:`~exucable.scenario.specs.{spec_cls.__name__}`.\n\n{_keys_doc(section)}\n\n"
                    "Raises\n------\nScenarioError\n    Unknown key or bad value, naming the dotted key.\n")
    return make


Cable = _part("cable", CableSpec, "The cable (paper Sect. 2.2): radius, density or mass per length, E, mesh.")
Contact = _part("contact", ContactSpec, "The cable–conduit contact law (paper Sects. 2.4–2.5, Eqs. 17–23).")
Pull = _part("pull", PullSpec, "The pulling rig (paper Sect. 2.1, Eq. 1) and the trailing-end load.")
Gravity = _part("gravity", GravitySpec, "Gravity along −z (``Gravity()``: g = 9.81 m/s²).")
Solver = _part("solver", SolverSpec, "Time integration settings.")
Output = _part("output", OutputSpec, "What is written besides the standard results (snapshots).")


class Route:
    """A conduit route built piece by piece (paper Sect. 2.3), or from survey points.

    Each method returns a new Route (a route is a value); every piece is checked as it is added,
    with the scenario file's dotted keys in the error (``conduit.path[1].radius``).

    Lengths are numbers in metres or strings with a unit (``"3.5 mm"``, ``"10 ft"``), as in a file.

    Parameters
    ----------
    inner_radius : float or str
        Conduit inner radius [m], checked at once.
    start : sequence of 3 float
        Start of the centreline [m] (default the origin).
    heading : sequence of 3 float
        Initial direction (default +x).
    max_segment_angle : float, optional
        Turning per straight contact segment on curved parts [deg] (default 1).
    segments_per_bend : int, optional
        Or: straight segments per bend/helix/fillet.
    """

    def __init__(self, inner_radius: float, start=(0.0, 0.0, 0.0), heading=(1.0, 0.0, 0.0),
                 max_segment_angle: float | None = None, segments_per_bend: int | None = None,
                 _pieces: tuple = (), _survey: dict | None = None):
        # read and checked here, so that a bad radius is named before the first piece
        inner_radius = coerce_value(FIELD_BY_KEY["conduit.inner_radius"],
                               quantities_to_si({"conduit": {"inner_radius": inner_radius}}, "si")["conduit"]
                               ["inner_radius"])
        keys: dict[str, Any] = {"inner_radius": inner_radius}
        if _survey is None:
            keys.update(start=list(start), heading=list(heading))
        if max_segment_angle is not None:
            keys["max_segment_angle"] = max_segment_angle
        if segments_per_bend is not None:
            keys["segments_per_bend"] = segments_per_bend
        self._keys = keys
        self._pieces = tuple(_pieces)
        self._survey = _survey
        if self._pieces or self._survey:
            self._spec = self._build()

    def _build(self, base_dir: Path = Path(".")) -> ConduitSpec:
        keys = dict(self._keys)
        if self._survey is not None:
            keys.update(self._survey)
        else:
            keys["path"] = [dict(p) for p in self._pieces]
        return parse_conduit(keys, base_dir)

    def _with(self, piece: dict) -> "Route":
        if self._survey is not None:
            raise ValueError("a survey route is complete: build pieces on a Route(inner_radius=...) instead")
        k = self._keys
        i = len(self._pieces)
        # lengths as in a file ("10 ft"), errors keyed conduit.path[i]
        piece = quantities_to_si({"conduit": {"path": [{}] * i + [dict(piece)]}}, "si")["conduit"]["path"][i]
        return Route(k["inner_radius"], k["start"], k["heading"], k.get("max_segment_angle"),
                     k.get("segments_per_bend"), _pieces=self._pieces + (piece,))

    def straight(self, length: float) -> "Route":
        """Append a straight of ``length`` [m]."""
        return self._with({"straight": length})

    def bend(self, angle: float, radius: float, turn: str | None = None, axis=None) -> "Route":
        """Append a circular bend of ``angle`` [deg] and centreline ``radius`` [m], turning
        ``"left"``/``"right"`` (about ±z) or ``"up"``/``"down"``, or about ``axis`` (right-hand rule)."""
        piece: dict[str, Any] = {"bend": angle, "radius": radius}
        if turn is not None:
            piece["turn"] = turn
        if axis is not None:
            piece["axis"] = list(axis)
        return self._with(piece)

    def helix(self, turns: float, radius: float, pitch: float, turn: str = "left") -> "Route":
        """Append a helix of ``turns`` coils, coil ``radius`` [m], rise ``pitch`` per coil along +z [m]."""
        return self._with({"helix_turns": turns, "radius": radius, "pitch": pitch, "turn": turn})

    @classmethod
    def from_survey(cls, points, bend_radius, inner_radius: float, max_segment_angle: float | None = None,
                    segments_per_bend: int | None = None) -> "Route":
        """A route through survey ``points`` [m] (N × 3), each interior vertex filleted with
        ``bend_radius`` [m] (one value, or one per interior vertex)."""
        pts = [[float(c) for c in p] for p in np.asarray(points, dtype=float)]
        br = bend_radius if np.isscalar(bend_radius) else [float(r) for r in bend_radius]
        return cls(inner_radius, max_segment_angle=max_segment_angle, segments_per_bend=segments_per_bend,
                   _survey={"points": pts, "bend_radius": br})

    @classmethod
    def from_csv(cls, path, inner_radius: float, bend_radius=None, max_segment_angle: float | None = None,
                 segments_per_bend: int | None = None) -> "Route":
        """A route from a survey CSV (header ``x,y,z`` or ``x,y,z,bend_radius``, metres);
        ``bend_radius`` [m] overrides the file's column."""
        survey: dict[str, Any] = {"points_csv": str(Path(path).resolve())}
        if bend_radius is not None:
            survey["bend_radius"] = bend_radius if np.isscalar(bend_radius) else list(bend_radius)
        return cls(inner_radius, max_segment_angle=max_segment_angle, segments_per_bend=segments_per_bend,
                   _survey=survey)

    def to_spec(self) -> ConduitSpec:
        """The validated :class:`~exucable.scenario.specs.ConduitSpec` of this route."""
        if not self._pieces and self._survey is None:
            from .errors import ScenarioError
            raise ScenarioError("conduit.path", "the route has no pieces: add .straight(...), .bend(...), ...")
        return self._spec

    @property
    def length_m(self) -> float:
        """Centreline length [m]."""
        return float(conduit_from_spec(self.to_spec()).centreline.length_m)

    def __repr__(self) -> str:
        what = f"{len(self._pieces)} pieces" if self._survey is None else "survey"
        return f"Route(inner_radius={self._keys['inner_radius']!r}, {what})"


# --------------------------------------------------------------------------------------------- results


@dataclass(frozen=True)
class History:
    """Time histories at the output interval (numpy arrays, one value per output time) [s], [N].

    A steady-mode result has no time: one row per static solve step, ``time_s`` the step number
    (README "Two solver modes").
    """

    time_s: np.ndarray
    pull_force_N: np.ndarray
    trailing_tension_N: np.ndarray
    max_tension_N: np.ndarray


@dataclass(frozen=True)
class TensionProfile:
    """Axial force N along the cable at the final time (paper Eq. 24), as ``tension_profile.csv``:
    from the equilibrium of the cable's loads (:func:`exucable.post.tension.equilibrium_tension`).

    Attributes
    ----------
    x_m : ndarray
        Material coordinate along the cable from the trailing end [m].
    tension_N : ndarray
        N at each x [N].
    """

    x_m: np.ndarray
    tension_N: np.ndarray

    @property
    def s_m(self) -> np.ndarray:
        """Arc length along the cable from the trailing end [m] (= :attr:`x_m`)."""
        return self.x_m


@dataclass(frozen=True)
class Result:
    """What :func:`run` gives back: the run's typed summary, its histories and profiles, the model.

    The numbers are the summary's (:class:`~exucable.output.summary.RunSummary`, what ``summary.json``
    holds), read as attributes; a number the run has none of reads as NaN here (None in the summary).

    Attributes
    ----------
    summary : RunSummary
        Everything ``summary.json`` holds (docs/results-format.md), typed: ``summary.flags``,
        ``summary.bends``, ``summary.pull_force_uncertainty_method``, ...; also readable by key.
    history : History
    tension_profile : TensionProfile
    model : exucable.model.build.Model
        The solved model: final coordinates (``model.coordinates()``), ``kernel``, ``mbs``.
    scenario : Scenario
    out_dir : Path or None
        Where the files went, if anywhere.
    cable_tensions : tuple of TensionProfile or None
        Several cables (``cable.count`` > 1): each cable's tension along it [N], cable 1 first, as
        ``cable_tensions.csv`` (``tension_profile`` is then their sum, the bundle's); None for one cable.
    """

    summary: RunSummary
    history: History
    tension_profile: TensionProfile
    model: Model
    scenario: Scenario
    out_dir: Path | None
    cable_tensions: tuple[TensionProfile, ...] | None = None

    def __repr__(self) -> str:
        s = self.summary
        u = self.pull_force_uncertainty_N
        force = f"{self.pull_force_N:.6g} N" + ("" if math.isnan(u) else f" ± {u:.2g} N")
        return (f"Result(status={self.status!r}, mode={s.mode!r}, pull_force_N={force}, "
                f"rope_pull_force_N={self.rope_pull_force_N:.6g} N, steps={s.steps}, "
                f"wall_time_s={_number(s.wall_time_s):.3g}, out_dir={self.out_dir!r})")

    @property
    def pull_force_N(self) -> float:
        """Mean pulling force in the steady window [N] (NaN if nothing was recorded); in steady mode the
        pulling force of the steady sliding state."""
        return _number(self.summary.pull_force_N)

    @property
    def pull_force_uncertainty_N(self) -> float:
        """Its uncertainty [N] (NaN where the summary has none: a made-up substitute would read as a
        bound): in steady mode the discretisation's and the solve's (a second solve on a coarser mesh,
        :mod:`exucable.solve.error_bar`), in dynamic mode the steady window's scatter and drift;
        ``summary.pull_force_uncertainty_method`` says which."""
        return _number(self.summary.pull_force_uncertainty_N)

    @property
    def status(self) -> str:
        """``"ok"``, ``"steady"`` (stopped once steady), ``"failed"``, or for a result that must not be
        trusted the first of ``"dynamic"``, ``"outside_conduit"``, ``"penetration"``, ``"not_steady"``
        (docs/results-format.md "Status"; every cause is in ``summary.flags``)."""
        return self.summary.status

    @property
    def message(self) -> str:
        """What the solver or the trust checks said: the failure, the flags' causes, or in steady mode how
        the static solve converged; ``""`` when there is nothing to say."""
        return self.summary.message or ""

    @property
    def trailing_tension_N(self) -> float:
        """Mean trailing-end tension in the steady window [N]."""
        return _number(self.summary.trailing_tension_N)

    @property
    def max_tension_N(self) -> float:
        """Largest tension along the cable [N]."""
        return _number(self.summary.max_tension_N)

    @property
    def max_sidewall_pressure_N_per_m(self) -> float:
        """Largest windowed sidewall pressure [N/m]: the contact force within s ± w/2 over the window
        w (``summary.pressure_window_m``), the calculators' SWBP; NaN without contact."""
        return _number(self.summary.max_sidewall_pressure_N_per_m)

    @property
    def rope_pull_force_N(self) -> float:
        """The quasi-static rope solver's pulling force, the reference [N]."""
        return _number(self.summary.rope_pull_force_N)


def _number(value) -> float:
    return float("nan") if value is None else float(value)


def run(scenario: Scenario | str | Path, out_dir=None, progress: bool = False, mode: str | None = None) -> Result:
    """Simulate one scenario.

    Parameters
    ----------
    scenario : Scenario, or path of a scenario file, or a shipped scenario's name
    out_dir : path, optional
        Write the result files there (docs/results-format.md); by default nothing is written.
    progress : bool
        Show a progress bar on stderr (only when it is a terminal).
    mode : {"dynamic", "steady"}, optional
        Solver mode, overriding ``solver.mode`` (README "Two solver modes").

    Returns
    -------
    Result
        A failed integration does not raise: ``status == "failed"`` and what was recorded.
    """
    from .errors import ScenarioError
    from .run import run_scenario

    if mode is not None and mode not in ("dynamic", "steady"):
        raise ScenarioError("solver.mode", f"mode must be \"dynamic\" or \"steady\", got {mode!r}")
    raw = run_scenario(scenario, out_dir, quiet=not progress, plots=out_dir is not None, mode=mode)
    h = raw.history
    return Result(
        history=History(**{k: np.asarray(h[k], dtype=float) for k in
                           ("time_s", "pull_force_N", "trailing_tension_N", "max_tension_N")}),
        tension_profile=TensionProfile(x_m=np.asarray(raw.tension_profile["x_m"], dtype=float),
                                       tension_N=np.asarray(raw.tension_profile["tension_N"], dtype=float)),
        summary=raw.summary,
        model=raw.model,
        scenario=raw.model.scenario,
        out_dir=Path(out_dir) if out_dir is not None else None,
        cable_tensions=_cable_profiles(raw.cable_tensions),
    )


def _cable_profiles(cables: dict | None) -> tuple[TensionProfile, ...] | None:
    """Each cable's :class:`TensionProfile` from a run's ``cable_tensions`` (``x_m`` and
    ``cable_<k>_tension_N``, k from 1), in cable order; None for one cable."""
    if cables is None:
        return None
    x = np.asarray(cables["x_m"], dtype=float)
    count = sum(1 for k in cables if k != "x_m")
    return tuple(TensionProfile(x_m=x, tension_N=np.asarray(cables[f"cable_{k}_tension_N"], dtype=float))
                 for k in range(1, count + 1))


def vary(scenario: Scenario, values: dict[str, Sequence], progress: bool = False,
         mode: str | None = None) -> list[tuple[dict, Result]]:
    """Run ``scenario`` for every combination of ``values``, one after another (a Python sweep).

    Named ``vary`` because ``exucable.sweep`` is the package of sweep files (``exucable sweep``).

    Parameters
    ----------
    scenario : Scenario
    values : dict
        Dotted key → values, e.g. ``{"contact.friction": [0.1, 0.2, 0.3]}``; the first key varies slowest.
    progress : bool
        Progress bar of each run.
    mode : {"dynamic", "steady"}, optional
        Solver mode of every run, overriding ``solver.mode`` (as :func:`run`).

    Returns
    -------
    list of (params, Result)
        ``params`` is the dict of dotted key → value of that case. Every case is validated
        (``Scenario.replace``) before the first one runs. For many cases in parallel, with
        results on disk and restarts, use ``exucable sweep``.
    """
    keys = list(values)
    params = [dict(zip(keys, combo)) for combo in itertools.product(*(values[k] for k in keys))]
    cases = [scenario.replace(**p) for p in params]
    return [(p, run(c, progress=progress, mode=mode)) for p, c in zip(params, cases)]
