r"""The oven LQG at long horizons: limits as H grows and the horizon at which the optimal first
control stops depending on H (closed forms; :mod:`rsmhp.models.lqg.oven` has the model). The
long-horizon study's own (no other study uses it; until version 5 ``rsmhp.models.lqg.horizon``).

With :math:`b = 1-a` and :math:`S_H = \sum_{n=0}^{H-1} b^{2n} = (1-b^{2H})/(1-b^2)`:

* **NBO's error** :math:`r v_H = r\sigma^2 S_H` grows with H to the limit
  :math:`r\sigma^2/(1-b^2)` (:func:`nbo_error_limit`); its relative gap to the limit is
  :math:`b^{2H}`.
* **Monte Carlo's decision regret** (:func:`rsmhp.models.lqg.oven.expected_regret`, the
sample-average
  argmin over P independent sequences) :math:`\kappa_H v_H / P` with :math:`\kappa_H = r^2
  a^2 S_H / (1 + r a^2 S_H)` and :math:`v_H = \sigma^2 S_H` tends to
  :math:`\kappa_\infty v_\infty / P` with :math:`S_\infty = 1/(1-b^2)`
  (:func:`mc_regret_limit`); with likeliness weights the first-order regret carries an
  extra :math:`(4/3)^{H/2}/3` and has no limit.
* **The paper's problem** (terminal cost :math:`r(x_H-T)^2 + \sum u_k^2`). Its optimal first
  control is :math:`u_0 = L_H (T - b^H x_0)` with :math:`L_H = r a b^{H-1}/(1 + r a^2 S_H)`
  (:func:`first_control_gain`; the open-loop optimum is also the first control of the
  feedback optimum, by certainty equivalence). :math:`L_H \to 0` like :math:`b^{H-1}`: the
  stationary first control of this problem is *no control*, and the optimal sequence
  :math:`u_k \propto b^{H-1-k}` is never independent of k (it depends on the time to go).
  The paper's definition of a long horizon (an approximately stationary optimal policy) is met
  only in this degenerate sense; :func:`vanishing_horizon` is the first H at which the
  first control's gain :math:`L_H \le \epsilon L_1` (the control itself also scales with
  :math:`T - b^H x_0`; for :math:`x_0 = 0` the two coincide).
* **A stage-cost variant** (beyond the paper: :math:`\sum_{k<H} r(x_k - T)^2 + u_k^2 + r(x_H -
  T)^2`, the textbook regulator). Its Riccati recursion :math:`P_H = r`,
  :math:`P_k = r + b^2 P_{k+1} - (a b P_{k+1})^2 / (1 + a^2 P_{k+1})` gives the first-step
  feedback gain :math:`K_H = a b P_1 / (1 + a^2 P_1)` (:func:`stage_cost_gains`; ``P_1``
  after H − 1 steps back), converging to the stationary gain :math:`K_\infty` of the
  algebraic Riccati equation :math:`P = r + b^2 P - (abP)^2/(1 + a^2 P)`
  (:func:`stationary_gain`); :func:`stationary_horizon` is the first H with
  :math:`|K_H - K_\infty| \le \epsilon K_\infty`.
"""

from __future__ import annotations

import numpy as np

from rsmhp.core import guards

__all__ = [
    "first_control_gain",
    "mc_regret_limit",
    "nbo_error_limit",
    "stage_cost_gains",
    "stationary_gain",
    "stationary_horizon",
    "vanishing_horizon",
]


def _ab(a: float) -> tuple[float, float]:
    a = guards.real("a", a, lo=0.0, hi=1.0, lo_open=True, hi_open=True)
    return a, 1.0 - a


def nbo_error_limit(*, a: float, r: float, sigma: float) -> float:
    r""":math:`\lim_{H\to\infty} r v_H = r\sigma^2/(1-(1-a)^2)`."""
    a, b = _ab(a)
    r = guards.real("r", r, lo=0.0, lo_open=True)
    sigma = guards.real("sigma", sigma, lo=0.0)
    return r * sigma**2 / (1.0 - b * b)


def mc_regret_limit(P: int, *, a: float, r: float, sigma: float) -> float:
    r""":math:`\lim_{H\to\infty} \kappa_H v_H / P = r^2 a^2 \sigma^2 S_\infty^2 / ((1 + r a^2
    S_\infty) P)`, :math:`S_\infty = 1/(1-(1-a)^2)`: the mean regret of uniform Monte Carlo
    with P trajectories at long horizons."""
    a, b = _ab(a)
    r = guards.real("r", r, lo=0.0, lo_open=True)
    sigma = guards.real("sigma", sigma, lo=0.0)
    P = guards.positive_int("P", P)
    S = 1.0 / (1.0 - b * b)
    return r * r * a * a * sigma**2 * S * S / ((1.0 + r * a * a * S) * P)


def first_control_gain(H: int | np.ndarray, *, a: float, r: float) -> float | np.ndarray:
    r""":math:`L_H = r a b^{H-1} / (1 + r a^2 S_H)`: the optimal first control of the
    H-step problem is :math:`L_H (T - b^H x_0)`. Vectorised over ``H`` (integers >= 1)."""
    a, b = _ab(a)
    r = guards.real("r", r, lo=0.0, lo_open=True)
    Hs = np.asarray(H)
    if not np.issubdtype(Hs.dtype, np.integer) or (Hs < 1).any():
        raise ValueError(f"H must be integers >= 1, got {H!r}")
    S = (1.0 - b ** (2.0 * Hs)) / (1.0 - b * b)
    out = r * a * b ** (Hs - 1.0) / (1.0 + r * a * a * S)
    return float(out) if np.ndim(out) == 0 else out


def vanishing_horizon(*, a: float, r: float, eps: float = 0.01, max_h: int = 10_000) -> int:
    r"""First H with :math:`L_H \le \epsilon L_1` (the first control no longer matters)."""
    eps = guards.real("eps", eps, lo=0.0, hi=1.0, lo_open=True, hi_open=True)
    Hs = np.arange(1, guards.positive_int("max_h", max_h) + 1)
    L = first_control_gain(Hs, a=a, r=r)
    hit = np.flatnonzero(L <= eps * L[0])
    if not hit.size:
        raise ValueError(f"L_H stays above {eps} L_1 up to H = {max_h}")
    return int(Hs[hit[0]])


def stage_cost_gains(H: int, *, a: float, r: float) -> np.ndarray:
    r""":math:`K_1, \dots, K_H` (shape (H,)): the first-step feedback gain of the stage-cost
    variant for horizons 1..H (module docstring), from one Riccati recursion."""
    a, b = _ab(a)
    r = guards.real("r", r, lo=0.0, lo_open=True)
    H = guards.positive_int("H", H)
    out = np.empty(H)
    P = r  # terminal weight
    for h in range(H):
        out[h] = a * b * P / (1.0 + a * a * P)
        P = r + b * b * P - (a * b * P) ** 2 / (1.0 + a * a * P)
    return out


def stationary_gain(*, a: float, r: float) -> float:
    r""":math:`K_\infty = abP/(1+a^2P)` with P the positive root of the scalar algebraic
    Riccati equation :math:`P = r + b^2P - (abP)^2/(1+a^2P)`, i.e. of
    :math:`a^2 P^2 + (1 - b^2 - r a^2) P - r = 0`."""
    a, b = _ab(a)
    r = guards.real("r", r, lo=0.0, lo_open=True)
    A, B, C = a * a, 1.0 - b * b - r * a * a, -r
    P = (-B + np.sqrt(B * B - 4.0 * A * C)) / (2.0 * A)
    return float(a * b * P / (1.0 + a * a * P))


def stationary_horizon(*, a: float, r: float, eps: float = 0.01, max_h: int = 10_000) -> int:
    r"""First H with :math:`|K_H - K_\infty| \le \epsilon K_\infty` (stage-cost variant)."""
    eps = guards.real("eps", eps, lo=0.0, hi=1.0, lo_open=True, hi_open=True)
    K = stage_cost_gains(guards.positive_int("max_h", max_h), a=a, r=r)
    k_inf = stationary_gain(a=a, r=r)
    hit = np.flatnonzero(np.abs(K - k_inf) <= eps * k_inf)
    if not hit.size:
        raise ValueError(f"K_H stays outside {eps} K_inf up to H = {max_h}")
    return int(hit[0] + 1)
