"""The compiled closed-loop step (rsmhp.models.uav.stepper) against its references, step by step.

The oracle chains the reference implementations the closed loop used before: aircraft
rsmhp.models.uav.kinematics.step, target F x + w, filterpy's KalmanFilter predict / update
(rsmhp.models.uav.tracker.Tracker, Joseph form) with R from rsmhp.models.uav.sensor.measurement_cov
at the
predicted estimate and the measurement noise of rsmhp.models.uav.sensor.measurement_noise in the
true geometry, detection rsmhp.models.uav.sensor.detected. Over random sequences of steps, for the
paper's sensor, quadratic noise growth and both footprint detections, every state agrees to 1e-12
relative (the products inside the 4x4 algebra may be summed in another order than numpy's).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rsmhp.models.uav import kinematics, sensor
from rsmhp.models.uav.kinematics import UAVParams
from rsmhp.models.uav.sensor import SensorModel
from rsmhp.models.uav.stepper import Stepper
from rsmhp.models.uav.target import TargetModel
from rsmhp.models.uav.tracker import Tracker

UAV = UAVParams(
    dt=1.0, g=9.81, accel_max=3.0, bank_max=math.pi / 4, speed_min=10, speed_max=35, altitude=100
)
MODEL = TargetModel(1.0, 0.5)
SENSORS = {
    "paper": SensorModel(0.05, 0.10, 100.0),
    "quadratic": SensorModel(0.05, 0.10, 100.0, noise_growth="quadratic"),
    "hard": SensorModel(0.05, 0.10, 100.0, footprint_radius=150.0),
    "logistic": SensorModel(
        0.05, 0.10, 100.0, footprint_radius=150.0, footprint_width=20.0, detection="logistic"
    ),
}


def _oracle_step(uav, x_true, trk, control, w, zeta, u, sens):
    uav = kinematics.step(uav, control, UAV)
    x_true = MODEL.F @ x_true + w
    trk.predict()
    seen = sensor.detected(uav[:2], x_true[:2], sens, u)
    if seen:
        R = sensor.measurement_cov(uav[:2], trk.x[:2], sens)
        v = sensor.measurement_noise(uav[:2], x_true[:2], sens, zeta)
        trk.update(x_true[:2] + v, R)
    err = float(np.hypot(*(trk.x[:2] - x_true[:2])))
    return uav, x_true, seen, err, float(np.trace(trk.P))


@settings(max_examples=25, deadline=None)
@given(
    kind=st.sampled_from(sorted(SENSORS)),
    seed=st.integers(0, 2**31),
    steps=st.integers(1, 40),
    spread=st.sampled_from([30.0, 300.0, 3000.0]),
)
def test_steps_match_the_reference_chain(kind, seed, steps, spread):
    sens = SENSORS[kind]
    rng = np.random.default_rng(seed)
    uav = np.array([*rng.uniform(-spread, spread, 2), rng.uniform(11, 34), rng.uniform(-3, 3)])
    x_true = np.array([*rng.uniform(-spread, spread, 2), *rng.uniform(-10, 10, 2)])
    A = rng.standard_normal((4, 4))
    P0 = np.diag([400.0, 400.0, 25.0, 25.0]) + A @ A.T
    x_est = x_true + rng.standard_normal(4) * 5
    trk = Tracker(x_est, P0, MODEL)
    stepper = Stepper(UAV, MODEL, sens)
    s_uav, s_true, s_est, s_P = uav.copy(), x_true.copy(), x_est.copy(), P0.copy()
    chol_q = np.linalg.cholesky(MODEL.Q)
    for _ in range(steps):
        control = rng.uniform(-1.2, 1.2, 2) * UAV.control_scale  # partly outside the box
        w = chol_q @ rng.standard_normal(4)
        zeta = rng.standard_normal(2)
        u = rng.random()
        uav, x_true, seen, err, tr = _oracle_step(uav, x_true, trk, control, w, zeta, u, sens)
        got = stepper.advance(s_uav, s_true, s_est, s_P, control, w, zeta, u)
        assert got[0] == seen
        np.testing.assert_allclose(s_uav, uav, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(s_true, x_true, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(s_est, trk.x, rtol=1e-10, atol=1e-8)
        np.testing.assert_allclose(s_P, trk.P, rtol=1e-10, atol=1e-10 * np.abs(trk.P).max())
        assert got[1] == pytest.approx(err, rel=1e-9, abs=1e-9)
        assert got[2] == pytest.approx(tr, rel=1e-10)
        # keep the two chains on the same state: differences stay at rounding, never grow
        s_uav[:], s_true[:], s_est[:], s_P[:] = uav, x_true, trk.x, trk.P


def test_overhead_and_out_of_footprint():
    """Target exactly below the UAV (bearing frozen at 0, as the numpy sensor); outside a
    hard footprint nothing is measured and P is the prediction."""
    sens = SENSORS["hard"]
    stepper = Stepper(UAV, MODEL, sens)
    uav = np.array([0.0, 0.0, 20.0, 0.0])
    after = kinematics.step(uav, np.zeros(2), UAV)
    x_true = np.array([after[0], after[1], 0.0, 0.0])  # the UAV's next position, at rest
    P = np.eye(4) * 100.0
    x_est = x_true.copy()
    seen, err, tr = stepper.advance(
        uav, x_true, x_est, P, np.zeros(2), np.zeros(4), np.ones(2), 0.5
    )
    assert seen and np.isfinite(err) and np.isfinite(P).all()
    far = np.array([1e4, 1e4, 0.0, 0.0])
    P2 = np.eye(4)
    seen, _, tr = stepper.advance(
        uav, far, far.copy(), P2, np.zeros(2), np.zeros(4), np.ones(2), 0.5
    )
    assert not seen
    Pp = MODEL.F @ np.eye(4) @ MODEL.F.T + MODEL.Q
    np.testing.assert_allclose(P2, Pp, rtol=1e-15)
    assert tr == pytest.approx(np.trace(Pp))
