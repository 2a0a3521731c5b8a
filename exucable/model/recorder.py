"""Recording a cable's pulling force and tensions as a simulation runs (paper Sect. 2.6, Eq. 24).

A :class:`Recorder` is a post-step callable: exucable's own :func:`exucable.solve.simulate` calls
it, and so can a user's post-step function or sensor user function in their own Exudyn model.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..tension import detect_steady_state, tension_at, tension_profile

__all__ = ["History", "Recorder", "expected_drift_N_per_s", "record_state", "steady_quantity"]


@dataclass
class History:
    """Time histories saved at the output interval."""

    time_s: list = field(default_factory=list)
    pull_force_N: list = field(default_factory=list)
    trailing_tension_N: list = field(default_factory=list)
    max_tension_N: list = field(default_factory=list)

    def arrays(self) -> dict[str, np.ndarray]:
        return {k: np.asarray(v, dtype=float) for k, v in self.__dict__.items()}


def steady_quantity(cable) -> str:
    """The history column whose steadiness ends a run: the pulling force, or for a
    force-controlled pull (whose pulling force is given) the trailing tension."""
    return "trailing_tension_N" if cable.applied_pull_force_N is not None else "pull_force_N"


def expected_drift_N_per_s(cable) -> float:
    """The drift the steady detector takes off the steady quantity [N/s]: the flexible reference's,
    as the cable leaves its conduit (pulling force of a velocity-controlled pull), else 0."""
    if steady_quantity(cable) != "pull_force_N":
        return 0.0
    return float(getattr(cable, "reference_drift_N_per_s", 0.0))


def record_state(cable, t: float, history: History) -> None:
    """Append the current pulling force, trailing tension and maximum tension to ``history``."""
    q, _ = cable.coordinates()
    EA = cable.axial_stiffness_N
    _, N = tension_profile(q, cable.layout.element_length_m, EA, points_per_element=2)
    trail = cable.trailing_reaction_N()
    if trail is None:
        trail = float(tension_at(q, cable.layout.element_length_m, EA, [0.0])[0])
    history.time_s.append(float(t))
    history.pull_force_N.append(cable.pull_force_N(t))
    history.trailing_tension_N.append(float(trail))
    history.max_tension_N.append(float(np.max(N)))


class Recorder:
    """Records a cable's forces every ``output_interval_s`` when called as ``recorder(mbs, t)``.

    Call it from your post-step function (``mbs.SetPostStepUserFunction``); it returns False
    once the steady state is reached if ``steady_stop`` is set (Exudyn then stops the run),
    else True. Nothing is recorded at t = 0: a rig's reaction force (a Lagrange multiplier)
    exists only once a step has been solved.

    Parameters
    ----------
    cable : CableInConduit
        The handles of :func:`exucable.model.build.add_cable_in_conduit`.
    output_interval_s : float
        Interval between records [s].
    steady_stop : bool
        Ask the solver to stop once the recorded pull force (the trailing tension of a
        force-controlled pull) is steady.
    steady_window_s, steady_tolerance : float
        Window [s] and relative drift/scatter bound of the steady check.
    progress : callable, optional
        ``progress(t, text)`` after each record.

    Attributes
    ----------
    history : History
    stopped_steady : bool
    """

    def __init__(self, cable, output_interval_s: float, steady_stop: bool = False, steady_window_s: float = 0.2,
                 steady_tolerance: float = 1e-3, progress=None):
        self.cable = cable
        self.output_interval_s = float(output_interval_s)
        self.steady_stop = steady_stop
        self.steady_window_s = steady_window_s
        self.steady_tolerance = steady_tolerance
        self.progress = progress
        self.history = History()
        self.stopped_steady = False
        self._next_s = self.output_interval_s

    def __call__(self, mbs, t: float) -> bool:
        if t < self._next_s - 1e-12 * max(1.0, t):
            return True
        self.record(t)
        self._next_s = (np.floor(t / self.output_interval_s + 1e-9) + 1.0) * self.output_interval_s
        if self.progress is not None:
            self.progress(t, f"F = {self.history.pull_force_N[-1]:.4g} N")
        if self.steady_stop and t >= self.steady_window_s:
            st = detect_steady_state(self.history.time_s, getattr(self.history, steady_quantity(self.cable)),
                                     self.steady_window_s, self.steady_tolerance,
                                     expected_drift_N_per_s=expected_drift_N_per_s(self.cable))
            if st.steady:
                self.stopped_steady = True
                return False
        return True

    def record(self, t: float) -> None:
        """Record the state now (at simulated time ``t`` [s])."""
        record_state(self.cable, t, self.history)
