"""The pulling rig (paper Sect. 2.1, Eq. 1) and end loads.

The rig is a velocity constraint on the leading end: the node's three position coordinates
follow a prescribed displacement ``d·u(t)`` along the exit tangent ``d`` (position-level
``CoordinateConstraint`` with both ``offsetUserFunction`` and ``offsetUserFunction_t``, as
Exudyn's docs ask for generalized-alpha). The same drive at the trailing end is the brake of a
force-controlled pull. Its reaction (the Lagrange multipliers) is the rig force.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import exudyn as exu
from exudyn.itemInterface import (CoordinateConstraint, LoadForceVector, MarkerNodeCoordinate,
                                  MarkerNodeCoordinates, MarkerNodePosition, NodePointGround, ObjectGenericODE2,
                                  ObjectConnectorCoordinateVector)

__all__ = ["Drive", "Guide", "add_guide", "add_reel", "TangentialDrive", "add_drive", "add_tangential_drive", "add_end_force",
           "smooth_ramp", "ramped_displacement", "pull_speed_factor", "pulled_distance_m", "drive_force_vector_N"]


def smooth_ramp(t: float, ramp_time_s: float) -> float:
    """C¹ ramp 0 → 1 over ``ramp_time_s`` (3τ² − 2τ³); 1 when the ramp time is 0."""
    if ramp_time_s <= 0.0 or t >= ramp_time_s:
        return 1.0
    if t <= 0.0:
        return 0.0
    tau = t / ramp_time_s
    return tau * tau * (3.0 - 2.0 * tau)


def ramped_displacement(t: float, speed_m_per_s: float, ramp_time_s: float) -> float:
    """Displacement [m] at time t of a drive whose speed follows ``speed·smooth_ramp``."""
    if ramp_time_s <= 0.0:
        return speed_m_per_s * t
    if t >= ramp_time_s:
        return speed_m_per_s * (t - 0.5 * ramp_time_s)
    tau = t / ramp_time_s
    return speed_m_per_s * ramp_time_s * (tau ** 3 - 0.5 * tau ** 4)


def _after(t: float, ramp_time_s: float) -> float:
    """:func:`smooth_ramp` started at time 0, 0 before it."""
    return 0.0 if t < 0.0 else smooth_ramp(t, ramp_time_s)


def _moved_after(t: float, ramp_time_s: float) -> float:
    """:func:`ramped_displacement` at unit speed started at time 0, 0 before it [m per m/s]."""
    return 0.0 if t <= 0.0 else ramped_displacement(t, 1.0, ramp_time_s)


def pull_speed_factor(t: float, ramp_time_s: float, stop_time_s: float | None = None,
                      hold_time_s: float | None = None) -> float:
    """The eye's speed over the pull speed at time ``t`` [s], a stopping pull's schedule [-]: the
    ramp up from 0, the ramp down from ``stop_time_s`` and, after ``hold_time_s`` standing still,
    the ramp up again, each the C¹ :func:`smooth_ramp` over ``ramp_time_s`` (a step when 0). No
    stop (None): :func:`smooth_ramp`. A stop at 0 is a pull standing still from the start."""
    f = _after(t, ramp_time_s)
    if stop_time_s is not None:
        f -= _after(t - stop_time_s, ramp_time_s)
        if hold_time_s is not None:
            f += _after(t - stop_time_s - hold_time_s, ramp_time_s)
    return f


def pulled_distance_m(t: float, speed_m_per_s: float, ramp_time_s: float, stop_time_s: float | None = None,
                      hold_time_s: float | None = None) -> float:
    """How far the eye has moved by time ``t`` [s] at ``speed_m_per_s`` [m/s] on the schedule of
    :func:`pull_speed_factor` [m] (its integral)."""
    x = _moved_after(t, ramp_time_s)
    if stop_time_s is not None:
        x -= _moved_after(t - stop_time_s, ramp_time_s)
        if hold_time_s is not None:
            x += _moved_after(t - stop_time_s - hold_time_s, ramp_time_s)
    return speed_m_per_s * x


@dataclass(frozen=True)
class Drive:
    """A node driven along a fixed direction; ``force_N(mbs)`` is the force the drive exerts
    on the cable along ``direction`` [N] (positive = pulling the node forward)."""

    constraints: tuple[int, int, int]
    direction: np.ndarray
    # Exudyn's multiplier is the force on the node with the opposite sign when the node's
    # coordinate is the constraint's second marker (checked: a cable held back by 100 N gives
    # -100 on the drive along +x); +1 when it is the first marker (a reel, add_reel).
    sign: float = -1.0

    def force_N(self, mbs) -> float:
        lam = np.array([mbs.GetObjectOutput(c, exu.OutputVariableType.Force) for c in self.constraints])
        return float(self.sign * (lam @ self.direction))


def drive_force_vector_N(mbs, drive, static: bool = False) -> np.ndarray:
    """The force [N] a :class:`Drive` or :class:`TangentialDrive` exerts on its node, as a vector:
    the multipliers of all three coordinates (the lateral ones hold the end on the rig's line).
    ``static``: the static solver's multipliers carry the opposite sign of the dynamic solver's."""
    flip = -1.0 if static else 1.0
    if isinstance(drive, TangentialDrive):
        return flip * drive.force_N(mbs) * drive.direction
    lam = np.array([mbs.GetObjectOutput(c, exu.OutputVariableType.Force) for c in drive.constraints], dtype=float)
    return flip * drive.sign * lam


def add_drive(mbs, node: int, direction, speed_m_per_s: float, ramp_time_s: float = 0.0,
              stop_time_s: float | None = None, hold_time_s: float | None = None) -> Drive:
    """Drive ``node``'s position along unit ``direction`` at ``speed_m_per_s`` (ramped over
    ``ramp_time_s``; stopping at ``stop_time_s`` and going on after ``hold_time_s``,
    :func:`pull_speed_factor`), holding it on that line. Returns the :class:`Drive`."""
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    # a ground coordinate to constrain against (one per drive keeps drives independent)
    mg = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
    cons = []
    for k in range(3):
        m = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=k))
        dk = float(d[k])
        cons.append(mbs.AddObject(CoordinateConstraint(
            markerNumbers=[mg, m],
            offsetUserFunction=lambda mbs, t, i, off, dk=dk: dk * pulled_distance_m(t, speed_m_per_s, ramp_time_s,
                                                                                  stop_time_s, hold_time_s),
            offsetUserFunction_t=lambda mbs, t, i, off, dk=dk: dk * speed_m_per_s * pull_speed_factor(
                t, ramp_time_s, stop_time_s, hold_time_s),
            visualization={"show": False, "drawSize": -1.0, "color": [-1.0, -1.0, -1.0, -1.0]},
        )))
    return Drive(constraints=tuple(cons), direction=d)


def add_reel(mbs, node: int, direction, coordinate_marker: int, radius_m: float) -> Drive:
    """Reel ``node`` in along unit ``direction`` d by ``radius_m`` × a user's coordinate (a drum's
    rotation angle [rad]): u_k = d_k·R·φ for each position coordinate k (three
    ``CoordinateConstraint``, the node's coordinate first, ``factor1 = d_k R``), so the drum
    feels the cable's pull as the torque R·F. Returns the :class:`Drive` (``force_N`` = F)."""
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    cons = []
    for k in range(3):
        m = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=k))
        cons.append(mbs.AddObject(CoordinateConstraint(
            markerNumbers=[m, coordinate_marker], factor1=float(d[k] * radius_m),
            visualization={"show": False, "drawSize": -1.0, "color": [-1.0, -1.0, -1.0, -1.0]})))
    return Drive(constraints=tuple(cons), direction=d, sign=1.0)


def add_end_force(mbs, node: int, force_vector_N, factor: Callable[[float], float] | None = None) -> int:
    """A force [N] on a node's position (back tension, or the pull of a force-controlled rig),
    optionally scaled in time by ``factor(t)``."""
    f = [float(x) for x in force_vector_N]
    m = mbs.AddMarker(MarkerNodePosition(nodeNumber=node))
    if factor is None:
        return mbs.AddLoad(LoadForceVector(markerNumber=m, loadVector=f))
    return mbs.AddLoad(LoadForceVector(
        markerNumber=m, loadVector=f,
        loadVectorUserFunction=lambda mbs, t, load, fac=factor: [fac(t) * x for x in load]))



@dataclass(frozen=True)
class Guide:
    """The sheave of a force-controlled pull (see :func:`add_guide`).

    Attributes
    ----------
    object : int
        Exudyn object index.
    node_index : int
        Index of the guided node within the cable (0 = trailing end).
    k : float
        Lateral stiffness [N/m].
    c : float
        Lateral damping [N s/m].
    """

    object: int
    node_index: int
    k: float
    c: float


def add_guide(mbs, node: int, direction, stiffness_N_per_m: float, damping_N_s_per_m: float,
              node_index: int = -1) -> Guide:
    """A sheave on the exit tangent for a force-controlled pull: ``node`` is held near the line
    through its start position along unit ``direction`` d by a stiff lateral spring-damper
    (force −k·P·u − c·P·v with P = I − d dᵀ, u its displacement), free to move along it.

    A mass-free ``ObjectGenericODE2`` on the node with constant stiffness k·P and damping c·P
    (Exudyn 1.13's ObjectConnectorCoordinateVector enforced only the first of two such rows in
    our tests). ``node_index`` is the node's index within the cable (for the record).
    """
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    P = np.eye(3) - np.outer(d, d)
    K = np.zeros((6, 6))
    D = np.zeros((6, 6))
    K[:3, :3] = float(stiffness_N_per_m) * P
    D[:3, :3] = float(damping_N_s_per_m) * P
    M, Kc, Dc = (exu.MatrixContainer() for _ in range(3))
    M.Initialize(6, 6, False)
    Kc.SetWithDenseMatrix(K, False)
    Dc.SetWithDenseMatrix(D, False)
    obj = mbs.AddObject(ObjectGenericODE2(
        nodeNumbers=[node], massMatrix=M, stiffnessMatrix=Kc, dampingMatrix=Dc,
        visualization={"show": False, "color": [-1.0, -1.0, -1.0, -1.0], "triangleMesh": [],
                       "showNodes": False, "graphicsDataUserFunction": 0}))
    return Guide(object=obj, node_index=int(node_index), k=float(stiffness_N_per_m), c=float(damping_N_s_per_m))


@dataclass(frozen=True)
class TangentialDrive:
    """A node's speed along a fixed direction, its motion across it free: the brake of a
    force-controlled pull, which pays the cable out at the trailing end while the end follows the
    conduit (a drive holding all three coordinates on the entry tangent would drag it across the
    wall of a helix: 2 mm off after 6 cm). ``force_N`` as for :class:`Drive`."""

    constraint: int
    direction: np.ndarray

    def force_N(self, mbs) -> float:
        # the multiplier is the force component along d that the constraint absorbs (checked:
        # +3.54 N for a 5 N load at 45°); the drive's force on the node is its negative
        return -float(mbs.GetObjectOutput(self.constraint, exu.OutputVariableType.Force))


def add_tangential_drive(mbs, node: int, direction, speed_m_per_s: float) -> TangentialDrive:
    """Velocity-level constraint d·u̇ = speed on ``node`` (unit ``direction`` d)."""
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    scale = np.zeros((1, 6))
    scale[0, :3] = d
    mg = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=mbs.AddNode(NodePointGround())))
    m = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=node))
    c = mbs.AddObject(ObjectConnectorCoordinateVector(
        markerNumbers=[mg, m], scalingMarker0=np.zeros((1, 0)), scalingMarker1=scale,
        offset=[float(speed_m_per_s)], velocityLevel=True, visualization={"show": False}))
    return TangentialDrive(constraint=c, direction=d)
