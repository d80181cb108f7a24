"""UAV models: kinematics (turn rate, speed clipping), sensor covariance, target hypotheses."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rsmhp.models.uav import kinematics, sensor, target
from rsmhp.models.uav.kinematics import UAVParams
from rsmhp.models.uav.sensor import SensorModel
from rsmhp.models.uav.target import TargetModel

UAV = UAVParams(
    dt=1.0, g=9.81, accel_max=3.0, bank_max=math.pi / 4, speed_min=10, speed_max=35, altitude=100
)
SENSOR = SensorModel(sigma_r_per_m=0.05, sigma_c_per_m=0.10, altitude=100.0)


@pytest.mark.parametrize(("speed", "bank"), [(20.0, 0.3), (10.0, -math.pi / 4), (35.0, 0.0)])
def test_turn_rate_is_g_tan_phi_over_s(speed, bank):
    state = np.array([5.0, -3.0, speed, 0.7])
    new = kinematics.step(state, np.array([0.0, bank]), UAV)
    assert new[3] - state[3] == pytest.approx(9.81 * math.tan(bank) / speed * UAV.dt, abs=1e-15)
    # position advances by s' dt along the new heading
    assert np.hypot(new[0] - 5.0, new[1] + 3.0) == pytest.approx(speed * UAV.dt)
    assert math.atan2(new[1] + 3.0, new[0] - 5.0) == pytest.approx(
        math.remainder(new[3], 2 * math.pi)
    )


@pytest.mark.parametrize(
    ("speed", "accel", "expected"),
    [(34.0, 3.0, 35.0), (11.0, -3.0, 10.0), (20.0, 2.0, 22.0), (20.0, 9.0, 23.0)],
)
def test_speed_is_clipped(speed, accel, expected):
    # the last case also clips the control to the box (|a| <= 3)
    new = kinematics.step(np.array([0.0, 0.0, speed, 0.0]), np.array([accel, 0.0]), UAV)
    assert new[2] == pytest.approx(expected)
    assert new[0] == pytest.approx(expected * UAV.dt)


def test_rollout_equals_repeated_steps(rng):
    state = np.array([0.0, 0.0, 20.0, 1.0])
    controls = rng.uniform(-1, 1, (3, 6, 2)) * UAV.control_scale
    out = kinematics.rollout(state, controls, UAV)
    for c in range(3):
        cur = state
        for j in range(6):
            cur = kinematics.step(cur, controls[c, j], UAV)
            np.testing.assert_array_equal(out[c, j], cur)


@pytest.mark.parametrize("bearing", [0.0, 0.4, 1.9, -2.5, math.pi])
def test_sensor_covariance_rotates_with_bearing(bearing):
    rho = 400.0
    uav_xy = np.array([10.0, -20.0])
    tgt_xy = uav_xy + rho * np.array([math.cos(bearing), math.sin(bearing)])
    R = sensor.measurement_cov(uav_xy, tgt_xy, SENSOR)
    d = math.hypot(rho, 100.0)
    e_r = np.array([math.cos(bearing), math.sin(bearing)])
    e_c = np.array([-math.sin(bearing), math.cos(bearing)])
    # eigen-directions: range and cross-range, eigenvalues (0.05 d)^2 and (0.10 d)^2
    np.testing.assert_allclose(R @ e_r, (0.05 * d) ** 2 * e_r, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(R @ e_c, (0.10 * d) ** 2 * e_c, rtol=1e-12, atol=1e-9)
    assert R[0, 1] == R[1, 0]


def test_sensor_covariance_scales_with_squared_3d_distance():
    uav_xy = np.zeros(2)
    r1 = sensor.measurement_cov(uav_xy, np.array([300.0, 400.0]), SENSOR)  # rho 500
    r2 = sensor.measurement_cov(uav_xy, np.array([600.0, 800.0]), SENSOR)  # rho 1000
    ratio = (1000.0**2 + 100.0**2) / (500.0**2 + 100.0**2)
    np.testing.assert_allclose(r2, ratio * r1, rtol=1e-13)


def test_sensor_covariance_never_singular_overhead():
    R = sensor.measurement_cov(np.array([7.0, 7.0]), np.array([7.0, 7.0]), SENSOR)
    assert np.all(np.isfinite(R))
    # d = h = 100: eigenvalues 5^2 and 10^2, det = (0.05 * 0.10)^2 * 100^4
    np.testing.assert_allclose(np.linalg.eigvalsh(R), [25.0, 100.0], rtol=1e-12)
    assert np.linalg.det(R) == pytest.approx((0.05 * 0.10) ** 2 * 100.0**4)


def test_measurement_noise_factor_reproduces_R(rng):
    uav_xy, tgt_xy = rng.normal(0, 300, 2), rng.normal(0, 300, 2)
    # v = L zeta is linear in zeta; its columns for zeta = e1, e2 give L with L L^T = R
    L = np.column_stack([sensor.measurement_noise(uav_xy, tgt_xy, SENSOR, e) for e in np.eye(2)])
    np.testing.assert_allclose(L @ L.T, sensor.measurement_cov(uav_xy, tgt_xy, SENSOR), rtol=1e-12)


def test_ncv_matrices():
    F, Q = target.transition_matrix(2.0), target.process_noise(2.0, 0.5)
    np.testing.assert_array_equal(F[:2, 2:], 2.0 * np.eye(2))
    np.testing.assert_allclose(Q[:2, :2], 0.5 * 8 / 3 * np.eye(2))
    np.testing.assert_allclose(Q[:2, 2:], 0.5 * 2 * np.eye(2))
    np.testing.assert_allclose(Q[2:, 2:], 0.5 * 2 * np.eye(2))
    assert np.all(np.linalg.eigvalsh(Q) > 0)


def test_nominal_is_noise_free_propagation():
    x = np.array([1.0, 2.0, 3.0, -4.0])
    nom = target.nominal(x, 3, TargetModel(1.0, 1.0))
    assert nom.shape == (1, 3, 4)
    np.testing.assert_allclose(nom[0, 2], [1 + 9, 2 - 12, 3, -4])


def test_sample_tree_without_and_with_pruning(rng):
    model = TargetModel(1.0, 1.0)
    x, P = np.zeros(4), np.diag([4.0, 4.0, 1.0, 1.0])
    full, _ = target.pruned_tree(x, P, 2, 3, 10_000, model, rng)
    assert full.shape == (27, 2, 4)  # N^(H+1) leaves, nothing pruned
    pruned, ll = target.pruned_tree(x, P, 4, 3, 7, model, np.random.default_rng(1))
    assert pruned.shape == (7, 4, 4)
    assert np.all(np.diff(ll) <= 0)  # sorted by decreasing likeliness
    # every kept path is consistent with the dynamics: x_j - F x_{j-1} is one of the level draws
    F = model.F
    for j in range(1, 4):
        w = pruned[:, j] - pruned[:, j - 1] @ F.T
        assert len(np.unique(np.round(w, 9), axis=0)) <= 3


@pytest.mark.parametrize("seed", range(40))
def test_compiled_tree_equals_generic_sampler(seed):
    """The compiled pruned tree against the generic :func:`rsmhp.core.sampling.sample_tree` on the
    same stream: same leaves in the same order (log-likeliness to rounding), same paths."""
    r = np.random.default_rng(1000 + seed)
    A = r.normal(size=(4, 4))
    P = A @ A.T * 10.0 ** r.uniform(-3, 3) + 1e-6 * np.eye(4)
    x = r.normal(size=4) * 100
    model = TargetModel(float(r.uniform(0.2, 2.0)), float(10.0 ** r.uniform(-2, 1)))
    H, N, M = int(r.integers(1, 7)), int(r.integers(1, 9)), int(r.integers(1, 150))
    got, ll = target.pruned_tree(x, P, H, N, M, model, np.random.default_rng(seed))
    ref, ll_ref = target.pruned_tree_reference(x, P, H, N, M, model, np.random.default_rng(seed))
    assert got.shape == ref.shape == (min(M, N ** (H + 1)), H, 4)
    np.testing.assert_allclose(ll, ll_ref, rtol=1e-12, atol=1e-12)
    scale = max(1.0, np.abs(ref).max())
    assert np.abs(got - ref).max() <= 1e-12 * scale


@pytest.mark.parametrize("m", [1, 3, 7, 12, 19])
def test_tree_pruning_keeps_what_a_stable_sort_keeps(m):
    """Ties at the pruning threshold go to the lower index, as with a stable descending sort."""
    vals = np.random.default_rng(m).integers(0, 5, size=20).astype(float)  # many ties
    expected = np.sort(np.argsort(-vals, kind="stable")[:m])
    np.testing.assert_array_equal(target._keep_top(vals, m), expected)


def test_sample_tree_refuses_bad_arguments(rng):
    model, P = TargetModel(1.0, 1.0), np.eye(4)
    for bad, name in (({"horizon": 0}, "horizon"), ({"n_branch": 0}, "N"), ({"max_keep": 0}, "M")):
        args = {"horizon": 3, "n_branch": 2, "max_keep": 4} | bad
        with pytest.raises(ValueError, match=f"{name}.*must be >= 1, got 0"):
            target.pruned_tree(np.zeros(4), P, model=model, rng=rng, **args)
    with pytest.raises(ValueError, match="P_hat must have shape"):
        target.pruned_tree(np.zeros(4), np.eye(3), 3, 2, 4, model, rng)


def test_sample_independent_moments():
    """Initial-state draws have mean x_hat and covariance P_hat: with n = 20000 draws the sample
    mean of each coordinate has sd sqrt(P_ii / n); 5 sd (per coordinate) bounds a false failure
    at ~6e-7 each."""
    model = TargetModel(1.0, 1.0)
    x, P = np.array([10.0, -5.0, 1.0, 2.0]), np.diag([2500.0, 900.0, 25.0, 4.0])
    n = 20_000
    hyp = target.sample_independent(x, P, 1, n, model, np.random.default_rng(3))
    # one step ahead: mean F x, covariance F P F^T + Q
    mean_expected = model.F @ x
    cov_expected = model.F @ P @ model.F.T + model.Q
    sd = np.sqrt(np.diag(cov_expected) / n)
    assert np.all(np.abs(hyp[:, 0].mean(axis=0) - mean_expected) < 5 * sd)
