"""Pull planning: both pull directions, section by section, with the limits checked.

What the installation calculators (Polywater Pull-Planner, Southwire SIMpull, Cableizer, the CommScope
and Southwire manuals' hand calculations) give for a route and a cable set, from exucable's rope
reference (:mod:`exucable.quasistatic.rope`): for each direction the tension entering and leaving every section,
the sidewall bearing pressure (SWBP) in every bend, the limit checks with margins, and the recommended
direction (the lower maximum tension among the directions that violate no limit). With ``engine =
"steady"`` (the default for one cable) or ``"dynamic"`` each direction is also run on the multibody model of one cable
(:func:`exucable.run.run_scenario`), whose section tensions and windowed SWBP replace the rope's, the rope's
kept beside them.

Several cables per duct enter as the calculators have them (:mod:`exucable.quasistatic.engineering`): the weight of
all cables W = n·w, and friction multiplied by the weight correction factor w_c, so that the rope
equation gives T_out = T_in + w_c μ W L on a level straight and T_out = T_in e^{w_c μ θ} in a bend
without weight (Polywater, "Weight Correction Factor in Pulling Tension Calculations"; with
``cable.weight_correction_in_bends = false``, T_in e^{μ θ} as in SEC TES-P-104.05). The rope keeps
gravity exactly on slopes and vertical bends, where the calculators use approximations.

The scenario keys used here beyond the simulation's: ``cable.count``, ``cable.arrangement``,
``[limits]``, ``pull.feed_from_reel`` and ``[display] units`` (rows of
:data:`exucable.scenario.fields.FIELDS`; quantities may be ``"value unit"`` strings, and bare numbers are
imperial with ``display.units = "imperial"``, converted to SI when the file is read).
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from exucable.quasistatic import engineering as eng
from exucable.errors import ExucableError, ModelError, ScenarioError
from exucable.geometry.centreline import Centreline
from exucable.quasistatic.rope import sidewall_pressure_N_per_m, solve_rope
from exucable.scenario.specs import Scenario, load_scenario, parse_scenario
from exucable.post.trust import TRUSTED_STATUSES
from exucable.scenario.units import SYSTEMS
from exucable.output.versions import versions

__all__ = ["PlanLimits", "PlanSpec", "plan_spec", "parse_plan_scenario", "load_plan_scenario", "plan_pull", "pull_in_rope",
           "arrangement_left", "run_headline", "BUNDLE_CPU_BUDGET_S",
           "ENGINES", "CHECKS", "point_names"]

ENGINES = ("auto", "rope", "steady", "dynamic")
#: CPU time a simulated bundle's steady solve may take per direction [s] before the plan gives it up
#: (status failed, saying so): bundles through bends do not yet solve reliably, and a plan must
#: answer in minutes rather than stall.
BUNDLE_CPU_BUDGET_S = 60.0


def resolve_engine(engine: str, count: int) -> tuple[str, str]:
    """The engine ``"auto"`` stands for, and why: the multibody steady solve for one cable (the
    most accurate single-cable answer, seconds per direction, the rope's values beside), the rope
    for several cables per duct (not simulated: the calculators' weight correction)."""
    if engine != "auto":
        return engine, "given (--engine)"
    if count == 1:
        return "steady", "auto: one cable, the multibody model's steady solve (--engine rope for an instant answer)"
    return "rope", (f"auto: {count} cables per duct, the rope with the weight correction factor (--engine steady "
                    "simulates them, but does not yet solve reliably through bends)")


@dataclass(frozen=True)
class PlanLimits:
    """The limits in force, SI (None: not given). See :class:`exucable.scenario.specs.LimitsSpec`.

    ``conductor_tension_N`` is computed from ``limits.conductor_*`` by
    :func:`exucable.quasistatic.engineering.max_tension_from_conductors_N`.
    """

    max_tension_N: float | None = None
    grip_limit_N: float | None = None
    conductor_tension_N: float | None = None
    max_sidewall_pressure_N_per_m: float | None = None
    min_bend_radius_multiple: float | None = None
    min_clearance_m: float | None = None
    max_fill_percent: float | None = None


@dataclass(frozen=True)
class PlanSpec:
    """Planning inputs taken from a scenario.

    Attributes
    ----------
    count : int
        Cables of the described kind in the duct (``cable.count``).
    arrangement : str
        ``cable.arrangement`` (``"auto"`` or an arrangement).
    units : str
        ``"si"`` or ``"imperial"``: units of the printed tables and the report.
    limits : PlanLimits
    feed_from_reel : bool
        Also compute the pull-in history (``pull.feed_from_reel``).
    weight_correction_in_bends : bool
        The weight correction factor multiplies the friction in bends too (``cable.weight_correction_in_bends``).
    """

    count: int = 1
    arrangement: str = "auto"
    units: str = "si"
    limits: PlanLimits = field(default_factory=PlanLimits)
    feed_from_reel: bool = False
    weight_correction_in_bends: bool = True


def plan_spec(scenario: Scenario, units: str | None = None) -> PlanSpec:
    """The planning inputs of a scenario; ``units`` overrides the display units of the output only."""
    lim = scenario.limits
    conductor = None
    if lim.conductor_material is not None:
        rule = lim.conductor_rule or ("us" if scenario.display.units == "imperial" else "iec")
        conductor = eng.max_tension_from_conductors_N(lim.conductor_material, lim.conductor_area_m2,
                                                      lim.conductors, rule)
    limits = PlanLimits(max_tension_N=lim.max_tension_N, grip_limit_N=lim.grip_limit_N,
                        conductor_tension_N=conductor,
                        max_sidewall_pressure_N_per_m=lim.max_sidewall_pressure_N_per_m,
                        min_bend_radius_multiple=lim.min_bend_radius_multiple, min_clearance_m=lim.min_clearance_m,
                        max_fill_percent=lim.max_fill_percent)
    if units is not None and units not in SYSTEMS:
        raise ExucableError(f"--units: must be one of {', '.join(SYSTEMS)}, got {units!r}")
    return PlanSpec(count=scenario.cable.count, arrangement=scenario.cable.arrangement,
                    units=units or scenario.display.units, limits=limits,
                    feed_from_reel=scenario.pull.feed_from_reel,
                    weight_correction_in_bends=scenario.cable.weight_correction_in_bends)


def parse_plan_scenario(data: dict, base_dir: Path, default_name: str = "scenario",
                        units: str | None = None) -> tuple[Scenario, PlanSpec]:
    """A scenario dict (as read from TOML) and its planning inputs; ``units``: display units of the output."""
    scenario = parse_scenario(data, base_dir, default_name)
    return scenario, plan_spec(scenario, units)


def load_plan_scenario(path, units: str | None = None) -> tuple[Scenario, PlanSpec]:
    """Read a scenario file and its planning inputs (``units`` overrides the output's display units)."""
    scenario = load_scenario(path)
    return scenario, plan_spec(scenario, units)


# ------------------------------------------------------------------------------------------ sections

def _slope_deg(direction) -> float:
    return math.degrees(math.asin(max(-1.0, min(1.0, float(direction[2]))))) + 0.0  # no "-0"


def _bend_plane(piece) -> str:
    """horizontal / vertical up / vertical down / 3D, from the bend's axis and its change of height."""
    if piece.kind == "helix":
        return "helix"
    axis_z = abs(float(piece.axis[2]))
    if axis_z > 1.0 - 1e-9:
        return "horizontal"
    if axis_z < 1e-9:
        dz = float(piece.end_tangent[2] - piece.direction[2])
        return "vertical up" if dz > 0 else "vertical down"
    return "3D"


def _piece_samples(piece, n: int = 65) -> np.ndarray:
    """Arc lengths inside a piece (kept off its ends, where the curvature of the neighbour begins)."""
    eps = 1e-9 * piece.length_m
    return np.linspace(piece.s_start_m + eps, piece.s_end_m - eps, n)


def _sections(curve, rope, w_N_per_m: float, swbp_factor: float) -> list[dict]:
    """Section table of one direction, in pull order, from the rope solution on ``curve``."""
    rows = []
    running_max = float(rope.trailing_tension_N)
    for i, p in enumerate(curve.pieces):
        s = _piece_samples(p)
        tension = np.asarray(rope.tension_at(s - 0.0), dtype=float)
        running_max = max(running_max, float(np.max(tension)))
        row = {
            "index": i + 1,
            "kind": p.kind,
            "length_m": float(p.length_m),
            "tension_in_N": float(rope.tension_at(p.s_start_m)),
            "tension_out_N": float(rope.tension_at(min(p.s_end_m, rope.cable_length_m))),
            "sidewall_pressure_N_per_m": None,
            "max_tension_so_far_N": running_max,
            "s_start_m": float(p.s_start_m),
        }
        if p.is_curved:
            pressure = sidewall_pressure_N_per_m(curve, s, tension, w_N_per_m)
            row["sidewall_pressure_N_per_m"] = float(np.max(pressure)) * swbp_factor
            row["plane"] = _bend_plane(p)
            row["radius_m"] = float(p.coil_radius_m)
            row["angle_deg"] = math.degrees(p.turning_angle_rad)
        else:
            row["plane"] = None
            row["slope_deg"] = _slope_deg(p.direction)
        rows.append(row)
    return rows


def point_names(scenario: Scenario, pieces: int) -> list[str]:
    """Names of the route's ``pieces + 1`` points in route order: ``display.point_names``, else A, B, …, Z,
    AA, AB, … (the letters the installation manuals put on their route drawings).

    Raises
    ------
    ScenarioError
        ``display.point_names`` of the wrong length, naming the count needed.
    """
    given = scenario.display.point_names
    if given is not None:
        if len(given) != pieces + 1:
            raise ScenarioError("display.point_names", f"must name {pieces + 1} points (the route's start and the "
                                                       f"end of each of its {pieces} pieces), got {len(given)}")
        return list(given)
    names = []
    for i in range(pieces + 1):
        name, k = "", i
        while True:
            name = chr(ord("A") + k % 26) + name
            k = k // 26 - 1
            if k < 0:
                break
        names.append(name)
    return names


def _name_sections(rows: list[dict], names: list[str], direction: str) -> None:
    """Give each section (pull order) its place on the route: ``route_index`` (1-based, route order),
    ``from_point`` and ``to_point`` in pull direction, ``name`` ("B–C"), and ``bend_number`` (bends and
    helices counted in route order, the same in both directions; None on straights)."""
    n = len(rows)
    curved = [r["sidewall_pressure_N_per_m"] is not None for r in (rows if direction == "forward" else rows[::-1])]
    bend_numbers = list(np.cumsum(curved))
    for r in rows:
        k = r["index"] if direction == "forward" else n + 1 - r["index"]
        a, b = (names[k - 1], names[k]) if direction == "forward" else (names[k], names[k - 1])
        r.update(route_index=k, from_point=a, to_point=b, name=f"{a}–{b}",
                 bend_number=int(bend_numbers[k - 1]) if curved[k - 1] else None)


def _pull_in_history(curve: Centreline, rope, n: int = 201) -> dict:
    """Tension at the cable's head while it advances from the entrance to the exit (rope, quasi-static).

    While the head is at distance x along the route, the cable fills [0, x] with the reel's back tension
    at its tail; the rope equation integrates from the tail, so the head's tension is the full pull's
    tension profile T(x): one solution gives the whole history. The pulling line from the head to the rig
    is taken as free of friction, so the rig's force is the head's tension. Grid: ``n`` uniform head
    positions plus every piece boundary.
    """
    L = curve.length_m
    grid = np.unique(np.concatenate([np.linspace(0.0, L, n), [p.s_end_m for p in curve.pieces]]))
    grid = np.clip(grid, 0.0, rope.cable_length_m)
    return {"engine": "rope", "pulled_length_m": grid.tolist(),
            "pull_force_N": np.asarray(rope.tension_at(grid)).tolist()}


def _steady_pull_in_history(scenario: Scenario, direction: str, rope) -> dict:
    """The multibody pull-in history (:func:`exucable.solve.pull_in.steady_pull_in`: one steady solve per
    head position, each from the last state), the rope's head tension at the same places beside
    (``rope_pull_force_N``). Failed points are left out of the table and counted (``failed_points``)."""
    from exucable.solve.pull_in import DEFAULT_POINTS, steady_pull_in  # builds Exudyn models

    sc = dataclasses.replace(scenario, pull=dataclasses.replace(scenario.pull, direction=direction))
    h = steady_pull_in(sc, DEFAULT_POINTS)
    ok = np.isfinite(h.pull_force_N)
    x = h.pulled_length_m[ok]
    return {"engine": "steady", "pulled_length_m": x.tolist(), "pull_force_N": h.pull_force_N[ok].tolist(),
            "rope_pull_force_N": np.asarray(rope.tension_at(np.clip(x, 0.0, rope.cable_length_m))).tolist(),
            "failed_points": int(h.failed), "cpu_time_s": h.cpu_time_s}


#: The rope solver's argument names (its errors' keys) → the scenario keys a plan gives them from.
_PLAN_ROPE_KEYS = {"friction": "contact.friction", "bend_friction": "contact.friction",
                   "trailing_tension_N": "pull.back_tension", "weight_per_length_N_per_m": "cable.mass_per_length"}


def pull_in_rope(scenario: Scenario, spec: PlanSpec, direction: str = "forward", friction: float | None = None,
                 bend_friction: float | None = None):
    """The rope of a full pull in ``direction`` with plan's conventions, whose tension profile is the
    pull-in history (see :func:`_pull_in_history`).

    Parameters
    ----------
    scenario : Scenario
    spec : PlanSpec
        Number of cables and arrangement (weight correction factor w_c, which multiplies the friction
        on straights, and in bends with ``spec.weight_correction_in_bends``).
    direction : {"forward", "reverse"}
    friction : float, optional
        Friction coefficient μ [-] (default ``contact.friction``).
    bend_friction : float, optional
        A separate μ [-] for bends and helices (default: ``friction``).

    Returns
    -------
    exucable.quasistatic.rope.RopeSolution
        ``tension_at(x)`` is the head tension [N] with the head x metres into the conduit.
    """
    d = 2.0 * scenario.cable.radius_m
    D = 2.0 * scenario.conduit.inner_radius_m
    arrangement = eng.auto_arrangement(spec.count, D, d) if spec.arrangement == "auto" else spec.arrangement
    wc = eng.weight_correction_factor(spec.count, arrangement, D, d)
    mu = scenario.contact.friction if friction is None else float(friction)
    g = scenario.gravity.g_m_per_s2 if scenario.gravity is not None else 0.0
    w_total = spec.count * scenario.cable.mass_per_length_kg_per_m * g
    mu_b = mu if bend_friction is None else float(bend_friction)
    # in bends: w_c μ (IEEE 1185, AEIC CG5, Polywater) or μ (SEC TES-P-104.05's worked example)
    mu_bend = wc * mu_b if spec.weight_correction_in_bends else mu_b
    return solve_rope(scenario.build_conduit().centreline, wc * mu, w_total, scenario.pull.back_tension_N,
                      direction, bend_friction=mu_bend)


def _check(name, value, limit, where, quantity, lower_is_better=True) -> dict:
    if lower_is_better:
        passed = value <= limit
        margin = (limit - value) / limit
    else:
        passed = value >= limit
        margin = (value - limit) / limit
    return {"name": name, "passed": bool(passed), "value": float(value), "limit": float(limit),
            "margin": float(margin), "where": where, "quantity": quantity}


def _label(row) -> str:
    if row.get("bend_number") is not None:
        return f"bend {row['bend_number']} ({row['name']})"
    if "name" in row:
        return f"{row['kind']} {row['name']}"
    return f"section {row['index']} ({row['kind']})"


def _checks(direction: dict, spec: PlanSpec, scenario: Scenario, clearance: float, jam) -> list[dict]:
    lim = spec.limits
    rows = direction["sections"]
    worst_t = max(rows, key=lambda r: r["max_tension_so_far_N"])
    where_t = f"{_label(worst_t)} leaving end" if worst_t["tension_out_N"] >= worst_t["tension_in_N"] \
        else f"{_label(worst_t)}"
    t_max = direction["max_tension_N"]
    out = []
    if not math.isfinite(t_max):
        # e^(mu theta) past any float: no limit passes this, given or not
        out.append({"name": "finite_tension", "passed": False, "value": t_max, "limit": None, "margin": None,
                    "quantity": "force", "where": f"{where_t}: the tension grows beyond any number "
                                                  "(friction times the angles turned is too large to pull)"})
    for name, limit in (("max_tension", lim.max_tension_N), ("conductor_tension", lim.conductor_tension_N),
                        ("grip_tension", lim.grip_limit_N)):
        if limit is not None:
            out.append(_check(name, t_max, limit, where_t, "force"))
    bends = [r for r in rows if r["sidewall_pressure_N_per_m"] is not None]
    if lim.max_sidewall_pressure_N_per_m is not None and bends:
        b = max(bends, key=lambda r: r["sidewall_pressure_N_per_m"])
        out.append(_check("max_sidewall_pressure", b["sidewall_pressure_N_per_m"], lim.max_sidewall_pressure_N_per_m,
                          _label(b), "force_per_length"))
    if lim.min_bend_radius_multiple is not None and bends:
        b = min(bends, key=lambda r: r["radius_m"])
        out.append(_check("min_bend_radius", b["radius_m"],
                          lim.min_bend_radius_multiple * 2.0 * scenario.cable.radius_m, _label(b),
                          "length", lower_is_better=False))
    if lim.min_clearance_m is not None:
        out.append(_check("min_clearance", clearance, lim.min_clearance_m, "duct cross-section", "small_length",
                          lower_is_better=False))
    if lim.max_fill_percent is not None:
        fill = eng.conduit_fill_percent(spec.count, 2.0 * scenario.conduit.inner_radius_m,
                                        2.0 * scenario.cable.radius_m)
        out.append(_check("max_fill", fill, lim.max_fill_percent, "duct cross-section", "percent"))
    if jam.risk != "not applicable":
        # A number to compare with: the jam band 2.6 ≤ JR < 2.9 is "significant" (Cableizer JR_p).
        passed = jam.risk != "significant"
        out.append({"name": "jam_ratio", "passed": passed, "value": jam.jam_ratio, "limit": None,
                    "margin": None, "quantity": None, "where": f"jam risk {jam.risk} (significant for 2.6 <= 1.05 D/d < 2.9)"})
    return out


#: Every check a plan can make: name -> (the scenario keys that enable it, what it compares).
CHECKS = {
    "max_tension": ("limits.max_tension", "largest tension against the allowed pulling tension"),
    "conductor_tension": ("limits.conductor_material, conductor_area, conductors",
                          "largest tension against the conductors' allowed stress"),
    "grip_tension": ("limits.grip_limit", "largest tension against the pulling eye's or grip's rating"),
    "max_sidewall_pressure": ("limits.max_sidewall_pressure", "largest sidewall bearing pressure in a bend"),
    "min_bend_radius": ("limits.min_bend_radius_multiple", "smallest bend radius against n cable diameters"),
    "min_clearance": ("limits.min_clearance", "clearance above the uppermost cable"),
    "max_fill": ("limits.max_fill", "conduit fill n·d²/D²"),
    "jam_ratio": ("cable.count = 3", "jam ratio 1.05·D/d outside the band 2.6–2.9"),
}


def _not_checked(checks: list[dict], spec: PlanSpec, has_bends: bool) -> list[dict]:
    """The checks of :data:`CHECKS` not made, each with its reason: no limit given, or not applicable."""
    made = {c["name"] for c in checks}
    out = []
    for name, (key, what) in CHECKS.items():
        if name in made:
            continue
        if name == "jam_ratio":
            why = f"not applicable: {spec.count} cable(s) (jamming concerns three cables)"
        elif name in ("max_sidewall_pressure", "min_bend_radius") and not has_bends and (
                (spec.limits.max_sidewall_pressure_N_per_m if name == "max_sidewall_pressure"
                 else spec.limits.min_bend_radius_multiple) is not None):
            why = "not applicable: the route has no bends"
        else:
            why = f"not checked: no limit given ({key})"
        out.append({"name": name, "what": what, "why": why})
    return out


def _finite_or_none(x):
    x = float(x)
    return x if math.isfinite(x) else None


def _simulated_sections(rope_entry: dict, s_c, T_c, length_m: float, name: str, bends: list, bend_extra):
    """The rope's section rows with the simulated tensions: ``T_c`` [N] at ``s_c`` [m] along the
    scenario's conduit, read at each section's ends (pull-oriented) and its largest inside; each
    bend's row takes its simulated windowed SWBP from ``bends`` (along the scenario's conduit) plus
    ``bend_extra(bend)``'s keys. Returns the sorted (s_c, T_c), the rows and the pull-oriented →
    conduit map."""
    order = np.argsort(s_c)
    s_c, T_c = np.asarray(s_c, dtype=float)[order], np.asarray(T_c, dtype=float)[order]
    to_conduit = (lambda s: s) if name == "forward" else (lambda s: length_m - s)

    def tension(s_pull):
        return float(np.interp(to_conduit(s_pull), s_c, T_c))

    bends = iter(bends if name == "forward" else bends[::-1])
    rows, running = [], tension(0.0)
    for r in rope_entry["sections"]:
        a, b = r["s_start_m"], r["s_start_m"] + r["length_m"]
        lo, hi = sorted((to_conduit(a), to_conduit(b)))
        inside = T_c[(s_c >= lo) & (s_c <= hi)]
        t_in, t_out = tension(a), tension(b)
        running = max(running, t_in, t_out, float(np.max(inside)) if inside.size else t_out)
        row = dict(r, tension_in_N=t_in, tension_out_N=t_out, max_tension_so_far_N=running,
                   rope_tension_in_N=r["tension_in_N"], rope_tension_out_N=r["tension_out_N"],
                   rope_sidewall_pressure_N_per_m=r["sidewall_pressure_N_per_m"])
        if r["sidewall_pressure_N_per_m"] is not None:
            bend = next(bends)
            row.update(sidewall_pressure_N_per_m=float(bend["peak_pressure_N_per_m"]),
                       mean_sidewall_pressure_N_per_m=_finite_or_none(bend["mean_pressure_N_per_m"]),
                       **bend_extra(bend))
        rows.append(row)
    return s_c, T_c, rows, to_conduit


#: Sampling step along the route [m] at which a failed bundle's last state is classified
#: (:func:`arrangement_left`): finer than a bend's length on the industry routes (R 3 m, 45°: 2.4 m).
LEFT_STATION_STEP_M = 0.5


def arrangement_left(model, asked: str, names: list[str], step_m: float = LEFT_STATION_STEP_M) -> list[dict]:
    """Where the cables of a bundle model's current state are not in the ``asked`` arrangement.

    Cross-sections every ``step_m`` along each piece of the scenario's route (inside the cables'
    extent) are classified (:func:`exucable.post.bundle.classify_cross_section`); consecutive
    stations classified otherwise form one stretch.

    Parameters
    ----------
    model : exucable.model.bundle.BundleModel
        Read at its current coordinates (after a failed solve: its last state).
    asked : str
        The arrangement the scenario asked for.
    names : list of str
        The route's point names in route order (:func:`point_names`).
    step_m : float
        Station spacing [m].

    Returns
    -------
    list of dict
        Per stretch, in route order: ``s_start_m``, ``s_end_m`` (the first and last station, along
        the scenario's route from its first point [m]), ``arrangement`` (the most frequent label
        there), ``pieces`` (the pieces it touches, e.g. ``"bend B–C"``).
    """
    from exucable.model.bundle import bundle_cross_sections
    from exucable.post.bundle import classify_cross_section

    sc = model.scenario
    pieces = sc.build_conduit().centreline.pieces      # route order, as the places are given
    stations = []
    for k, piece in enumerate(pieces):
        n = max(3, int(math.ceil(piece.length_m / step_m)))
        s = piece.s_start_m + piece.length_m * (np.arange(n) + 0.5) / n
        stations += [(float(x), k) for x in s]
    s_all = np.array([x for x, _ in stations])
    offsets = bundle_cross_sections(model, s_all)
    labels = []
    for offs in offsets:
        labels.append(None if np.isnan(offs).any() else
                      classify_cross_section(offs, sc.conduit.inner_radius_m, sc.cable.radius_m)["arrangement"])
    stretches, run = [], []
    for (x, k), lab in zip(stations + [(math.nan, -1)], labels + [None]):
        if lab is not None and lab != asked:
            run.append((x, k, lab))
            continue
        if run:
            found = [r[2] for r in run]
            touched = sorted({r[1] for r in run})
            stretches.append({"s_start_m": run[0][0], "s_end_m": run[-1][0],
                              "arrangement": max(set(found), key=found.count),
                              "pieces": [f"{'bend' if pieces[j].is_curved else 'straight'} {names[j]}–{names[j + 1]}"
                                         for j in touched]})
            run = []
    return stretches


def _left_phrase(asked: str, stretches: list[dict], max_shown: int = 4) -> str:
    """``stretches`` (:func:`arrangement_left`) in words, e.g. "the cables left the triangle at 57–63 m
    (bend B–C: cradled)"."""
    word = "the triangle" if asked == "triangular" else f"the {asked} arrangement"
    if not stretches:
        return f"in its last state the cables were still in {word} everywhere"
    shown = [f"{st['s_start_m']:.1f}–{st['s_end_m']:.1f} m ({', '.join(st['pieces'])}: {st['arrangement']})"
             for st in stretches[:max_shown]]
    more = f" and {len(stretches) - max_shown} more" if len(stretches) > max_shown else ""
    return f"in its last state the cables had left {word} at {'; '.join(shown)}{more} (along the route from its start)"


def _bundle_fallback(name: str, engine: str, rope_entry: dict, progress: bool, names: list[str], first, first_cpu_s: float, as_given: bool, notify) -> dict:
    """A bundle's direction whose asked arrangement (``first``: its failed run) is not the one the
    calculators' rule gives for its D/d (:func:`exucable.quasistatic.engineering.auto_arrangement`).

    Says where the asked arrangement broke in the failed run's last state (:func:`arrangement_left`);
    then, unless ``as_given``, simulates the rule's arrangement and returns that entry labelled
    "simulated as <rule> (the <asked> did not hold: …)", the calculators' values for the asked one
    (``rope_*``) beside. With ``as_given`` the failed entry is returned, the reason and place in its
    message. Either way ``arrangement_fallback`` holds ``asked``, ``simulated`` (None: not simulated),
    ``rule``, ``reason``, ``left`` (the stretches), ``attempt_status``, ``attempt_message`` and
    ``attempt_cpu_s``.
    """
    from exucable.run import run_scenario

    sc = first.model.scenario
    asked = first.model.arrangement
    n = sc.cable.count
    D, d = 2.0 * sc.conduit.inner_radius_m, 2.0 * sc.cable.radius_m
    rule = eng.auto_arrangement(n, D, d)
    left = arrangement_left(first.model, asked, names)
    word = "triangle" if asked == "triangular" else f"{asked} arrangement"
    reason = (f"its steady solve found no steady state in {first_cpu_s:.3g} s CPU; D/d {D / d:.3g}, where the "
              f"calculators' rule gives {n} free cables {rule}; {_left_phrase(asked, left)}")
    info = {"asked": asked, "simulated": None if as_given else rule, "rule": rule, "reason": reason, "left": left,
            "attempt_status": first.summary["status"], "attempt_message": first.summary["message"],
            "attempt_cpu_s": first_cpu_s}
    if as_given:
        entry = _bundle_direction(first, name, rope_entry)
        entry["message"] = (f"the {word} did not hold ({reason}); {entry['message']}; fix: plan without "
                            f"--arrangement-as-given to simulate it as {rule}, the rule's arrangement")
        return dict(entry, arrangement_fallback=info, simulated_arrangement=asked)
    if notify is not None:
        notify(f"{name}: the {word} did not hold ({reason}); simulating as {rule}")
    second = run_scenario(sc.replace(**{"cable.arrangement": rule}), None, quiet=not progress, plots=False,
                          mode=engine, cpu_budget_s=BUNDLE_CPU_BUDGET_S)
    entry = _bundle_direction(second, name, rope_entry)
    note = f"simulated as {rule} (the {word} did not hold: {reason})"
    entry["message"] = note + (f"; {entry['message']}" if entry["message"] else "")
    return dict(entry, arrangement_fallback=info, simulated_arrangement=rule)


def run_headline(entry: dict) -> str:
    """The run's message for the ``multibody_run`` check: whole where the run is not trusted (its
    reason and fix), else its first clause (what was simulated), the solve's details, which the
    direction's status line prints in full, left out."""
    message = entry["message"]
    if entry["status"] not in TRUSTED_STATUSES:
        return message
    depth = 0
    for i, ch in enumerate(message):
        depth += {"(": 1, ")": -1}.get(ch, 0)
        if depth == 0 and message.startswith("; ", i):
            return message[:i]
    return message


def _multibody_direction(scenario: Scenario, name: str, engine: str, rope_entry: dict, progress: bool,
                         names: list[str] | None = None, as_given: bool = False, notify=None) -> dict:
    """One direction's plan entry from the multibody model, the rope's values kept beside.

    The scenario is run in ``engine``'s solver mode with ``pull.direction = name`` (the reverse pull is
    the reversed route). Section tensions are the cable's tension (from its loads' equilibrium, at its nodes) interpolated at
    the section boundaries along the conduit (``s_conduit_m``); a bend's SWBP is the peak of the
    windowed sidewall pressure over the bend (:mod:`exucable.post.pressure`: the contact forces of the check
    points within ±w/2, over w), with the bend body's mean windowed pressure and the point loads at
    its ends beside it. A dynamic run's tensions are those of its last state; its pulling force is the
    mean over its steady window.
    """
    from exucable.run import cable_tension_along_conduit, run_scenario  # builds an Exudyn model

    sc = dataclasses.replace(scenario, pull=dataclasses.replace(scenario.pull, direction=name))
    budget = {"cpu_budget_s": BUNDLE_CPU_BUDGET_S} if sc.cable.count > 1 else {}
    cpu0 = time.process_time()
    result = run_scenario(sc, None, quiet=not progress, plots=False, mode=engine, **budget)
    summary = result.summary
    bundle = summary.get("bundle")
    if bundle is not None:
        model = result.model
        D, d = 2.0 * sc.conduit.inner_radius_m, 2.0 * sc.cable.radius_m
        # cables laid at cable.positions are the user's lay, kept as --arrangement-as-given keeps one
        if (summary["status"] == "failed" and sc.cable.positions_m is None
                and model.arrangement != eng.auto_arrangement(sc.cable.count, D, d)):
            return _bundle_fallback(name, engine, rope_entry, progress,
                                    names or point_names(sc, len(model.conduit.centreline.pieces)), result,
                                    time.process_time() - cpu0, as_given, notify)
        from exucable.post.bundle import laid_phrase

        return dict(_bundle_direction(result, name, rope_entry), arrangement_fallback=None,
                    simulated_arrangement=laid_phrase(bundle))
    L = scenario.build_conduit().centreline.length_m
    s_c, T_c, rows, to_conduit = _simulated_sections(
        rope_entry, *cable_tension_along_conduit(result.model), L, name, summary["bends"],
        lambda bend: dict(rope_windowed_sidewall_pressure_N_per_m=float(bend["rope_peak_pressure_N_per_m"]),
                          entry_point_load_N=float(bend["entry_point_load_N"]),
                          entry_s_conduit_m=float(bend["entry_s_conduit_m"]),
                          exit_point_load_N=float(bend["exit_point_load_N"]),
                          exit_s_conduit_m=float(bend["exit_s_conduit_m"])))
    s_pull = np.clip(np.array([to_conduit(s) for s in s_c]), 0.0, L)
    back = np.argsort(s_pull)
    pressures = [r["sidewall_pressure_N_per_m"] for r in rows if r["sidewall_pressure_N_per_m"] is not None]
    return {
        # a run that failed before its first converged state has no pulling force
        "pull_force_N": float("nan") if summary["pull_force_N"] is None else summary["pull_force_N"],
        # the rig pulls on the leading end, so the largest tension is at least the pulling force (a dynamic
        # run's sections are its last state, its pulling force the mean over its steady window)
        "max_tension_N": max([r["max_tension_so_far_N"] for r in rows]
                             + ([] if summary["pull_force_N"] is None else [float(summary["pull_force_N"])])),
        "max_sidewall_pressure_N_per_m": max(pressures) if pressures else None,
        "slack": rope_entry["slack"],
        "sections": rows,
        "profile": {"s_m": s_pull[back].tolist(), "tension_N": T_c[back].tolist()},
        "rope_pull_force_N": rope_entry["pull_force_N"],
        "rope_max_tension_N": rope_entry["max_tension_N"],
        "rope_max_sidewall_pressure_N_per_m": rope_entry["max_sidewall_pressure_N_per_m"],
        "rope_profile": rope_entry["profile"],
        "status": summary["status"],
        "message": summary["message"],
        "flags": summary.get("flags", []),
        "pull_force_std_N": summary.get("pull_force_std_N"),
        "pull_force_uncertainty_N": summary.get("pull_force_uncertainty_N"),
        "pull_force_uncertainty_method": summary.get("pull_force_uncertainty_method"),
        "pressure_window_m": summary.get("pressure_window_m"),
        "elements": int(result.model.layout.element_length_m.size),
        "wall_time_s": summary["wall_time_s"],
    }


def _bundle_direction(result, name: str, rope_entry: dict) -> dict:
    """One direction's plan entry from a simulated bundle (``cable.count`` > 1, steady mode), the
    calculators' values (the rope with the weight correction factor) kept beside.

    Section tensions are the bundle's (the cables' summed, each from its loads' equilibrium,
    :func:`exucable.model.bundle.bundle_tension_along_conduit`);
    a bend's SWBP is the most loaded cable's peak windowed pressure, with the calculators' formula on
    the simulated exit tension beside it (``formula_sidewall_pressure_N_per_m``). A failed solve
    keeps the calculators' sections and says so in ``status`` and ``message``.
    """
    from exucable.model.bundle import bundle_tension_along_conduit

    summary = result.summary
    bundle = summary["bundle"]
    common = {
        "rope_pull_force_N": rope_entry["pull_force_N"], "rope_max_tension_N": rope_entry["max_tension_N"],
        "rope_max_sidewall_pressure_N_per_m": rope_entry["max_sidewall_pressure_N_per_m"],
        "rope_profile": rope_entry["profile"], "status": summary["status"], "message": summary["message"],
        "flags": summary.get("flags", []),
        "pull_force_uncertainty_N": summary.get("pull_force_uncertainty_N"),
        "pull_force_uncertainty_method": summary.get("pull_force_uncertainty_method"),
        "elements": int(result.model.layout.element_length_m.size), "wall_time_s": summary["wall_time_s"],
        "bundle": {k: bundle.get(k) for k in ("count", "arrangement", "positions_given", "weight_correction_factor",
                                              "formula_weight_correction_factor", "straights", "sections", "bends",
                                              "jam", "jam_s_conduit_m", "cables")},
    }
    if summary["status"] == "failed":
        # no simulated state to report: the calculators' sections and values, marked so by the status
        common["bundle"] = {k: (v if k in ("count", "arrangement", "formula_weight_correction_factor") else None)
                            for k, v in common["bundle"].items()}
        return dict(rope_entry, pull_force_N=float("nan"), **common)
    L = result.model.scenario.build_conduit().centreline.length_m
    s_c, T_c, rows, to_conduit = _simulated_sections(
        rope_entry, *bundle_tension_along_conduit(result.model), L, name, bundle["bends"],
        lambda bend: dict(formula_sidewall_pressure_N_per_m=float(bend["formula_pressure_N_per_m"]),
                          most_loaded_cable=int(bend["most_loaded_cable"])))
    pressures = [r["sidewall_pressure_N_per_m"] for r in rows if r["sidewall_pressure_N_per_m"] is not None]
    order = np.argsort([to_conduit(s) for s in s_c])
    return {
        "pull_force_N": summary["pull_force_N"],
        "max_tension_N": max([r["max_tension_so_far_N"] for r in rows] + [float(summary["pull_force_N"])]),
        "max_sidewall_pressure_N_per_m": max(pressures) if pressures else None,
        "slack": rope_entry["slack"],
        "sections": rows,
        "profile": {"s_m": [float(np.clip(to_conduit(s), 0.0, L)) for s in s_c[order]], "tension_N": T_c[order].tolist()},
        **common,
    }


def _label_bundle_sections(entry: dict, formula_arrangement: str) -> None:
    """Put on each section row of a simulated bundle's direction the arrangement the formula assumed,
    the one simulated, and the one found there in the simulated state (None when nothing solved)."""
    found = {row["section"]: row["arrangement"] for row in (entry["bundle"].get("sections") or [])}
    solved = entry["bundle"].get("weight_correction_factor") is not None
    for r in entry["sections"]:
        r.update(formula_arrangement=formula_arrangement, simulated_arrangement=entry["simulated_arrangement"],
                 arrangement_found=found.get(r["route_index"]) if solved else None)


def plan_pull(scenario: Scenario, spec: PlanSpec, engine: str = "auto", progress: bool = False,
              arrangement_as_given: bool = False, notify=None) -> dict:
    """Plan a pull in both directions.

    Parameters
    ----------
    scenario : Scenario
        Route, cable (one of the ``spec.count`` identical cables), friction, back tension, gravity.
    spec : PlanSpec
    engine : {"auto", "rope", "steady", "dynamic"}
        ``"auto"`` (default): ``"steady"`` for one cable, ``"rope"`` for several (:func:`resolve_engine`).
        ``"rope"``: the quasi-static rope (instant). ``"steady"`` / ``"dynamic"``: the multibody model of
        one cable (:func:`exucable.run.run_scenario` in that solver mode, one run per direction, the
        reverse run on the reversed route); the rope's values stay beside each section's
        (``rope_*`` keys), see :func:`_multibody_direction`. Several cables: ``"steady"`` simulates the
        bundle (:func:`_bundle_direction`, the calculators' values beside).
    progress : bool
        Show the multibody runs' progress bars on a terminal (stderr).
    arrangement_as_given : bool
        Several cables, ``"steady"``: when the asked arrangement is not the one the calculators' rule
        gives for the duct's D/d (:func:`exucable.quasistatic.engineering.auto_arrangement`: three free
        cables are cradled at D/d ≥ 2.5) and its solve fails, report it failed, with where it broke
        (:func:`arrangement_left`), rather than simulate the rule's arrangement (the default; the
        direction's ``arrangement_fallback`` and ``simulated_arrangement`` say which was simulated
        and why, the calculators' values for the asked arrangement beside).
    notify : callable, optional
        Called with a line of text when a direction falls back to the rule's arrangement (the
        command prints it; another solve of up to :data:`BUNDLE_CPU_BUDGET_S` follows).

    Returns
    -------
    dict
        The content of ``plan.json`` (SI): ``engine`` (the one used), ``engine_rule``, ``directions.forward`` / ``.reverse`` (each with
        ``pull_force_N``, ``max_tension_N``, ``max_sidewall_pressure_N_per_m``, ``sections``, ``checks``,
        ``passed`` and, if asked, ``pull_in``), ``recommended_direction``, ``weight_correction_factor``,
        ``jam_ratio``, ``jam_risk``, ``clearance_m``, ``arrangement``, ``count``, ``checks`` and
        ``not_checked`` (those of the recommended direction; every direction has its own), ``passed``,
        ``fill_percent``, ``point_names`` (route order), ``inputs``, ``versions``. Each section row has
        ``route_index``, ``name`` ("B–C" in pull direction) and ``bend_number`` (route order); a simulated
        bundle's rows also ``formula_arrangement`` (the calculators'), ``simulated_arrangement`` and
        ``arrangement_found`` (in that section of the simulated state; None without one).

    Raises
    ------
    ExucableError
        An unknown ``engine``; ``cable.count`` > 1 with the dynamic engine (it simulates one cable).
    """
    if engine not in ENGINES:
        raise ExucableError(f"--engine: must be one of {', '.join(ENGINES)}, got {engine!r}")
    engine, engine_rule = resolve_engine(engine, spec.count)
    if engine == "dynamic" and spec.count != 1:
        raise ScenarioError("cable.count", f"--engine dynamic simulates one cable, got {spec.count}; plan "
                                           "several cables per duct with --engine rope (weight correction "
                                           "factor) or --engine steady (simulated), or set cable.count = 1")
    if scenario.pull.force_N is not None:
        raise ScenarioError("pull.force", "exucable plan computes the pulling force from the back tension; give "
                                          "pull.back_tension (the reel's) instead of a prescribed pull.force")
    d = 2.0 * scenario.cable.radius_m
    D = 2.0 * scenario.conduit.inner_radius_m
    arrangement = eng.auto_arrangement(spec.count, D, d) if spec.arrangement == "auto" else spec.arrangement
    wc = eng.weight_correction_factor(spec.count, arrangement, D, d)
    swbp_factor = eng.sidewall_pressure_factor(spec.count, arrangement, wc)
    jam = eng.jam_risk(spec.count, D, d)
    clearance = eng.clearance_m(spec.count, arrangement, D, d)
    g = scenario.gravity.g_m_per_s2 if scenario.gravity is not None else 0.0
    w_total = spec.count * scenario.cable.mass_per_length_kg_per_m * g
    back = scenario.pull.back_tension_N
    centreline = scenario.build_conduit().centreline
    names = point_names(scenario, len(centreline.pieces))

    directions = {}
    for name in ("forward", "reverse"):
        curve = centreline if name == "forward" else centreline.reversed()
        try:
            rope = pull_in_rope(scenario, spec, name)
        except ModelError as exc:
            # the rope solver names its own arguments; the user knows the scenario's keys
            raise ModelError(_PLAN_ROPE_KEYS.get(exc.key, exc.key), exc.message) from None
        rows = _sections(curve, rope, w_total, swbp_factor)
        _name_sections(rows, names, name)
        bends = [r["sidewall_pressure_N_per_m"] for r in rows if r["sidewall_pressure_N_per_m"] is not None]
        entry = {
            "pull_force_N": rope.pull_force_N,
            "max_tension_N": max(rope.max_tension_N, max(r["max_tension_so_far_N"] for r in rows)),
            "max_sidewall_pressure_N_per_m": max(bends) if bends else None,
            "slack": rope.slack,
            "sections": rows,
            "profile": {"s_m": (rope.s_cable_m).tolist(), "tension_N": rope.tension_N.tolist()},
        }
        if engine != "rope":
            entry = _multibody_direction(scenario, name, engine, entry, progress, names, arrangement_as_given,
                                         notify)
            if "bundle" in entry:
                _label_bundle_sections(entry, arrangement)
        entry["checks"] = _checks(entry, spec, scenario, clearance, jam)
        entry["not_checked"] = _not_checked(entry["checks"], spec, any(r["bend_number"] for r in rows))
        if engine != "rope":
            # a run that failed or is flagged (exucable.post.trust) gives numbers no check should pass on
            entry["checks"].append({"name": "multibody_run", "passed": entry["status"] in TRUSTED_STATUSES,
                                    "value": None, "limit": None, "margin": None, "quantity": None,
                                    "where": f"status {entry['status']}" + (f": {run_headline(entry)}" if entry["message"] else "")})
        entry["passed"] = all(c["passed"] for c in entry["checks"])
        if spec.feed_from_reel:
            entry["pull_in"] = _pull_in_history(curve, rope)
            if engine == "steady":
                entry["pull_in"] = _steady_pull_in_history(scenario, name, rope)
        directions[name] = entry

    ok = [n for n in directions if directions[n]["passed"]]
    pool = ok or list(directions)
    recommended = min(pool, key=lambda n: directions[n]["max_tension_N"])
    return {
        "engine": engine,
        "engine_rule": engine_rule,
        "directions": directions,
        "recommended_direction": recommended,
        "weight_correction_factor": wc,
        "weight_correction_in_bends": spec.weight_correction_in_bends,
        "sidewall_pressure_factor": swbp_factor,
        "jam_ratio": jam.jam_ratio,
        "jam_risk": jam.risk,
        "clearance_m": clearance,
        "arrangement": arrangement,
        "arrangement_as_given": arrangement_as_given,
        "count": spec.count,
        "checks": directions[recommended]["checks"],
        "not_checked": directions[recommended]["not_checked"],
        "passed": bool(ok),
        # without [limits] only the plan's own checks ran (finiteness, jam, the multibody run)
        "limits_checked": any(getattr(spec.limits, f.name) is not None for f in dataclasses.fields(spec.limits)),
        "fill_percent": eng.conduit_fill_percent(spec.count, D, d),
        "point_names": names,
        "point_s_m": [float(p.s_start_m) for p in centreline.pieces] + [float(centreline.length_m)],
        "inputs": {
            "scenario": scenario.name,
            "description": scenario.description,
            "scenario_file": None if scenario.source_path is None else str(scenario.source_path),
            "cable_diameter_m": d,
            "duct_inner_diameter_m": D,
            "count": spec.count,
            "arrangement": spec.arrangement,
            "positions_m": None if scenario.cable.positions_m is None else [list(p) for p in scenario.cable.positions_m],
            "weight_per_length_one_cable_N_per_m": scenario.cable.mass_per_length_kg_per_m * g,
            "gravity_m_per_s2": g,
            "friction": scenario.contact.friction,
            "back_tension_N": back,
            "route_length_m": centreline.length_m,
            "youngs_modulus_Pa": scenario.cable.youngs_modulus_Pa,
            "bending_stiffness_N_m2": scenario.cable.bending_stiffness_N_m2,
            "bending_stiffness_given": scenario.cable.bending_stiffness_given_N_m2 is not None,
            "units": spec.units,
            "limits": scenario.limits.to_dict(),
        },
        "versions": versions(),
    }
