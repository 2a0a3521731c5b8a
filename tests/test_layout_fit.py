"""The start layout's least-squares fit (exucable.model.layout.lay_cable): its sums over the fit's rows,
taken element by element in whole arrays, are the row-by-row sums of the plain forms bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from exucable.model import layout


def rows(n_elements, k, seed=0):
    """The fit's rows as lay_cable lays them: the trailing node, k Gauss points per element, the
    leading node; uneven element lengths."""
    rng = np.random.default_rng(seed)
    Le = rng.uniform(0.5, 2.0, n_elements)
    x_nodes = np.concatenate([[0.0], np.cumsum(Le)])
    xi, _ = np.polynomial.legendre.leggauss(k)
    xs = (x_nodes[:-1, None] + 0.5 * (xi + 1.0)[None, :] * Le[:, None]).ravel()
    xs = np.concatenate([[0.0], xs, [x_nodes[-1]]])
    e_of = np.clip(np.searchsorted(x_nodes, xs, side="right") - 1, 0, n_elements - 1)
    cols, vals = layout._hermite_rows(e_of, (xs - x_nodes[e_of]) / Le[e_of], Le)
    return cols, vals, rng


@pytest.mark.parametrize("n_elements, k", [(1, 8), (2, 3), (57, 8), (300, 5)])
def test_fit_sums_are_the_row_by_row_sums_bit_for_bit(n_elements, k):
    cols, vals, rng = rows(n_elements, k)
    m, n_unknowns = len(vals), 2 * (n_elements + 1)
    # targets of every magnitude and sign, exact zeros included (the sums' order decides the last bits)
    target = rng.standard_normal((m, 3)) * 10.0 ** rng.integers(-6, 6, (m, 3))
    target[rng.random((m, 3)) < 0.05] = 0.0
    coef = rng.standard_normal((n_unknowns, 3)) * 10.0 ** rng.integers(-6, 6, (n_unknowns, 3))

    order = layout._point_major(n_elements, k)
    assert sorted(order) == list(range(m))
    vals_t = vals[order].T.copy()
    rhs = layout._fit_rhs(vals_t, target[order].T.copy(), n_elements, k)
    plain_rhs = np.stack([np.bincount(cols.ravel(), (vals * target[:, j, None]).ravel(), n_unknowns)
                          for j in range(3)])
    assert np.array_equal(rhs.view(np.int64), plain_rhs.view(np.int64))

    fitted = layout._fit_values(vals_t, coef, n_elements, k)
    plain_fitted = np.einsum("mk,mkj->mj", vals, coef[cols])[order].T
    assert np.array_equal(fitted.view(np.int64), plain_fitted.view(np.int64))

    normal = layout._normal_matrix_banded(vals_t, n_elements, k)
    plain = np.zeros((4, n_unknowns))
    a, b = np.triu_indices(4)
    np.add.at(plain, ((3 + cols[:, a] - cols[:, b]).ravel(), cols[:, b].ravel()), (vals[:, a] * vals[:, b]).ravel())
    assert np.array_equal(normal.view(np.int64), plain.view(np.int64))


def test_row_dot_sums_as_numpy_sums_rows():
    rng = np.random.default_rng(3)
    a, b = rng.standard_normal((2, 10000, 3)) * 10.0 ** rng.integers(-8, 8, (2, 10000, 3))
    assert np.array_equal(layout._dot3(a.T, b.T), np.sum(a * b, axis=1))
    assert np.array_equal(np.sqrt(layout._dot3(a.T, a.T)), np.linalg.norm(a, axis=1))
