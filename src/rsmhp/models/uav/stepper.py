r"""One closed-loop step after the plan, compiled: aircraft, target, detection, tracker.

Given the applied control :math:`u_0` and the step's random numbers (process noise
:math:`w_k`, standard normals :math:`\zeta_k`, detection uniform :math:`u_k`), one call does,
in the closed loop's order (:mod:`rsmhp.models.uav.simulation`):

1. aircraft: :func:`rsmhp.models.uav.kinematics.step`;
2. target: :math:`x_k = F x_{k-1} + w_k`;
3. tracker predict: :math:`\hat x^- = F \hat x`, :math:`P^- = F P F^T + Q`;
4. detection: :func:`rsmhp.models.uav.sensor.detected` (always without a footprint);
5. if detected, measurement :math:`z = (p_x, p_y) + v` with
   :math:`v = G\,\mathrm{diag}(\sigma_r, \sigma_c)\,\zeta` in the *true* geometry
   (:func:`rsmhp.models.uav.sensor.measurement_noise`) and the tracker's update with R at the
   *predicted* estimate (:func:`rsmhp.models.uav.sensor.measurement_cov`) in Joseph form,
   :math:`K = P^- H^T S^{-1}`, :math:`\hat x = \hat x^- + K (z - H \hat x^-)`,
   :math:`P = (I - KH) P^- (I - KH)^T + K R K^T` (filterpy's ``KalmanFilter.update``);
6. error :math:`\|\hat p_k - p_k\|` and :math:`\mathrm{tr}\,P`.

Each line is the arithmetic of its reference (the numpy functions named above and filterpy's
:class:`~filterpy.kalman.KalmanFilter`, kept as the oracles of
``tests/models/uav/test_uav_stepper.py``);
only the order of the terms inside the small matrix products may differ from numpy's, so the
two agree to rounding (the test bound is 1e-12 relative per step). Why compiled: with the
planner in compiled code, the dozen numpy and filterpy calls of a step (about 0.2 ms) were
most of an NBO run's time.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from rsmhp.core import guards
from rsmhp.models.uav.kinematics import UAVParams
from rsmhp.models.uav.sensor import SensorModel
from rsmhp.models.uav.target import TargetModel

__all__ = ["Stepper", "warm_up"]


@njit(cache=True, inline="always", error_model="numpy")
def _geometry(uav, target, h2):  # pragma: no cover - compiled
    """(d^2, cos beta, sin beta) from the UAV to ``target`` (rsmhp.models.uav.sensor._geometry:
    bearing 0 directly overhead)."""
    dx = target[0] - uav[0]
    dy = target[1] - uav[1]
    rho2 = dx * dx + dy * dy
    rho = np.sqrt(rho2)
    c = dx / rho if rho != 0.0 else 1.0
    s = dy / rho if rho != 0.0 else 0.0
    return rho2 + h2, c, s


@njit(cache=True, nogil=True, error_model="numpy")
def _advance(uav, x_true, x_est, P, control, w, zeta, det_u, F, Q, ucfg, sens):  # pragma: no cover
    """In place on ``uav`` (4,), ``x_true`` (4,), ``x_est`` (4,), ``P`` (4, 4); returns
    (detected, error, trace). ``ucfg`` = (dt, g, a_max, phi_max, s_min, s_max); ``sens`` =
    (f_r, f_c, h, quadratic 0/1, d_0, footprint 0/1, rho_0, w, hard 0/1)."""
    dt, g, amax, phimax, smin, smax = ucfg[0], ucfg[1], ucfg[2], ucfg[3], ucfg[4], ucfg[5]
    # 1. aircraft (rsmhp.models.uav.kinematics._step)
    accel = min(max(control[0], -amax), amax)
    bank = min(max(control[1], -phimax), phimax)
    speed, heading = uav[2], uav[3]
    new_speed = min(max(speed + accel * dt, smin), smax)
    new_heading = heading + g * np.tan(bank) / speed * dt
    uav[0] = uav[0] + new_speed * dt * np.cos(new_heading)
    uav[1] = uav[1] + new_speed * dt * np.sin(new_heading)
    uav[2] = new_speed
    uav[3] = new_heading
    # 2. target, 3. tracker predict
    xt = np.empty(4)
    xe = np.empty(4)
    for r in range(4):
        a = 0.0
        b = 0.0
        for c in range(4):
            a += F[r, c] * x_true[c]
            b += F[r, c] * x_est[c]
        xt[r] = a + w[r]
        xe[r] = b
    FP = F @ P
    Pp = FP @ F.T + Q
    for r in range(4):
        x_true[r] = xt[r]
        x_est[r] = xe[r]
    # 4. detection (rsmhp.models.uav.sensor.detected)
    seen = True
    if sens[5] != 0.0:
        rho = np.hypot(x_true[0] - uav[0], x_true[1] - uav[1])
        if sens[8] != 0.0:
            seen = rho <= sens[6]
        else:
            seen = det_u < 1.0 / (1.0 + np.exp((rho - sens[6]) / sens[7]))
    if seen:
        fr2, fc2, h2 = sens[0] * sens[0], sens[1] * sens[1], sens[2] * sens[2]
        # R at the predicted estimate (rsmhp.models.uav.sensor._measurement_cov_entries)
        d2, c, s = _geometry(uav, x_est, h2)
        if sens[3] != 0.0:
            d2 = d2 * d2 / (sens[4] * sens[4])
        R = np.empty((2, 2))
        R[0, 0] = d2 * (fr2 * c * c + fc2 * s * s)
        R[0, 1] = d2 * (fr2 - fc2) * c * s
        R[1, 0] = R[0, 1]
        R[1, 1] = d2 * (fr2 * s * s + fc2 * c * c)
        # noise in the true geometry (rsmhp.models.uav.sensor.measurement_noise)
        d2, c, s = _geometry(uav, x_true, h2)
        d = d2 / sens[4] if sens[3] != 0.0 else np.sqrt(d2)
        zr = zeta[0] * (sens[0] * d)
        zc = zeta[1] * (sens[1] * d)
        z0 = x_true[0] + (c * zr - s * zc)
        z1 = x_true[1] + (s * zr + c * zc)
        # Joseph-form update (filterpy KalmanFilter.update with H = [I 0])
        y0 = z0 - x_est[0]
        y1 = z1 - x_est[1]
        s11 = Pp[0, 0] + R[0, 0]
        s12 = Pp[0, 1] + R[0, 1]
        s21 = Pp[1, 0] + R[1, 0]
        s22 = Pp[1, 1] + R[1, 1]
        det = s11 * s22 - s12 * s21
        i11, i12, i21, i22 = s22 / det, -s12 / det, -s21 / det, s11 / det
        K = np.empty((4, 2))
        for r in range(4):
            K[r, 0] = Pp[r, 0] * i11 + Pp[r, 1] * i21
            K[r, 1] = Pp[r, 0] * i12 + Pp[r, 1] * i22
        for r in range(4):
            x_est[r] = x_est[r] + (K[r, 0] * y0 + K[r, 1] * y1)
        IKH = np.eye(4)
        for r in range(4):
            IKH[r, 0] -= K[r, 0]
            IKH[r, 1] -= K[r, 1]
        Pn = (IKH @ Pp) @ IKH.T + (K @ R) @ K.T
        P[:, :] = Pn
    else:
        P[:, :] = Pp
    err = np.hypot(x_est[0] - x_true[0], x_est[1] - x_true[1])
    tr = P[0, 0] + P[1, 1] + P[2, 2] + P[3, 3]
    return seen, err, tr


class Stepper:
    """The compiled closed-loop step for one setup (model constants converted once).

    ``advance(uav, x_true, x_est, P, control, w, zeta, det_u)`` updates the four state arrays
    in place (float64, contiguous: UAV state (4,), true target (4,), estimate (4,),
    covariance (4, 4)) and returns ``(detected, error, trace)``; ``control`` (2,), ``w``
    (4,), ``zeta`` (2,), ``det_u`` in [0, 1) (used only with a logistic footprint)."""

    __slots__ = ("F", "Q", "sens", "ucfg")

    def __init__(self, uav: UAVParams, target: TargetModel, sensor: SensorModel) -> None:
        guards.instance_of("uav", uav, UAVParams)
        guards.instance_of("target", target, TargetModel)
        guards.instance_of("sensor", sensor, SensorModel)
        self.F = np.ascontiguousarray(target.F, dtype=float)
        self.Q = np.ascontiguousarray(target.Q, dtype=float)
        self.ucfg = (
            float(uav.dt),
            float(uav.g),
            float(uav.accel_max),
            float(uav.bank_max),
            float(uav.speed_min),
            float(uav.speed_max),
        )
        limited = bool(sensor.limited)
        self.sens = (
            float(sensor.sigma_r_per_m),
            float(sensor.sigma_c_per_m),
            float(sensor.altitude),
            1.0 if sensor.noise_growth == "quadratic" else 0.0,
            float(sensor.reference_distance),
            1.0 if limited else 0.0,
            float(sensor.footprint_radius) if limited else 0.0,
            float(sensor.footprint_width),
            1.0 if sensor.detection == "hard" else 0.0,
        )

    def advance(
        self,
        uav: np.ndarray,
        x_true: np.ndarray,
        x_est: np.ndarray,
        P: np.ndarray,
        control: np.ndarray,
        w: np.ndarray,
        zeta: np.ndarray,
        det_u: float,
    ) -> tuple[bool, float, float]:
        seen, err, tr = _advance(
            uav, x_true, x_est, P, control, w, zeta, float(det_u), self.F, self.Q,
            self.ucfg, self.sens,
        )  # fmt: skip
        return bool(seen), float(err), float(tr)


def warm_up() -> float:
    """Compile (or load from the cache) the closed-loop step; returns the seconds it took."""
    import time

    t0 = time.perf_counter()
    step = Stepper(
        UAVParams(1.0, 9.81, 3.0, 0.7, 10.0, 35.0, 100.0),
        TargetModel(1.0, 1.0),
        SensorModel(0.05, 0.1, 100.0),
    )
    state, eye = np.array([1.0, 0.0, 20.0, 0.0]), np.eye(4)
    zeros = np.zeros(4)
    step.advance(state, np.ones(4), np.ones(4), eye.copy(), np.zeros(2), zeros, np.zeros(2), 0.5)
    return time.perf_counter() - t0
