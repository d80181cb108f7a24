"""General linear-quadratic problems: quadratic form, estimator variances, samplers.

Every statistical check uses a tolerance of 5 standard errors, the standard error coming from
the closed-form variance or, for second moments, from the sample's fourth moment.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from rsmhp.core.designs import (
    antithetic,
    cubature,
    gauss_hermite,
    gauss_hermite_order,
    monte_carlo,
    sobol,
)
from rsmhp.core.sampling import rollout, sample_independent, sample_tree
from rsmhp.models.lqg import oven as lqg
from rsmhp.models.lqg.linear_quadratic import LinearQuadratic
from tests.conftest import PAPER, PAPER_U


def vector_problem(H: int = 3) -> LinearQuadratic:
    """A 4-D double integrator (position, velocity in 2-D) with a 2-D acceleration input."""
    dt = 1.0
    A = np.block([[np.eye(2), dt * np.eye(2)], [np.zeros((2, 2)), np.eye(2)]])
    B = np.vstack([0.5 * dt**2 * np.eye(2), dt * np.eye(2)])
    Sigma = np.diag([0.2, 0.1, 0.3, 0.25]) + 0.05
    return LinearQuadratic(
        A=A,
        B=B,
        Sigma=Sigma,
        Q=np.diag([1.0, 1.0, 0.1, 0.1]),
        R=0.5 * np.eye(2),
        Qf=np.diag([5.0, 5.0, 1.0, 1.0]),
        target=[3.0, -1.0, 0.0, 0.0],
        x0=[0.0, 0.0, 1.0, 0.5],
        u=np.array([[0.5, -0.2], [0.1, 0.0], [-0.3, 0.2], [0.0, 0.1]])[:H],
    )


def test_scalar_case_agrees_with_lqg_module():
    qf = LinearQuadratic.scalar_lqg(PAPER_U, **PAPER).quadratic_form
    assert qf.mean() == pytest.approx(lqg.exact_cost(PAPER_U, **PAPER), rel=1e-13)
    assert qf.nominal() == pytest.approx(
        lqg.nbo_cost(PAPER_U, x0=0.0, a=0.5, r=10.0, target=1.0), rel=1e-13
    )
    assert qf.variance() == pytest.approx(lqg.cost_variance(PAPER_U, **PAPER), rel=1e-13)
    assert qf.weighted_limit() == pytest.approx(lqg.weighted_limit(PAPER_U, **PAPER), rel=1e-13)
    assert qf.independent_variance(100) == pytest.approx(lqg.mhp_variance(100, PAPER_U, **PAPER))


@pytest.mark.parametrize("H", [1, 2, 4])
def test_quadratic_form_reproduces_rollout_costs(H, rng):
    prob = vector_problem(H)
    w = prob.noise.sample(rng, (50, H))
    traj = rollout(prob, prob.x0, prob.u, w)
    np.testing.assert_allclose(prob.quadratic_form.evaluate(w), traj.cost, rtol=1e-11)
    # the nominal trajectory is the NBO cost
    zero = rollout(prob, prob.x0, prob.u, np.zeros((1, H, 4)))
    assert zero.cost[0] == pytest.approx(prob.nbo_cost(), rel=1e-12)


def test_exact_cost_and_variance_match_simulation(rng):
    prob = vector_problem(4)
    n = 400_000
    g = sample_independent(prob, prob.x0, prob.u, n, rng).cost
    qf = prob.quadratic_form
    assert abs(g.mean() - qf.mean()) < 5 * np.sqrt(qf.variance() / n)
    se_var = np.sqrt((np.mean((g - g.mean()) ** 4) - g.var() ** 2) / n)
    assert abs(g.var(ddof=1) - qf.variance()) < 5 * se_var


def _check_variance(samples: np.ndarray, mean: float, var: float) -> None:
    R = samples.size
    assert abs(samples.mean() - mean) < 5 * np.sqrt(var / R)
    se_var = np.sqrt((np.mean((samples - samples.mean()) ** 4) - samples.var() ** 2) / R)
    assert abs(samples.var(ddof=1) - var) < 5 * se_var


@pytest.mark.parametrize(("H", "N"), [(2, 3), (3, 4), (4, 2)])
def test_tree_variances_match_simulation(H, N, rng):
    prob = vector_problem(H)
    qf = prob.quadratic_form
    R = 3000
    shared = np.array(
        [sample_tree(prob, prob.x0, prob.u, N, rng).leaves.cost.mean() for _ in range(R)]
    )
    _check_variance(shared, qf.mean(), qf.tree_variance(N))
    pernode = np.array(
        [
            sample_tree(prob, prob.x0, prob.u, N, rng, shared_draws=False).leaves.cost.mean()
            for _ in range(R)
        ]
    )
    _check_variance(pernode, qf.mean(), qf.pernode_tree_variance(N))
    # shared ancestors make both trees worse than N^H independent trajectories
    assert qf.tree_variance(N) > qf.pernode_tree_variance(N) > qf.independent_variance(N**H)


def test_pernode_tree_with_one_level_is_independent_sampling():
    qf = vector_problem(1).quadratic_form
    assert qf.pernode_tree_variance(7) == pytest.approx(qf.independent_variance(7))


@pytest.mark.parametrize("weighted", [False, True])
def test_grid_average_equals_tree_enumeration(weighted, rng):
    prob = vector_problem(3)
    N = 4
    leaves = sample_tree(prob, prob.x0, prob.u, N, rng).leaves
    draws = [leaves.noise[:: N ** (2 - k), k][:N] for k in range(3)]
    if weighted:
        weights = [np.exp(prob.noise.logpdf(d)) for d in draws]
        q = np.exp(leaves.log_likeliness - leaves.log_likeliness.max())
        enumerated = float(np.sum(q * leaves.cost) / q.sum())
    else:
        weights, enumerated = None, float(leaves.cost.mean())
    assert prob.quadratic_form.grid_average(draws, weights) == pytest.approx(enumerated, rel=1e-11)


def test_weighted_tree_converges_to_tilted_limit_not_j(rng):
    """Large shared-draw trees (N = 10^5 per level, evaluated exactly by the grid average)."""
    prob = LinearQuadratic.scalar_lqg(PAPER_U, **PAPER)
    qf = prob.quadratic_form
    N, R = 100_000, 12
    est = []
    for _ in range(R):
        draws = [prob.noise.sample(rng, N) for _ in range(prob.H)]
        est.append(qf.grid_average(draws, [np.exp(prob.noise.logpdf(d)) for d in draws]))
    est = np.array(est)
    se = est.std(ddof=1) / np.sqrt(R)
    # the O(1/N) ratio-estimator bias is below 1e-3 of the estimate here, far under 5 se
    assert abs(est.mean() - qf.weighted_limit()) < 5 * se + 1e-3 * abs(qf.weighted_limit())
    assert abs(est.mean() - qf.mean()) > 100 * se


def test_samplers_shapes_and_weights(rng):
    chol = np.linalg.cholesky(vector_problem().Sigma)
    for sampler in (monte_carlo, antithetic, sobol):
        w, wt = sampler(rng, 64, 3, chol)
        assert w.shape == (64, 3, 4) and wt.sum() == pytest.approx(1.0)
    with pytest.raises(ValueError, match="even"):
        antithetic(rng, 7, 3, chol)
    with pytest.raises(ValueError, match="power of 2"):
        sobol(rng, 48, 3, chol)
    assert gauss_hermite_order(100, 2) == 10 and gauss_hermite_order(100, 7) == 0
    assert gauss_hermite_order(4096, 4) == 8


def test_quadrature_is_exact_for_quadratic_costs():
    prob = vector_problem(2)
    chol = np.linalg.cholesky(prob.Sigma)
    for w, wt in (cubature(2, chol), gauss_hermite(2, 2, chol)):
        est = float(wt @ rollout(prob, prob.x0, prob.u, w).cost)
        assert est == pytest.approx(prob.exact_cost(), rel=1e-10)
    # and the Gauss-Hermite nodes/weights integrate a quartic exactly with q = 3
    w, wt = gauss_hermite(3, 1, np.eye(1))
    assert wt @ w[:, 0, 0] ** 4 == pytest.approx(3.0)


def test_antithetic_variance_and_sobol_unbiasedness(rng):
    prob = vector_problem(3)
    qf = prob.quadratic_form
    chol = np.linalg.cholesky(prob.Sigma)
    R, n = 3000, 16

    def estimate(sampler):
        w, wt = sampler(rng, n, 3, chol)
        return float(wt @ rollout(prob, prob.x0, prob.u, w).cost)

    anti = np.array([estimate(antithetic) for _ in range(R)])
    _check_variance(anti, qf.mean(), qf.antithetic_variance(n))
    sob = np.array([estimate(sobol) for _ in range(R)])
    # unbiased: the mean of R independent scrambles is within 5 empirical standard errors of J
    assert abs(sob.mean() - qf.mean()) < 5 * sob.std(ddof=1) / np.sqrt(R)
    assert stats.ttest_1samp(sob, qf.mean()).pvalue > 1e-6


def test_invalid_problems_rejected():
    with pytest.raises(ValueError, match="Sigma must have shape"):
        LinearQuadratic(
            A=np.eye(2),
            B=np.eye(2),
            Sigma=np.eye(3),
            Q=np.eye(2),
            R=np.eye(2),
            Qf=np.eye(2),
            target=[0, 0],
            x0=[0, 0],
            u=np.zeros((2, 2)),
        )
    with pytest.raises(ValueError, match="positive semi-definite"):
        LinearQuadratic(
            A=np.eye(1),
            B=np.eye(1),
            Sigma=np.eye(1),
            Q=-np.eye(1),
            R=np.eye(1),
            Qf=np.eye(1),
            target=[0],
            x0=[0],
            u=[0.0],
        )
    with pytest.raises(ValueError, match="a must lie"):
        LinearQuadratic.scalar_lqg([0.1], x0=0, a=1.0, r=1, target=0, sigma=1)


@pytest.mark.parametrize("weighted", [False, True])
def test_pruned_tree_tends_to_the_nbo_cost(weighted, rng):
    """With N -> inf and M fixed, every kept trajectory uses, at each level, one of the M most
    likely (smallest |w|) draws of that level. If the M-th smallest |w| of N draws is below t,
    |estimate - c| <= ||b||_1 t + lambda_max(K) H t^2. For N = 20000, M = 2, t = 0.005:
    P(fewer than 2 of 20000 draws within |w| < t) = P(Bin(20000, 0.004) < 2) < 1e-30."""
    prob = LinearQuadratic.scalar_lqg(PAPER_U, **PAPER)
    qf = prob.quadratic_form
    N, M, t = 20_000, 2, 0.005
    leaves = sample_tree(prob, prob.x0, prob.u, N, rng, max_keep=M).leaves
    assert np.abs(leaves.noise).max() < t
    est = (
        float(
            np.sum(np.exp(leaves.log_likeliness - leaves.log_likeliness.max()) * leaves.cost)
            / np.sum(np.exp(leaves.log_likeliness - leaves.log_likeliness.max()))
        )
        if weighted
        else float(leaves.cost.mean())
    )
    bound = np.abs(qf.b).sum() * t + np.linalg.eigvalsh(qf.K).max() * prob.H * t**2
    assert abs(est - qf.nominal()) <= bound
    assert bound < 0.01 * (qf.mean() - qf.nominal())  # i.e. the estimate carries the NBO error
