"""Long-horizon closed forms of the oven LQG (rsmhp.studies.horizon.closed_forms) against
independent oracles: the open-loop optimum of rsmhp.models.lqg.oven, a least-squares solution
of the stage-cost regulator, the algebraic Riccati equation and the finite sums."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rsmhp.models.lqg import oven as lqg
from rsmhp.studies.horizon import closed_forms as lh

A_VALUES = st.floats(0.05, 0.95)
R_VALUES = st.floats(0.1, 50.0)


@settings(max_examples=40, deadline=None)
@given(a=A_VALUES, r=R_VALUES, H=st.integers(1, 30))
def test_first_control_gain_is_the_first_optimal_control(a, r, H):
    # u* = L_H (T - b^H x0) c / c_0: with x0 = 0, T = 1 the first control is L_H
    u = lqg.optimal_controls(H, x0=0.0, a=a, r=r, target=1.0)
    assert lh.first_control_gain(H, a=a, r=r) == pytest.approx(u[0], rel=1e-12, abs=1e-300)


@settings(max_examples=30, deadline=None)
@given(a=A_VALUES, r=R_VALUES, H=st.integers(1, 12))
def test_stage_cost_gain_is_the_least_squares_regulator(a, r, H):
    """Oracle: the deterministic H-step problem min sum_{k<H} (r x_k^2 + u_k^2) + r x_H^2
    with x_{k+1} = b x_k + a u_k from x_0 = 1 (certainty equivalence: the stochastic
    problem's first feedback control is the same) solved as least squares; u_0 = -K_H."""
    b = 1.0 - a
    # x_k = b^k + sum_{j<k} b^{k-1-j} a u_j  for k = 1..H
    G = np.zeros((H, H))
    for k in range(1, H + 1):
        for j in range(k):
            G[k - 1, j] = b ** (k - 1 - j) * a
    x_free = b ** np.arange(1, H + 1)
    M = np.vstack([np.sqrt(r) * G, np.eye(H)])
    y = np.concatenate([-np.sqrt(r) * x_free, np.zeros(H)])
    u = np.linalg.lstsq(M, y, rcond=None)[0]
    assert lh.stage_cost_gains(H, a=a, r=r)[-1] == pytest.approx(-u[0], rel=1e-9)


@settings(max_examples=30, deadline=None)
@given(a=A_VALUES, r=R_VALUES)
def test_stationary_gain_solves_the_riccati_equation_and_is_the_limit(a, r):
    b = 1.0 - a
    k = lh.stationary_gain(a=a, r=r)
    P = k / (a * b - a * a * k)  # invert K = a b P / (1 + a^2 P)
    assert P > 0
    assert r + b * b * P - (a * b * P) ** 2 / (1 + a * a * P) == pytest.approx(P, rel=1e-10)
    assert lh.stage_cost_gains(2000, a=a, r=r)[-1] == pytest.approx(k, rel=1e-10)
    h = lh.stationary_horizon(a=a, r=r)
    K = lh.stage_cost_gains(h, a=a, r=r)
    assert abs(K[-1] - k) <= 0.01 * k and (h == 1 or abs(K[-2] - k) > 0.01 * k)


@settings(max_examples=30, deadline=None)
@given(a=A_VALUES, r=R_VALUES, sigma=st.floats(0.1, 5.0))
def test_nbo_error_tends_to_its_limit_with_gap_b_to_the_2h(a, r, sigma):
    lim = lh.nbo_error_limit(a=a, r=r, sigma=sigma)
    for H in (1, 6, 24):
        gap = 1.0 - lqg.nbo_error(H, a=a, r=r, sigma=sigma) / lim
        assert gap == pytest.approx((1.0 - a) ** (2 * H), rel=1e-9, abs=1e-15)


@pytest.mark.parametrize("a", [0.1, 0.3, 0.5, 0.7, 0.9])
def test_vanishing_horizon_is_the_first_below_eps(a):
    h = lh.vanishing_horizon(a=a, r=10.0, eps=0.01)
    L = lh.first_control_gain(np.arange(1, h + 1), a=a, r=10.0)
    assert L[-1] <= 0.01 * L[0] and (h == 1 or L[-2] > 0.01 * L[0])


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="a"):
        lh.stationary_gain(a=1.0, r=1.0)
    with pytest.raises(ValueError, match="H must be integers >= 1"):
        lh.first_control_gain(0, a=0.5, r=1.0)
    with pytest.raises(ValueError, match="eps"):
        lh.vanishing_horizon(a=0.5, r=1.0, eps=0.0)


def test_horizon_table_and_its_text_read_the_closed_forms():
    from rsmhp.studies.horizon.section import _lqg_text
    from rsmhp.studies.horizon.summarise_uav import lqg_horizon_table

    q = lqg_horizon_table([0.3, 0.5], [6, 24], r=10.0, sigma=1.0, eps=0.01)
    row = q.set_index("a").loc[0.5]
    assert row["nbo_limit"] == pytest.approx(10.0 / (1 - 0.25))
    assert row["nbo_share_H6"] == pytest.approx(100 * (1 - 0.5**12))
    assert row["vanishing_H"] == lh.vanishing_horizon(a=0.5, r=10.0)
    assert row["stationary_H"] == lh.stationary_horizon(a=0.5, r=10.0)
    text = _lqg_text(q, 0.5, 0.01)
    assert f"at H = {int(row['vanishing_H'])} (from H = " in text and "13.33" in text
