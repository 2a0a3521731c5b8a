"""One helper for the mass-free ``ObjectGenericODE2`` that carries a Python force on cable nodes."""

from __future__ import annotations

import exudyn as exu
from exudyn.itemInterface import ObjectGenericODE2

__all__ = ["add_user_force_object"]


def add_user_force_object(mbs, nodes, n_coordinates: int, force_function, jacobian_function) -> int:
    """Add an ``ObjectGenericODE2`` over ``nodes`` with no mass, stiffness or damping of its own,
    whose generalized force and its exact LHS Jacobian come from the two user functions
    (Exudyn's signatures ``f(mbs, t, item, q, q_t)`` and ``J(mbs, t, item, q, q_t, f_q, f_v)``).

    Returns
    -------
    int
        The Exudyn object index.
    """
    empty = [exu.MatrixContainer() for _ in range(3)]
    for m in empty:
        m.Initialize(n_coordinates, n_coordinates, False)
    return mbs.AddObject(ObjectGenericODE2(
        nodeNumbers=list(nodes),
        massMatrix=empty[0], stiffnessMatrix=empty[1], dampingMatrix=empty[2],
        forceUserFunction=force_function, jacobianUserFunction=jacobian_function,
        visualization={"show": False, "color": [-1.0, -1.0, -1.0, -1.0], "triangleMesh": [],
                       "showNodes": False, "graphicsDataUserFunction": 0},
    ))
