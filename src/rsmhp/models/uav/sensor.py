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

Model variants (beyond the paper's model; the defaults reproduce it exactly):

* **noise growth** ``quadratic``: :math:`\sigma_r = f_r d^2 / d_0`, :math:`\sigma_c = f_c d^2 /
  d_0` (equal to the linear model at the reference distance :math:`d_0`), i.e. the factor
  :math:`d^2` in R becomes :math:`d^4 / d_0^2`.
* **footprint**: a horizontal radius :math:`\rho_0` outside which the sensor sees nothing.
  The truth simulation (``detection``) either detects exactly when :math:`\rho \le \rho_0`
  (``hard``) or with probability :math:`p_d(\rho)` (``logistic``). The planner always uses
  the smooth detection probability
  :math:`p_d(\rho) = 1 / (1 + e^{(\rho - \rho_0)/w})` (width w in m) and the expected
  update :math:`P^+ = P^- - p_d\, K S K^T` (:mod:`rsmhp.models.uav.kernel`): exact for the expected
  covariance of one step, and differentiable in the UAV position, whereas a hard footprint
  makes every hypothesis's cost a step function of the controls (zero gradient almost
  everywhere). Without a footprint (:math:`\rho_0 = \infty`) :math:`p_d = 1`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from rsmhp.core import guards

__all__ = [
    "GROWTHS",
    "SensorModel",
    "detected",
    "detection_probability",
    "measurement_cov",
    "measurement_cov_entries",
    "measurement_noise",
]

GROWTHS = ("linear", "quadratic")
DETECTIONS = ("hard", "logistic")


@dataclass(frozen=True)
class SensorModel:
    """Noise fractions ``f_r``, ``f_c`` (per metre of distance) and UAV altitude ``h`` (m);
    optional variants: noise growth (``linear`` or ``quadratic`` with reference distance
    ``reference_distance`` :math:`d_0`, m), footprint radius :math:`\rho_0` (m, ``inf`` =
    unlimited) with planner width ``footprint_width`` w (m) and truth ``detection`` model."""

    sigma_r_per_m: float
    sigma_c_per_m: float
    altitude: float
    noise_growth: str = "linear"
    reference_distance: float = 100.0
    footprint_radius: float = float("inf")
    footprint_width: float = 10.0
    detection: str = "hard"

    def __post_init__(self) -> None:
        for name in ("sigma_r_per_m", "sigma_c_per_m", "altitude", "reference_distance"):
            guards.real(f"SensorModel.{name}", getattr(self, name), lo=0.0, lo_open=True)
        guards.one_of("SensorModel.noise_growth", self.noise_growth, GROWTHS)
        guards.one_of("SensorModel.detection", self.detection, DETECTIONS)
        # inf: unlimited
        guards.real(
            "SensorModel.footprint_radius",
            self.footprint_radius,
            lo=0.0,
            lo_open=True,
            finite=False,
        )
        guards.real("SensorModel.footprint_width", self.footprint_width, lo=0.0, lo_open=True)

    @property
    def limited(self) -> bool:
        """Whether the sensor has a finite footprint."""
        return bool(np.isfinite(self.footprint_radius))

    @classmethod
    def from_config(cls, uav: Mapping[str, Any]) -> SensorModel:
        sen = uav["sensor"]
        radius = sen.get("footprint_radius")
        return cls(
            sigma_r_per_m=float(sen["sigma_r_per_m"]),
            sigma_c_per_m=float(sen["sigma_c_per_m"]),
            altitude=float(uav["aircraft"]["altitude"]),
            noise_growth=str(sen.get("noise_growth", "linear")),
            reference_distance=float(sen.get("reference_distance", 100.0)),
            footprint_radius=float("inf") if radius is None else float(radius),
            footprint_width=float(sen.get("footprint_width", 10.0)),
            detection=str(sen.get("detection", "hard")),
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


def _check_xy(
    sensor: SensorModel,
    uav_xy: np.ndarray,
    target_xy: np.ndarray,
    std_normal: np.ndarray | None = None,
) -> None:
    """Cheap checks of the geometry helpers' arguments (once per call, no pass over the
    values: the helpers are elementwise, so NaN stays NaN): ``sensor`` is a
    :class:`SensorModel` and every array has a last axis of 2 entries."""
    if not isinstance(sensor, SensorModel):
        guards.instance_of("sensor", sensor, SensorModel)
    for name, a in (("uav_xy", uav_xy), ("target_xy", target_xy), ("std_normal", std_normal)):
        if a is None and name == "std_normal":
            continue
        shape = a.shape if isinstance(a, np.ndarray) else np.shape(a)
        if not shape or shape[-1] != 2:
            raise ValueError(f"{name} must have shape (..., 2), got {shape}")


def measurement_cov_entries(
    uav_xy: np.ndarray, target_xy: np.ndarray, sensor: SensorModel
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(R_xx, R_xy, R_yy)``, each of the broadcast shape of ``uav_xy[..., 0]`` and
    ``target_xy[..., 0]`` (m²)."""
    _check_xy(sensor, uav_xy, target_xy)
    return _measurement_cov_entries(uav_xy, target_xy, sensor)


def _measurement_cov_entries(
    uav_xy: np.ndarray, target_xy: np.ndarray, sensor: SensorModel
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    d2, c, s = _geometry(np.asarray(uav_xy), np.asarray(target_xy), sensor.altitude)
    fr2, fc2 = sensor.sigma_r_per_m**2, sensor.sigma_c_per_m**2
    if sensor.noise_growth == "quadratic":
        d2 = d2 * d2 / sensor.reference_distance**2  # the factor d^2 of R becomes d^4 / d0^2
    rxx = d2 * (fr2 * c * c + fc2 * s * s)
    rxy = d2 * (fr2 - fc2) * c * s
    ryy = d2 * (fr2 * s * s + fc2 * c * c)
    return rxx, rxy, ryy


def measurement_cov(uav_xy: np.ndarray, target_xy: np.ndarray, sensor: SensorModel) -> np.ndarray:
    """R as ``(..., 2, 2)`` matrices."""
    _check_xy(sensor, uav_xy, target_xy)
    rxx, rxy, ryy = _measurement_cov_entries(uav_xy, target_xy, sensor)
    return np.stack([np.stack([rxx, rxy], -1), np.stack([rxy, ryy], -1)], -2)


def measurement_noise(
    uav_xy: np.ndarray, target_xy: np.ndarray, sensor: SensorModel, std_normal: np.ndarray
) -> np.ndarray:
    r"""Noise :math:`v = G\,\mathrm{diag}(\sigma_r, \sigma_c)\,\zeta` for a standard-normal
    ``std_normal`` :math:`\zeta` (2,), so that :math:`v \sim \mathcal N(0, R)`.

    Methods share :math:`\zeta` (paired design); :math:`v` itself depends on each method's
    geometry.
    """
    _check_xy(sensor, uav_xy, target_xy, std_normal)
    d2, c, s = _geometry(np.asarray(uav_xy), np.asarray(target_xy), sensor.altitude)
    d = np.sqrt(d2)
    if sensor.noise_growth == "quadratic":
        d = d2 / sensor.reference_distance
    sr, sc = sensor.sigma_r_per_m * d, sensor.sigma_c_per_m * d
    zr, zc = std_normal[..., 0] * sr, std_normal[..., 1] * sc
    return np.stack([c * zr - s * zc, s * zr + c * zc], axis=-1)


def detection_probability(
    uav_xy: np.ndarray, target_xy: np.ndarray, sensor: SensorModel
) -> np.ndarray:
    r"""The planner's :math:`p_d = 1/(1 + e^{(\rho - \rho_0)/w})` (broadcast shape of the
    positions' leading axes); 1 without a footprint."""
    _check_xy(sensor, uav_xy, target_xy)
    return _detection_probability(uav_xy, target_xy, sensor)


def _detection_probability(
    uav_xy: np.ndarray, target_xy: np.ndarray, sensor: SensorModel
) -> np.ndarray:
    uav_xy, target_xy = np.asarray(uav_xy, dtype=float), np.asarray(target_xy, dtype=float)
    rho = np.hypot(target_xy[..., 0] - uav_xy[..., 0], target_xy[..., 1] - uav_xy[..., 1])
    if not sensor.limited:
        return np.ones_like(rho)
    with np.errstate(over="ignore"):
        return 1.0 / (1.0 + np.exp((rho - sensor.footprint_radius) / sensor.footprint_width))


def detected(uav_xy: np.ndarray, target_xy: np.ndarray, sensor: SensorModel, u: float) -> bool:
    """Whether the truth simulation gets a measurement: always without a footprint; with one,
    ``rho <= rho_0`` (``hard``) or ``u < p_d(rho)`` for a uniform ``u`` (``logistic``)."""
    _check_xy(sensor, uav_xy, target_xy)
    if np.shape(uav_xy) != (2,) or np.shape(target_xy) != (2,):
        raise ValueError(
            f"uav_xy and target_xy must have shape (2,) (one position each), got "
            f"{np.shape(uav_xy)} and {np.shape(target_xy)}"
        )
    if not sensor.limited:
        return True
    if sensor.detection == "hard":
        rho = float(np.hypot(target_xy[0] - uav_xy[0], target_xy[1] - uav_xy[1]))
        return rho <= sensor.footprint_radius
    guards.probability("u", u)
    return bool(u < float(_detection_probability(uav_xy, target_xy, sensor)))
