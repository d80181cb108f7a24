r"""The UAV's position sensor: target position plus range/cross-range shaped noise.

:math:`z = (p_x, p_y) + v`, :math:`v \sim \mathcal N(0, R)` with

.. math::
    R = G \,\mathrm{diag}(\sigma_r^2, \sigma_c^2)\, G^T, \qquad
    \sigma_r = f_r\, d, \quad \sigma_c = f_c\, d,

where :math:`G` is the rotation by the horizontal bearing :math:`\beta` from UAV to target
(columns: unit range direction :math:`(\cos\beta, \sin\beta)` and cross-range direction
:math:`(-\sin\beta, \cos\beta)`) and :math:`d = \sqrt{\rho^2 + h^2}` is the 3-D distance
(:math:`\rho` horizontal distance, :math:`h` altitude). Written out (symmetric, 3 entries):

.. math::
    R_{xx} = d^2 (f_r^2 c^2 + f_c^2 s^2), \quad
    R_{xy} = d^2 (f_r^2 - f_c^2)\, c s, \quad
    R_{yy} = d^2 (f_r^2 s^2 + f_c^2 c^2),

with :math:`c = \cos\beta, s = \sin\beta`. Directly overhead (:math:`\rho = 0`) the bearing is
undefined and we take :math:`\beta = 0`; since :math:`d \ge h > 0`,
:math:`\det R = f_r^2 f_c^2 d^4 > 0`: R is never singular.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["SensorModel", "measurement_cov", "measurement_cov_entries", "measurement_noise"]


@dataclass(frozen=True)
class SensorModel:
    """Noise fractions ``f_r``, ``f_c`` (per metre of distance) and UAV altitude ``h`` (m)."""

    sigma_r_per_m: float
    sigma_c_per_m: float
    altitude: float

    @classmethod
    def from_config(cls, uav: Mapping[str, Any]) -> SensorModel:
        return cls(
            sigma_r_per_m=float(uav["sensor"]["sigma_r_per_m"]),
            sigma_c_per_m=float(uav["sensor"]["sigma_c_per_m"]),
            altitude=float(uav["aircraft"]["altitude"]),
        )


def _geometry(uav_xy: np.ndarray, target_xy: np.ndarray, altitude: float):
    """(d², cos β, sin β) for broadcastable ``uav_xy``, ``target_xy`` (..., 2)."""
    dx = target_xy[..., 0] - uav_xy[..., 0]
    dy = target_xy[..., 1] - uav_xy[..., 1]
    rho2 = dx * dx + dy * dy
    rho = np.sqrt(rho2)
    flat = rho == 0.0
    safe = np.where(flat, 1.0, rho)
    c = np.where(flat, 1.0, dx / safe)
    s = np.where(flat, 0.0, dy / safe)
    return rho2 + altitude * altitude, c, s


def measurement_cov_entries(
    uav_xy: np.ndarray, target_xy: np.ndarray, sensor: SensorModel
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(R_xx, R_xy, R_yy)``, each of the broadcast shape of ``uav_xy[..., 0]`` and
    ``target_xy[..., 0]`` (m²)."""
    d2, c, s = _geometry(np.asarray(uav_xy), np.asarray(target_xy), sensor.altitude)
    fr2, fc2 = sensor.sigma_r_per_m**2, sensor.sigma_c_per_m**2
    rxx = d2 * (fr2 * c * c + fc2 * s * s)
    rxy = d2 * (fr2 - fc2) * c * s
    ryy = d2 * (fr2 * s * s + fc2 * c * c)
    return rxx, rxy, ryy


def measurement_cov(uav_xy: np.ndarray, target_xy: np.ndarray, sensor: SensorModel) -> np.ndarray:
    """R as ``(..., 2, 2)`` matrices."""
    rxx, rxy, ryy = measurement_cov_entries(uav_xy, target_xy, sensor)
    return np.stack([np.stack([rxx, rxy], -1), np.stack([rxy, ryy], -1)], -2)


def measurement_noise(
    uav_xy: np.ndarray, target_xy: np.ndarray, sensor: SensorModel, std_normal: np.ndarray
) -> np.ndarray:
    r"""Noise :math:`v = G\,\mathrm{diag}(\sigma_r, \sigma_c)\,\zeta` for a standard-normal
    ``std_normal`` :math:`\zeta` (2,), so that :math:`v \sim \mathcal N(0, R)`.

    Methods share :math:`\zeta` (paired design); :math:`v` itself depends on each method's
    geometry.
    """
    d2, c, s = _geometry(np.asarray(uav_xy), np.asarray(target_xy), sensor.altitude)
    d = np.sqrt(d2)
    sr, sc = sensor.sigma_r_per_m * d, sensor.sigma_c_per_m * d
    zr, zc = std_normal[..., 0] * sr, std_normal[..., 1] * sc
    return np.stack([c * zr - s * zc, s * zr + c * zc], axis=-1)
