"""rsmhp.core.boxqn, the compiled projected L-BFGS, against known minimisers and scipy's L-BFGS-B.

* strictly convex quadratics over the box, f = 1/2 x^T A x - b^T x: the minimiser is unique,
  and found by scipy's L-BFGS-B to its tolerance; the projected gradient at our answer is
  below pgtol and the two answers agree;
* a separable quadratic whose minimiser is known in closed form (the clipped unconstrained
  minimiser);
* Rosenbrock's valley in the box (minimum at (1, 1) on the boundary of [-1, 1]^2);
* contracts: never worse than the start, budgets respected, status codes.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit
from scipy.optimize import Bounds, minimize

from rsmhp.core import boxqn


@njit
def _quadratic(x, g, data):
    A, b = data
    f = 0.0
    for i in range(x.size):
        s = -b[i]
        for j in range(x.size):
            s += A[i, j] * x[j]
        g[i] = s
        f += x[i] * (0.5 * (s + b[i]) - b[i])
    return f


@njit
def _rosenbrock(x, g, data):
    scale = data[0]
    f = scale * ((1.0 - x[0]) ** 2 + 100.0 * (x[1] - x[0] ** 2) ** 2)
    g[0] = scale * (-2.0 * (1.0 - x[0]) - 400.0 * x[0] * (x[1] - x[0] ** 2))
    g[1] = scale * 200.0 * (x[1] - x[0] ** 2)
    return f


def _run(fg, data, x0, maxiter=200, maxfun=1000):
    out = np.empty_like(x0)
    f, f0, nit, nfev, status = boxqn.minimise(
        fg, data, x0, maxiter, maxfun, boxqn.MEMORY, boxqn.PGTOL, boxqn.FTOL, out
    )
    return out, f, f0, nit, nfev, status


def _projected_gradient(x, g):
    return np.abs(np.clip(x - g, -1, 1) - x).max()


@settings(max_examples=40, deadline=None)
@given(n=st.integers(1, 12), seed=st.integers(0, 2**31), cond=st.floats(1.0, 1e3))
def test_convex_quadratic_reaches_the_unique_minimiser(n, seed, cond):
    rng = np.random.default_rng(seed)
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    A = Q @ np.diag(np.geomspace(1.0, cond, n)) @ Q.T
    b = rng.uniform(-3, 3, n) * cond  # the unconstrained minimiser is often outside the box
    x0 = rng.uniform(-1, 1, n)
    x, f, f0, _, _, status = _run(_quadratic, (A, b), x0)
    g = A @ x - b
    assert f <= f0
    assert status in (0, 1), boxqn.STATUS[status]
    ref = minimize(
        lambda z: (0.5 * z @ A @ z - b @ z, A @ z - b),
        x0,
        jac=True,
        method="L-BFGS-B",
        bounds=Bounds(-np.ones(n), np.ones(n)),
        options={"maxiter": 200, "maxfun": 1000},
    )
    # both stop at an approximate KKT point of the same strictly convex problem: costs agree
    # to what the stopping rules allow (ftol relative decrease, pgtol)
    tol = 1e-6 * max(1.0, abs(ref.fun))
    assert f == pytest.approx(ref.fun, abs=tol)
    if status == 0:
        assert _projected_gradient(x, g) <= boxqn.PGTOL


def test_separable_quadratic_closed_form():
    """f = sum_i d_i/2 (x_i - m_i)^2: the minimiser is clip(m, -1, 1)."""
    d = np.array([1.0, 10.0, 100.0, 0.5, 3.0])
    m = np.array([0.3, 2.0, -5.0, -0.7, 1.0])
    A, b = np.diag(d), d * m
    x, *_ = _run(_quadratic, (A, b), np.zeros(5))
    np.testing.assert_allclose(x, np.clip(m, -1, 1), atol=1e-6)


def test_rosenbrock_in_the_box():
    x, f, f0, *_ = _run(_rosenbrock, np.array([1.0]), np.array([-0.9, 0.9]))
    np.testing.assert_allclose(x, [1.0, 1.0], atol=1e-3)
    assert f < 1e-6 < f0


def test_budgets_and_start_are_respected():
    x0 = np.array([-0.9, 0.9])
    for maxiter, maxfun in ((1, 1000), (3, 1000), (200, 1), (200, 5)):
        x, f, f0, nit, nfev, status = _run(_rosenbrock, np.array([1.0]), x0, maxiter, maxfun)
        assert nit <= maxiter
        assert nfev <= maxfun  # a hard cap, the start's evaluation included
        assert f <= f0
        assert status in (2, 3)
        assert np.all(np.abs(x) <= 1.0)
    # a start outside the box is clipped into it first
    x, *_ = _run(_rosenbrock, np.array([1.0]), np.array([5.0, -5.0]), 1, 1)
    np.testing.assert_array_equal(x, [1.0, -1.0])


def test_a_kkt_start_stops_at_once():
    """At a corner where the gradient points out of the box the projected gradient is 0."""
    A, b = np.eye(2), np.array([10.0, -10.0])  # minimiser (10, -10): corner (1, -1)
    _, _, _, nit, nfev, status = _run(_quadratic, (A, b), np.array([1.0, -1.0]))
    assert (nit, nfev, status) == (0, 1, 0)
