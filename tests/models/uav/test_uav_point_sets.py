"""The point-set planners of the UAV registry: RQMC (scrambled Sobol'), antithetic pairs and
sigma points, and the map they share (rsmhp.models.uav.target.from_normals).

Oracles: i.i.d. normals through ``from_normals`` are :func:`draw_independent`'s hypotheses
(same draws, same states); the sigma points' weighted mean and covariance of every predicted
target state equal the Kalman prediction in closed form, :math:`F^j \\hat x` and
:math:`F^j \\hat P F^{j\\top} + \\sum_{i<j} F^i Q F^{i\\top}`; each scrambled Sobol' set puts
exactly one point in each of the N_T strata of every coordinate, and averaged over
independent scrambles the hypotheses' mean is the prediction within a tolerance from the
scrambles' own spread; antithetic sets are exact pairs. The registry round trip, the config
checks and a planning step of each method follow.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import special

from rsmhp.models.uav import methods, target
from rsmhp.models.uav.methods.antithetic import Antithetic
from rsmhp.models.uav.methods.rqmc import RQMC
from rsmhp.models.uav.methods.sigma_points import SigmaPoints, n_points
from rsmhp.models.uav.planner import Belief
from rsmhp.models.uav.simulation import UAVSetup
from rsmhp.pipeline.config import ConfigError, check_config
from rsmhp.report.palette import method_colour

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
SETUP = UAVSetup.from_config(CONFIG["uav"])
P_HAT = np.array(
    [
        [900.0, 120.0, 30.0, -4.0],
        [120.0, 400.0, 5.0, 9.0],
        [30.0, 5.0, 16.0, 1.0],
        [-4.0, 9.0, 1.0, 9.0],
    ]
)
BELIEF = Belief(np.array([0.0, 0.0, 20.0, 0.0]), np.array([300.0, -50.0, 6.0, 2.0]), P_HAT)


def _prediction(x_hat, P_hat, H, model):
    """Kalman prediction of the target H steps ahead: means (H, 4) and covariances (H, 4, 4)."""
    F, Q = model.F, model.Q
    m, P, means, covs = np.asarray(x_hat, float), np.asarray(P_hat, float), [], []
    for _ in range(H):
        m, P = F @ m, F @ P @ F.T + Q
        means.append(m)
        covs.append(P)
    return np.array(means), np.array(covs)


def _weighted_moments(states, w):
    mean = np.einsum("i,ijk->jk", w, states)
    d = states - mean
    return mean, np.einsum("i,ijk,ijl->jkl", w, d, d)


# ------------------------------------------------------------------------ the shared map


def test_iid_normals_give_draw_independents_hypotheses():
    n, H = 40, SETUP.planner.horizon
    states, noise = target.draw_independent(
        BELIEF.x_hat, P_HAT, H, n, SETUP.target, np.random.default_rng(5)
    )
    rng = np.random.default_rng(5)  # the same stream, in draw_independent's order
    z0 = rng.standard_normal((n, 4))
    zw = rng.standard_normal((n * H, 4)).reshape(n, H, 4)
    z = np.concatenate([z0[:, None, :], zw], axis=1)
    s2, n2 = target.from_normals(BELIEF.x_hat, P_HAT, z, SETUP.target)
    np.testing.assert_allclose(s2, states, rtol=1e-13, atol=1e-10)
    np.testing.assert_allclose(n2, noise, rtol=1e-13, atol=1e-10)


def test_from_normals_refuses_bad_shapes_and_values():
    x, m = BELIEF.x_hat, SETUP.target
    with pytest.raises(ValueError, match=r"z must have shape \(n, H \+ 1, 4\).*\(3, 1, 4\)"):
        target.from_normals(x, P_HAT, np.zeros((3, 1, 4)), m)
    with pytest.raises(ValueError, match=r"z must have shape"):
        target.from_normals(x, P_HAT, np.zeros((3, 4, 2)), m)
    bad = np.zeros((3, 4, 4))
    bad[1, 2, 0] = np.nan
    with pytest.raises(ValueError, match=r"z"):
        target.from_normals(x, P_HAT, bad, m)


# ------------------------------------------------------------------------ sigma points


@settings(max_examples=25, deadline=None)
@given(
    H=st.integers(1, 12),
    scale=st.floats(0.01, 100.0),
    corr=st.floats(-0.9, 0.9),
)
def test_sigma_points_match_the_kalman_prediction(H, scale, corr):
    P = scale * P_HAT.copy()
    P[0, 1] = P[1, 0] = corr * math.sqrt(P[0, 0] * P[1, 1])
    setup = copy.copy(SETUP)
    object.__setattr__(setup, "planner", copy.copy(SETUP.planner))
    object.__setattr__(setup.planner, "horizon", H)
    belief = Belief(BELIEF.uav, BELIEF.x_hat, P)
    hyp = SigmaPoints().hypotheses(belief, setup, None)
    assert hyp.n == n_points(H) == 8 * (H + 1)
    assert (hyp.weights > 0).all() and math.isclose(hyp.weights.sum(), 1.0, rel_tol=1e-12)
    mean, cov = _weighted_moments(hyp.states, hyp.weights)
    want_m, want_P = _prediction(BELIEF.x_hat, P, H, SETUP.target)
    np.testing.assert_allclose(mean, want_m, rtol=1e-10, atol=1e-9 * math.sqrt(scale))
    tol = 1e-10 * np.abs(want_P).max()
    np.testing.assert_allclose(cov, want_P, rtol=1e-9, atol=tol)
    # and the draws: initial deviation ~ (0, P), each process noise ~ (0, Q)
    d0 = hyp.noise[:, 0]
    np.testing.assert_allclose(hyp.weights @ d0, 0.0, atol=1e-9 * math.sqrt(scale))
    np.testing.assert_allclose((hyp.weights[:, None] * d0).T @ d0, P, rtol=1e-10, atol=tol)


def test_sigma_points_are_deterministic_and_need_no_stream():
    assert SigmaPoints.uses_rng is False
    a = SigmaPoints().hypotheses(BELIEF, SETUP, None)
    b = SigmaPoints().hypotheses(BELIEF, SETUP, np.random.default_rng(1))
    np.testing.assert_array_equal(a.states, b.states)


# ------------------------------------------------------------------------ antithetic


def test_antithetic_hypotheses_are_exact_pairs():
    n, H = 32, SETUP.planner.horizon
    hyp = Antithetic(n).hypotheses(BELIEF, SETUP, np.random.default_rng(2))
    assert hyp.states.shape == (n, H, 4)
    np.testing.assert_array_equal(hyp.weights, np.full(n, 1 / n))
    np.testing.assert_allclose(hyp.noise[: n // 2], -hyp.noise[n // 2 :], rtol=0, atol=1e-12)
    # linear in the noise: each pair's mean state is the prediction exactly
    want_m, _ = _prediction(BELIEF.x_hat, P_HAT, H, SETUP.target)
    pair_mean = 0.5 * (hyp.states[: n // 2] + hyp.states[n // 2 :])
    np.testing.assert_allclose(pair_mean, np.broadcast_to(want_m, pair_mean.shape), atol=1e-9)


def test_antithetic_refuses_odd_sizes():
    with pytest.raises(ValueError, match=r"n_traj \(N_T\) must be even.*got 5"):
        Antithetic(5)
    with pytest.raises(ValueError, match=r"antithetic_nt\[1\] must be even"):
        methods.from_config({"antithetic_nt": [4, 7]}, "uav.methods")


# ------------------------------------------------------------------------ RQMC


@pytest.mark.parametrize("n", [16, 64, 256])
def test_rqmc_points_stratify_every_coordinate(n):
    """Scrambled Sobol' points in a power of 2: each one-dimensional projection has exactly
    one point in each of the n intervals [k/n, (k+1)/n) (a (0, m, 1)-net property)."""
    hyp = RQMC(n).hypotheses(BELIEF, SETUP, np.random.default_rng(7))
    L = np.linalg.cholesky(P_HAT)
    z0 = np.linalg.solve(L, hyp.noise[:, 0].T).T  # back to standard-normal coordinates
    Lq = SETUP.target.noise.chol
    zw = np.linalg.solve(Lq, hyp.noise[:, 1:].reshape(-1, 4).T).T.reshape(n, -1)
    for z in np.concatenate([z0, zw], axis=1).T:
        strata = np.floor(special.ndtr(z) * n).astype(int)
        assert sorted(strata) == list(range(n))


def test_rqmc_is_unbiased_over_scrambles():
    """The mean hypothesis over R independent scrambles estimates the prediction; the test
    allows 4.5 standard errors of that mean, estimated from the R scrambles themselves."""
    H, R, n = SETUP.planner.horizon, 200, 16
    rng = np.random.default_rng(11)
    means = np.array(
        [RQMC(n).hypotheses(BELIEF, SETUP, rng).states.mean(axis=0) for _ in range(R)]
    )  # (R, H, 4)
    want_m, _ = _prediction(BELIEF.x_hat, P_HAT, H, SETUP.target)
    se = means.std(axis=0, ddof=1) / math.sqrt(R)
    assert (np.abs(means.mean(axis=0) - want_m) <= 4.5 * se).all()


def test_rqmc_scrambles_afresh_at_every_step():
    rng = np.random.default_rng(3)
    a = RQMC(16).hypotheses(BELIEF, SETUP, rng)
    b = RQMC(16).hypotheses(BELIEF, SETUP, rng)
    assert not np.allclose(a.states, b.states)
    c = RQMC(16).hypotheses(BELIEF, SETUP, np.random.default_rng(3))
    np.testing.assert_array_equal(a.states, c.states)  # the stream decides, nothing else


def test_rqmc_refuses_sizes_that_are_not_powers_of_two():
    with pytest.raises(ValueError, match=r"n_traj \(N_T\) must be a power of 2.*got 100"):
        RQMC(100)
    cfg = copy.deepcopy(CONFIG)
    cfg["uav"]["methods"]["rqmc_nt"] = [16, 100]
    with pytest.raises(ConfigError, match=r"uav\.methods\.rqmc_nt\[1\]: 100 is not a power of 2"):
        check_config(cfg)


# ------------------------------------------------------------------------ registry and planning

BLOCK = {"nbo": True, "rsmhp_nt": [], "rqmc_nt": [16, 256], "antithetic_nt": [32], "sigma": True}


def test_the_new_families_round_trip_through_the_registry():
    got = methods.from_config(BLOCK, "uav.methods")
    assert list(got) == ["nbo", "rqmc_nt16", "rqmc_nt256", "antithetic_nt32", "sigma"]
    for name, m in got.items():
        assert methods.from_name(name) == m
        assert methods.from_spec(m.spec()) == m
        assert m.label() and method_colour(m.name).startswith("#")
    assert method_colour("rqmc_nt16") != method_colour("rqmc_nt256")
    assert got["sigma"].columns() == {"N_T": 0, "N": 0, "M": 0}
    cfg = copy.deepcopy(CONFIG)
    cfg["uav"]["methods"] = BLOCK
    check_config(cfg)


@pytest.mark.parametrize("name", ["rqmc_nt16", "antithetic_nt32", "sigma"])
def test_each_new_method_plans_a_step(name):
    m = methods.from_name(name)
    H = SETUP.planner.horizon
    rng = np.random.default_rng(0) if m.uses_rng else None
    res = m.planner(SETUP).plan(BELIEF, np.zeros((H, 2)), rng)
    scale = np.array([SETUP.uav.accel_max, SETUP.uav.bank_max])
    assert res.controls.shape == (H, 2) and (np.abs(res.controls) <= scale * (1 + 1e-12)).all()
    assert np.isfinite(res.cost) and res.cost <= res.cost_warm
    assert res.hypotheses.n == (n_points(H) if name == "sigma" else m.n_traj)


# ------------------------------------------------------------------------ Sobol' points


@settings(max_examples=40, deadline=None)
@given(
    d=st.integers(1, 60),
    m=st.integers(0, 10),
    extra=st.integers(0, 5),
    seed=st.integers(0, 2**32 - 1),
)
def test_sobol_points_are_scipys_bit_for_bit(d, m, extra, seed):
    """designs.sobol_points = qmc.Sobol(d, scramble=True, rng).random(n), also for n not a
    power of 2, and both leave the parent generator in the same state."""
    import warnings

    from scipy.stats import qmc

    from rsmhp.core import designs

    n = 2**m + extra
    r1, r2 = np.random.default_rng(seed), np.random.default_rng(seed)
    ours = [designs.sobol_points(r1, n, d) for _ in range(2)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # scipy's balance warning for n not a power of 2
        theirs = [qmc.Sobol(d, scramble=True, rng=r2).random(n) for _ in range(2)]
    for a, b in zip(ours, theirs, strict=True):
        np.testing.assert_array_equal(a, b)
    assert r1.random() == r2.random()


def test_sobol_points_refuse_bad_arguments():
    from scipy.stats import qmc

    from rsmhp.core import designs

    rng = np.random.default_rng(0)
    assert designs.SOBOL_MAXDIM == qmc.Sobol.MAXDIM  # our copy of scipy's limit
    with pytest.raises(ValueError, match=r"d must be at most 21201, got 30000"):
        designs.sobol_points(rng, 4, 30000)
    with pytest.raises(ValueError, match=r"n"):
        designs.sobol_points(rng, 0, 3)
