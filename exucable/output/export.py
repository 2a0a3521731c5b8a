"""The exact discrete problem of a scenario, for cross-checking a solver written from scratch.

``export_problem(scenario, out_dir)`` builds the model as ``exucable run`` does and writes what a
solver of one's own needs to start from exactly exucable's state (field by field, with units, in
``docs/results-format.md``; a JSON Schema for each file in ``exucable/output/schemas/``):

``problem.json``          the mode and every parameter used, each force term with its formula as
                          the code evaluates it (``equations``: elastic terms and their quadrature,
                          internal damping, gravity's load vector, end forces, the rig's constraint
                          and what the pulling force is; ``contact``: the law, its damping and the
                          friction law of the mode), the held node and the lead-out, solver
                          settings, exucable's and Exudyn's versions
``nodes_initial.csv``     initial nodal coordinates and rates (ANCF ``[r, r']``), node 0 trailing
``elements.csv``          element → nodes, reference length, pre-strain
``check_points.csv``      element, ξ, quadrature weight ω, contact weight w = L_e ω / h_ref
``conduit_segments.csv``  the straight segments the contact search runs on
``conduit_pieces.csv``    the exact straights, bends and helices the smooth wall refines onto

Arc lengths follow the one convention of every exucable file: ``x_m`` = material coordinate
along the cable from its trailing end; ``s_conduit_m`` = along the scenario's conduit from its
start (for ``pull.direction = "reverse"`` the model runs on the reversed conduit; the exported
``s_conduit_m`` columns are mapped back, L − s).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .formats import EXPORT_FILES, FORMAT_VERSION, PIECE_COLUMNS
from ..io import write_csv, write_json
from ..post.tension import axial_strain

__all__ = ["export_problem", "problem_description", "problem_tables", "conduit_s", "elastic_quadrature"]

# Exudyn's ObjectANCFCable (useReducedOrderIntegration 0, 1, 2): the rules of its axial and bending
# virtual work on [0, 1] as (points, weights); Gauss orders 9/5, 7/3, and Lobatto order 3 / Gauss 3
_GAUSS = {n: np.polynomial.legendre.leggauss(n) for n in (2, 3, 4, 5)}
_LOBATTO3 = (np.array([-1.0, 0.0, 1.0]), np.array([1.0, 4.0, 1.0]) / 3.0)
_RULES = {"full": (("gauss", 5), ("gauss", 3)), "reduced": (("gauss", 4), ("gauss", 2)),
          "lobatto": (("lobatto", 3), ("gauss", 2))}


def elastic_quadrature(integration: str) -> dict:
    """The points ξ ∈ [0, 1] and weights (summing to 1, times L_e) of Exudyn's ANCF cable's axial and
    bending terms for ``cable.integration`` (``full``, ``reduced``, ``lobatto``)."""
    out = {}
    for term, (kind, n) in zip(("axial", "bending"), _RULES[integration]):
        x, w = _LOBATTO3 if kind == "lobatto" else _GAUSS[n]
        out[term] = {"rule": f"{kind} {n} points", "xi": [float(v) for v in 0.5 * (x + 1.0)],
                     "weight": [float(v) for v in 0.5 * w]}
    return out

def conduit_s(model, s_pull_m):
    """Arc length along the scenario's conduit [m] from one along the model's pull-oriented conduit."""
    s = np.asarray(s_pull_m, dtype=float)
    if model.scenario.pull.direction == "reverse":
        return model.conduit.centreline.length_m - s
    return s


def _vec(v):
    return None if v is None else [float(x) for x in np.asarray(v, dtype=float)]


def problem_description(model) -> dict:
    """Everything that defines the discrete problem except the tables, as a JSON-ready dict."""
    from .versions import versions

    sc = model.scenario
    props = model.properties
    kernel = model.kernel
    centre = model.conduit.centreline
    g = sc.gravity.g_m_per_s2 if sc.gravity is not None else 0.0
    t_exit = np.asarray(centre.tangent(centre.length_m), dtype=float)
    t_entry = np.asarray(centre.tangent(centre.length_m - sc.cable_length_m), dtype=float)
    sp = sc.solver
    contact = None
    if kernel is not None:
        law = kernel.law
        contact = {
            "law": "f_n = w * max(0, K * delta**e + C * min(delta/delta_d, 1) * delta_dot) (paper Eq. 18); "
                   "F = -f_n n - mu(|v_t|) f_n v_t / sqrt(|v_t|^2 + eps^2) (Eqs. 19-23)",
            "stiffness_N_per_m_e": law.stiffness,
            "damping_N_s_per_m": law.damping,
            "exponent": law.exponent,
            "friction": law.friction,
            "static_friction": law.static_friction,
            "stribeck_velocity_m_per_s": law.stribeck_velocity_m_per_s,
            "regularisation_velocity_m_per_s": law.regularisation_velocity_m_per_s,
            "damping_onset_m": law.damping_onset_m,
            "reference_spacing_m": kernel.reference_spacing_m,
            "weight_rule": "contact_weight = reference_length_m * weight / reference_spacing_m (check_points.csv)",
            "check_points_per_element": kernel.n_check_points,
            "check_point_rule": kernel.rule,
            "gap_m": kernel.gap_m,
            "surface": kernel.surface,
            "smooth_wall_newton_iterations": 2 if kernel.surface == "smooth" else 0,
            "open_ends": kernel.open_ends,
            "closest_point": "nearest conduit segment (ties: lower index); past the first segment's start "
                             "or the last one's end: no contact; surface 'smooth': refined onto that "
                             "segment's piece, continued along the piece's end tangent beyond its ends",
        }
        contact.update(model.kernel.law_statement())
    steady = sc.solver.mode == "steady"
    damper = model.startup_damper
    guide = model.guide
    rig = {
        "controlled": "speed" if model.lead_drive is not None else "force",
        "leading_node": model.layout.n_elements,
        "exit_tangent": _vec(t_exit),
        "entry_tangent": _vec(t_entry),
        "speed_m_per_s": sc.pull.speed_m_per_s,
        "ramp_time_s": sc.pull.ramp_time_s,
        "ramp": "3 tau^2 - 2 tau^3, tau = t / ramp_time_s (1 when ramp_time_s = 0)",
        "stop_time_s": sc.pull.stop_time_s,
        "hold_time_s": sc.pull.hold_time_s,
        "schedule": ("the leading node's speed is speed_m_per_s * (ramp(t) - ramp(t - stop_time_s) + "
                     "ramp(t - stop_time_s - hold_time_s)), each ramp 0 before its start; a null time drops its terms"),
        "lead": ("position of the leading node held on the exit tangent line, moving along it at "
                 "speed_m_per_s * ramp" if model.lead_drive is not None else
                 "force applied_pull_force_N * ramp * exit_tangent on the leading node"),
        "applied_pull_force_N": model.applied_pull_force_N,
        "back_tension_N": model.back_tension_N if model.lead_drive is not None else 0.0,
        "back_tension": "force -back_tension_N * ramp * entry_tangent on the trailing node",
        "trailing_brake": (None if model.trail_drive is None else
                           "trailing node's velocity along entry_tangent held at speed_m_per_s * ramp"),
        "guide": None if guide is None else {
            "node": guide.node_index, "stiffness_N_per_m": guide.k, "damping_N_s_per_m": guide.c,
            "law": "-k (I - d d^T) u - c (I - d d^T) v on the leading node, d = exit_tangent"},
    }
    if steady:
        held = model.layout.n_elements if model.lead_drive is not None else 0
        rig.update({
            "held_node": held,
            "lead": ("the held node's three position coordinates fixed at nodes_initial.csv's (its slopes free); "
                     "the static solve's multipliers are the force the rig exerts on it, Q_rig"),
            "pull_force": ("pull_force_N = Q_rig . exit_tangent, the rig's reaction along the exit tangent"
                           if model.lead_drive is not None else
                           "applied_pull_force_N along exit_tangent; the trailing node is held and its "
                           "reaction along -entry_tangent is the trailing tension"),
            "ramp": "none (a static solve: every load at full scale)",
        })
    else:
        rig["pull_force"] = ("pull_force_N = the drive's reaction on the leading node along exit_tangent"
                             if model.lead_drive is not None else "applied_pull_force_N * ramp")
    lead_out = float(getattr(model.start, "lead_out_m", 0.0) or 0.0)
    quad = elastic_quadrature(props.integration)
    equations = {
        "equilibrium": ("Q_elastic(q) = Q_contact(q) + Q_gravity + Q_end + Q_rig (static: the steady sliding state)"
                        if steady else
                        "M q'' + Q_elastic(q, q') = Q_contact(q, q') + Q_gravity(t) + Q_end(t) + Q_rig + Q_dampers"),
        "generalized_force": "element e's 12 coordinates [r_i, r'_i, r_j, r'_j]; the point force F at xi "
                             "contributes S(xi)^T F, S = [N1 I, N2 I, N3 I, N4 I]",
        "axial": {"formula": "Q_a = L_e sum_g w_g EA (|r'| - 1) (dS/dx)^T r'/|r'| at xi_g "
                             "(Exudyn ObjectANCFCable: eps = |r'| - 1, no reference strain)",
                  **quad["axial"]},
        "bending": {"formula": "Q_b = L_e sum_g w_g EJ (d kappa/dq)^T kappa at xi_g, kappa = (r' x r'') / |r'|^2, a vector "
                               "(Exudyn ObjectANCFCable's material measure of curvature; its magnitude is "
                               "|r' x r''| / |r'|^2, not the geometric |r' x r''| / |r'|^3)",
                    **quad["bending"]},
        "internal_damping": (None if steady else
                             "Kelvin-Voigt: axial_damping_N_s * d|r'|/dt added to EA (|r'| - 1) at the axial points, "
                             "bending_damping_N_m2_s * d kappa/dt to EJ kappa at the bending points"),
        "internal_damping_rule": ("steady mode: none (it acts on the nodal rates, which a static solve does not "
                                  "have; in steady flow its axial force tau V dN/dx is negligible)" if steady else
                                  "dynamic mode: on the nodal rates"),
        "gravity": ("consistent load of rho A g on element e: rho A L_e [g/2, L_e g/12, g/2, -L_e g/12] on "
                    "[r_i, r'_i, r_j, r'_j] (Exudyn LoadMassProportional: the integral of rho A S^T g, exact)"
                    + ("" if steady else ", times ramp(t)")),
        "end_forces": ("back tension: -back_tension_N * entry_tangent on the trailing node's position"
                       + ("" if steady else ", times ramp(t)")
                       + ("; force-controlled pull: applied_pull_force_N * exit_tangent on the leading node's position"
                          if model.lead_drive is None else "")),
    }
    return {
        "format_version": FORMAT_VERSION,
        "name": sc.name,
        "mode": sc.solver.mode,
        "units": "SI: m, s, kg, N; angles in rad",
        "conventions": {
            "x_m": "material (unstretched) coordinate along the cable from its trailing end",
            "s_conduit_m": "arc length along the scenario's conduit from its start",
            "s_pull_m": "arc length along the pull-oriented conduit the model runs on (leading end at its end); "
                        "equals s_conduit_m unless pull.direction = 'reverse', then L - s_conduit_m",
            "coordinates": "node i: [r, r'] (position, slope dr/dx), ANCF cable, cubic Hermite shape functions "
                           "N1 = 1 - 3xi^2 + 2xi^3, N2 = L(xi - 2xi^2 + xi^3), N3 = 3xi^2 - 2xi^3, "
                           "N4 = L(xi^3 - xi^2) (paper Eqs. 2-6)",
        },
        "pull_direction": sc.pull.direction,
        "conduit_length_m": centre.length_m,
        "inner_radius_m": model.conduit.inner_radius_m,
        "cable": {
            "length_m": sc.cable_length_m,
            "elements": model.layout.n_elements,
            "radius_m": sc.cable.radius_m,
            "mass_per_length_kg_per_m": props.mass_per_length_kg_per_m,
            "axial_stiffness_N": props.axial_stiffness_N,
            "bending_stiffness_N_m2": props.bending_stiffness_N_m2,
            "axial_damping_N_s": props.axial_damping_N_s,
            "bending_damping_N_m2_s": props.bending_damping_N_m2_s,
            "integration": props.integration,
            "strain": "absolute: eps = |r'| - 1, curvature vector kappa = (r' x r'') / |r'|^2 (Exudyn "
                      "ObjectANCFCable, strainIsRelativeToReference = 0)",
            "lead_out_m": lead_out,
            "lead_out": "cable laid out past the conduit's exit at the start, along the exit tangent (steady mode "
                        "and solver.start_from = 'steady': the rig sits that far out; 0: flush with the exit)",
        },
        "equations": equations,
        "gravity_m_per_s2": [0.0, 0.0, -g if g else 0.0],
        "contact": contact,
        "rig": rig,
        "startup_damper": None if damper is None else {
            "rate_1_per_s": damper.rate, "duration_s": damper.duration,
            "law": "-c(t) m_k (v_k - v_k,initial) on node positions, m_k = lumped mass, "
                   "c(t) = rate (1 - smoothstep(t / duration))",
        },
        "exit_span_damper": None if getattr(model, "exit_span_damper", None) is None else {
            "rate_1_per_s": model.exit_span_damper.rate, "ramp_length_m": model.exit_span_damper.ramp_length,
            "law": "-rate w_k m_k (v_k - V r'_k/|r'_k|) on node positions, m_k = lumped mass, V = rig speed, "
                   "w_k = smoothstep(((r_k - exit point) . exit_tangent) / ramp_length_m), clipped to [0, 1]",
        },
        "solver": {
            "method": ("Exudyn's static Newton (exucable's own loop on the assembled system, or Exudyn "
                       "MainSolverStatic: solver.static_solver): pseudo-transient continuation to the static "
                       "equilibrium (exucable/solve/steady.py); no time, no inertia" if steady else
                       "Exudyn MainSolverImplicitSecondOrder (generalized-alpha), adaptive step, full Newton"),
            "steady_residual": sp.steady_residual,
            "steady_residual_rule": ("steady mode: stop when |residual| <= steady_residual * the rope "
                                     "solution's largest tension"),
            "end_time_s": sp.end_time_s,
            "step_s": sp.step_s,
            "min_step_s": sp.min_step_s,
            "newton_max_iterations": sp.newton_max_iterations,
            "newton_tolerance": sp.newton_tolerance,
            "spectral_radius": sp.spectral_radius,
            "pretension": sp.pretension,
        },
        "scenario": sc.to_dict(),
        "versions": versions(),
    }


def problem_tables(model) -> dict[str, dict]:
    """The CSV tables of the export: file name -> {column: array}."""
    lay = model.layout
    n_el = lay.n_elements
    Le = np.asarray(lay.element_length_m, dtype=float)
    q0 = lay.coordinates
    nodes = {"node": np.arange(n_el + 1), "x_m": lay.node_x_m, "s_conduit_m": conduit_s(model, lay.node_s_m)}
    for k, c in enumerate("xyz"):
        nodes[f"pos_{c}_m"] = lay.position_m[:, k]
        nodes[f"slope_{c}"] = lay.slope[:, k]
        nodes[f"vel_{c}_m_per_s"] = lay.velocity_m_per_s[:, k]
        nodes[f"slope_rate_{c}_1_per_s"] = lay.slope_rate_1_per_s[:, k]
    x_mid = lay.node_x_m[:-1] + 0.5 * Le
    eps_mid = axial_strain(q0, Le, x_mid)
    elements = {"element": np.arange(n_el), "node_i": np.arange(n_el), "node_j": np.arange(1, n_el + 1),
                "reference_length_m": Le, "x_start_m": lay.node_x_m[:-1], "pre_strain_mid": eps_mid,
                "tension_mid_N": model.axial_stiffness_N * eps_mid}
    tables = {"nodes_initial.csv": nodes, "elements.csv": elements}
    kernel = model.kernel
    if kernel is not None:
        n_k = kernel.n_check_points
        e = np.repeat(np.arange(n_el), n_k)
        xi = np.tile(kernel.xi, n_el)
        om = np.tile(kernel.omega, n_el)
        tables["check_points.csv"] = {"element": e, "point": np.tile(np.arange(n_k), n_el), "xi": xi,
                                      "weight": om, "contact_weight": Le[e] * om / kernel.reference_spacing_m,
                                      "x_m": lay.node_x_m[e] + xi * Le[e]}
    seg = model.conduit.segments
    centre = model.conduit.centreline
    sv = np.asarray(seg.s_vertex_m, dtype=float)
    mid = np.clip(0.5 * (sv[1:] + sv[:-1]), 0.0, centre.length_m)
    segs = {"segment": np.arange(seg.count), "piece": np.asarray(centre.piece_index(mid))}
    for k, c in enumerate("xyz"):
        segs[f"start_{c}_m"] = seg.start_m[:, k]
        segs[f"end_{c}_m"] = seg.end_m[:, k]
    segs.update(s_start_pull_m=sv[:-1], s_end_pull_m=sv[1:], s_start_conduit_m=conduit_s(model, sv[:-1]),
                s_end_conduit_m=conduit_s(model, sv[1:]))
    tables["conduit_segments.csv"] = segs
    pieces = centre.pieces
    rows = {c: [] for c in PIECE_COLUMNS}
    for i, p in enumerate(pieces):
        rows["piece"].append(i)
        rows["curved"].append(1 if p.is_curved else 0)
        rows["s_start_pull_m"].append(p.s_start_m)
        rows["length_m"].append(p.length_m)
        for name, v in (("start", p.start_m), ("dir", p.direction), ("centre", p.centre_m), ("e1", p.e1),
                        ("e2", p.e2), ("axis", p.axis)):
            v = np.full(3, np.nan) if v is None else np.asarray(v, dtype=float)
            unit = "_m" if name in ("start", "centre") else ""
            for k, c in enumerate("xyz"):
                rows[f"{name}_{c}{unit}"].append(v[k])
        rows["coil_radius_m"].append(p.coil_radius_m if p.is_curved else np.nan)
        rows["rise_m_per_rad"].append(p.rise_m_per_rad if p.is_curved else 0.0)
        rows["phi_rad"].append(p.phi_rad if p.is_curved else 0.0)
    tables["conduit_pieces.csv"] = rows
    return tables


def export_problem(scenario, out_dir, mode: str | None = None) -> list[Path]:
    """Build ``scenario``'s model and write its discrete problem into ``out_dir``; ``problem.json``
    last (its presence marks a complete export). ``mode`` (``"dynamic"`` or ``"steady"``) overrides
    ``solver.mode``, as for ``exucable run``. Returns the paths written.

    ``out_dir`` is checked and owned before the model is built
    (:func:`exucable.output.outdir.owned_out_dir`)."""
    import dataclasses

    from ..model.build import build_model
    from ..scenario.specs import Scenario, load_scenario
    from .outdir import owned_out_dir

    sc = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    if mode is not None and mode != sc.solver.mode:
        sc = dataclasses.replace(sc, solver=dataclasses.replace(sc.solver, mode=mode))
    with owned_out_dir(out_dir) as out:
        return _export(sc, build_model(sc), out)


def _export(sc, model, out: Path) -> list[Path]:
    """Write the tables, then ``problem.json``; an earlier export's ``problem.json`` goes first, so
    it never vouches for tables of this one that a failed write left out."""
    (out / "problem.json").unlink(missing_ok=True)
    written = []
    for name, data in problem_tables(model).items():
        write_csv(out / name, EXPORT_FILES[name], data)
        written.append(out / name)
    write_json(out / "problem.json", problem_description(model))
    written.append(out / "problem.json")
    return written
