r"""UAV kinematics: a bank-to-turn aircraft at constant altitude.

State :math:`(p_x, p_y, s, \psi)` (m, m, m/s, rad), control :math:`(a, \phi)` (forward
acceleration in m/s², bank angle in rad). One step of length :math:`\Delta t`:

.. math::
    s' = \mathrm{clip}(s + a\,\Delta t,\ s_{\min}, s_{\max}), \qquad
    \psi' = \psi + \frac{g \tan\phi}{s}\,\Delta t, \qquad
    p' = p + s'\,\Delta t\,(\cos\psi', \sin\psi').

The turn rate :math:`g\tan\phi/s` uses the speed *before* the step. Controls are boxed,
:math:`|a| \le a_{\max}`, :math:`|\phi| \le \phi_{\max}`; the UAV flies at altitude ``h``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from rsmhp.core import guards

__all__ = ["UAVParams", "rollout", "step", "turn_rate"]


@dataclass(frozen=True)
class UAVParams:
    """Aircraft constants (SI units; ``bank_max`` in rad)."""

    dt: float
    g: float
    accel_max: float
    bank_max: float
    speed_min: float
    speed_max: float
    altitude: float

    def __post_init__(self) -> None:
        pos = {"lo": 0.0, "lo_open": True}
        guards.real("UAVParams.dt", self.dt, **pos)
        guards.real("UAVParams.g", self.g, **pos)
        guards.real("UAVParams.accel_max", self.accel_max, lo=0.0)
        # tan(phi) is unbounded at 90 degrees
        guards.real("UAVParams.bank_max", self.bank_max, lo=0.0, hi=math.pi / 2, hi_open=True)
        guards.real("UAVParams.speed_min", self.speed_min, **pos)  # the turn rate divides by s
        guards.real("UAVParams.speed_max", self.speed_max, **pos)
        guards.ordered(
            "UAVParams.speed_min",
            self.speed_min,
            "UAVParams.speed_max",
            self.speed_max,
            strict=False,
        )
        guards.real("UAVParams.altitude", self.altitude, **pos)

    @classmethod
    def from_config(cls, uav: Mapping[str, Any]) -> UAVParams:
        """From the ``uav`` config section (``dt``, ``g`` and ``aircraft``)."""
        ac = uav["aircraft"]
        return cls(
            dt=float(uav["dt"]),
            g=float(uav["g"]),
            accel_max=float(ac["accel_max"]),
            bank_max=math.radians(float(ac["bank_max_deg"])),
            speed_min=float(ac["speed_min"]),
            speed_max=float(ac["speed_max"]),
            altitude=float(ac["altitude"]),
        )

    @property
    def control_scale(self) -> np.ndarray:
        """``(a_max, phi_max)``: controls are ``scale * x`` with ``x`` in ``[-1, 1]^2``."""
        return np.array([self.accel_max, self.bank_max])


def turn_rate(speed: np.ndarray | float, bank: np.ndarray | float, g: float) -> np.ndarray:
    r"""Coordinated-turn rate :math:`\dot\psi = g \tan\phi / s` (rad/s); ``speed`` > 0,
    ``|bank|`` < 90 degrees, ``g`` > 0."""
    guards.real("g", g, lo=0.0, lo_open=True)
    speed = guards.finite_array("speed", speed)
    bank = guards.finite_array("bank", bank)
    if np.any(speed <= 0):
        raise ValueError(
            f"speed must be > 0 (the turn rate divides by it), got {guards.show(speed)}"
        )
    if np.any(np.abs(bank) >= math.pi / 2):
        raise ValueError(
            f"bank must lie in the open interval (-pi/2, pi/2), got {guards.show(bank)}"
        )
    return _turn_rate(speed, bank, g)


def _turn_rate(speed, bank, g):
    return g * np.tan(bank) / speed


def step(state: np.ndarray, control: np.ndarray, params: UAVParams) -> np.ndarray:
    """One kinematic step for a batch: ``state`` (..., 4), ``control`` (..., 2) -> (..., 4).

    Controls outside the box are clipped to it (the optimiser never proposes them).
    Checked: ``params`` is a :class:`UAVParams`, the last axes have 4 and 2 entries (values
    are not checked: the function is elementwise, NaN stays NaN).
    """
    guards.instance_of("params", params, UAVParams)
    state = np.asarray(state, dtype=float)
    control = np.asarray(control, dtype=float)
    if state.ndim == 0 or state.shape[-1] != 4:
        raise ValueError(f"state must have shape (..., 4), got {state.shape}")
    if control.ndim == 0 or control.shape[-1] != 2:
        raise ValueError(f"control must have shape (..., 2), got {control.shape}")
    return _step(state, control, params)


def _step(state: np.ndarray, control: np.ndarray, params: UAVParams) -> np.ndarray:
    """:func:`step` without checks (float arrays)."""
    accel = np.clip(control[..., 0], -params.accel_max, params.accel_max)
    bank = np.clip(control[..., 1], -params.bank_max, params.bank_max)
    speed, heading = state[..., 2], state[..., 3]
    new_speed = np.clip(speed + accel * params.dt, params.speed_min, params.speed_max)
    new_heading = heading + _turn_rate(speed, bank, params.g) * params.dt
    px = state[..., 0] + new_speed * params.dt * np.cos(new_heading)
    py = state[..., 1] + new_speed * params.dt * np.sin(new_heading)
    return np.stack([px, py, new_speed, new_heading], axis=-1)


def rollout(state: np.ndarray, controls: np.ndarray, params: UAVParams) -> np.ndarray:
    """States after each of ``H`` controls: ``state`` (4,) or (..., 4), ``controls``
    (..., H, 2) -> (..., H, 4); entry ``j`` is the state after applying ``controls[..., j, :]``."""
    guards.instance_of("params", params, UAVParams)
    controls = guards.finite_array("controls", controls)
    if controls.ndim < 2 or controls.shape[-1] != 2 or controls.shape[-2] < 1:
        raise ValueError(f"controls must have shape (..., H, 2) with H >= 1, got {controls.shape}")
    state = guards.finite_array("state", state)
    if state.ndim == 0 or state.shape[-1] != 4:
        raise ValueError(f"state must have shape (4,) or (..., 4), got {state.shape}")
    if np.any(state[..., 2] <= 0):
        raise ValueError(
            f"state speed state[..., 2] must be > 0 (the turn rate divides by it), got "
            f"{guards.show(state[..., 2])}"
        )
    horizon = controls.shape[-2]
    cur = np.broadcast_to(state, (*controls.shape[:-2], 4))
    out = np.empty((*controls.shape[:-1], 4))
    for j in range(horizon):
        cur = _step(cur, controls[..., j, :], params)
        out[..., j, :] = cur
    return out
