"""Closed forms of rsmhp.models.lqg.oven against brute-force Monte Carlo and the paper's formulas.

Monte-Carlo tolerances are 5 standard errors, where the standard error comes from the known
variance (closed form) or, for second moments, from the sample's own fourth moment.
"""

from __future__ import annotations

import numpy as np
import pytest

from rsmhp.core.cost_estimators import nbo_estimate, weighted_estimate
from rsmhp.core.sampling import sample_independent
from rsmhp.models.lqg import oven as lqg
from tests.conftest import PAPER, PAPER_U

N_MC = 1_000_000
CASES = [
    (PAPER_U, PAPER),
    (np.array([0.3, -0.2, 1.0, 0.4, 0.0]), {**PAPER, "a": 0.2, "x0": 1.5, "sigma": 0.7}),
    (np.array([2.0]), {**PAPER, "a": 0.9, "r": 3.0, "target": -1.0, "sigma": 2.0}),
]


def simulate_xh(u, p, n, rng):
    """Brute force: iterate the recursion with explicit noise (independent of
    rsmhp.core.sampling)."""
    x = np.full(n, p["x0"])
    for uk in u:
        x = (1 - p["a"]) * x + p["a"] * uk + p["sigma"] * rng.standard_normal(n)
    return x


@pytest.mark.parametrize(("u", "p"), CASES)
def test_state_mean_and_variance_match_simulation(u, p, rng):
    x = simulate_xh(u, p, N_MC, rng)
    m = lqg.state_mean(u, x0=p["x0"], a=p["a"])
    v = lqg.state_variance(len(u), a=p["a"], sigma=p["sigma"])
    assert abs(x.mean() - m) < 5 * np.sqrt(v / N_MC)
    # sample variance of Gaussian data: sd = v * sqrt(2 / (n - 1))
    assert abs(x.var(ddof=1) - v) < 5 * v * np.sqrt(2 / (N_MC - 1))


@pytest.mark.parametrize(("u", "p"), CASES)
def test_exact_cost_and_cost_variance_match_simulation(u, p, rng):
    x = simulate_xh(u, p, N_MC, rng)
    g = p["r"] * (x - p["target"]) ** 2 + np.dot(u, u)
    j = lqg.exact_cost(u, **p)
    var_g = lqg.cost_variance(u, **p)
    assert abs(g.mean() - j) < 5 * np.sqrt(var_g / N_MC)
    # standard error of the sample variance from the sample's fourth central moment
    m4 = np.mean((g - g.mean()) ** 4)
    se_var = np.sqrt((m4 - g.var() ** 2) / N_MC)
    assert abs(g.var(ddof=1) - var_g) < 5 * se_var


def test_nbo_error_matches_paper_formula_h2():
    # paper, Sec. III-A: |J_NBO - J| = r sigma^2 ((1-a)^2 + 1) for H = 2
    for a in (0.1, 0.5, 0.77):
        for sigma in (0.5, 1.0, 3.0):
            expected = 10.0 * sigma**2 * ((1 - a) ** 2 + 1)
            assert lqg.nbo_error(2, a=a, r=10.0, sigma=sigma) == pytest.approx(expected, rel=1e-14)


@pytest.mark.parametrize("H", [1, 2, 3, 7, 20])
def test_nbo_error_general_h_is_exact_minus_nbo(H):
    u = np.linspace(-1, 1, H)
    p = {**PAPER, "a": 0.3, "sigma": 1.3}
    explicit = p["r"] * p["sigma"] ** 2 * sum((1 - p["a"]) ** (2 * n) for n in range(H))
    err = lqg.nbo_error(H, a=p["a"], r=p["r"], sigma=p["sigma"])
    assert err == pytest.approx(explicit, rel=1e-13)
    nbo = lqg.nbo_cost(u, x0=p["x0"], a=p["a"], r=p["r"], target=p["target"])
    assert lqg.exact_cost(u, **p) - nbo == pytest.approx(err, rel=1e-12)


def test_paper_h2_nbo_cost_expression():
    # paper's J_NBO = r((1-a)^2 x0 + a(1-a) u0 + a u1 - T)^2 + u0^2 + u1^2
    a, x0, r, T = 0.37, 0.8, 10.0, 1.0
    u0, u1 = PAPER_U
    expected = r * ((1 - a) ** 2 * x0 + a * (1 - a) * u0 + a * u1 - T) ** 2 + u0**2 + u1**2
    assert lqg.nbo_cost(PAPER_U, x0=x0, a=a, r=r, target=T) == pytest.approx(expected, rel=1e-14)


@pytest.mark.parametrize(("u", "p"), CASES)
def test_nbo_cost_equals_simulated_nominal_trajectory(u, p):
    model = lqg.LQGModel(a=p["a"], r=p["r"], target=p["target"], sigma=p["sigma"])
    sim = nbo_estimate(model, [p["x0"]], u)
    closed = lqg.nbo_cost(u, x0=p["x0"], a=p["a"], r=p["r"], target=p["target"])
    assert sim == pytest.approx(closed, rel=1e-12)


def test_mhp_variance_and_chebyshev():
    var_g = lqg.cost_variance(PAPER_U, **PAPER)
    # paper setting: v = 1.25, mu = -0.7775 -> Var(g) = 100 (2 v^2 + 4 mu^2 v)
    assert var_g == pytest.approx(100 * (2 * 1.25**2 + 4 * 0.7775**2 * 1.25), rel=1e-12)
    assert lqg.mhp_variance(400, PAPER_U, **PAPER) == pytest.approx(var_g / 400)
    assert lqg.chebyshev_bound(400, 2.0, PAPER_U, **PAPER) == pytest.approx(var_g / 1600)
    assert lqg.chebyshev_bound(10, 0.1, PAPER_U, **PAPER) == 1.0


def test_uniform_estimator_variance_matches_replicates(rng):
    """Var of the P-sample estimator over many replicates vs Var(g)/P (chi-square tolerance)."""
    model = lqg.LQGModel(a=0.5, r=10.0, target=1.0, sigma=1.0)
    P, R = 200, 4000
    est = np.array(
        [sample_independent(model, [0.0], PAPER_U, P, rng).cost.mean() for _ in range(R)]
    )
    var = lqg.mhp_variance(P, PAPER_U, **PAPER)
    # the mean of P=200 draws is close to Gaussian: sd of the sample variance ~ var sqrt(2/(R-1));
    # allow 6 sd because the residual non-normality (excess kurtosis / P) widens it slightly
    assert abs(est.var(ddof=1) - var) < 6 * var * np.sqrt(2 / (R - 1))
    assert abs(est.mean() - lqg.exact_cost(PAPER_U, **PAPER)) < 5 * np.sqrt(var / R)


@pytest.mark.parametrize(("u", "p"), CASES[:2])
def test_weighted_estimator_converges_to_derived_limit(u, p, rng):
    model = lqg.LQGModel(a=p["a"], r=p["r"], target=p["target"], sigma=p["sigma"])
    traj = sample_independent(model, [p["x0"]], u, N_MC, rng)
    est = float(weighted_estimate(traj.cost, traj.log_likeliness))
    limit = lqg.weighted_limit(u, **p)
    # delta-method standard error of a self-normalized ratio estimator
    q = np.exp(traj.log_likeliness - traj.log_likeliness.max())
    q /= q.mean()
    se = np.sqrt(np.mean(q**2 * (traj.cost - est) ** 2) / N_MC)
    assert abs(est - limit) < 5 * se
    # and the limit really differs from J (by r v_H / 2)
    gap = lqg.exact_cost(u, **p) - limit
    assert gap == pytest.approx(lqg.nbo_error(len(u), a=p["a"], r=p["r"], sigma=p["sigma"]) / 2)
    assert abs(est - lqg.exact_cost(u, **p)) > 20 * se


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [({"a": 1.0}, "a"), ({"a": 0.0}, "a"), ({"sigma": -1.0}, "sigma"), ({"r": -2.0}, "r")],
)
def test_closed_forms_reject_bad_parameters(kwargs, field):
    p = {**PAPER, **kwargs}
    with pytest.raises(ValueError, match=field):
        lqg.exact_cost(PAPER_U, **p)


def test_empty_control_sequence_rejected():
    with pytest.raises(ValueError, match="u must be"):
        lqg.nbo_cost([], x0=0, a=0.5, r=1, target=1)


def test_decision_closed_forms_and_their_pieces():
    kw = {"x0": 0.3, "a": 0.4, "r": 10.0, "target": 1.0}
    c = lqg.coefficients(3, 0.4)
    np.testing.assert_array_equal(c, 0.6 ** np.arange(2, -1, -1))
    assert 1.3**2 * c @ c == pytest.approx(lqg.state_variance(3, a=0.4, sigma=1.3))
    assert lqg.optimal_cost(3, **kw, sigma=1.3) == lqg.exact_cost(
        lqg.optimal_controls(3, **kw), **kw, sigma=1.3
    )
    # (4/3)^{H/2}/3 < 1 (weighting helps) exactly up to H = 7
    assert lqg.weighted_regret_ratio(2) == pytest.approx(4 / 9)
    assert lqg.weighted_regret_ratio(7) < 1 < lqg.weighted_regret_ratio(8)
    assert lqg.weighted_expected_regret(50, 3, a=0.4, r=10.0, sigma=1.3) == pytest.approx(
        lqg.expected_regret(50, 3, a=0.4, r=10.0, sigma=1.3) * (4 / 3) ** 1.5 / 3
    )
    assert lqg.regret_standard_error(2.0, 8) == pytest.approx(1.0)  # 2 * sqrt(2/8)
    with pytest.raises(ValueError, match="R must be"):
        lqg.regret_standard_error(1.0, 0)


def test_lqg_model_is_the_one_definition():
    from rsmhp.models.lqg.linear_quadratic import LinearQuadratic

    model = lqg.LQGModel.from_config({**PAPER, "a": "0.5"})
    assert model == lqg.LQGModel(**PAPER)
    assert model.closed_form_args() == PAPER
    assert lqg.LQGModel.from_config(PAPER, a=0.3).a == 0.3
    assert "sigma" not in model.closed_form_args(sigma=False)
    assert lqg.exact_cost(PAPER_U, **model.closed_form_args()) == pytest.approx(
        LinearQuadratic.from_lqg(model, PAPER_U).exact_cost(), rel=1e-14
    )
    prob = LinearQuadratic.scalar_lqg(PAPER_U, **PAPER)
    np.testing.assert_array_equal(prob.A, LinearQuadratic.from_lqg(model, PAPER_U).A)
    with pytest.raises(ValueError, match="x0 must be finite"):
        lqg.LQGModel(a=0.5, r=1.0, target=1.0, sigma=1.0, x0=float("nan"))
