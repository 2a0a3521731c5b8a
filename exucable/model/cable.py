"""The cable as Exudyn 3D ANCF cable elements (paper Sect. 2.2, Eqs. 2-13).

``NodePointSlope1`` nodes carry ``[x, y, z, x', y', z']`` (position [m] and slope dr/dx [-]);
``ObjectANCFCable`` elements join consecutive nodes. Strain and curvature are measured
absolutely (``strainIsRelativeToReference = 0``), so a node layout that is stretched or curved
carries tension or bending moment from the start: that is how a pre-tensioned start is built.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import exudyn as exu
from exudyn.itemInterface import MarkerBodyMass, NodePointSlope1, ObjectANCFCable, LoadMassProportional

from ..scenario.fields import default_of

__all__ = ["CableProperties", "CableHandles", "add_cable", "add_gravity", "item_dict", "INTEGRATION"]

# Exudyn's useReducedOrderIntegration. Full Gauss quadrature lets coarse elements on curves carry
# a saw-tooth of axial force (Example 3 with 40 elements: 43.5 N inside a cable pulled with
# 40 N); Lobatto quadrature of the axial term removes it (40.6 N) at the same end forces.
INTEGRATION = {"full": 0, "reduced": 1, "lobatto": 2}


@dataclass(frozen=True)
class CableProperties:
    """Section properties of the cable.

    Attributes
    ----------
    mass_per_length_kg_per_m : float
        ρA [kg/m].
    axial_stiffness_N : float
        EA [N].
    bending_stiffness_N_m2 : float
        EJ [N m²].
    axial_damping_N_s : float
        Axial (Kelvin-Voigt) damping, force per strain rate [N s].
    bending_damping_N_m2_s : float
        Bending damping, moment per curvature rate [N m² s].
    integration : str
        ``"full"``, ``"reduced"`` or ``"lobatto"`` quadrature (see ``INTEGRATION``).
    """

    mass_per_length_kg_per_m: float
    axial_stiffness_N: float
    bending_stiffness_N_m2: float
    axial_damping_N_s: float = 0.0
    bending_damping_N_m2_s: float = 0.0
    integration: str = default_of("cable.integration")


@dataclass(frozen=True)
class CableHandles:
    """Exudyn indices of the cable: ``nodes[0]`` is the trailing end; ``elements`` is empty when
    the cable's elastic forces are assembled by exucable (:func:`add_cable`'s ``with_elements``)."""

    nodes: tuple[int, ...]
    elements: tuple[int, ...]
    element_length_m: np.ndarray

    @property
    def n_elements(self) -> int:
        return len(self.element_length_m)


def item_dict(item) -> dict:
    """An Exudyn item's dict (``dict(NodePointSlope1(...))``) without the entries that equal its
    class's defaults, its type kept: Exudyn fills those in with the same defaults
    (``tests/test_cable.py`` compares the items) and reads the shorter dict in about half the time."""
    given, default = dict(item), dict(type(item)())
    kind = next(iter(given))            # nodeType, objectType, markerType or loadType: first
    return {k: v for k, v in given.items()
            if k == kind or k not in default or not np.array_equal(np.asarray(v, dtype=object), np.asarray(default[k], dtype=object))}


def add_cable(mbs, coordinates, element_length_m, properties: CableProperties, velocities=None,
              draw_radius_m: float = 0.0, with_elements: bool = True) -> CableHandles:
    """Add ANCF cable nodes and elements to ``mbs``.

    Parameters
    ----------
    mbs : exudyn.MainSystem
    coordinates : array_like (n_el + 1, 6)
        Reference coordinates ``[x, y, z, x', y', z']`` of each node [m, -]; the simulation starts
        there (initial displacement zero).
    element_length_m : array_like (n_el,)
        Unstretched element lengths [m].
    properties : CableProperties
    velocities : array_like (n_el + 1, 6), optional
        Initial coordinate rates [m/s, 1/s].
    draw_radius_m : float
        Radius for Exudyn's renderer only [m].
    with_elements : bool
        False: the nodes only, no ``ObjectANCFCable`` (a steady solve whose cable forces come from
        :class:`exucable.contact.ancf_cable.AncfCableForces` in the contact's user function).
    """
    coords = np.asarray(coordinates, dtype=float)
    lengths = np.asarray(element_length_m, dtype=float)
    if coords.ndim != 2 or coords.shape[1] != 6 or coords.shape[0] != len(lengths) + 1:
        raise ValueError("coordinates must have shape (n_elements + 1, 6)")
    vel = np.zeros_like(coords) if velocities is None else np.asarray(velocities, dtype=float)
    p = properties
    # Each item from its interface class's dict with the per-item values replaced, less the entries
    # that are the class's defaults (:func:`item_dict`): the same items, at about a quarter of the cost
    # of building an interface object per item (a long route adds tens of thousands). A fresh dict per
    # call: Exudyn writes the item's name into the one it gets.
    node = item_dict(NodePointSlope1())
    nodes = tuple(mbs.AddNode(dict(node, referenceCoordinates=c, initialVelocities=v))
                  for c, v in zip(coords, vel))       # numpy rows: Exudyn reads them without Python floats
    element = item_dict(ObjectANCFCable(
        nodeNumbers=[0, 1],
        length=1.0,
        massPerLength=p.mass_per_length_kg_per_m,
        axialStiffness=p.axial_stiffness_N,
        bendingStiffness=p.bending_stiffness_N_m2,
        axialDamping=p.axial_damping_N_s,
        bendingDamping=p.bending_damping_N_m2_s,
        useReducedOrderIntegration=INTEGRATION[p.integration],
        visualization={"show": True, "radius": draw_radius_m, "color": [-1.0, -1.0, -1.0, -1.0]},
    ))
    elements = tuple(mbs.AddObject(dict(element, nodeNumbers=[nodes[i], nodes[i + 1]], length=length))
                     for i, length in enumerate(lengths.tolist())) if with_elements else ()
    return CableHandles(nodes=nodes, elements=elements, element_length_m=lengths)


def add_gravity(mbs, cable: CableHandles, acceleration_m_per_s2, factor=None) -> list[int]:
    """Weight of every element: a mass-proportional load ``ρA·g`` [N/m].

    ``factor(t)`` (optional) scales it in time, for a ramped start.
    """
    g = [float(a) for a in acceleration_m_per_s2]
    loads = []
    marker, load = item_dict(MarkerBodyMass()), item_dict(LoadMassProportional(loadVector=g))
    for e in cable.elements:
        m = mbs.AddMarker(dict(marker, bodyNumber=e))    # as in add_cable: the item's dict, fresh
        if factor is None:
            loads.append(mbs.AddLoad(dict(load, markerNumber=m)))
        else:
            loads.append(mbs.AddLoad(LoadMassProportional(
                markerNumber=m, loadVector=g,
                loadVectorUserFunction=lambda mbs, t, load, f=factor: [f(t) * x for x in load])))
    return loads
