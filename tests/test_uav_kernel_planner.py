"""The batched covariance kernel against filterpy, and the planner built on it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rsmhp.uav import kinematics, sensor, target
from rsmhp.uav.kernel import covariance_traces, objective
from rsmhp.uav.kinematics import UAVParams
from rsmhp.uav.planner import PlannerParams, PlanningProblem, plan, shift_plan
from rsmhp.uav.sensor import SensorModel
from rsmhp.uav.target import TargetModel
from rsmhp.uav.tracker import Tracker

UAV = UAVParams(
    dt=1.0, g=9.81, accel_max=3.0, bank_max=math.pi / 4, speed_min=10, speed_max=35, altitude=100
)
SENSOR = SensorModel(0.05, 0.10, 100.0)
MODEL = TargetModel(1.0, 1.0)
PLANNER = PlannerParams(horizon=6, maxiter=30, maxfun=60, fd_step=1e-4)


def _inputs(rng, n_c=4, n_t=7, H=6):
    A = rng.standard_normal((4, 4))
    P0 = np.diag([2500.0, 2500.0, 25.0, 25.0]) + 10 * A @ A.T
    uav_xy = rng.uniform(-600, 600, (n_c, H, 2))
    tgt_xy = rng.uniform(-600, 600, (n_t, H, 2))
    tgt_xy[0, 2] = uav_xy[0, 2]  # one measurement taken directly overhead
    return P0, uav_xy, tgt_xy


def test_kernel_matches_filterpy_per_trajectory(rng):
    P0, uav_xy, tgt_xy = _inputs(rng)
    traces, covs = covariance_traces(P0, uav_xy, tgt_xy, 1.0, MODEL.Q, SENSOR, return_cov=True)
    for c in range(uav_xy.shape[0]):
        for i in range(tgt_xy.shape[0]):
            trk = Tracker(np.zeros(4), P0, MODEL)
            for j in range(uav_xy.shape[1]):
                trk.predict()
                trk.update(np.zeros(2), sensor.measurement_cov(uav_xy[c, j], tgt_xy[i, j], SENSOR))
                P = trk.P
                scale = np.abs(P).max()
                np.testing.assert_allclose(covs[c, i, j], P, rtol=0, atol=1e-9 * scale)
                assert traces[c, i, j] == pytest.approx(np.trace(P), rel=1e-9)
    # exact symmetry of the carried covariance
    np.testing.assert_array_equal(covs, np.swapaxes(covs, -1, -2))


def test_objective_is_mean_over_hypotheses_of_summed_traces(rng):
    P0, uav_xy, tgt_xy = _inputs(rng)
    tr = covariance_traces(P0, uav_xy, tgt_xy, 1.0, MODEL.Q, SENSOR)
    np.testing.assert_allclose(
        objective(P0, uav_xy, tgt_xy, 1.0, MODEL.Q, SENSOR), tr.sum(axis=2).mean(axis=1)
    )
    # each hypothesis is independent of the others in the batch
    alone = covariance_traces(P0, uav_xy[1:2], tgt_xy[3:4], 1.0, MODEL.Q, SENSOR)
    np.testing.assert_allclose(alone[0, 0], tr[1, 3], rtol=1e-14)


def _problem(rng, n_traj=30):
    uav_state = np.array([0.0, 0.0, 20.0, 0.0])
    x_hat = np.array([450.0, 250.0, -6.0, 4.0])
    P_hat = np.diag([900.0, 900.0, 16.0, 16.0])
    hyp = target.sample_independent(x_hat, P_hat, 6, n_traj, MODEL, rng)
    return PlanningProblem(uav_state, P_hat, hyp[..., :2], UAV, MODEL, SENSOR, PLANNER)


def test_batched_gradient_is_one_kernel_call_and_matches_central_differences(rng):
    prob = _problem(rng)
    x = rng.uniform(-0.8, 0.8, 12)
    f, g = prob.value_and_grad(x)
    assert prob.n_kernel_calls == 1
    # Forward differences with step h have truncation error h/2 |f''(xi)| (Taylor); we bound
    # |f''| by a second difference with step 1e-3 (x 2 for its variation over the step) and
    # add rounding, ~4 eps |f| / h. Central differences (step 1e-5) are the reference.
    h, eps = PLANNER.fd_step, np.finfo(float).eps
    for i, e in enumerate(np.eye(12)):
        fp, fm = prob.costs(x[None] + 1e-5 * e)[0], prob.costs(x[None] - 1e-5 * e)[0]
        central = (fp - fm) / 2e-5
        f2p, f2m = prob.costs(x[None] + 1e-3 * e)[0], prob.costs(x[None] - 1e-3 * e)[0]
        curvature = abs(f2p - 2 * f + f2m) / 1e-6
        tol = h / 2 * 2 * curvature + 4 * eps * abs(f) / h + 4 * eps * abs(f) / 1e-5
        assert abs(g[i] - central) <= tol, (i, g[i], central, tol)
    assert f == prob.costs(x[None])[0]


def test_gradient_steps_backward_at_the_upper_bound(rng):
    prob = _problem(rng)
    x = np.ones(12)
    _, g = prob.value_and_grad(x)
    assert np.all(np.isfinite(g))


def test_optimizer_decreases_objective_vs_warm_start(rng):
    prob = _problem(rng)
    warm = np.zeros((6, 2))  # straight ahead (east) while the target is north-east
    res = plan(prob, warm)
    assert res.cost_warm == pytest.approx(prob.costs(np.zeros((1, 12)))[0])
    assert res.cost == pytest.approx(
        prob.costs((res.controls / UAV.control_scale).reshape(1, -1))[0]
    )
    # must improve by more than the objective's finite-difference noise (relative ~1e-12)
    assert res.cost < res.cost_warm * (1 - 1e-6)
    assert np.all(np.abs(res.controls) <= UAV.control_scale + 1e-12)
    np.testing.assert_allclose(res.uav_path, kinematics.rollout(prob.uav_state, res.controls, UAV))


def test_shift_plan():
    u = np.arange(12.0).reshape(6, 2)
    np.testing.assert_array_equal(shift_plan(u), np.vstack([u[1:], u[-1:]]))
