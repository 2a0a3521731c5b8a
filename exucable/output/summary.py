"""The run summary: one typed record of everything ``summary.json`` holds (docs/results-format.md).

:func:`exucable.run.run_scenario` fills a :class:`RunSummary`, :func:`exucable.output.results.write_results`
writes it as ``summary.json`` and :class:`exucable.api.Result` exposes it. Its fields are the file's keys,
in one place: :data:`SUMMARY_KEYS` lists them, and ``tests/test_run_summary.py`` checks that the results
format names each one.

A summary also reads like the JSON object it is written as (``summary["pull_force_N"]``,
``summary.get("bends")``, ``"start" in summary``): keys that do not apply to a run (a bundle's
``bundle``, a single cable's ``mode_rule``; the optional ones below when unset) are absent there,
exactly as in the file.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Iterator

__all__ = ["RunSummary", "SUMMARY_KEYS"]

# Which runs write a key: "cable" (one cable: cable.count = 1), "bundle" (cable.count > 1), both, or
# "time" (one cable, and several cables in the dynamic mode: what a time integration finds).
_ONE, _BUNDLE, _BOTH, _TIME = "cable", "bundle", "both", "time"


def _key(doc: str, runs: str = _ONE, optional: bool | str = False, default: Any = None):
    """A summary.json key: ``doc`` says what it holds (with its unit); ``optional`` keys are left out
    of the file while unset (None), the others are written as null; ``optional`` naming another
    key: written (null too) exactly when that key is set."""
    return field(default=default, metadata={"doc": doc, "runs": runs, "optional": optional})


@dataclass(frozen=True, eq=False)
class RunSummary(Mapping):
    """What one run found, as written to ``summary.json`` (attributes: below, from the key table)."""

    name: str = _key("the scenario's name", _BOTH, default="")
    mode: str = _key('"dynamic" (time integration) or "steady" (the static solve of steady sliding): the mode used',
                     _BOTH, default="dynamic")
    mode_rule: str | None = _key('the mode as given, or what solver.mode = "auto" chose and why')
    cable_element: str | None = _key('who assembled the cable\'s elastic forces: "compiled" (exucable\'s copy of '
                                     'the ANCF cable element, steady mode, solver.cable_element) or "exudyn" '
                                     '(Exudyn\'s ObjectANCFCable)')
    static_solver: str | None = _key('steady mode: who ran the static solves\' Newton iterations: "exucable" (our '
                                     'own loop on the assembled system, solver.static_solver) or "exudyn" '
                                     '(Exudyn\'s static solver); None in dynamic mode')
    status: str = _key('"ok", "steady", "failed" or the first trust flag (docs/results-format.md "Status")',
                       _BOTH, default="failed")
    message: str = _key("what the solver or the trust checks said; empty when there is nothing to say",
                        _BOTH, default="")
    pull_force_N: float | None = _key("pulling force at the leading end [N]: the steady window's mean (dynamic) "
                                      "or the steady sliding state's (steady); None without a recorded state",
                                      _BOTH)
    pull_force_std_N: float | None = _key("scatter of the pulling force in the steady window about the "
                                          "references' drift [N]", _TIME)
    reference_drift_N_per_s: float | None = _key("how fast the references move as the cable leaves the "
                                                 "conduit under gravity [N/s]", _TIME)
    pull_force_uncertainty_N: float | None = _key("uncertainty of pull_force_N [N] (None: none made)", _BOTH)
    pull_force_uncertainty_method: str | None = _key("how pull_force_uncertainty_N was found", _BOTH)
    trailing_tension_uncertainty_N: float | None = _key(
        "force-controlled steady solve: uncertainty of trailing_tension_N [N]",
        optional="trailing_tension_uncertainty_method")
    trailing_tension_uncertainty_method: str | None = _key(
        "force-controlled steady solve: how trailing_tension_uncertainty_N was found", optional=True)
    pull_force_drift_N_per_s: float | None = _key("dynamic mode: the pulling force's drift over the steady "
                                                  "window [N/s]", _TIME)
    pull_force_unexplained_drift_N_per_s: float | None = _key(
        "dynamic mode: that drift less the references' expected drift [N/s]", _TIME)
    pull_force_uncertainty: dict | None = _key("the uncertainty's parts (dynamic: periods and window [s]; "
                                               "steady: mesh_N, solve_N, wall_N, coarse_value_N, coarse_elements; "
                                               "several cables also layer_N, cpu_time_s [s])", _BOTH)
    steady_quantity: str | None = _key("the history column the steady detector watches", _TIME)
    steady_drift_N: float | None = _key("drift of that quantity over the steady window [N]", _TIME)
    trailing_tension_N: float | None = _key("tension at the trailing end [N] (a bundle: its back tension)", _BOTH)
    max_tension_N: float | None = _key("largest tension along the cable [N] (a bundle: in any cable)", _BOTH)
    steady: bool | None = _key("whether a steady state was found", _TIME)
    steady_from_s: float | None = _key("start of the steady window [s]", _TIME)
    simulated_time_s: float | None = _key("simulated time reached [s] (steady mode: 0)", _TIME)
    steps: int | None = _key("accepted time or pseudo-time steps", _BOTH)
    newton_iterations: int | None = _key("Newton iterations, those of rejected steps included", _BOTH)
    newton_iterations_per_step: float | None = _key("newton_iterations per accepted step", _TIME)
    jacobian_updates: int | None = _key("Jacobian updates of the solver", _TIME)
    wall_time_s: float | None = _key("wall time of the solve [s]", _BOTH)
    build_time_s: float | None = _key("wall time of building the model [s]", _BOTH)
    kernel_time_s: float | None = _key("wall time in the contact kernel [s]", _TIME)
    max_check_point_line_load_N_per_m: float | None = _key(
        "largest single check point's normal force over its share of the element [N/m] (a mesh-dependent "
        "line load, not a pressure to set against a cable's limit); None without contact")
    rope_pull_force_N: float | None = _key("the centreline rope reference's pulling force [N]")
    rope_trailing_tension_N: float | None = _key("the rope reference's trailing tension [N]")
    rope_max_sidewall_pressure_N_per_m: float | None = _key("the rope reference's largest sidewall pressure [N/m]")
    rope_clearance_pull_force_N: float | None = _key("the rope with clearance's pulling force [N] (the EJ -> 0 "
                                                     "limit)")
    reference_pulled_out_m: float | None = _key("how far the cable was pulled out of its start where the "
                                                "references were taken [m]")
    max_sidewall_pressure_N_per_m: float | None = _key(
        "largest windowed sidewall pressure [N/m] (contact force within s +- w/2 over w); None without contact")
    pressure_window_m: float | None = _key("the sidewall pressure's window w [m]", optional=True)
    pressure_window_rule: str | None = _key("how the window was chosen", optional=True)
    max_sidewall_pressure_s_conduit_m: float | None = _key("where max_sidewall_pressure_N_per_m is, along the "
                                                           "scenario's conduit [m]", optional=True)
    rope_max_windowed_sidewall_pressure_N_per_m: float | None = _key(
        "the rope's largest windowed sidewall pressure [N/m]", optional=True)
    bends: list | None = _key("one row per bend (bends.csv's columns)")
    bundle: dict | None = _key("several cables: the bundle's report (docs/results-format.md \"Several cables\")",
                               _BUNDLE)
    mesh: dict | None = _key("elements, check points, the rule's values and their source", _BOTH)
    warnings: list = _key("what the run warns about, one sentence each", _BOTH, default=())
    scenario: dict | None = _key("the scenario with every default filled in", _BOTH)
    versions: dict | None = _key("versions of exucable, Exudyn, numpy, Python", _BOTH)
    start: dict | None = _key('solver.start_from = "steady": how the dynamic run was started', _TIME, optional=True)
    failed_at_s: float | None = _key("a failed run: the simulated time of the failure [s]", _TIME, optional=True)
    flags: list = _key("every trust flag found: flag, message, place s_conduit_m [m], time time_s [s]", _BOTH,
                       default=())
    trust_limits: dict | None = _key("the limits the trust flags apply", _TIME)
    snapshots_s: list | None = _key("times of the snapshots written [s]", optional=True)
    snapshots_not_reached_s: list | None = _key("snapshot times the run did not reach [s]", optional=True)
    files: dict | None = _key("each data file the summary vouches for -> its size in bytes (set when written)",
                              _BOTH, optional=True)

    @cached_property
    def _data(self) -> dict:
        kind = _BUNDLE if self.bundle is not None else _ONE
        kinds = (kind, _BOTH) + ((_TIME,) if kind == _ONE or self.mode == "dynamic" else ())
        out = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            optional = f.metadata["optional"]
            decides = getattr(self, optional) if isinstance(optional, str) else value
            if f.metadata["runs"] not in kinds or (optional and decides is None):
                continue
            out[f.name] = list(value) if isinstance(value, tuple) else value
        return out

    def to_dict(self) -> dict:
        """The JSON object of ``summary.json`` (a new dict; values not copied)."""
        return dict(self._data)

    def __getitem__(self, key: str) -> Any:
        return self._data[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __repr__(self) -> str:
        return (f"RunSummary(name={self.name!r}, mode={self.mode!r}, status={self.status!r}, "
                f"pull_force_N={self.pull_force_N!r})")

    @classmethod
    def from_dict(cls, data: Mapping) -> "RunSummary":
        """A summary from a ``summary.json`` object (keys this version does not know are refused)."""
        unknown = set(data) - set(SUMMARY_KEYS)
        if unknown:
            raise ValueError(f"summary keys unknown to this exucable: {', '.join(sorted(unknown))}")
        return cls(**data)


#: Every key ``summary.json`` may hold, in the order it is written.
SUMMARY_KEYS: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(RunSummary))

RunSummary.__doc__ += "\n\nAttributes\n----------\n" + "\n".join(
    f"{f.name} : {f.type}\n    {f.metadata['doc']}" + (" (only when set)" if f.metadata["optional"] else "")
    + {_BOTH: "", _ONE: " (one cable only)", _BUNDLE: " (several cables only)",
       _TIME: " (one cable, and several cables in the dynamic mode)"}[f.metadata["runs"]]
    for f in dataclasses.fields(RunSummary))
