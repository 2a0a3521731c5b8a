"""Recording a cable's pulling force and tensions as a simulation runs (paper Sect. 2.6, Eq. 24).

A :class:`Recorder` is a post-step callable: exucable's own :func:`exucable.solve.dynamic.simulate` calls
it, and so can a user's post-step function or sensor user function in their own Exudyn model.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..post.tension import detect_steady_state, profile_stations_m
from ..post.trust import AxisGauge, cable_sample_points

__all__ = ["History", "Recorder", "earliest_steady_s", "expected_drift_N_per_s", "record_state", "steady_quantity"]


@dataclass
class History:
    """Time histories saved at the output interval."""

    time_s: list = field(default_factory=list)
    pull_force_N: list = field(default_factory=list)
    trailing_tension_N: list = field(default_factory=list)
    max_tension_N: list = field(default_factory=list)
    max_penetration_m: list = field(default_factory=list)
    max_axis_offset_m: list = field(default_factory=list)
    max_axis_offset_s_conduit_m: list = field(default_factory=list)

    def arrays(self) -> dict[str, np.ndarray]:
        """The recorded columns as float arrays; a column nothing was recorded into (the contact
        columns of a steady solve, whose pseudo-time steps record forces only) is left out, so
        that every column returned has one value per row."""
        rows = len(self.time_s)
        return {k: np.asarray(v, dtype=float) for k, v in self.__dict__.items() if len(v) or not rows}


def earliest_steady_s(cable) -> float:
    """Where a steady window may start [s]: after the start-up damper has faded
    (``solver.startup_time``), 0 without one."""
    damper = getattr(cable, "startup_damper", None)
    return float(damper.duration) if damper is not None else 0.0


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


def record_state(cable, t: float, history: History, gauge: AxisGauge | None = None,
                 tension_N: np.ndarray | None = None) -> None:
    """Append the current pulling force, trailing tension and maximum tension (from the equilibrium
    of the cable's loads, :meth:`exucable.model.build.CableInConduit.tension_N`) to ``history``, and
    (with a contact kernel) the largest penetration [m] and the cable axis's largest distance from
    the conduit's axis [m] with its place s [m] along the scenario's conduit (``gauge``:
    :class:`exucable.post.trust.AxisGauge` of the pull-oriented conduit). ``tension_N``: that
    tension [N] at :func:`exucable.post.tension.profile_stations_m`'s stations, when the caller has it."""
    q, v = cable.coordinates()
    # the tension from the equilibrium of the cable's loads, at the tension profile's stations
    # (exucable.post.tension.equilibrium_tension; EA·ε spikes next to the bend ends' point loads)
    N = cable.tension_N(profile_stations_m(cable.layout.element_length_m)) if tension_N is None else tension_N
    trail = cable.trailing_reaction_N()
    if trail is None:
        trail = float(N[0])
    history.time_s.append(float(t))
    history.pull_force_N.append(cable.pull_force_N(t))
    history.trailing_tension_N.append(float(trail))
    history.max_tension_N.append(float(np.max(N)))
    pen = offset = s_off = float("nan")
    if cable.kernel is not None:
        # the tension's contact pass at this state (kept by the kernel) has every point's δ
        delta = cable.kernel.points(q.reshape(-1), v.reshape(-1)).penetration_m
        found = np.isfinite(delta)
        pen = float(np.max(delta[found])) if found.any() else -np.inf
        if gauge is not None:
            d, s = gauge(cable_sample_points(q, cable.layout.element_length_m))
            # beyond the conduit's ends the cable is free (feed, pulling line): not the wall's business
            d = np.where((s >= 0.0) & (s <= gauge.length_m), d, -np.inf)
            i = int(np.argmax(d))
            offset = float(d[i]) if np.isfinite(d[i]) else float("nan")
            s_off = float(s[i]) if cable.scenario.pull.direction != "reverse" else float(gauge.length_m - s[i])
    history.max_penetration_m.append(pen)
    history.max_axis_offset_m.append(offset)
    history.max_axis_offset_s_conduit_m.append(s_off)


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
    earliest_steady_s : float
        No steady window starts before this time [s] (see :func:`earliest_steady_s`).

    Attributes
    ----------
    history : History
    stopped_steady : bool
    """

    def __init__(self, cable, output_interval_s: float, steady_stop: bool = False, steady_window_s: float = 0.2,
                 steady_tolerance: float = 1e-3, progress=None, earliest_steady_s: float = 0.0):
        self.cable = cable
        self.output_interval_s = float(output_interval_s)
        self.steady_stop = steady_stop
        self.steady_window_s = steady_window_s
        self.steady_tolerance = steady_tolerance
        self.earliest_steady_s = float(earliest_steady_s)
        self.progress = progress
        self.history = History()
        self.stopped_steady = False
        self._next_s = self.output_interval_s
        self._gauge = None

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
                                     expected_drift_N_per_s=expected_drift_N_per_s(self.cable),
                                     earliest_s=self.earliest_steady_s)
            if st.steady:
                self.stopped_steady = True
                return False
        return True

    def record(self, t: float) -> None:
        """Record the state now (at simulated time ``t`` [s])."""
        if self._gauge is None and self.cable.kernel is not None:
            # built on first use: the axis samples cost a tree over the centreline
            self._gauge = AxisGauge(self.cable.conduit.centreline, self.cable.conduit.inner_radius_m)
        # a model of several cables records its own row (the bundle's: exucable.model.bundle_rig)
        own = getattr(self.cable, "record_state", None)
        if own is not None:
            own(t, self.history, self._gauge)
        else:
            record_state(self.cable, t, self.history, self._gauge)
