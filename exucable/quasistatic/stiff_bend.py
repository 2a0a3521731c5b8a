"""A stiff cable pulled round a bend: what its bending stiffness changes against the rope
Pure Python; no Exudyn.

A rope turns by the curvature of the wall it lies on, so its curvature jumps from 0 to 1/ρ where a
straight meets a bend, and it presses the bend with T/ρ [N/m]. A cable of bending stiffness EJ
cannot jump in curvature: it stays off the wall over about a bending length λ = √(EJ/T) after the
bend's start (and before its end), turns there as a free elastica, and lands on the wall with a
**point load** — the concentrated bend-end force that Iordanescu & Tamowski's PULLFLEX adds to the
rope (IEEE Trans. Power Delivery 11(2), 1996, 1015–1022), of the size √(EJ·T)/ρ, with its friction
μ·P and the capstan factor of the rest of the bend.

The model (derivation in ``reference/README.md``, "Bending stiffness at a bend"): a planar,
inextensible elastica under tension, no weight, on an arc of radius ρ (the cable axis' radius on
the inner wall, ρ = R − c), between free straights it does not touch.

- In a free span no load acts, so the force vector is constant, of magnitude T (the far tension
  on that side); with ψ the angle between the cable and the straight, EJ ψ'' = T sin ψ, whose
  decaying solution has ψ' = (2/λ) sin(ψ/2).
- On the arc the curvature is 1/ρ, the moment EJ/ρ is constant, the shear zero, so the contact
  pressure is N/ρ and dN/ds = μ N/ρ: the capstan on the contact arc (Eq. 26 of Yang et al. 2013).
- At the contact edge the moment is continuous, so the free span's curvature is 1/ρ there:
  sin(ψ_e/2) = λ/(2ρ). The span arrives at angle ψ_e with axial force T cos ψ_e and shear
  T sin ψ_e; the shear stops at the wall: the point load P = T sin ψ_e ≈ √(EJ T)/ρ, normal to the
  wall, with friction μ P along the cable.

Entry (far tension T_in, edge angle ψ_0) and exit (far tension T_out, ψ_1), with the contact arc
turning θ − ψ_0 − ψ_1:

    T_out (cos ψ_1 − μ sin ψ_1) = T_in (cos ψ_0 + μ sin ψ_0) · e^{μ(θ − ψ_0 − ψ_1)}

solved by fixed point (ψ_1 depends on T_out). With μ = 0 it gives T_out = T_in exactly
(N + EJ κ²/2 is conserved along a frictionless elastica). For small λ/ρ

    T_out / (T_in e^{μθ}) − 1 ≈ −(1 + μ²) · EJ/(2ρ²) · (1/T_in − 1/T_out) < 0:

the point loads turn the cable by the same angles as the pressure they replace, so the friction
is unchanged at first order in λ/ρ; at second order the entry loses (its span pulls the contact
edge with T cos ψ_0 < T_in) more than the exit gains, and a stiff cable is pulled round a bend
slightly *more easily* than a rope. Valid while the free spans' offset from the rope's line,
λ²/(2ρ) (exact for the elastica), fits in the conduit (``offset ≤ 2 c``: otherwise the cable also presses
the straight's opposite wall, PULLFLEX's three-point bending, not modelled) and while the bend is
longer than the two edge angles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["StiffBend", "stiff_bend", "free_span_stiffness_N"]


@dataclass(frozen=True)
class StiffBend:
    """The stiff cable's tension and bend-end loads on one bend (:func:`stiff_bend`).

    Attributes
    ----------
    tension_out_N : float
        Far tension leaving the bend [N].
    rope_tension_out_N : float
        The rope's, T_in e^{μθ} [N].
    entry_point_load_N, exit_point_load_N : float
        Point loads T sin ψ_e at the contact edges [N] (normal to the wall).
    entry_edge_m, exit_edge_m : float
        Arc length along the cable's axis from the bend's start (end) to its contact edge,
        ρ ψ_e [m], inside the bend.
    entry_offset_m, exit_offset_m : float
        How far the free span's straight lies from the rope's line (towards the outer wall) [m].
    contact_angle_rad : float
        θ − ψ_0 − ψ_1, the arc on the wall [rad].
    """

    tension_out_N: float
    rope_tension_out_N: float
    entry_point_load_N: float
    exit_point_load_N: float
    entry_edge_m: float
    exit_edge_m: float
    entry_offset_m: float
    exit_offset_m: float
    contact_angle_rad: float

    @property
    def vs_rope(self) -> float:
        """T_out / (T_in e^{μθ}) − 1, the bending stiffness' relative change of the pull."""
        return self.tension_out_N / self.rope_tension_out_N - 1.0

    def fits(self, clearance_m: float) -> bool:
        """Whether the model's assumptions hold in a conduit of this clearance c [m]: both free
        spans' offsets ≤ 2c and a contact arc left between the edges."""
        return max(self.entry_offset_m, self.exit_offset_m) <= 2.0 * clearance_m and self.contact_angle_rad > 0.0


def _edge_angle_rad(bending_stiffness_N_m2: float, tension_N: float, radius_m: float) -> float:
    """ψ_e with sin(ψ_e/2) = λ/(2ρ), λ = √(EJ/T) [rad]."""
    half = math.sqrt(bending_stiffness_N_m2 / tension_N) / (2.0 * radius_m)
    if half >= 1.0:
        raise ValueError(f"bending length √(EJ/T) = {2 * half * radius_m:.3g} m exceeds the bend's diameter "
                         f"{2 * radius_m:.3g} m: the cable cannot lie on this bend")
    return 2.0 * math.asin(half)


def _offset_m(bending_stiffness_N_m2: float, tension_N: float, radius_m: float) -> float:
    """How far a free span's far straight lies from the rope's line, towards the outer wall [m].

    From the bend's end to the edge the arc rises ρ(1 − cos ψ_e) = λ²/(2ρ) off the rope's line; the
    span, from the edge outwards, comes back ∫ sin ψ ds = λ ∫_0^{ψ_e} cos(ψ/2) dψ = 2λ sin(ψ_e/2)
    = λ²/ρ: exactly λ²/(2ρ) beyond the line.
    """
    return bending_stiffness_N_m2 / tension_N / (2.0 * radius_m)


def stiff_bend(tension_in_N: float, friction: float, angle_rad: float, radius_m: float,
               bending_stiffness_N_m2: float, exit_held_m: float | None = None, tol: float = 1e-12) -> StiffBend:
    """Far tension out of a planar bend for a cable of bending stiffness EJ, and its bend-end loads.

    Parameters
    ----------
    tension_in_N : float
        Far tension T_in entering the bend [N] (> 0).
    friction : float
        Coulomb coefficient μ (≥ 0).
    angle_rad : float
        The bend's turning angle θ [rad].
    radius_m : float
        ρ, the radius of the cable's axis on the bend's inner wall [m] (R − c).
    bending_stiffness_N_m2 : float
        EJ [N m²] (≥ 0; 0 gives the capstan, Eq. 26 of Yang et al. 2013).
    exit_held_m : float, optional
        Where the cable is held on the rope's line after the bend, as by a pulling rig on the exit
        straight's line, this far beyond the bend's end [m]. The exit span's line, which would lie
        λ²/(2ρ) towards the outer wall, then runs from there to the held point: the cable turns
        Δθ = atan(λ²/(2ρ) / (exit_held_m + ρψ_1)) more on the wall, a factor e^{μΔθ}. Default:
        free (a long exit straight).

    Returns
    -------
    StiffBend
        See the module docstring for the model and its validity (:meth:`StiffBend.fits`).
    """
    if tension_in_N <= 0.0:
        raise ValueError(f"tension_in_N must be > 0, got {tension_in_N}")
    mu, theta, rho, ej = friction, angle_rad, radius_m, bending_stiffness_N_m2
    rope_out = tension_in_N * math.exp(mu * theta)
    psi0 = _edge_angle_rad(ej, tension_in_N, rho)
    entry_axial = tension_in_N * (math.cos(psi0) + mu * math.sin(psi0))
    t_out = rope_out

    def held_turn_rad(t, psi1):
        return 0.0 if exit_held_m is None else math.atan(_offset_m(ej, t, rho) / (exit_held_m + rho * psi1))

    for _ in range(200):
        psi1 = _edge_angle_rad(ej, t_out, rho)
        denominator = math.cos(psi1) - mu * math.sin(psi1)
        if denominator <= 0.0:
            raise ValueError(f"the exit span's edge angle {psi1:.3g} rad locks with friction {mu}: outside the model")
        new = entry_axial * math.exp(mu * (theta + held_turn_rad(t_out, psi1) - psi0 - psi1)) / denominator
        if abs(new - t_out) <= tol * new:
            t_out = new
            break
        t_out = new
    psi1 = _edge_angle_rad(ej, t_out, rho)
    return StiffBend(tension_out_N=t_out, rope_tension_out_N=rope_out,
                     entry_point_load_N=tension_in_N * math.sin(psi0), exit_point_load_N=t_out * math.sin(psi1),
                     entry_edge_m=rho * psi0, exit_edge_m=rho * psi1,
                     entry_offset_m=_offset_m(ej, tension_in_N, rho), exit_offset_m=_offset_m(ej, t_out, rho),
                     contact_angle_rad=theta + held_turn_rad(t_out, psi1) - psi0 - psi1)


def free_span_stiffness_N(bending_stiffness_N_m2: float, friction: float, radius_m: float, clearance_m: float,
                          weight_normal_N_per_m: float, tension_N: float) -> float:
    """Extra pull [N] from one free span crossing the clearance between a straight's floor and a
    vertical bend's upper wall, because the cable has bending stiffness EJ.

    Where a bend's pressure T/ρ opposes the weight w⊥ (an up-bend, ρ w⊥ < T), the flexible cable
    in its clearance leaves the floor and lands tangentially on the bend's upper wall in a free span
    of curvature k = w⊥/T, of horizontal length X₀ = √(4c / (k (1 − kρ))) from lift-off to landing
    (the parabola −c + kx²/2 touching the arc c + u²/(2ρ)). A beam (λ = √(EJ/T)) cannot jump in
    curvature at either end: solving EJ w⁗ − T w″ = −w⊥ across the span with the floor's and the
    arc's curvature at its ends, it leaves the floor λ earlier and lands λ later, with point loads
    w⊥λ and λ(T/ρ − w⊥) that replace the pressure of those stretches (no change at first order),
    and its ends' curvature lifts it λ²(1/ρ − k/2) more, which the span makes up by leaving the
    floor λ²/(2ρ k X₀) later. That much more floor carries w⊥ — and the rope counts a floor load
    twice: once on the floor, once more where it must be taken off the bend's opposite pressure —
    so the friction grows by

        ΔF = 2 μ w⊥ · λ²/(2ρ k X₀) = μ EJ / (ρ X₀),

    independent of the weight's size, linear in EJ. A span at a bend's entry grows through the
    bend by the capstan factor like any load there (the caller applies it).

    Parameters
    ----------
    bending_stiffness_N_m2 : float
        EJ [N m²].
    friction : float
        μ.
    radius_m : float
        ρ, the radius of the cable's axis on the bend's upper wall [m].
    clearance_m : float
        c [m] (the axis moves ±c about the centreline).
    weight_normal_N_per_m : float
        w⊥, the weight per length normal to the straight [N/m] (> 0).
    tension_N : float
        T at the span [N].

    Returns
    -------
    float
        ΔF at the span [N]; 0 where no span forms (ρ w⊥ ≥ T: the cable stays on the floor).
    """
    k = weight_normal_N_per_m / tension_N
    if k * radius_m >= 1.0 or clearance_m <= 0.0:
        return 0.0
    span_m = math.sqrt(4.0 * clearance_m / (k * (1.0 - k * radius_m)))
    return friction * bending_stiffness_N_m2 / (radius_m * span_m)
