"""Several cables pulled together through one conduit, in the dynamic mode (``cable.count`` 2-4).

The same bundle as the steady model (:mod:`exucable.model.bundle`): one ANCF cable per conductor
with the scenario's cable data, laid in the arrangement's cross-section turned toward the lateral
load and pre-tensioned to the rope of one cable carrying its share (or started in the steady
bundle's solved state, ``solver.start_from = "steady"``), each with its own wall contact (the
cable-conduit kernel, paper Eqs. 18-23, with the nodal rates) and the contact between the cables
(:class:`~exucable.contact.cable_pairs.CableContactKernel` with the points' velocities from the
nodal rates) as one more coupling.

Each cable is a :func:`~exucable.model.build.add_cable_in_conduit` of the one-cable dynamic run in
the same Exudyn system: its weight, start-up damper, Kelvin-Voigt damping and, at the trailing
end, its share T_b/n of the bundle's back tension along the entry tangent (identical cables fed off
one reel set or one brake, as the steady model takes it). The pulling eye is the rig (paper
Sect. 2.1, :func:`~exucable.model.rig.add_drive`) on each leading end, all moving along the exit
tangent at the pull speed from their places in the eye: a rigid eye that does not turn, whose
reaction, the pulling force, is the sum of the ends' reactions along the pull.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np
import exudyn as exu

from ..errors import ModelError
from ..post.tension import equilibrium_tension, profile_stations_m
from ..post.trust import cable_sample_points
from .bundle import BundleLayout, BundleModel
from .generic import add_user_force_object
from .layout import InitialLayout, sliding_layout
from .rig import pulled_distance_m

__all__ = ["BundleDynamicModel", "build_bundle_dynamic_model", "solved_bundle_layouts", "PairContactCoupling"]


class PairContactCoupling:
    """Contact between the cables (:class:`~exucable.contact.cable_pairs.CableContactKernel`) in a
    dynamic run: one mass-free ``ObjectGenericODE2`` over every cable's nodes whose force uses the
    points' velocities from the nodal rates, with the exact LHS Jacobian -(f_q ∂Q/∂q + f_v ∂Q/∂q̇)."""

    def __init__(self, mbs, nodes, reference_coordinates, kernel):
        self.kernel = kernel
        self.q_ref = np.ascontiguousarray(np.asarray(reference_coordinates, dtype=float).reshape(-1))
        self.n = self.q_ref.size
        self._last = None
        self.evaluations = 0
        self.kernel_time_s = 0.0
        self.object = add_user_force_object(mbs, nodes, self.n, self._force, self._jacobian)

    def _evaluate(self, q, q_t):
        # Exudyn asks for the residual and then the Jacobian at one state: one kernel pass serves
        # both, reused only for the same coordinates and rates bit for bit
        qa = self.q_ref + np.asarray(q, dtype=float)
        va = np.asarray(q_t, dtype=float)
        last = self._last
        if last is not None and np.array_equal(last[0], qa) and np.array_equal(last[1], va):
            return last[2]
        t0 = time.perf_counter()
        res = self.kernel.evaluate(qa, jacobian=True, q_t=va)
        self.kernel_time_s += time.perf_counter() - t0
        self.evaluations += 1
        self._last = (qa.copy(), va.copy(), res)
        return res

    def _force(self, mbs, t, item, q, q_t):
        return self._evaluate(q, q_t).generalized_force

    def _jacobian(self, mbs, t, item, q, q_t, f_q, f_v):
        res = self._evaluate(q, q_t)
        # LHS derivative: the contact force is on the right-hand side, hence the minus sign
        J = (-(f_q * res.jacobian + f_v * res.jacobian_t)).tocoo()
        keep = J.data != 0.0   # Exudyn's sparse triplets must not contain zeros
        m = exu.MatrixContainer()
        if keep.any():
            m.SetWithSparseMatrix(np.column_stack([J.row[keep].astype(float), J.col[keep].astype(float), J.data[keep]]),
                                  self.n, self.n, False)
        else:
            m.Initialize(self.n, self.n, False)
        return m


class _WallCouplings:
    """The cables' wall couplings as one for :func:`exucable.solve.dynamic.simulate`: each holds its
    check points' damping onset within a step."""

    def __init__(self, parts):
        self.parts = parts

    def start_step(self, mbs, t) -> None:
        for p in self.parts:
            p.start_step(mbs, t)

    @property
    def kernel_time_s(self) -> float:
        return float(sum(p.kernel_time_s for p in self.parts))


@dataclass(eq=False, repr=False)
class BundleDynamicModel:
    """Several cables in one conduit in an assembled Exudyn system, for the time integration
    (:func:`build_bundle_dynamic_model`). It answers what :func:`exucable.solve.dynamic.simulate`
    and its recorder ask of a model, and what :func:`exucable.model.bundle.bundle_report` asks of a
    bundle.

    Attributes
    ----------
    scenario : Scenario
        The bundle's scenario (``cable.count`` > 1, dynamic mode).
    mbs, system_container
    handles : list of CableInConduit
        One per cable, trailing end first in each: its nodes, wall kernel and coupling, start-up
        damper, drive (its leading end in the eye) and loads.
    start : BundleModel
        The steady bundle model whose start (or solved state) the run starts from; its rope
        references, offsets and arrangement are the run's.
    between : CableContactKernel
    between_coupling : PairContactCoupling
    start_layout : BundleLayout
        The cables' start state (the reference coordinates).
    reference_drift_N_per_s : float
        How fast the bundle's rope pulling force moves as the cables leave the conduit [N/s]: n
        times one cable's share rope (friction μ times the calculators' weight correction, back
        tension T_b/n), :func:`exucable.quasistatic.extent.reference_drift_N_per_s`.
    """

    scenario: object
    mbs: exu.MainSystem
    system_container: exu.SystemContainer
    handles: list
    start: BundleModel
    between: object
    between_coupling: PairContactCoupling
    start_layout: BundleLayout
    reference_drift_N_per_s: float = 0.0
    applied_pull_force_N: float | None = None
    share_history_N: list = field(default_factory=list)
    _ode2_index: np.ndarray | None = field(default=None)

    def __repr__(self) -> str:
        return (f"BundleDynamicModel({self.scenario.name!r}: {self.n_cables} cables {self.arrangement}, "
                f"{len(self.handles[0].cable.elements)} elements each)")

    # -- what the steady bundle's report reads, the start's
    @property
    def n_cables(self) -> int:
        return len(self.handles)

    @property
    def conduit(self):
        return self.start.conduit

    @property
    def arrangement(self) -> str:
        return self.start.arrangement

    @property
    def offsets_m(self) -> np.ndarray:
        return self.start.offsets_m

    @property
    def rope(self):
        return self.start.rope

    @property
    def rope_alone(self):
        return self.start.rope_alone

    @property
    def mesh(self):
        return self.start.mesh

    @property
    def lead_out_m(self) -> float:
        return self.start.lead_out_m

    @property
    def back_tension_N(self) -> float:
        return self.scenario.pull.back_tension_N

    @property
    def properties(self):
        return self.handles[0].properties

    @property
    def axial_stiffness_N(self) -> float:
        return self.properties.axial_stiffness_N

    @property
    def cables(self) -> list:
        return [h.cable for h in self.handles]

    @property
    def walls(self) -> list:
        return [h.kernel for h in self.handles]

    @property
    def kernel(self):
        """The first cable's wall kernel (the recorder measures every cable: :meth:`record_state`)."""
        return self.handles[0].kernel

    @property
    def coupling(self) -> _WallCouplings:
        return _WallCouplings([h.coupling for h in self.handles])

    @property
    def startup_damper(self):
        return self.handles[0].startup_damper

    def pulled_m(self, t: float | None = None) -> float:
        """How far the eye has moved along the pull since the start at time ``t`` [s] (now) [m]."""
        t = float(self.mbs.systemData.GetTime()) if t is None else float(t)
        p = self.scenario.pull
        return pulled_distance_m(t, p.speed_m_per_s, p.ramp_time_s, p.stop_time_s, p.hold_time_s)

    @property
    def layout(self) -> BundleLayout:
        """The cables' start: the report's stations along the route are the material points laid
        there at the start, as in steady mode (:func:`exucable.model.bundle.straight_weight_correction`),
        here moved on by the eye's travel :meth:`pulled_m` since. Material points, not places: the
        check points are material too, so two stations keep their places between the check points
        (the contact loads are concentrated there) and the tension rise between them does not step
        as a check point passes."""
        return self.start_layout

    # -- state
    @property
    def ode2_index(self) -> np.ndarray:
        """The cables' coordinates in the system's ODE2 vector, cable after cable."""
        if self._ode2_index is None:
            self._ode2_index = np.concatenate([h.ode2_index for h in self.handles])
        return self._ode2_index

    def coordinates(self) -> tuple[np.ndarray, np.ndarray]:
        """Absolute nodal coordinates and rates of all cables, each (n_cables·(n_el + 1), 6)."""
        sd = self.mbs.systemData
        q = np.asarray(sd.GetODE2Coordinates())[self.ode2_index]
        v = np.asarray(sd.GetODE2Coordinates_t())[self.ode2_index]
        return self.start_layout.coordinates + q.reshape(-1, 6), v.reshape(-1, 6)

    def cable_coordinates(self) -> list[np.ndarray]:
        """Each cable's absolute nodal coordinates (n_el + 1, 6)."""
        return [h.coordinates()[0] for h in self.handles]

    def pull_shares_N(self) -> np.ndarray:
        """Each cable's pull at the eye now [N]: its leading end's reaction along the exit tangent."""
        return np.array([h.lead_drive.force_N(self.mbs) for h in self.handles])

    def pull_force_N(self, t: float) -> float:
        """The eye's pull along the exit tangent [N]: the sum of the leading ends' reactions."""
        return float(np.sum(self.pull_shares_N()))

    def cable_loads(self) -> list:
        """Each cable's external loads now (:meth:`exucable.model.build.CableInConduit.loads`: the
        wall's contact forces, weight, inertia, dampers, its back tension share and its end's
        reaction in the eye) with the other cables' contact forces at its check points
        (:meth:`~exucable.contact.cable_pairs.CableContactKernel.point_forces_N`, the points'
        velocities from the nodal rates)."""
        q, v = self.coordinates()
        x_between, f_between = self.between.point_forces_N(q.reshape(-1), v.reshape(-1))
        out = []
        for i, h in enumerate(self.handles):
            loads = h.loads()
            out.append(dataclasses.replace(loads, point_x_m=np.concatenate([loads.point_x_m, x_between]),
                                           point_force_N=np.concatenate([loads.point_force_N, f_between[i]])))
        return out

    def tension_N(self, x_m) -> np.ndarray:
        """Each cable's tension [N] at material stations ``x_m`` [m] from the trailing ends, shape
        (n_cables, m), from the equilibrium of its loads (:meth:`cable_loads`,
        :func:`~exucable.post.tension.equilibrium_tension`, inertia included)."""
        Le = self.start_layout.element_length_m
        return np.stack([equilibrium_tension(q, Le, loads, x_m)
                         for q, loads in zip(self.cable_coordinates(), self.cable_loads())])

    def record_state(self, t: float, history, gauge=None) -> None:
        """Append the bundle's row to ``history`` (the recorder's, as for one cable): the eye's pull,
        the cables' trailing tensions summed, the largest tension of any cable, the largest wall
        penetration of any cable and the largest distance of any cable's axis from the conduit's
        axis with its place along the scenario's conduit. Each cable's share of the pull is kept
        in :attr:`share_history_N` (time, shares)."""
        shares = self.pull_shares_N()
        N = self.tension_N(profile_stations_m(self.start_layout.element_length_m))
        history.time_s.append(float(t))
        history.pull_force_N.append(float(np.sum(shares)))
        history.trailing_tension_N.append(float(np.sum(N[:, 0])))
        history.max_tension_N.append(float(np.max(N)))
        self.share_history_N.append((float(t), shares))
        pen, offset, s_off = -np.inf, -np.inf, float("nan")
        L = self.conduit.centreline.length_m
        for h in self.handles:
            q, v = h.coordinates()
            delta = h.kernel.points(q.reshape(-1), v.reshape(-1)).penetration_m
            found = np.isfinite(delta)
            if found.any():
                pen = max(pen, float(np.max(delta[found])))
            if gauge is not None:
                d, s = gauge(cable_sample_points(q, h.layout.element_length_m))
                # beyond the conduit's ends the cable is free (feed, pulling line): not the wall's business
                d = np.where((s >= 0.0) & (s <= L), d, -np.inf)
                i = int(np.argmax(d))
                if np.isfinite(d[i]) and d[i] > offset:
                    offset = float(d[i])
                    s_off = float(s[i]) if self.scenario.pull.direction != "reverse" else float(L - s[i])
        history.max_penetration_m.append(pen)
        history.max_axis_offset_m.append(offset if np.isfinite(offset) else float("nan"))
        history.max_axis_offset_s_conduit_m.append(s_off)

    def mean_shares_N(self, from_s: float) -> np.ndarray | None:
        """Each cable's pull share averaged over the records from ``from_s`` [s] on (None without)."""
        rows = [s for t, s in self.share_history_N if t >= from_s - 1e-12]
        return np.mean(rows, axis=0) if rows else None


def solved_bundle_layouts(model: BundleModel) -> list:
    """Each cable's start for a dynamic run from a solved steady bundle: its solved shape, the
    material sliding along it at the pull speed (:func:`exucable.model.layout.sliding_layout`)."""
    V = model.scenario.pull.speed_m_per_s
    out = []
    for lay, q in zip(model.layout.cables, model.cable_coordinates()):
        out.append(sliding_layout(lay.element_length_m, lay.node_x_m, lay.node_s_m, q[:, :3], q[:, 3:], V))
    return out


def build_bundle_dynamic_model(scenario, refine: float = 1.0, start: BundleModel | None = None,
                               layouts: list | None = None) -> BundleDynamicModel:
    """Build and assemble the Exudyn system of ``scenario``'s bundle for the time integration.

    Parameters
    ----------
    scenario : Scenario
        ``cable.count`` > 1, ``solver.mode = "dynamic"``.
    refine : float
        Divides the mesh rule's element length.
    start : BundleModel, optional
        The steady bundle model of the same scenario (``solver.mode = "steady"``) whose start the
        run takes: mesh, arrangement, lead-out, rope references, layout. Built here when not given.
    layouts : list of CableLayout, optional
        Each cable's start instead of ``start``'s own (:func:`solved_bundle_layouts`: the solved
        steady state).

    Raises
    ------
    ModelError
        A case the model does not cover (:func:`exucable.model.bundle.check_bundle_supported`).
    """
    from ..quasistatic.extent import reference_drift_N_per_s
    from ..contact import ContactLaw
    from ..contact.cable_pairs import CableContactKernel
    from .build import add_cable_in_conduit
    from .bundle import build_bundle_model, check_bundle_supported

    sc = scenario
    if sc.solver.mode != "dynamic":
        raise ModelError("solver.mode", f"the bundle's dynamic model is for solver.mode = \"dynamic\", got {sc.solver.mode!r}")
    check_bundle_supported(sc)
    n = sc.cable.count
    if start is None:
        start = build_bundle_model(sc.replace(**{"solver.mode": "steady", "contact.static_friction": None,
                                                 "pull.stop_time": None, "pull.hold_time": None}), refine=refine)
    cables = list(layouts) if layouts is not None else list(start.layout.cables)
    if len(cables) != n or any(c.n_elements != start.layout.cables[0].n_elements for c in cables):
        raise ValueError("internal: the start's layouts do not match the bundle's cables and mesh")
    lay_all = BundleLayout(element_length_m=cables[0].element_length_m, cables=cables, n_cables=n)
    # each cable is the one-cable dynamic model with its share T_b/n of the back tension
    share = sc.replace(**{"pull.back_tension": sc.pull.back_tension_N / n})

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    handles = []
    for lay in cables:
        init = InitialLayout(conduit=start.conduit, rope=start.rope, cable=lay,
                             weight_per_length_N_per_m=sc.cable.mass_per_length_kg_per_m *
                             (sc.gravity.g_m_per_s2 if sc.gravity is not None else 0.0),
                             exit_tangent=start.exit_tangent, entry_tangent=start.entry_tangent, mesh=start.mesh,
                             lead_out_m=start.lead_out_m)
        handles.append(add_cable_in_conduit(mbs, share, start=init))
    ct = sc.contact
    # the wall's normal law, damping and its onset included (a cable dropping onto another must not
    # bounce on the elastic Hertz law), with the cables' own friction
    between_law = ContactLaw(stiffness=ct.stiffness, damping=ct.damping, exponent=ct.exponent,
                             friction=ct.cable_friction, damping_onset_m=ct.damping_onset_m,
                             regularisation_velocity_m_per_s=ct.friction_regularisation_velocity_m_per_s)
    b = start.between
    between = CableContactKernel(n, lay_all.element_length_m, sc.cable.radius_m, between_law, b.n_k,
                                 ct.reference_spacing_m, sc.pull.speed_m_per_s, window=b.window)
    all_nodes = [nd for h in handles for nd in h.cable.nodes]
    between_coupling = PairContactCoupling(mbs, all_nodes, lay_all.coordinates, between)
    mbs.Assemble()
    # the bundle's expected drift: n cables each as its share rope (μ times the weight correction)
    from ..quasistatic import engineering as eng
    wcf = eng.weight_correction_factor(n, start.arrangement, 2.0 * sc.conduit.inner_radius_m, 2.0 * sc.cable.radius_m)
    drift_sc = share.replace(**{"contact.friction": sc.contact.friction * wcf})
    drift = n * reference_drift_N_per_s(drift_sc, start.conduit, sc.solver.end_time_s)
    model = BundleDynamicModel(scenario=sc, mbs=mbs, system_container=SC, handles=handles, start=start,
                               between=between, between_coupling=between_coupling, start_layout=lay_all,
                               reference_drift_N_per_s=drift)
    return model
