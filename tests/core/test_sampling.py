"""Sampling and estimator invariants: counts, likeliness, pruning, weights, and exact oracles."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats

from rsmhp.core.cost_estimators import (
    likeliness_weights,
    nbo_estimate,
    uniform_estimate,
    weighted_estimate,
)
from rsmhp.core.sampling import GaussianNoise, sample_independent, sample_tree, top_m
from rsmhp.models.lqg import oven as lqg
from tests.conftest import PAPER

MODEL = lqg.LQGModel(a=0.4, r=10.0, target=1.0, sigma=0.8)
U = np.array([0.55, 0.17, -0.3])


def recompute(model, x0, u, noise):
    """Replay trajectories from their noise (independent of the sampler's bookkeeping)."""
    x = np.full(noise.shape[0], x0, dtype=float)
    states = [x]
    cost = np.zeros_like(x)
    for k, uk in enumerate(u):
        cost += uk**2
        x = (1 - model.a) * x + model.a * uk + noise[:, k, 0]
        states.append(x)
    cost += model.r * (x - model.target) ** 2
    ll = stats.norm.logpdf(noise[..., 0], scale=model.sigma).sum(axis=1)
    return np.stack(states, axis=1), cost, ll


def test_gaussian_noise_logpdf_and_moments(rng):
    cov = np.array([[2.0, 0.3, 0.1], [0.3, 1.0, -0.2], [0.1, -0.2, 0.5]])
    noise = GaussianNoise(cov)
    w = noise.sample(rng, (4, 5))
    assert w.shape == (4, 5, 3)
    ref = stats.multivariate_normal(mean=np.zeros(3), cov=cov).logpdf(w.reshape(-1, 3))
    np.testing.assert_allclose(noise.logpdf(w).ravel(), ref, rtol=1e-12)
    n = 400_000
    s = np.cov(noise.sample(rng, n).T)
    # sd of a sample covariance entry: sqrt((S_ii S_jj + S_ij^2) / n)
    sd = np.sqrt((np.outer(np.diag(cov), np.diag(cov)) + cov**2) / n)
    assert np.all(np.abs(s - cov) < 5 * sd)
    scalar = GaussianNoise(0.64)
    np.testing.assert_allclose(
        scalar.logpdf(np.array([[0.3], [-1.0]])), stats.norm.logpdf([0.3, -1.0], scale=0.8)
    )


def test_gaussian_noise_rejects_bad_covariance():
    with pytest.raises(ValueError, match="symmetric"):
        GaussianNoise(np.array([[1.0, 0.5], [0.0, 1.0]]))
    with pytest.raises(np.linalg.LinAlgError):
        GaussianNoise(np.array([[1.0, 2.0], [2.0, 1.0]]))


def test_independent_sampling_is_consistent(rng):
    traj = sample_independent(MODEL, [0.2], U, 500, rng)
    assert traj.states.shape == (500, 4, 1) and traj.noise.shape == (500, 3, 1)
    states, cost, ll = recompute(MODEL, 0.2, U, traj.noise)
    np.testing.assert_allclose(traj.states[..., 0], states, rtol=1e-12)
    np.testing.assert_allclose(traj.cost, cost, rtol=1e-12)
    np.testing.assert_allclose(traj.log_likeliness, ll, rtol=1e-12)


@pytest.mark.parametrize(("N", "shared"), [(2, True), (3, True), (5, True), (3, False)])
def test_unpruned_tree_has_n_to_the_h_leaves(N, shared, rng):
    tree = sample_tree(MODEL, [0.0], U, N, rng, shared_draws=shared)
    leaves = tree.leaves
    assert len(leaves) == N ** len(U)
    states, cost, ll = recompute(MODEL, 0.0, U, leaves.noise)
    np.testing.assert_allclose(leaves.states[..., 0], states, rtol=1e-12)
    np.testing.assert_allclose(leaves.cost, cost, rtol=1e-12)
    np.testing.assert_allclose(leaves.log_likeliness, ll, rtol=1e-12)
    for k in range(len(U)):
        distinct = np.unique(leaves.noise[:, k, 0]).size
        # shared: the same N values at every node of a level; per-node: N^(k+1) values
        assert distinct == (N if shared else N ** (k + 1))
    # every leaf path is a distinct combination of draws
    assert np.unique(leaves.noise[..., 0], axis=0).shape[0] == N ** len(U)


def _factorized_tree_average(model, x0, u, draws, weights):
    """Exact weighted average over the product grid of per-step draws (LQG, shared draws).

    With c_k = (1-a)^(H-1-k), x_H - T = mu + sum_k c_k w_k, so the average of r (x_H - T)^2
    over all N^H combinations with product weights is
    r [ (mu + sum_k c_k wbar_k)^2 + sum_k c_k^2 (s2_k - wbar_k^2) ] with per-step weighted
    mean wbar_k and second moment s2_k.
    """
    H = len(u)
    c = (1 - model.a) ** np.arange(H - 1, -1, -1)
    mu = lqg.state_mean(u, x0=x0, a=model.a) - model.target
    wbar = np.array([np.average(d, weights=w) for d, w in zip(draws, weights, strict=True)])
    s2 = np.array([np.average(d**2, weights=w) for d, w in zip(draws, weights, strict=True)])
    inner = (mu + c @ wbar) ** 2 + np.sum(c**2 * (s2 - wbar**2))
    return model.r * inner + float(np.dot(u, u))


@pytest.mark.parametrize("N", [2, 4, 7])
def test_tree_estimators_match_factorized_oracle(N, rng):
    tree = sample_tree(MODEL, [0.3], U, N, rng)
    leaves = tree.leaves
    # recover the N draws of each step (leaves are in parent-major order)
    draws = [leaves.noise[:: N ** (len(U) - 1 - k), k, 0][:N] for k in range(len(U))]
    ones = [np.ones(N)] * len(U)
    dens = [stats.norm.pdf(d, scale=MODEL.sigma) for d in draws]
    assert uniform_estimate(leaves.cost) == pytest.approx(
        _factorized_tree_average(MODEL, 0.3, U, draws, ones), rel=1e-11
    )
    assert weighted_estimate(leaves.cost, leaves.log_likeliness) == pytest.approx(
        _factorized_tree_average(MODEL, 0.3, U, draws, dens), rel=1e-11
    )


@pytest.mark.parametrize(("N", "M"), [(3, 2), (4, 4), (5, 3), (6, 1), (3, 3)])
def test_pruning_keeps_top_m_at_every_level(N, M, rng):
    tree = sample_tree(MODEL, [0.0], U, N, rng, max_keep=M, keep_history=True)
    n_parent = 1
    for level in tree.history:
        n_children = n_parent * N
        assert level.states.shape[0] == n_children
        assert level.kept.sum() == min(M, n_children)
        if (~level.kept).any():
            assert level.log_likeliness[level.kept].min() >= level.log_likeliness[~level.kept].max()
        n_parent = int(level.kept.sum())
    assert len(tree.leaves) == min(M, N ** len(U))
    _, cost, ll = recompute(MODEL, 0.0, U, tree.leaves.noise)
    np.testing.assert_allclose(tree.leaves.cost, cost, rtol=1e-12)
    np.testing.assert_allclose(tree.leaves.log_likeliness, ll, rtol=1e-12)


def test_pruned_tree_leaves_are_the_most_likely_children_of_kept_parents(rng):
    tree = sample_tree(MODEL, [0.0], U, 5, rng, max_keep=3, keep_history=True)
    last = tree.history[-1]
    np.testing.assert_allclose(
        np.sort(tree.leaves.log_likeliness), np.sort(last.log_likeliness)[-3:], rtol=1e-12
    )


def test_top_m_order_and_ties():
    ll = np.array([0.0, 2.0, 2.0, -1.0, 5.0])
    assert top_m(ll, 3).tolist() == [4, 1, 2]
    assert top_m(ll, 10).tolist() == [4, 1, 2, 0, 3]
    with pytest.raises(ValueError, match="M must be"):
        top_m(ll, 0)


def test_tree_arguments_are_checked(rng):
    with pytest.raises(ValueError, match="N"):
        sample_tree(MODEL, [0.0], U, 0, rng)
    with pytest.raises(ValueError, match="M"):
        sample_tree(MODEL, [0.0], U, 3, rng, max_keep=0)
    with pytest.raises(ValueError, match="leaves"):
        sample_tree(MODEL, [0.0], np.zeros(12), 10, rng)
    with pytest.raises(ValueError, match="at least one step"):
        sample_independent(MODEL, [0.0], [], 3, rng)


def test_likeliness_weights_sum_to_n_and_are_shift_invariant(rng):
    ll = rng.normal(size=50) * 30 - 500  # products of many densities: tiny likeliness
    q = likeliness_weights(ll)
    assert q.sum() == pytest.approx(50)
    np.testing.assert_allclose(q, likeliness_weights(ll + 123.0), rtol=1e-12)
    g = rng.normal(size=50)
    direct = np.sum(np.exp(ll - ll.max()) * g) / np.sum(np.exp(ll - ll.max()))
    assert weighted_estimate(g, ll) == pytest.approx(direct, rel=1e-12)
    # equal likeliness: weighted == uniform
    assert weighted_estimate(g, np.zeros(50)) == pytest.approx(uniform_estimate(g))
    with pytest.raises(ValueError, match="zero"):
        uniform_estimate(np.array([]))


def test_nbo_estimate_is_the_zero_noise_trajectory():
    model = lqg.LQGModel(a=PAPER["a"], r=PAPER["r"], target=PAPER["target"], sigma=2.0)
    u = np.array([0.55, 0.17])
    expected = lqg.nbo_cost(u, x0=0.0, a=0.5, r=10.0, target=1.0)
    assert nbo_estimate(model, [0.0], u) == pytest.approx(expected, rel=1e-13)


def test_level_noise_gives_each_level_its_own_distribution():
    first, later = GaussianNoise(np.diag([4.0, 1.0])), GaussianNoise(np.diag([0.01, 0.09]))

    class Walk:
        noise = later

        def step(self, x, u_k, w):
            return x + w

        def stage_cost(self, x, u_k):
            return np.zeros(x.shape[0])

        def terminal_cost(self, x):
            return np.zeros(x.shape[0])

    tree = sample_tree(
        Walk(),
        [0.0, 0.0],
        [0, 1, 2],
        3,
        np.random.default_rng(5),
        level_noise=[first, later, later],
    )
    replay = np.random.default_rng(5)
    expected = [first.sample(replay, 3), later.sample(replay, 3), later.sample(replay, 3)]
    w = tree.leaves.noise
    for k in range(3):
        np.testing.assert_allclose(np.unique(w[:, k, 0]), np.sort(expected[k][:, 0]))
    ll = first.logpdf(w[:, 0]) + later.logpdf(w[:, 1]) + later.logpdf(w[:, 2])
    np.testing.assert_allclose(tree.leaves.log_likeliness, ll, rtol=1e-12)
    with pytest.raises(ValueError, match="one noise model per level"):
        sample_tree(Walk(), [0.0, 0.0], [0, 1], 3, np.random.default_rng(5), level_noise=[first])


@pytest.mark.parametrize(
    ("N", "M", "shared"),
    [(3, None, True), (3, None, False), (8, 4, True), (5, 1, True), (16, 16, True), (4, 2, False)],
)
@pytest.mark.parametrize("H", [1, 4])
def test_batched_trees_equal_one_tree_at_a_time_bit_for_bit(N, M, shared, H):
    """Scalar problem (row-wise step, costs and density): every batched tree is exactly the
    tree sample_tree draws from the same generator."""
    from rsmhp.core.sampling import sample_tree_batch
    from rsmhp.core.seeding import job_rng
    from rsmhp.models.lqg.linear_quadratic import LinearQuadratic

    u = [0.55, 0.17, 0.3, 0.1][:H]
    prob = LinearQuadratic.scalar_lqg(u, x0=0.2, a=0.5, r=10.0, target=1.0, sigma=1.3)
    assert prob.noise.rowwise
    rngs = [job_rng(7, "batch-test", rep=r) for r in range(9)]
    cost, loglik = sample_tree_batch(
        prob, prob.x0, prob.u, N, rngs, max_keep=M, shared_draws=shared
    )
    for r in range(9):
        tree = sample_tree(
            prob,
            prob.x0,
            prob.u,
            N,
            job_rng(7, "batch-test", rep=r),
            max_keep=M,
            shared_draws=shared,
        )
        np.testing.assert_array_equal(cost[r], tree.leaves.cost)
        np.testing.assert_array_equal(loglik[r], tree.leaves.log_likeliness)


def test_batched_trees_agree_for_vector_noise():
    """4-D noise: the batched density may round differently (batched LAPACK solve), so the
    trees agree to rounding, with the same survivors."""
    from rsmhp.core.sampling import sample_tree_batch
    from rsmhp.core.seeding import job_rng
    from rsmhp.models.lqg.ablation import build_problem

    spec = {
        "kind": "ncv_2d",
        "dt": 1.0,
        "q": 1.0,
        "w_pos": 0.1,
        "w_vel": 0.1,
        "r_u": 1.0,
        "f_pos": 5.0,
        "f_vel": 1.0,
        "target": [10.0, 5.0, 0.0, 0.0],
        "x0": [0.0, 0.0, 1.0, 0.5],
        "u": [[0.5, 0.2], [0.3, 0.1], [-0.2, 0.0]],
    }
    prob = build_problem(spec, {})
    assert not prob.noise.rowwise
    rngs = [job_rng(3, "batch-test-4d", rep=r) for r in range(5)]
    cost, loglik = sample_tree_batch(prob, prob.x0, prob.u, 6, rngs, max_keep=5)
    for r in range(5):
        tree = sample_tree(prob, prob.x0, prob.u, 6, job_rng(3, "batch-test-4d", rep=r), max_keep=5)
        np.testing.assert_allclose(cost[r], tree.leaves.cost, rtol=1e-12)
        np.testing.assert_allclose(loglik[r], tree.leaves.log_likeliness, rtol=1e-12)


def test_batched_tree_arguments_are_checked(rng):
    from rsmhp.core.sampling import sample_tree_batch
    from rsmhp.models.lqg.linear_quadratic import LinearQuadratic

    prob = LinearQuadratic.scalar_lqg([0.5], x0=0.0, a=0.5, r=10.0, target=1.0, sigma=1.0)
    with pytest.raises(ValueError, match="N"):
        sample_tree_batch(prob, prob.x0, prob.u, 0, [rng])
    with pytest.raises(ValueError, match="M"):
        sample_tree_batch(prob, prob.x0, prob.u, 2, [rng], max_keep=0)
    with pytest.raises(ValueError, match="at least one generator"):
        sample_tree_batch(prob, prob.x0, prob.u, 2, [])


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.integers(-5, 5), min_size=1, max_size=60),  # small integers: many ties
    st.integers(1, 70),
    st.booleans(),
)
def test_top_m_selects_exactly_what_the_stable_full_sort_selects(values, m, with_nan):
    """top_m takes a partition shortcut; the oracle is the stable argsort it replaced, ties
    by index, NaN (never produced by a likeliness, but defined) last."""
    x = np.asarray(values, dtype=float) / 3.0
    if with_nan:
        x[len(x) // 2] = np.nan
    expected = np.argsort(-x, kind="stable")[:m]
    np.testing.assert_array_equal(top_m(x, m), expected)
