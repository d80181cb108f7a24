r"""Scalar LQG "oven" case study (paper Section III-A) and its closed forms.

Model
-----
.. math::

    x_{k+1} = (1-a) x_k + a u_k + w_k,\qquad w_k \sim \mathcal N(0, \sigma^2),\qquad 0<a<1,

    J(u) = E\Big[ r (x_H - T)^2 + \sum_{k=0}^{H-1} u_k^2 \Big].

Closed forms (all exact, used as test oracles). Write :math:`b = 1-a` and
:math:`c_k = b^{H-1-k}`, so that :math:`x_H = b^H x_0 + \sum_k c_k (a u_k + w_k)`:

* mean of the final state   :math:`m_H = b^H x_0 + a \sum_k c_k u_k`
* variance of the final state :math:`v_H = \sigma^2 \sum_{n=0}^{H-1} b^{2n}`
* exact cost   :math:`J = r[(m_H - T)^2 + v_H] + \sum_k u_k^2`
* NBO cost     :math:`J_{NBO} = r (m_H - T)^2 + \sum_k u_k^2`
* NBO error    :math:`J - J_{NBO} = r v_H = r\sigma^2\sum_{n=0}^{H-1}(1-a)^{2n}` (paper's formula)
* per-trajectory cost variance: with :math:`\mu = m_H - T`, :math:`x_H - T \sim \mathcal N(\mu,
  v_H)` and :math:`\mathrm{Var}[(x_H-T)^2] = 2 v_H^2 + 4\mu^2 v_H`, so
  :math:`\mathrm{Var}(g) = r^2 (2 v_H^2 + 4 \mu^2 v_H)`
* variance of the P-sample uniform (non-overlapping) estimator: :math:`\mathrm{Var}(g)/P`
* Chebyshev bound (Prop. 3): :math:`P(|J_P - J| \ge \epsilon) \le \mathrm{Var}(g)/(P\epsilon^2)`
* limit of the likeliness-weighted non-overlapping estimator: weighting each draw by its density
  :math:`\phi_\sigma(w)` tilts :math:`\mathcal N(0,\sigma^2)` to :math:`\phi_\sigma^2 \propto
  \mathcal N(0, \sigma^2/2)`, so the weighted average converges to :math:`J` evaluated at
  :math:`\sigma^2/2`, i.e. :math:`J - r v_H / 2` (not to :math:`J`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rsmhp.sampling import GaussianNoise

__all__ = [
    "LQGModel",
    "chebyshev_bound",
    "cost_variance",
    "exact_cost",
    "mhp_variance",
    "nbo_cost",
    "nbo_error",
    "state_mean",
    "state_variance",
    "weighted_limit",
]


def _check(a: float | None = None, sigma: float | None = None, r: float | None = None) -> None:
    if a is not None and not 0.0 < a < 1.0:
        raise ValueError(f"a must lie in the open interval (0, 1), got {a}")
    if sigma is not None and not sigma >= 0.0:
        raise ValueError(f"sigma must be >= 0, got {sigma}")
    if r is not None and not r >= 0.0:
        raise ValueError(f"r must be >= 0, got {r}")


def _u(u: np.ndarray | list[float]) -> np.ndarray:
    u = np.atleast_1d(np.asarray(u, dtype=float))
    if u.ndim != 1 or u.size == 0:
        raise ValueError("u must be a non-empty 1-D control sequence (length H)")
    return u


def state_mean(u: np.ndarray | list[float], *, x0: float, a: float) -> float:
    r""":math:`E[x_H] = (1-a)^H x_0 + a\sum_{k=0}^{H-1}(1-a)^{H-1-k}u_k` (H = len(u))."""
    _check(a=a)
    u = _u(u)
    horizon = u.size
    b = 1.0 - a
    c = b ** np.arange(horizon - 1, -1, -1)
    return float(b**horizon * x0 + a * np.dot(c, u))


def state_variance(H: int, *, a: float, sigma: float) -> float:
    r""":math:`\mathrm{Var}[x_H] = \sigma^2 \sum_{n=0}^{H-1} (1-a)^{2n}`."""
    _check(a=a, sigma=sigma)
    if H < 1:
        raise ValueError(f"H must be >= 1, got {H}")
    return float(sigma**2 * np.sum((1.0 - a) ** (2 * np.arange(H))))


def nbo_cost(u: np.ndarray | list[float], *, x0: float, a: float, r: float, target: float) -> float:
    r""":math:`J_{NBO} = r(m_H - T)^2 + \sum_k u_k^2` (all noise at its mean 0)."""
    _check(a=a, r=r)
    u = _u(u)
    return float(r * (state_mean(u, x0=x0, a=a) - target) ** 2 + np.dot(u, u))


def exact_cost(
    u: np.ndarray | list[float], *, x0: float, a: float, r: float, target: float, sigma: float
) -> float:
    r""":math:`J = r[(m_H - T)^2 + v_H] + \sum_k u_k^2`."""
    u = _u(u)
    return nbo_cost(u, x0=x0, a=a, r=r, target=target) + nbo_error(u.size, a=a, r=r, sigma=sigma)


def nbo_error(H: int, *, a: float, r: float, sigma: float) -> float:
    r""":math:`|J_{NBO} - J| = r\sigma^2\sum_{n=0}^{H-1}(1-a)^{2n}` (independent of u and x0)."""
    _check(r=r)
    return r * state_variance(H, a=a, sigma=sigma)


def cost_variance(
    u: np.ndarray | list[float], *, x0: float, a: float, r: float, target: float, sigma: float
) -> float:
    r"""Variance of one trajectory's cost, :math:`r^2(2v_H^2 + 4\mu^2 v_H)`, :math:`\mu=m_H-T`."""
    u = _u(u)
    mu = state_mean(u, x0=x0, a=a) - target
    v = state_variance(u.size, a=a, sigma=sigma)
    return float(r**2 * (2 * v**2 + 4 * mu**2 * v))


def mhp_variance(
    P: int | np.ndarray,
    u: np.ndarray | list[float],
    *,
    x0: float,
    a: float,
    r: float,
    target: float,
    sigma: float,
) -> float | np.ndarray:
    r"""Variance of the uniform estimator from ``P`` non-overlapping trajectories:
    :math:`\mathrm{Var}(g)/P`."""
    P = np.asarray(P)
    if np.any(P < 1):
        raise ValueError("P must be >= 1")
    out = cost_variance(u, x0=x0, a=a, r=r, target=target, sigma=sigma) / P
    return float(out) if out.ndim == 0 else out


def chebyshev_bound(
    P: int | np.ndarray,
    eps: float | np.ndarray,
    u: np.ndarray | list[float],
    *,
    x0: float,
    a: float,
    r: float,
    target: float,
    sigma: float,
) -> float | np.ndarray:
    r"""Prop. 3: :math:`\min\{1, \mathrm{Var}(g)/(P\epsilon^2)\}` bounds
    :math:`P(|J_P - J| \ge \epsilon)`."""
    eps = np.asarray(eps, dtype=float)
    if np.any(eps <= 0):
        raise ValueError("eps must be > 0")
    var = mhp_variance(P, u, x0=x0, a=a, r=r, target=target, sigma=sigma)
    out = np.minimum(1.0, np.asarray(var) / eps**2)
    return float(out) if out.ndim == 0 else out


def weighted_limit(
    u: np.ndarray | list[float], *, x0: float, a: float, r: float, target: float, sigma: float
) -> float:
    r"""Limit (P -> inf) of the likeliness-weighted non-overlapping estimator: :math:`J` at
    noise variance :math:`\sigma^2/2`, i.e. :math:`J - r v_H/2`."""
    return exact_cost(u, x0=x0, a=a, r=r, target=target, sigma=sigma / np.sqrt(2.0))


@dataclass(frozen=True)
class LQGModel:
    """The oven system as a vectorized :class:`rsmhp.sampling.System` (state dim 1)."""

    a: float
    r: float
    target: float
    sigma: float

    def __post_init__(self) -> None:
        _check(a=self.a, sigma=self.sigma, r=self.r)
        if self.sigma == 0:
            raise ValueError("sigma must be > 0 for sampling (the noise density is undefined)")

    @property
    def noise(self) -> GaussianNoise:
        return GaussianNoise(self.sigma**2)

    def step(self, x: np.ndarray, u_k: float, w: np.ndarray) -> np.ndarray:
        """:math:`x_{k+1} = (1-a)x_k + a u_k + w_k`, shapes (n, 1)."""
        return (1.0 - self.a) * x + self.a * u_k + w

    def stage_cost(self, x: np.ndarray, u_k: float) -> np.ndarray:
        """:math:`g(x_k, u_k) = u_k^2`, shape (n,)."""
        return np.full(x.shape[0], float(u_k) ** 2)

    def terminal_cost(self, x: np.ndarray) -> np.ndarray:
        """:math:`g_H(x_H) = r (x_H - T)^2`, shape (n,)."""
        return self.r * (x[:, 0] - self.target) ** 2
