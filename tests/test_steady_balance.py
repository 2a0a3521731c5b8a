"""A steady state that is not the steady pull is caught (exucable.post.balance), never reported "ok".

The check's two conditions hold for every steady sliding state with Coulomb friction (the module's
docstring derives them); the cases here are closed forms: a straight horizontal cable of weight W on
the conduit's floor pulled at F = T_b + μW (the rope's exact answer on a straight) passes; the same
cable balanced with only part of the friction μN on the floor's reactions (as check points that slide
without friction, or leave the wall's force without its friction, would give) fails, as does a state
whose loads do not balance.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from exucable.post.balance import BALANCE_TOLERANCE, steady_balance
from exucable.post.tension import CableLoads

MU, W_PER_M, L, T_B = 0.3, 20.0, 10.0, 50.0


def _straight(friction_share: float = 1.0, pull_N: float | None = None):
    """Loads of a straight horizontal cable along +x on the floor: the floor carries the weight W
    (normal force up, friction ``friction_share``·μN against the motion, in 100 check points); pulled
    at ``pull_N`` (default: what balances, T_b + share·μW)."""
    W = W_PER_M * L
    n = 100
    point = np.tile([-friction_share * MU * W / n, 0.0, W / n], (n, 1))
    F = T_B + friction_share * MU * W if pull_N is None else pull_N
    lead = np.array([F, 0.0, 0.0])
    trail = np.array([-T_B, 0.0, 0.0])
    nodes = np.zeros((11, 6))
    nodes[:, 0] = np.linspace(0.0, L, 11)
    nodes[:, 3] = 1.0
    loads = CableLoads(point_x_m=np.linspace(0.05, L - 0.05, n), point_force_N=point, node_force_N=np.zeros((11, 3)),
                       line_load_N_per_m=np.array([0.0, 0.0, -W_PER_M]), mass_per_length_kg_per_m=W_PER_M / 9.81,
                       acceleration=None, trailing_force_N=trail, leading_force_N=lead)
    return loads, nodes


def test_the_steady_pull_on_a_straight_passes():
    loads, nodes = _straight()
    check = steady_balance(loads, nodes, L, MU)
    assert check.ok, check.message
    # P/V = F − T_b = μW exactly; the bound is μ/(1 + μ)·|E| with |E| = √((μW)² + W²)
    W = W_PER_M * L
    assert check.power_N == pytest.approx(MU * W, rel=1e-12)
    assert check.friction_bound_N == pytest.approx(MU / (1 + MU) * np.hypot(MU * W, W), rel=1e-12)
    assert check.unbalanced_N < 1e-9


def test_reactions_without_their_friction_are_not_the_steady_pull():
    # a fifth of the friction: F = T_b + 0.2 μW balances, but Coulomb's law is broken
    loads, nodes = _straight(0.2)
    check = steady_balance(loads, nodes, L, MU)
    assert check.unbalanced_N < 1e-9          # an equilibrium ...
    assert not check.ok                       # ... but not a pull through the conduit
    assert "power" in check.message and "lack their friction" in check.message


def test_unbalanced_loads_are_named():
    loads, nodes = _straight(pull_N=T_B + MU * W_PER_M * L * (1 + 10 * BALANCE_TOLERANCE))
    check = steady_balance(loads, nodes, L, MU)
    assert not check.ok and "do not balance" in check.message


def test_a_frictionless_pull_needs_only_its_back_tension():
    loads, nodes = _straight()
    loads = dataclasses.replace(loads, point_force_N=np.tile([0.0, 0.0, W_PER_M * L / 100], (100, 1)),
                                leading_force_N=np.array([T_B, 0.0, 0.0]))
    check = steady_balance(loads, nodes, L, 0.0)
    assert check.ok, check.message
