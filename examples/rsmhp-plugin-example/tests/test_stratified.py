"""The example plugin's family, RS-MHP with Latin-hypercube-stratified hypotheses (``lhs``).

* rsmhp found it through the entry point, as a plugin of this distribution, and it passes
  rsmhp's conformance check (``rsmhp.testing.check_method``: the whole method contract);
* it is inert unless configured, and its config key is accepted in ``methods`` blocks;
* its math: in every one of the 4 (H + 1) dimensions the N_T standard-normal coordinates fall
  one in each stratum of probability 1/N_T; the mean of the hypotheses' initial states is
  within five standard deviations of the belief mean, the standard deviation of a stratified
  mean computed in closed form (and far below plain Monte Carlo's); the draws come from the
  step's stream only.
"""

from __future__ import annotations

import numpy as np
import pytest
from rsmhp_plugin_example.stratified import Stratified, latin_hypercube
from scipy import special, stats

from rsmhp.core.seeding import job_rng
from rsmhp.models.uav import methods
from rsmhp.testing import check_method, example_belief, example_setup


def _stream(m, seed=1, step=1):
    """The member's stream of a closed-loop planning step (run 0)."""
    return job_rng(seed, "uav_plan", run=0, step=step, **m.job_key())


def _normals(hyp, belief, setup):
    """The standard-normal coordinates z (N_T, H + 1, 4) of hypotheses, from their noise:
    noise[:, 0] = L_P z_0 and noise[:, j] = L_Q z_j."""
    L_P = np.linalg.cholesky(belief.P_hat)
    L_Q = setup.target.noise.chol
    z0 = np.linalg.solve(L_P, hyp.noise[:, 0].T).T
    zj = np.linalg.solve(L_Q, hyp.noise[:, 1:].reshape(-1, 4).T).T.reshape(hyp.n, -1, 4)
    return np.concatenate([z0[:, None], zj], axis=1)


def test_registered_as_a_plugin_of_this_distribution():
    found = {p.family: p for p in methods.plugins()}
    assert found["lhs"].cls is Stratified
    assert found["lhs"].distribution == "rsmhp-plugin-example"
    assert found["lhs"].entry_point == "example = rsmhp_plugin_example.stratified"
    m = methods.from_name("lhs_nt64")
    assert m == Stratified(64) and m.label() == "LHS N_T=64"


def test_passes_the_conformance_check():
    report = check_method(Stratified)
    assert report.members == ("lhs_nt4", "lhs_nt8")
    check_method(Stratified, value=[3, 50], setup=example_setup(horizon=6))


def test_inert_unless_configured():
    assert not any(isinstance(m, Stratified) for m in methods.from_config({}).values())
    got = methods.from_config({"nbo": True, "lhs_nt": [64, 16]}, "uav.methods")
    assert list(got) == ["nbo", "lhs_nt16", "lhs_nt64"]
    assert methods.schema()["properties"]["lhs_nt"] is Stratified.schema


@pytest.mark.parametrize("n", [1, 5, 64])
def test_every_stratum_of_every_dimension_is_hit_once(n):
    setup, belief = example_setup(), example_belief()
    m = Stratified(n)
    for step in range(1, 4):
        hyp = m.hypotheses(belief, setup, _stream(m, step=step))
        assert hyp.states.shape == (n, setup.planner.horizon, 4)
        np.testing.assert_array_equal(hyp.weights, np.full(n, 1.0 / n))
        u = special.ndtr(_normals(hyp, belief, setup).reshape(n, -1))  # back to [0, 1)
        strata = np.floor(u * n).astype(int)
        for j in range(strata.shape[1]):
            assert sorted(strata[:, j]) == list(range(n)), f"dimension {j}"


def test_latin_hypercube_columns_are_stratified_and_paired_at_random():
    u = latin_hypercube(np.random.default_rng(3), 100, 12)
    assert u.shape == (100, 12) and ((u >= 0) & (u < 1)).all()
    for col in u.T:
        np.testing.assert_array_equal(np.sort(np.floor(col * 100)), np.arange(100))
    # the pairing of strata across dimensions is random: columns are not comonotone
    assert abs(stats.spearmanr(u[:, 0], u[:, 1]).statistic) < 0.5


def _stratified_mean_variance(n: int) -> float:
    """Var of the mean of n Latin-hypercube standard normals in one dimension: the sum of
    the within-stratum variances over n^2 (strata [a_k, b_k] of probability 1/n; truncated-
    normal moments E z = n (phi(a) - phi(b)), E z^2 = 1 + n (a phi(a) - b phi(b)))."""
    edges = special.ndtri(np.arange(n + 1) / n)
    a, b = edges[:-1], edges[1:]
    phi_a, phi_b = stats.norm.pdf(a), stats.norm.pdf(b)
    a_phi = np.where(np.isfinite(a), a, 0.0) * phi_a  # z phi(z) -> 0 at -inf and inf
    b_phi = np.where(np.isfinite(b), b, 0.0) * phi_b
    mean = n * (phi_a - phi_b)
    second = 1.0 + n * (a_phi - b_phi)
    return float(np.sum(second - mean**2)) / n**2


def test_the_initial_states_average_to_the_belief_mean():
    setup, belief = example_setup(), example_belief()
    n = 64
    v = _stratified_mean_variance(n)
    assert v < 0.05 / n  # stratification removes most of plain Monte Carlo's 1/n
    # the mean of x_0 = x_hat + L_P z_0 has covariance v P (independent columns of z_0)
    sd = np.sqrt(v * np.diag(belief.P_hat))
    m = Stratified(n)
    for step in range(1, 6):
        hyp = m.hypotheses(belief, setup, _stream(m, step=step))
        x0 = belief.x_hat + hyp.noise[:, 0]
        err = np.abs(x0.mean(axis=0) - belief.x_hat)
        assert (err <= 5 * sd).all(), (step, err / sd)


def test_draws_depend_on_the_stream_only():
    setup, belief = example_setup(), example_belief()
    m = Stratified(16)
    a = m.hypotheses(belief, setup, _stream(m))
    np.random.seed(0)  # noqa: NPY002 (the global state must not matter)
    b = Stratified(16).hypotheses(belief, setup, _stream(m))
    c = m.hypotheses(belief, setup, _stream(m, step=2))
    np.testing.assert_array_equal(a.states, b.states)
    assert not np.array_equal(a.states, c.states)
    # another member's stream (another N_T) is another key: no shared draws
    other = Stratified(32).hypotheses(belief, setup, _stream(Stratified(32)))
    assert not np.allclose(a.noise[:, 0], other.noise[:16, 0])
