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
    r"""Coordinated-turn rate :math:`\dot\psi = g \tan\phi / s` (rad/s)."""
    return g * np.tan(bank) / speed


def step(state: np.ndarray, control: np.ndarray, params: UAVParams) -> np.ndarray:
    """One kinematic step for a batch: ``state`` (..., 4), ``control`` (..., 2) -> (..., 4).

    Controls outside the box are clipped to it (the optimiser never proposes them).
    """
    state = np.asarray(state, dtype=float)
    control = np.asarray(control, dtype=float)
    accel = np.clip(control[..., 0], -params.accel_max, params.accel_max)
    bank = np.clip(control[..., 1], -params.bank_max, params.bank_max)
    speed, heading = state[..., 2], state[..., 3]
    new_speed = np.clip(speed + accel * params.dt, params.speed_min, params.speed_max)
    new_heading = heading + turn_rate(speed, bank, params.g) * params.dt
    px = state[..., 0] + new_speed * params.dt * np.cos(new_heading)
    py = state[..., 1] + new_speed * params.dt * np.sin(new_heading)
    return np.stack([px, py, new_speed, new_heading], axis=-1)


def rollout(state: np.ndarray, controls: np.ndarray, params: UAVParams) -> np.ndarray:
    """States after each of ``H`` controls: ``state`` (4,) or (..., 4), ``controls``
    (..., H, 2) -> (..., H, 4); entry ``j`` is the state after applying ``controls[..., j, :]``."""
    controls = np.asarray(controls, dtype=float)
    horizon = controls.shape[-2]
    cur = np.broadcast_to(np.asarray(state, dtype=float), (*controls.shape[:-2], 4))
    out = np.empty((*controls.shape[:-1], 4))
    for j in range(horizon):
        cur = step(cur, controls[..., j, :], params)
        out[..., j, :] = cur
    return out
