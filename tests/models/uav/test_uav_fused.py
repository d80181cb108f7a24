"""The compiled planner kernel (rsmhp.models.uav.fused) against independent oracles.

* values: the numpy kernel (rsmhp.models.uav.kernel) after the numpy kinematics, to 1e-12 relative;
* gradients: complex-step differentiation of a dense reference written here (4x4 matrices,
  np.linalg.solve, generic dtype), which shares no code with the kernel and has no
  truncation or cancellation error (step 1e-30), and central differences with a
  Richardson error estimate;
* geometry: the target directly below the UAV (bearing undefined), just off it, far away,
  tiny and huge initial covariance.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from numba import njit

from rsmhp.models.uav import fused, kinematics
from rsmhp.models.uav.kernel import covariance_traces, objective
from rsmhp.models.uav.kinematics import UAVParams
from rsmhp.models.uav.sensor import SensorModel
from rsmhp.models.uav.target import TargetModel
from rsmhp.models.uav.tracker import MEASUREMENT_MATRIX

UAV = UAVParams(
    dt=1.0, g=9.81, accel_max=3.0, bank_max=math.pi / 4, speed_min=10, speed_max=35, altitude=100
)
SENSOR = SensorModel(0.05, 0.10, 100.0)
MODEL = TargetModel(1.0, 1.0)


def dense_reference(x, state, uav, P0, target_xy, model, sensor):
    """J(x) with dense 4x4 algebra, any dtype (complex for complex-step derivatives).

    Kinematics as in rsmhp.models.uav.kinematics (clips decided on the real part), R from its
    definition R = G diag(sr², sc²) G^T with the bearing frozen at 0 when the target is
    exactly below, Kalman update P - P H^T S^-1 H P with np.linalg.solve.
    """
    H = len(x) // 2
    F, Q, Hm = model.F, model.Q, MEASUREMENT_MATRIX
    px, py, s, psi = (state[k] + 0 * x[0] for k in range(4))
    positions = []
    for j in range(H):
        a = uav.accel_max * x[2 * j]
        phi = uav.bank_max * x[2 * j + 1]
        v = s + a * uav.dt
        if v.real >= uav.speed_max:
            v = uav.speed_max + 0 * v
        elif v.real <= uav.speed_min:
            v = uav.speed_min + 0 * v
        psi = psi + uav.g * np.tan(phi) / s * uav.dt
        s = v
        px = px + s * uav.dt * np.cos(psi)
        py = py + s * uav.dt * np.sin(psi)
        positions.append((px, py))
    total = 0
    for i in range(target_xy.shape[0]):
        P = P0.astype(complex if np.iscomplexobj(x) else float)
        for j in range(H):
            dx = target_xy[i, j, 0] - positions[j][0]
            dy = target_xy[i, j, 1] - positions[j][1]
            rho2 = dx * dx + dy * dy
            if np.real(dx) == 0.0 and np.real(dy) == 0.0:
                c, sn = 1.0 + 0 * dx, 0.0 * dx  # bearing frozen at 0 (no derivative)
            else:
                rho = np.sqrt(rho2)
                c, sn = dx / rho, dy / rho
            d2 = rho2 + sensor.altitude**2
            G = np.array([[c, -sn], [sn, c]])
            D = np.diag([sensor.sigma_r_per_m**2 * d2, sensor.sigma_c_per_m**2 * d2])
            R = G @ D @ G.T
            P = F @ P @ F.T + Q
            S = Hm @ P @ Hm.T + R
            P = P - P @ Hm.T @ np.linalg.solve(S, Hm @ P)
            total = total + np.trace(P)
    return total / target_xy.shape[0]


def complex_step_grad(x, *args):
    h = 1e-30
    out = np.empty(len(x))
    for k in range(len(x)):
        xc = x.astype(complex)
        xc[k] += 1j * h
        out[k] = dense_reference(xc, *args).imag / h
    return out


def _case(rng, n_t=5, H=6, p0_scale=1.0, far=False):
    A = rng.standard_normal((4, 4))
    P0 = p0_scale * (np.diag([2500.0, 2500.0, 25.0, 25.0]) + 10 * A @ A.T)
    state = np.array([*rng.uniform(-100, 100, 2), rng.uniform(12, 33), rng.uniform(-3, 3)])
    span = 1e5 if far else 400.0
    target_xy = rng.uniform(-span, span, (n_t, H, 2))
    x = rng.uniform(-0.95, 0.95, 2 * H)
    return x, state, P0, target_xy


def _numpy_cost(xs, state, P0, target_xy):
    H = xs.shape[1] // 2
    controls = (xs * np.tile(UAV.control_scale, H)).reshape(len(xs), H, 2)
    states = kinematics.rollout(state, controls, UAV)
    return objective(P0, states[..., :2], target_xy, MODEL.dt, MODEL.Q, SENSOR)


@pytest.mark.parametrize("p0_scale", [1e-6, 1.0, 1e6])
@pytest.mark.parametrize("far", [False, True])
def test_value_equals_numpy_kernel(rng, p0_scale, far):
    x, state, P0, txy = _case(rng, p0_scale=p0_scale, far=far)
    xs = np.vstack([x, rng.uniform(-1, 1, (6, x.size)), np.ones(x.size), -np.ones(x.size)])
    ours = fused.cost(xs, state, UAV, P0, txy, MODEL.dt, MODEL.Q, SENSOR)
    ref = _numpy_cost(xs, state, P0, txy)
    np.testing.assert_allclose(ours, ref, rtol=1e-12, atol=0)
    ours_g, _ = fused.cost_and_grad(xs, state, UAV, P0, txy, MODEL.dt, MODEL.Q, SENSOR)
    np.testing.assert_array_equal(ours_g, ours)  # the gradient pass changes no value


def test_traces_twin_equals_numpy_kernel(rng):
    _, _, P0, txy = _case(rng, n_t=7)
    uav_xy = rng.uniform(-600, 600, (4, 6, 2))
    uav_xy[1, 3] = txy[2, 3]  # directly overhead once
    np.testing.assert_allclose(
        fused.covariance_traces(P0, uav_xy, txy, MODEL.dt, MODEL.Q, SENSOR),
        covariance_traces(P0, uav_xy, txy, MODEL.dt, MODEL.Q, SENSOR),
        rtol=1e-12,
        atol=0,
    )


def test_dense_reference_is_a_valid_oracle(rng):
    """The complex-step oracle's forward value agrees with the numpy kernel (so its
    derivative is the derivative of the planner's objective)."""
    x, state, P0, txy = _case(rng)
    ref = dense_reference(x, state, UAV, P0, txy, MODEL, SENSOR)
    assert ref == pytest.approx(_numpy_cost(x[None], state, P0, txy)[0], rel=1e-12)


@pytest.mark.parametrize("p0_scale", [1e-6, 1.0, 1e6])
@pytest.mark.parametrize("far", [False, True])
def test_gradient_equals_complex_step(rng, p0_scale, far):
    x, state, P0, txy = _case(rng, p0_scale=p0_scale, far=far)
    _, g = fused.cost_and_grad(x, state, UAV, P0, txy, MODEL.dt, MODEL.Q, SENSOR)
    ref = complex_step_grad(x, state, UAV, P0, txy, MODEL, SENSOR)
    # both exact up to rounding: compare with the gradient's scale
    np.testing.assert_allclose(g[0], ref, rtol=0, atol=1e-9 * np.abs(ref).max())


def test_gradient_equals_central_differences(rng):
    """Central differences D_h carry a truncation error ~ (D_2h - D_h) / 3 (Richardson, from
    the Taylor expansion) plus rounding ~ eps |J| / h; the exact gradient must lie within
    twice that of D_h."""
    x, state, P0, txy = _case(rng)
    frozen = fused.Frozen(state, UAV, P0, txy, MODEL.dt, MODEL.Q, SENSOR)
    f0, g = fused.evaluate(x[None], frozen, want_grad=True)
    h, eps = 1e-5, np.finfo(float).eps
    for k in range(x.size):
        e = np.zeros(x.size)
        e[k] = 1.0

        def d(step, e=e):
            xs = np.vstack([x + step * e, x - step * e])
            fp, fm = fused.evaluate(xs, frozen, want_grad=False)[0]
            return (fp - fm) / (2 * step)

        d1, d2 = d(h), d(2 * h)
        tol = 2 * (abs(d2 - d1) / 3 + 4 * eps * abs(f0[0]) / h)
        assert abs(g[0, k] - d1) <= tol, (k, g[0, k], d1, tol)


def _overhead_case():
    """Straight flight along x at 20 m/s with zero controls: positions (20 j, 0) exactly; the
    target hypothesis sits exactly below the UAV at step 3 and 1 cm off it at step 5."""
    H = 6
    state = np.array([0.0, 0.0, 20.0, 0.0])
    x = np.zeros(2 * H)
    txy = np.array([[[50.0, 30.0], [60.0, 10.0], [60.0, 0.0], [60.0, 0.0], [100.0, 20.0]]])
    txy = np.concatenate([txy, np.array([[[120.0, 0.01]]])], axis=1)  # (1, 6, 2)
    P0 = np.diag([2500.0, 2500.0, 25.0, 25.0])
    return x, state, P0, txy


def test_overhead_value_and_frozen_bearing_gradient():
    x, state, P0, txy = _overhead_case()
    path = kinematics.rollout(state, np.zeros((6, 2)), UAV)
    assert path[2, 0] == txy[0, 2, 0] and path[2, 1] == txy[0, 2, 1]  # exactly overhead
    c, g = fused.cost_and_grad(x, state, UAV, P0, txy, MODEL.dt, MODEL.Q, SENSOR)
    assert c[0] == pytest.approx(_numpy_cost(x[None], state, P0, txy)[0], rel=1e-12)
    assert np.all(np.isfinite(g))
    # the oracle freezes the bearing at exactly zero distance, as documented; 1 cm off the
    # target (step 5) the derivative is exact and large (~ h^2 |Rbar| / rho)
    ref = complex_step_grad(x, state, UAV, P0, txy, MODEL, SENSOR)
    np.testing.assert_allclose(g[0], ref, rtol=0, atol=1e-9 * np.abs(ref).max())


def test_speed_clip_zeroes_the_acceleration_derivative():
    """At full speed with full forward acceleration the speed is clipped at every step:
    acceleration has no effect (derivative 0), bank angles still do."""
    state = np.array([0.0, 0.0, 35.0, 0.0])
    x = np.tile([1.0, 0.3], 6)
    txy = np.random.default_rng(3).uniform(-300, 300, (4, 6, 2))
    _, g = fused.cost_and_grad(x, state, UAV, np.eye(4) * 100, txy, 1.0, MODEL.Q, SENSOR)
    np.testing.assert_array_equal(g[0, 0::2], 0.0)
    assert np.all(g[0, 1::2] != 0.0)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**32 - 1),
    log_p0=st.floats(-6, 8),
    span=st.sampled_from([1.0, 100.0, 1e4]),
    n_t=st.integers(1, 4),
    H=st.integers(1, 8),
)
def test_property_gradient_and_value(seed, log_p0, span, n_t, H):
    """Random geometry (targets within 1 m of the UAV's start up to 10 km away), covariance
    scales 1e-6..1e8, horizons 1..8: value = numpy kernel, gradient = complex step, and the
    gradient pass leaves the value unchanged."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((4, 4))
    P0 = 10.0**log_p0 * (np.eye(4) + 0.3 * A @ A.T)
    state = np.array([0.0, 0.0, rng.uniform(10, 35), rng.uniform(-4, 4)])
    txy = rng.uniform(-span, span, (n_t, H, 2))
    x = rng.uniform(-1, 1, 2 * H)
    c, g = fused.cost_and_grad(x, state, UAV, P0, txy, MODEL.dt, MODEL.Q, SENSOR)
    assert c[0] == pytest.approx(_numpy_cost(x[None], state, P0, txy)[0], rel=1e-12)
    ref = complex_step_grad(x, state, UAV, P0, txy, MODEL, SENSOR)
    np.testing.assert_allclose(g[0], ref, rtol=0, atol=1e-8 * np.abs(ref).max() + 1e-300)


def test_bad_shapes_are_refused():
    frozen = fused.Frozen(
        np.zeros(4) + 20, UAV, np.eye(4), np.zeros((2, 6, 2)), 1.0, MODEL.Q, SENSOR
    )
    with pytest.raises(ValueError, match="target_xy has 6 steps, x has 5"):
        fused.evaluate(np.zeros((1, 10)), frozen, want_grad=False)
    with pytest.raises(ValueError, match=r"x must have shape \(C, 2H\)"):
        fused.evaluate(np.zeros(12), frozen, want_grad=False)


@pytest.mark.parametrize("limited", [False, True])
@pytest.mark.parametrize("n_t", [1, 23, 24, 57])
def test_both_layouts_match_the_oracle_and_each_other(rng, n_t, limited):
    """Below SOA_MIN_HYPOTHESES the kernel runs one hypothesis at a time, from it on
    vectorised over hypotheses: on both sides of the threshold (and with the footprint's
    separate detection loop) the value equals the numpy kernel to 1e-12 and the gradient the
    complex step; forced through either layout, value and gradient are bit-identical."""
    sensor = SensorModel(0.05, 0.10, 100.0, footprint_radius=250.0) if limited else SENSOR
    x, state, P0, _ = _case(rng)
    txy = rng.uniform(-400, 400, (n_t, x.size // 2, 2))
    c, g = fused.cost_and_grad(x, state, UAV, P0, txy, MODEL.dt, MODEL.Q, sensor)
    H = x.size // 2
    controls = (x * np.tile(UAV.control_scale, H)).reshape(1, H, 2)
    pos = kinematics.rollout(state, controls, UAV)[..., :2]
    ref = objective(P0, pos, txy, MODEL.dt, MODEL.Q, sensor)
    np.testing.assert_allclose(c, ref, rtol=1e-12, atol=0)
    frozen = fused.Frozen(state, UAV, P0, txy, MODEL.dt, MODEL.Q, sensor)
    ws = fused._workspace(H, n_t, limited)
    outs = []
    for layout in (_scalar_layout, _soa_layout):  # the dispatcher picks by T; here both
        grad = np.empty(2 * H)
        outs.append((layout(x, *frozen.args, ws, grad), grad))
    assert outs[0][0] == outs[1][0] == c[0]
    np.testing.assert_array_equal(outs[0][1], outs[1][1])
    np.testing.assert_array_equal(outs[0][1], g[0])


@njit(cache=True)
def _scalar_layout(x, st, cfg, p0, q, sens, tx, ty, wts, ws, grad):
    return fused._value_grad_scalar(
        x, st, cfg, p0, q, sens, tx, ty, wts,
        ws[6], ws[7], ws[8], ws[9], ws[10], ws[11], ws[12], True, grad,
    )  # fmt: skip


@njit(cache=True)
def _soa_layout(x, st, cfg, p0, q, sens, tx, ty, wts, ws, grad):
    return fused._value_grad_soa(x, st, cfg, p0, q, sens, tx, ty, wts, ws, True, grad)
