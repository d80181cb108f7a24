r"""The planner's objective kernel: Kalman covariance recursions for many hypotheses at once.

For ``C`` candidate control sequences (UAV positions ``uav_xy`` (C, H, 2)) and ``T`` target
hypotheses (positions ``target_xy`` (T, H, 2)) the kernel runs, for every pair (c, i) and
:math:`j = 1..H`, the Kalman covariance recursion of :mod:`rsmhp.models.uav.tracker`

.. math::
    P^-_j = F P_{j-1} F^T + Q, \quad S_j = H P^-_j H^T + R_j, \quad
    P_j = P^-_j - P^-_j H^T S_j^{-1} H P^-_j,

with :math:`R_j = R(\mathrm{uav}_{c,j}, \mathrm{target}_{i,j})` and :math:`P_0 = \hat P`, and
returns the traces :math:`\mathrm{tr}\,P_j` (C, T, H). The planner's cost of candidate c is
:math:`\frac1T \sum_i \sum_{j=1}^H \mathrm{tr}\, P_j^{c,i}` (:func:`objective`).

Structure used (exact, not approximations): write :math:`P = [[A, B], [B^T, C]]` with
2x2 blocks (A, C symmetric) and :math:`F = [[I, \Delta t I], [0, I]]`, :math:`H = [I\ 0]`:

.. math::
    A^- = A + \Delta t (B + B^T) + \Delta t^2 C + Q_A, \quad B^- = B + \Delta t C + Q_B,
    \quad C^- = C + Q_C, \\
    S = A^- + R, \quad A^+ = A^- - A^- S^{-1} A^- = R S^{-1} A^-, \quad
    B^+ = B^- - A^- S^{-1} B^- = R S^{-1} B^-, \quad C^+ = C^- - B^{-T} S^{-1} B^-,

with the closed-form 2x2 inverse :math:`S^{-1} = \mathrm{adj}(S)/\det S`. The 10 distinct
entries of P are carried as arrays of shape (C, T); only upper triangles of the symmetric
blocks are formed, so symmetry holds exactly. :math:`A^+` and :math:`B^+` are evaluated as
:math:`R S^{-1} A^-` and :math:`R S^{-1} B^-` (equal because :math:`S - A^- = R`): the
difference :math:`A^- - A^- S^{-1} A^-` cancels catastrophically when R is tiny next to
:math:`A^-` (error about :math:`u\,\kappa(S)\,\|P^-\|`; with :math:`A^-` ~ 1e8 m^2 and R ~
1e-4 m^2 it gave a negative trace), the product does not. It agrees with filterpy's Joseph
form to rounding error (tests/core/test_properties.py).

With a sensor footprint (:class:`rsmhp.models.uav.sensor.SensorModel`) the update is the expected
one, :math:`P^+ = P^- - p_d\, K S K^T = (1 - p_d) P^- + p_d (P^- - K S K^T)` with
:math:`p_d = p_d(\mathrm{uav}_{c,j}, \mathrm{target}_{i,j})`: :math:`p_d = 0` is a
prediction only (no measurement).
"""

from __future__ import annotations

import numpy as np

from rsmhp.core import guards
from rsmhp.models.uav.sensor import SensorModel, detection_probability, measurement_cov_entries

__all__ = ["check_arguments", "covariance_traces", "objective"]


def check_arguments(
    P0: np.ndarray,
    uav_xy: np.ndarray,
    target_xy: np.ndarray,
    dt: float,
    Q: np.ndarray,
    sensor: SensorModel,
) -> None:
    """The checks of :func:`covariance_traces` (and of its compiled twin
    :func:`rsmhp.models.uav.fused.covariance_traces`): ``P0`` and ``Q`` finite symmetric positive
    semidefinite (4, 4); ``uav_xy`` (C, H, 2) and ``target_xy`` (T, H, 2) finite with
    C, T, H >= 1 and the same H; ``dt`` > 0; ``sensor`` a :class:`SensorModel`."""
    guards.spd_matrix("P0", P0, semi=True, size=4)
    uxy = guards.finite_array("uav_xy", uav_xy, shape=("C", "H", 2), nonempty=True)
    txy = guards.finite_array("target_xy", target_xy, shape=("T", "H", 2), nonempty=True)
    if txy.shape[1] != uxy.shape[1]:
        raise ValueError(
            f"target_xy must have the horizon of uav_xy (H = {uxy.shape[1]}), got shape {txy.shape}"
        )
    guards.real("dt", dt, lo=0.0, lo_open=True)
    guards.spd_matrix("Q", Q, semi=True, size=4)
    guards.instance_of("sensor", sensor, SensorModel)


def covariance_traces(
    P0: np.ndarray,
    uav_xy: np.ndarray,
    target_xy: np.ndarray,
    dt: float,
    Q: np.ndarray,
    sensor: SensorModel,
    *,
    return_cov: bool = False,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Traces ``tr P_j`` of shape (C, T, H) (see module docstring).

    ``P0`` (4, 4) is the current posterior; ``uav_xy`` (C, H, 2); ``target_xy`` (T, H, 2);
    ``Q`` (4, 4) symmetric. With ``return_cov`` also the full covariances (C, T, H, 4, 4)
    (slow path for tests). Arguments are checked by :func:`check_arguments`.
    """
    check_arguments(P0, uav_xy, target_xy, dt, Q, sensor)
    Q = np.asarray(Q, dtype=float)
    uav_xy = np.asarray(uav_xy, dtype=float)
    target_xy = np.asarray(target_xy, dtype=float)
    n_c, horizon = uav_xy.shape[:2]
    n_t = target_xy.shape[0]
    shape = (n_c, n_t)
    P0 = 0.5 * (np.asarray(P0, dtype=float) + np.asarray(P0, dtype=float).T)
    full = lambda v: np.full(shape, v)  # noqa: E731
    a11, a12, a22 = full(P0[0, 0]), full(P0[0, 1]), full(P0[1, 1])
    b11, b12, b21, b22 = full(P0[0, 2]), full(P0[0, 3]), full(P0[1, 2]), full(P0[1, 3])
    c11, c12, c22 = full(P0[2, 2]), full(P0[2, 3]), full(P0[3, 3])
    qa11, qa12, qa22 = Q[0, 0], Q[0, 1], Q[1, 1]
    qb11, qb12, qb21, qb22 = Q[0, 2], Q[0, 3], Q[1, 2], Q[1, 3]
    qc11, qc12, qc22 = Q[2, 2], Q[2, 3], Q[3, 3]
    dt2 = dt * dt
    # R for every (candidate, hypothesis, step): (C, T, H) each
    rxx, rxy, ryy = measurement_cov_entries(uav_xy[:, None, :, :], target_xy[None, :, :, :], sensor)
    # expected-update factor (C, T, H); None: every step measures (the paper's model)
    pd = (
        detection_probability(uav_xy[:, None, :, :], target_xy[None, :, :, :], sensor)
        if sensor.limited
        else None
    )
    traces = np.empty((n_c, n_t, horizon))
    covs = np.empty((n_c, n_t, horizon, 4, 4)) if return_cov else None
    for j in range(horizon):
        # predict
        pa11 = a11 + 2 * dt * b11 + dt2 * c11 + qa11
        pa12 = a12 + dt * (b12 + b21) + dt2 * c12 + qa12
        pa22 = a22 + 2 * dt * b22 + dt2 * c22 + qa22
        pb11 = b11 + dt * c11 + qb11
        pb12 = b12 + dt * c12 + qb12
        pb21 = b21 + dt * c12 + qb21
        pb22 = b22 + dt * c22 + qb22
        pc11, pc12, pc22 = c11 + qc11, c12 + qc12, c22 + qc22
        # innovation covariance and its inverse (adjugate / determinant)
        s11 = pa11 + rxx[:, :, j]
        s12 = pa12 + rxy[:, :, j]
        s22 = pa22 + ryy[:, :, j]
        inv_det = 1.0 / (s11 * s22 - s12 * s12)
        i11, i12, i22 = s22 * inv_det, -s12 * inv_det, s11 * inv_det
        # M = S^-1 A^-  (2x2), N = S^-1 B^-  (2x2)
        m11 = i11 * pa11 + i12 * pa12
        m12 = i11 * pa12 + i12 * pa22
        m21 = i12 * pa11 + i22 * pa12
        m22 = i12 * pa12 + i22 * pa22
        n11 = i11 * pb11 + i12 * pb21
        n12 = i11 * pb12 + i12 * pb22
        n21 = i12 * pb11 + i22 * pb21
        n22 = i12 * pb12 + i22 * pb22
        # update: A+ = A- - A- M = R M, B+ = B- - A- N = R N (as S - A- = R: no cancellation
        # when R is tiny next to A-), C+ = C- - B-^T N
        r11, r12, r22 = rxx[:, :, j], rxy[:, :, j], ryy[:, :, j]
        ra11 = r11 * m11 + r12 * m21
        ra12 = r11 * m12 + r12 * m22
        ra22 = r12 * m12 + r22 * m22
        rb11 = r11 * n11 + r12 * n21
        rb12 = r11 * n12 + r12 * n22
        rb21 = r12 * n11 + r22 * n21
        rb22 = r12 * n12 + r22 * n22
        if pd is None:
            a11, a12, a22 = ra11, ra12, ra22
            b11, b12, b21, b22 = rb11, rb12, rb21, rb22
            c11 = pc11 - (pb11 * n11 + pb21 * n21)
            c12 = pc12 - (pb11 * n12 + pb21 * n22)
            c22 = pc22 - (pb12 * n12 + pb22 * n22)
        else:  # expected update P- - p_d K S K^T = (1 - p_d) P- + p_d (P- - K S K^T)
            p = pd[:, :, j]
            qd = 1.0 - p
            a11, a12, a22 = qd * pa11 + p * ra11, qd * pa12 + p * ra12, qd * pa22 + p * ra22
            b11, b12 = qd * pb11 + p * rb11, qd * pb12 + p * rb12
            b21, b22 = qd * pb21 + p * rb21, qd * pb22 + p * rb22
            c11 = pc11 - p * (pb11 * n11 + pb21 * n21)
            c12 = pc12 - p * (pb11 * n12 + pb21 * n22)
            c22 = pc22 - p * (pb12 * n12 + pb22 * n22)
        traces[:, :, j] = a11 + a22 + c11 + c22
        if covs is not None:
            rows = (
                (a11, a12, b11, b12),
                (a12, a22, b21, b22),
                (b11, b21, c11, c12),
                (b12, b22, c12, c22),
            )
            for r, row in enumerate(rows):
                for col, val in enumerate(row):
                    covs[:, :, j, r, col] = val
    if return_cov:
        return traces, covs
    return traces


def objective(
    P0: np.ndarray,
    uav_xy: np.ndarray,
    target_xy: np.ndarray,
    dt: float,
    Q: np.ndarray,
    sensor: SensorModel,
    weights: np.ndarray | None = None,
) -> np.ndarray:
    r"""Cost per candidate (C,): :math:`\sum_{i=1}^T \omega_i \sum_{j=1}^H \mathrm{tr}
    P_j^{c,i}` (m² + m²/s², summed as the paper's trace), with hypothesis weights ``weights``
    (T,) summing to 1; ``None``: :math:`\omega_i = 1/T`."""
    per_hyp = covariance_traces(P0, uav_xy, target_xy, dt, Q, sensor).sum(axis=2)
    if weights is None:
        return per_hyp.mean(axis=1)
    w = guards.finite_array("weights", weights, shape=(np.shape(target_xy)[0],))
    return per_hyp @ w
