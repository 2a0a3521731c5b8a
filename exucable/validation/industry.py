"""``exucable validate --suite industry``: the published worked pulls of ``scenarios/industry/``.

For every worked example of ``reference/industry_values.toml`` (a manufacturer's manual or a
calculator vendor's page, each cited there and in its scenario file) one row per solver mode:

- the **published** pulling force with its rounding bound (the manual's hand calculation rounds every
  section's tension and the bend factors; the bound propagates those roundings along the route,
  :func:`published_bounds_N`);
- the **centreline rope** (:mod:`exucable.quasistatic.rope`, through :func:`exucable.plan.pull.plan_pull`): what the
  published calculators compute; checked against the published value within that bound;
- the **rope with clearance** (``rope_clearance_pull_force_N``, :mod:`exucable.quasistatic.clearance`): the
  EJ → 0 limit of the cable free to hang in free spans across its clearance;
- **exucable** on the default mesh and on ``levels − 1`` meshes each refined by :data:`REFINE` (element
  length and check-point spacing halved), extrapolated with its error estimate (Richardson from the
  last three levels where the sequence allows, :func:`exucable.post.convergence.extrapolate`; with two levels
  the refined value): the mesh check is |default − converged| / converged ≤ :data:`MESH_TOLERANCE`; a dynamic
  run's steady scatter (std/mean over its window) must be ≤ :data:`SCATTER_TOLERANCE`; where both modes
  ran, |steady − dynamic| / dynamic ≤ :data:`MODE_TOLERANCE`, with steady mode solved again in the
  dynamic run's state (laid out as far as it had pulled: ``solver.steady_lead_out`` = its
  ``reference_pulled_out_m``);
- the **difference from the published value explained**: published − rope is the calculator's rounding
  (the first check); rope with clearance − rope is the free spans (reference/README.md, "What separates
  exucable from the rope"); exucable − rope with clearance is what the rope lacks, bending stiffness,
  measured by √(EJ/T)/R on the route's tightest bend. The study there found exucable within 0.1 % of
  the rope with clearance for √(EJ/T)/R ≤ 0.01 (:data:`FLEXIBLE_LIMIT`), which is checked where it
  applies; beyond it the difference is reported beside two estimates, not judged: the stiff-bend model
  (:mod:`exucable.quasistatic.stiff_bend`, bend by bend) and the beam in the conduit (:mod:`exucable.quasistatic.beam`).

Writes ``industry.csv``, ``industry.md`` and ``industry.png`` (each atomically) into the output
directory, each run's results in ``<out>/<mode>/<example>/level_<k>/``.
"""

from __future__ import annotations

import csv
import io
import math
import time
import tomllib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..data import data_path
from ..io import atomic_write_text
from ..post.trust import TRUSTED_STATUSES

__all__ = ["LBF_N", "REFINE", "MESH_TOLERANCE", "SCATTER_TOLERANCE", "MODE_TOLERANCE", "FLEXIBLE_LIMIT",
           "FLEXIBLE_TOLERANCE", "load_industry_examples", "published_values", "published_bounds_N", "IndustryRow",
           "IndustryValidation", "validate_industry", "format_industry_table", "write_industry_report"]

#: One pound-force [N] (the published values are in lbf).
LBF_N = 4.4482216152605
#: Refinement of the second mesh: element length and check-point spacing divided by this.
REFINE = 2.0
#: The targets: default mesh within 0.2 % of the refined answer, scatter ≤ 0.2 %, modes within 0.2 %.
MESH_TOLERANCE = 2e-3
SCATTER_TOLERANCE = 2e-3
MODE_TOLERANCE = 2e-3
#: √(EJ/T)/R up to which the rope-difference study measured exucable within FLEXIBLE_TOLERANCE of the
#: rope with clearance (reference/README.md: −0.09 … +0.08 % on every case at √(EJ/T)/R ≤ 0.01).
FLEXIBLE_LIMIT = 0.01
FLEXIBLE_TOLERANCE = 1e-3


def load_industry_examples(path=None) -> list[dict]:
    """The ``[[example]]`` tables of ``reference/industry_values.toml`` (or of ``path``)."""
    with open(data_path("reference", "industry_values.toml") if path is None else path, "rb") as f:
        return tomllib.load(f)["example"]


FT_M = 0.3048
LB_PER_FT_N_PER_M = LBF_N / FT_M


def published_values(example: dict) -> dict:
    """The example's published numbers in N, N/m and m, whichever units it was printed in.

    Returns ``tension_N`` (the printed section tensions, or their ``tension_out_corrected_*`` where the
    printed value is an erratum), ``rounding_N``, ``pressure_N_per_m``, ``radius_m`` and
    ``pressure_rounding_N_per_m``.
    """
    if "tension_out_N" in example:
        tension = example.get("tension_out_corrected_N", example["tension_out_N"])
        return {"tension_N": list(map(float, tension)), "rounding_N": example["tension_rounding_N"],
                "pressure_N_per_m": example.get("sidewall_pressure_N_per_m", []),
                "radius_m": example.get("bend_radius_m"), "pressure_rounding_N_per_m": example.get("pressure_rounding_N_per_m")}
    tension = example.get("tension_out_corrected_lbf", example["tension_out_lbf"])
    return {"tension_N": [t * LBF_N for t in tension], "rounding_N": example["tension_rounding_lbf"] * LBF_N,
            "pressure_N_per_m": [p * LB_PER_FT_N_PER_M for p in example.get("sidewall_pressure_lb_per_ft", [])],
            "radius_m": example["bend_radius_ft"] * FT_M if "bend_radius_ft" in example else None,
            "pressure_rounding_N_per_m": example.get("pressure_rounding_lb_per_ft", 0.0) * LB_PER_FT_N_PER_M}


def published_bounds_N(example: dict, sections: list[dict], mu_bend: float, w_N_per_m: float) -> list[float]:
    """Bound |exact − published| [N] for every published tension: interval propagation of the hand calculation.

    Per step from the previous published value to the next: the carried error times the bend factors
    e^(μθ) between (chained calculations, paper Eq. 26), the bend factors' rounding, the weight correction
    factor's rounding on the straights' add-ons, the weight in the bends the hand calculation drops
    (``bend_weight_ignored``) and the printed value's own rounding (rule in the header of
    ``reference/industry_values.toml``).

    Parameters
    ----------
    example : dict
        One ``[[example]]`` table.
    sections : list of dict
        The route's sections in pulling order, as :func:`exucable.plan.pull.plan_pull` gives them.
    mu_bend : float
        The friction coefficient in bends (with the weight correction where the calculation applies it).
    w_N_per_m : float
        Weight per length of all cables [N/m].
    """
    pub = published_values(example)
    delta = example["bend_factor_rounding"]
    wc_rel = example.get("weight_correction_rounding", 0.0) / example.get("weight_correction_published", 1.0)
    bounds, e, prev_idx, prev_pub = [], 0.0, 0, 0.0
    for idx, value in zip(example["sections"], pub["tension_N"]):
        between = sections[prev_idx:idx]
        bends = [b for b in between if b["kind"] == "bend"]
        factor = math.prod(math.exp(mu_bend * math.radians(b["angle_deg"])) for b in bends)
        carried = factor * e if example["chained"] else 0.0
        # within the step, in pull order: a straight's add-on error, a bend multiplies what came before
        # and adds the weight the hand calculation drops in it
        step = 0.0
        for r in between:
            if r["kind"] == "straight":
                step += wc_rel * (r["tension_out_N"] - r["tension_in_N"])
                continue
            grow = math.exp(mu_bend * math.radians(r["angle_deg"]))
            step *= grow
            if example.get("bend_weight_ignored", False):
                R = r["radius_m"]
                step += ((grow - 1.0) * w_N_per_m**2 * R**2 / (2.0 * r["tension_in_N"]) if r["plane"] == "horizontal"
                         else (grow - 1.0) * w_N_per_m * R)
        e = carried + len(bends) * delta * max(prev_pub, 0.0) * factor + pub["rounding_N"] + step
        bounds.append(e)
        prev_idx, prev_pub = idx, value
    return bounds


@dataclass
class IndustryRow:
    """One example in one solver mode. Forces in N; relative differences as fractions."""

    example: str                 # scenario stem and direction
    source: str
    kind: str
    mode: str
    published_N: float
    published_bound_N: float
    rope_N: float                # centreline rope, the published calculators' model, whole route
    flexibility: float           # max over bends of √(EJ/T_out)/R (rope tensions)
    liftoff_over_2c: float       # max over bends of λ²/(2R) / 2c, λ = √(EJ/T_out)
    stiff_estimate: float = float("nan")   # exucable/quasistatic/stiff_bend.py along the route, vs the rope
    stiff_estimate_fits: bool = False      # every bend within that model's validity (offset ≤ 2c)
    beam_estimate: float = float("nan")    # exucable/quasistatic/beam.py (3D chain, both walls), vs its EJ → 0
    run_rope_N: float | None = None            # both references for the run's extent of cable (a dynamic
    run_rope_clearance_N: float | None = None  # run's window has pulled some out; steady: = the route's)
    same_state_steady_N: float | None = None   # dynamic rows: steady mode laid out as far as the dynamic
                                               # run had pulled (solver.steady_lead_out), default mesh
    values_N: list = field(default_factory=list)        # exucable per mesh level (default first)
    elements: list = field(default_factory=list)
    scatter: list = field(default_factory=list)         # std/mean per level (dynamic), None for steady
    uncertainty_N: list = field(default_factory=list)
    statuses: list = field(default_factory=list)
    messages: list = field(default_factory=list)
    wall_time_s: list = field(default_factory=list)

    @property
    def value_N(self) -> float:
        """exucable's answer: the default mesh's."""
        return self.values_N[0] if self.values_N else float("nan")

    @property
    def converged(self):
        """The mesh-converged value as an :class:`exucable.post.convergence.Extrapolation` (three levels or
        more), the finest value with error |finest − previous| (two levels), None with one level or a
        failed level."""
        from ..post.convergence import Extrapolation, extrapolate
        v = self.values_N
        if len(v) < 2 or not np.all(np.isfinite(v)):
            return None
        if len(v) == 2:
            return Extrapolation(v[1], abs(v[1] - v[0]), float("nan"), "two levels: the refined value")
        return extrapolate(v, REFINE, [u or 0.0 for u in self.uncertainty_N])

    @property
    def mesh_difference(self) -> float | None:
        """(default − converged) / converged; None with one level, NaN with a failed level."""
        if len(self.values_N) < 2:
            return None
        c = self.converged
        return float("nan") if c is None else (self.values_N[0] - c.value) / abs(c.value)

    @property
    def trusted(self) -> bool:
        return bool(self.statuses) and all(s in TRUSTED_STATUSES for s in self.statuses)

    def rel(self, reference) -> float:
        return (self.value_N - reference) / abs(reference) if reference else float("nan")

    @property
    def free_span_part(self) -> float | None:
        """(rope with clearance − rope) / rope: what the free spans across the clearance save."""
        if self.run_rope_clearance_N is None or not self.run_rope_N:
            return None
        return (self.run_rope_clearance_N - self.run_rope_N) / self.run_rope_N

    @property
    def remainder(self) -> float | None:
        """(exucable − rope with clearance) / rope with clearance, both for the run's extent: what the
        rope lacks (bending stiffness)."""
        return None if self.run_rope_clearance_N is None else self.rel(self.run_rope_clearance_N)

    def checks(self) -> list[tuple[str, bool, str]]:
        """(name, passed, detail) of each check this row makes."""
        out = [("rope vs published", abs(self.rope_N - self.published_N) <= self.published_bound_N,
                f"|{self.rope_N:.5g} − {self.published_N:.5g}| ≤ {self.published_bound_N:.3g} N (published rounding)")]
        out.append(("trusted status", self.trusted, ", ".join(self.statuses) or "not run"))
        md = self.mesh_difference
        if md is not None:
            out.append(("mesh", abs(md) <= MESH_TOLERANCE,
                        f"default vs converged {100 * md:+.3f} % (≤ {100 * MESH_TOLERANCE:.1f} %)"))
        for level, sc in enumerate(self.scatter):
            if sc is not None:
                out.append((f"steadiness level {level}", sc <= SCATTER_TOLERANCE,
                            f"scatter {100 * sc:.3f} % (≤ {100 * SCATTER_TOLERANCE:.1f} %)"))
        rem = self.remainder
        if rem is not None and self.flexibility <= FLEXIBLE_LIMIT:
            out.append(("vs rope with clearance", abs(rem) <= FLEXIBLE_TOLERANCE,
                        f"{100 * rem:+.3f} % at √(EJ/T)/R = {self.flexibility:.3g} ≤ {FLEXIBLE_LIMIT}"))
        return out

    @property
    def passed(self) -> bool:
        return all(ok for _, ok, _ in self.checks())

    def explanation(self) -> str:
        """The difference from the published value, part by part."""
        parts = [f"published − rope {self.published_N - self.rope_N:+.3g} N (rounding, bound ±{self.published_bound_N:.3g} N)"]
        if len(self.values_N) > 1:
            c = self.converged
            parts.append("mesh: " + " / ".join(f"{v:.6g}" for v in self.values_N) + " N at "
                         + " / ".join(str(n) for n in self.elements) + " elements"
                         + ("" if c is None else f", {c.method.split(':')[0]}"))
        if self.free_span_part is not None:
            parts.append(f"free spans {100 * self.free_span_part:+.2f} % (rope with clearance vs rope)")
        if self.remainder is not None and np.isfinite(self.value_N):
            regime = ("flexible: the study's 0.1 % applies" if self.flexibility <= FLEXIBLE_LIMIT
                      else "bending stiffness; lift-off λ²/2R = "
                      f"{self.liftoff_over_2c:.2g} × 2c: " + ("the beam spans to the outer wall, extra friction "
                                                               "expected (PULLFLEX)" if self.liftoff_over_2c > 1
                                                               else "rides the inner wall, no first-order change "
                                                                    "expected"))
            parts.append(f"exucable vs rope with clearance {100 * self.remainder:+.2f} % at √(EJ/T)/R = "
                         f"{self.flexibility:.3g} ({regime}); the stiff-bend model (exucable/quasistatic/stiff_bend.py, bend "
                         f"by bend, no free spans) predicts {100 * self.stiff_estimate:+.2f} % vs the rope"
                         + ("" if self.stiff_estimate_fits else " but is outside its validity (offset > 2c)")
                         + (f"; the beam-in-conduit model (exucable/quasistatic/beam.py: both walls, the weight, free "
                            f"spans) predicts {100 * self.beam_estimate:+.2f} % vs its flexible limit"
                            if np.isfinite(self.beam_estimate) else ""))
        return "; ".join(parts)


@dataclass
class IndustryValidation:
    rows: list = field(default_factory=list)
    skipped: list = field(default_factory=list)    # examples the multibody model cannot run, with why
    wall_time_s: float = 0.0
    mode_wall_time_s: dict = field(default_factory=dict)

    def mode_differences(self) -> list[tuple[str, float, float, float, bool]]:
        """(example, steady, dynamic, reference shift, same state) where both modes ran on the default mesh.

        Where the dynamic run's extent is known, ``steady`` is steady mode solved in that state (laid out as
        far as the dynamic run had pulled its cable, as ``exucable validate`` does for the paper's cases)
        and the shift is 0; otherwise it is the steady row's own state, and the shift is (rope at the
        dynamic window's extent − rope at the steady run's) / the latter: how much of the difference the
        cable pulled out during the dynamic run accounts for."""
        by = {(r.example, r.mode): r for r in self.rows}
        out = []
        for ex, m in by:
            if m == "steady" and (ex, "dynamic") in by:
                st, dy = by[(ex, "steady")], by[(ex, "dynamic")]
                if dy.same_state_steady_N is not None:
                    out.append((ex, dy.same_state_steady_N, dy.value_N, 0.0, True))
                    continue
                shift = ((dy.run_rope_N - st.run_rope_N) / st.run_rope_N if dy.run_rope_N and st.run_rope_N
                         else float("nan"))
                out.append((ex, st.value_N, dy.value_N, shift, False))
        return out

    @property
    def failures(self) -> list[str]:
        out = [f"{r.example} ({r.mode}): {name}: {detail}" for r in self.rows for name, ok, detail in r.checks() if not ok]
        for ex, steady, dynamic, _, _ in self.mode_differences():
            d = (steady - dynamic) / abs(dynamic)
            if not abs(d) <= MODE_TOLERANCE:
                out.append(f"{ex}: steady vs dynamic {100 * d:+.3f} % (≤ {100 * MODE_TOLERANCE:.1f} %)")
        return out


def _flexibility(scenario, plan_sections) -> tuple[float, float]:
    """Over the route's bends, with the rope's tension T leaving each: max √(EJ/T)/R, and max of the
    lift-off λ²/(2R) (λ = √(EJ/T)) over the 2c across the conduit — above 1 the beam that cannot follow the
    bend's curvature jump presses the outer wall too (PULLFLEX's bend-end forces; reference/README.md)."""
    ej = scenario.cable.bending_stiffness_N_m2
    two_c = 2.0 * (scenario.conduit.inner_radius_m - scenario.cable.radius_m)
    bends = [(s["tension_out_N"], s["radius_m"]) for s in plan_sections
             if s["kind"] == "bend" and s.get("radius_m") and s["tension_out_N"] > 0]
    return (max((math.sqrt(ej / t) / r for t, r in bends), default=0.0),
            max((ej / t / (2.0 * r) / two_c for t, r in bends), default=0.0))


def _stiff_estimate(scenario, plan_sections) -> tuple[float, bool]:
    """Bending stiffness' change of the pulling force against the rope, from :func:`exucable.quasistatic.stiff_bend.stiff_bend`
    bend by bend along the route (the rope's straights' add-ons kept, free spans and weight in bends not):
    (T_stiff − T_rope) / T_rope, and whether every bend is within that model's validity (offset ≤ 2c)."""
    from ..quasistatic.stiff_bend import stiff_bend
    c = scenario.conduit.inner_radius_m - scenario.cable.radius_m
    ej, mu = scenario.cable.bending_stiffness_N_m2, scenario.contact.friction
    t, fits = plan_sections[0]["tension_in_N"], True
    for sec in plan_sections:
        if sec["kind"] == "bend" and t > 0:
            sb = stiff_bend(t, mu, math.radians(sec["angle_deg"]), sec["radius_m"] - c, ej)
            fits = fits and sb.fits(c)
            t = sb.tension_out_N
        else:
            t += sec["tension_out_N"] - sec["tension_in_N"]
    rope = plan_sections[-1]["tension_out_N"]
    return (t - rope) / rope, fits


def _beam_estimate(scenario) -> float:
    """Bending stiffness' change of the pulling force from :func:`exucable.quasistatic.beam.stiff_route_difference`
    (the stiff cable may press both walls: PULLFLEX's three-point bending; its weight on the round
    conduit's floor, free spans), relative to that model's EJ → 0 limit; NaN for a route it does not model
    (a bend out of the horizontal plane, no weight or no clearance)."""
    from ..quasistatic.beam import BeamConduitError, route_pieces, stiff_route_difference
    conduit = scenario.build_conduit()
    if scenario.pull.direction == "reverse":
        conduit = conduit.reversed()
    centre = conduit.centreline
    c = scenario.conduit.inner_radius_m - scenario.cable.radius_m
    g = scenario.gravity.g_m_per_s2 if scenario.gravity is not None else 0.0
    horizontal = all(abs(float(centre.tangent(s)[2])) < 1e-9 for s in np.linspace(0.0, centre.length_m, 257))
    if not horizontal or c <= 0.0 or g <= 0.0:
        return float("nan")
    try:
        return stiff_route_difference(route_pieces(centre), c, scenario.contact.friction,
                                      scenario.cable.mass_per_length_kg_per_m * g, scenario.cable.bending_stiffness_N_m2,
                                      max(scenario.pull.back_tension_N, 1e-3))["difference"]
    except BeamConduitError:
        return float("nan")


def validate_industry(fast: bool = False, out_dir="validation/industry", quiet: bool = True,
                      modes=("steady",), examples=None, progress: Callable[[str], None] | None = None,
                      scenario_dir=None, levels: int = 3) -> IndustryValidation:
    """Run the industry suite; returns its rows and writes its table and figure into ``out_dir``.

    Parameters
    ----------
    fast : bool
        The default mesh only (no refined run, so no mesh check); overrides ``levels``.
    out_dir : str or os.PathLike
        Output directory.
    quiet : bool
        No progress bars in the runs.
    modes : iterable of {"steady", "dynamic"}
        Solver modes; the dynamic one costs minutes per route (``benchmarks/industry_suite.py``).
    examples : list of dict, optional
        ``[[example]]`` tables (default: all of ``reference/industry_values.toml``).
    progress : callable, optional
        Called with one line of text as each run starts and ends.
    scenario_dir : path, optional
        Where the examples' scenario files are (default: the shipped ``scenarios/industry``).
    levels : int
        Mesh levels (the default mesh, then each refined by :data:`REFINE`); 3 or more extrapolate.
    """
    from ..plan.pull import plan_pull, plan_spec
    from ..run import run_scenario
    from ..scenario.specs import load_scenario

    say = progress or (lambda line: None)
    sdir = Path(scenario_dir) if scenario_dir is not None else data_path("scenarios", "industry")
    out = Path(out_dir)
    iv = IndustryValidation()
    t0 = time.perf_counter()
    refines = (1.0,) if fast else tuple(REFINE**k for k in range(max(int(levels), 1)))
    for mode in modes:
        tm = time.perf_counter()
        for ex in examples if examples is not None else load_industry_examples():
            sc = load_scenario(sdir / ex["scenario"])
            if sc.cable.count != 1:
                note = (f"{ex['scenario']} ({ex['direction']}): {sc.cable.count} cables in the duct; this suite "
                        "runs single cables (`exucable plan` checks the bundle against the published value, "
                        "`exucable validate --suite bundle` the bundle model against closed forms)")
                if note not in iv.skipped:
                    iv.skipped.append(note)
                    say(f"validate industry: skipped {note}")
                continue
            if ex["direction"] != sc.pull.direction:
                sc = sc.replace(**{"pull.direction": ex["direction"]})
            spec = plan_spec(sc)
            plan = plan_pull(sc, spec, engine="rope")   # the calculators' method, checked against the published value
            sections = plan["directions"][ex["direction"]]["sections"]
            mu_bend = sc.contact.friction * (plan["weight_correction_factor"] if spec.weight_correction_in_bends
                                             else 1.0)
            w = plan["inputs"]["weight_per_length_one_cable_N_per_m"] * plan["count"]
            bound = published_bounds_N(ex, sections, mu_bend, w)[-1]
            name = f"{Path(ex['scenario']).stem}-{ex['direction']}"
            row = IndustryRow(name, ex["source"], ex["kind"], mode, published_values(ex)["tension_N"][-1], bound,
                              plan["directions"][ex["direction"]]["pull_force_N"], *_flexibility(sc, sections))
            row.stiff_estimate, row.stiff_estimate_fits = _stiff_estimate(sc, sections)
            row.beam_estimate = _beam_estimate(sc)
            k0 = None
            for level, refine in enumerate(refines):
                say(f"validate industry: {name}, {mode}, mesh level {level} (element length / {refine:g}) ...")
                res = run_scenario(sc, out / mode / name / f"level_{level}", quiet=quiet, plots=False,
                                   refine=refine, check_points_per_element=k0, mode=mode)
                s = res.summary
                k0 = s["mesh"]["check_points_per_element"] if k0 is None else k0
                failed = s["status"] == "failed" or s["pull_force_N"] is None
                value = float("nan") if failed else s["pull_force_N"]   # a failed solve's last state is no answer
                row.values_N.append(value)
                row.elements.append(s["mesh"]["elements"])
                std = s.get("pull_force_std_N")
                row.scatter.append(abs(std / value) if mode == "dynamic" and std is not None and value else None)
                row.uncertainty_N.append(s.get("pull_force_uncertainty_N"))
                row.statuses.append(s["status"])
                row.messages.append(s.get("message") or "")
                row.wall_time_s.append(s["wall_time_s"])
                if level == 0:
                    row.run_rope_N = s.get("rope_pull_force_N")
                    row.run_rope_clearance_N = s.get("rope_clearance_pull_force_N")
                    pulled_out_m = s.get("reference_pulled_out_m")
                    if mode == "dynamic" and not failed and pulled_out_m is not None:
                        # the two modes compared in one state: steady laid out as far as this run had
                        # pulled its cable (its start's lead-out included), as `validate` does for the paper
                        say(f"validate industry: {name}, steady in the dynamic run's state "
                            f"(lead-out {pulled_out_m:.3g} m) ...")
                        same = run_scenario(sc.replace(**{"solver.steady_lead_out": pulled_out_m}),
                                            out / "same_state" / name, quiet=quiet, plots=False,
                                            check_points_per_element=k0, mode="steady").summary
                        if same["status"] != "failed" and same["pull_force_N"] is not None:
                            row.same_state_steady_N = float(same["pull_force_N"])
                say(f"  {s['mesh']['elements']} elements: pulling force {value:.6g} N, status {s['status']}, "
                    f"wall {s['wall_time_s']:.1f} s" + (f": {s.get('message')}" if failed else ""))
            iv.rows.append(row)
        iv.mode_wall_time_s[mode] = time.perf_counter() - tm
    iv.wall_time_s = time.perf_counter() - t0
    write_industry_report(iv, out, fast)
    return iv


def _converged(r: IndustryRow) -> str:
    c = r.converged
    return "-" if c is None else f"{c.value:.6g} ± {c.error:.2g}"


def _pct(x, digits=3):
    return "-" if x is None or not np.isfinite(x) else f"{100 * x:+.{digits}f} %"


def _g(x, fmt=".6g"):
    return "-" if x is None or not np.isfinite(x) else format(x, fmt)


HEADER = ["example", "mode", "published [N]", "rope [N]", "rope w/ clearance [N] (run's extent)", "exucable [N]", "converged [N]",
          "mesh", "scatter", "vs published", "vs rope", "vs rope w/ clearance", "sqrt(EJ/T)/R", "liftoff/2c", "stiff-bend est.",
          "beam-in-conduit est.", "pass"]


def table_rows(iv: IndustryValidation):
    rows = []
    for r in iv.rows:
        sc = r.scatter[0] if r.scatter else None
        rows.append([r.example, r.mode, f"{r.published_N:.5g} ± {r.published_bound_N:.2g}", _g(r.rope_N),
                     _g(r.run_rope_clearance_N), _g(r.value_N),
                     _converged(r), _pct(r.mesh_difference),
                     "-" if sc is None else f"{100 * sc:.3f} %", _pct(r.rel(r.published_N), 2), _pct(r.rel(r.run_rope_N), 2),
                     _pct(r.remainder, 2), f"{r.flexibility:.3g}", f"{r.liftoff_over_2c:.2g}",
                     _pct(r.stiff_estimate, 2) + ("" if r.stiff_estimate_fits else " (outside)"), _pct(r.beam_estimate, 2), "PASS" if r.passed else "FAIL"])
    return HEADER, rows


def format_industry_table(iv: IndustryValidation) -> str:
    from .paper import text_table
    text = text_table(*table_rows(iv))
    text += "\n\nThe differences, explained:\n" + "\n".join(f"  {r.example} ({r.mode}): {r.explanation()}" for r in iv.rows)
    diffs = iv.mode_differences()
    if diffs:
        text += "\n\nSteady against dynamic (default mesh):\n" + "\n".join(
            f"  {ex}: steady {s:.6g} N, dynamic {d:.6g} N, {100 * (s - d) / abs(d):+.3f} % "
            + ("(same state: steady laid out as far as the dynamic run had pulled)" if same else
               f"(the rope moves by {100 * sh:+.3f} % between their extents)")
            for ex, s, d, sh, same in diffs)
    return text


def write_industry_report(iv: IndustryValidation, out: Path, fast: bool) -> None:
    """``industry.csv`` (one row per example and mode), ``industry.md`` and ``industry.png``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["example", "mode", "source", "published_N", "published_bound_N", "rope_pull_force_N",
                "rope_clearance_pull_force_N", "pull_force_N", "level_pull_forces_N", "converged_pull_force_N", "converged_error_N", "mesh_difference",
                "scatter", "elements", "flexibility_sqrt_EJ_over_T_per_R", "liftoff_over_2c",
                "stiff_bend_estimate", "beam_conduit_estimate", "status",
                "wall_time_s", "passed"])
    for r in iv.rows:
        w.writerow([r.example, r.mode, r.source, repr(r.published_N), repr(r.published_bound_N), repr(r.rope_N),
                    "" if r.run_rope_clearance_N is None else repr(r.run_rope_clearance_N), repr(r.value_N),
                    ";".join(repr(v) for v in r.values_N), "" if r.converged is None else repr(r.converged.value),
                    "" if r.converged is None else repr(r.converged.error),
                    "" if r.mesh_difference is None else repr(r.mesh_difference),
                    "" if not r.scatter or r.scatter[0] is None else repr(r.scatter[0]),
                    ";".join(str(n) for n in r.elements),
                    repr(r.flexibility), repr(r.liftoff_over_2c),
                    repr(r.stiff_estimate), repr(r.beam_estimate), ";".join(r.statuses), ";".join(f"{t:.1f}" for t in r.wall_time_s), r.passed])
    atomic_write_text(out / "industry.csv", buf.getvalue())
    header, rows = table_rows(iv)
    md = [f"# exucable industry validation ({'default mesh only' if fast else 'default and refined meshes'})", "",
          "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    md += ["| " + " | ".join(str(x) for x in row) + " |" for row in rows]
    md += ["", "## The differences, explained", ""] + [f"- {r.example} ({r.mode}): {r.explanation()}" for r in iv.rows]
    md += [f"- skipped: {n}" for n in iv.skipped]
    md += ["", "## Sources", ""] + sorted({f"- {r.example}: {r.source} ({r.kind})" for r in iv.rows})
    times = ", ".join(f"{m} {t:.1f} s" for m, t in iv.mode_wall_time_s.items())
    md += ["", f"Wall time {iv.wall_time_s:.1f} s ({times})."]
    md += [f"- FAIL {f}" for f in iv.failures]
    atomic_write_text(out / "industry.md", "\n".join(md) + "\n")
    if iv.rows:
        from ..plots.validation import plot_industry
        plot_industry(iv, out / "industry.png")
