r"""The target tracker's reference implementation: a linear Kalman filter (filterpy) on the
NCV model.

Predict with :math:`F, Q` (:mod:`rsmhp.models.uav.target`); update with :math:`H = [I_2\ 0]` and the
geometry-dependent :math:`R` (:mod:`rsmhp.models.uav.sensor`) evaluated by the caller at the
tracker's
*predicted* target position (the true geometry is unknown to the tracker). filterpy updates the
covariance in Joseph form, :math:`P^+ = (I-KH)P^-(I-KH)^T + K R K^T`.

The closed loop runs the same filter compiled into its step (:mod:`rsmhp.models.uav.stepper`: a
filterpy call per step cost more than an NBO planning step); this class is the oracle that
step is tested against, step by step (``tests/models/uav/test_uav_stepper.py``).
"""

from __future__ import annotations

import numpy as np
from filterpy.kalman import KalmanFilter

from rsmhp.core import guards
from rsmhp.models.uav.target import TargetModel

__all__ = ["MEASUREMENT_MATRIX", "Tracker"]

MEASUREMENT_MATRIX = np.hstack([np.eye(2), np.zeros((2, 2))])


class Tracker:
    """Thin wrapper: state ``x`` (4,), covariance ``P`` (4, 4), ``predict()``, ``update(z, R)``.

    ``x0`` finite (4,), ``P0`` finite symmetric positive semidefinite (4, 4)."""

    def __init__(self, x0: np.ndarray, P0: np.ndarray, model: TargetModel) -> None:
        guards.finite_array("x0", x0, shape=(4,))
        guards.spd_matrix("P0", P0, semi=True, size=4)
        guards.instance_of("model", model, TargetModel)
        kf = KalmanFilter(dim_x=4, dim_z=2)
        kf.F = model.F
        kf.Q = model.Q
        kf.H = MEASUREMENT_MATRIX.copy()
        kf.x = np.asarray(x0, dtype=float).reshape(4, 1).copy()
        kf.P = np.asarray(P0, dtype=float).copy()
        self.kf = kf

    @property
    def x(self) -> np.ndarray:
        return self.kf.x[:, 0].copy()

    @property
    def P(self) -> np.ndarray:
        return self.kf.P.copy()

    def predict(self) -> None:
        self.kf.predict()

    def update(self, z: np.ndarray, R: np.ndarray, *, check: bool = True) -> None:
        """Measurement update; ``z`` (2,) is passed to filterpy as a (2, 1) column. ``z`` must
        be finite with 2 entries and ``R`` finite symmetric positive semidefinite (2, 2)
        (``check=False`` skips this, for a caller that builds them itself)."""
        if check:
            zz = guards.finite_array("z", z)
            if zz.size != 2:
                raise ValueError(f"z must have 2 entries (a position), got shape {zz.shape}")
            guards.spd_matrix("R", R, semi=True, size=2)
        self.kf.update(np.asarray(z, dtype=float).reshape(2, 1), R=np.asarray(R, dtype=float))
