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

Decisions (open-loop controls). :math:`J` is a convex quadratic in :math:`u` with Hessian
:math:`2A`, :math:`A = I + r a^2 c c^\top`, and :math:`v_H` does not depend on :math:`u`, so
NBO's cost and the exact cost have the same minimiser (certainty equivalence):

* optimum :math:`u^* = \dfrac{r a (T - b^H x_0)}{1 + r a^2 |c|^2}\, c`
* regret of any :math:`u`: :math:`J(u) - J(u^*) = (u - u^*)^\top A (u - u^*)`
* a sample-average cost :math:`\hat J(u) = \sum_i \omega_i r (x_H^i(u) - T)^2 + |u|^2`
  (noise draws :math:`w^i` held fixed, :math:`\sum_i\omega_i = 1`) is NBO's cost with the
  target moved to :math:`T - \bar e`, :math:`\bar e = \sum_i \omega_i\, c^\top w^i` (the
  weighted mean of the sampled final-state noise). Its minimiser is
  :math:`\hat u = u^* - \dfrac{r a \bar e}{1 + r a^2|c|^2}\, c` and its regret is
  :math:`\kappa\, \bar e^2` with :math:`\kappa = \dfrac{r^2 a^2 |c|^2}{1 + r a^2 |c|^2}`.
* hence, for :math:`P` i.i.d. trajectories with uniform weights,
  :math:`\bar e \sim \mathcal N(0, v_H/P)` and the regret is :math:`\kappa v_H/P` times a
  :math:`\chi^2_1` variable (mean :math:`\kappa v_H/P`); for the tree with the same
  :math:`N` draws at every node of a level (uniform weights over its :math:`N^H` leaves) every
  draw of level :math:`k` appears in the same number of leaves, so
  :math:`\bar e = \sum_k c_k \bar w_k` with :math:`\bar w_k` the mean of level k's N draws:
  regret :math:`\kappa v_H/N` times :math:`\chi^2_1`, the regret of only :math:`N`
  independent trajectories; antithetic pairs and symmetric sigma points give
  :math:`\bar e = 0`, zero regret.
* with likeliness weights :math:`\omega_i \propto \phi(w^i)` (the density of the whole
  sequence) the self-normalised :math:`\bar e` of P i.i.d. trajectories has variance
  :math:`E[\phi^2 (c^\top w)^2] / (P\, E[\phi]^2) = (4/3)^{H/2} v_H / (3P)` to first order
  in 1/P, so the mean regret is :math:`\kappa v_H (4/3)^{H/2}/(3P)`, the uniform one times
  :math:`(4/3)^{H/2}/3` (below 1, i.e. weighting helps, for :math:`H \le 7`).
* a regret that is a mean :math:`\rho` times a :math:`\chi^2_1` variable has variance
  :math:`2\rho^2`, so a mean of R independent regrets has standard error
  :math:`\rho\sqrt{2/R}`.

:class:`LQGModel` is the one definition of the problem's constants (a, r, T, σ, x_0); it is
the simulated system and gives the keyword arguments of the closed forms
(:meth:`LQGModel.closed_form_args`).
:meth:`rsmhp.models.lqg.linear_quadratic.LinearQuadratic.from_lqg`
writes it in the general linear-quadratic form.

Shared by the studies ``rsmhp.studies.decisions``, ``rsmhp.studies.horizon`` and
``rsmhp.studies.lqg`` (so it lives below them).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Self

import numpy as np

from rsmhp.core import guards
from rsmhp.core.sampling import GaussianNoise

__all__ = [
    "LQGModel",
    "chebyshev_bound",
    "coefficients",
    "cost_variance",
    "exact_cost",
    "expected_regret",
    "mhp_variance",
    "nbo_cost",
    "nbo_error",
    "optimal_controls",
    "optimal_cost",
    "regret",
    "regret_gain",
    "regret_standard_error",
    "sample_argmin",
    "state_mean",
    "state_variance",
    "weighted_expected_regret",
    "weighted_limit",
    "weighted_regret_ratio",
]


def _check(
    a: float | None = None,
    sigma: float | None = None,
    r: float | None = None,
    **finite: float | None,
) -> None:
    """Model parameters: ``a`` in (0, 1), ``sigma`` >= 0, ``r`` >= 0, and the named values
    ``finite`` (``x0``, ``target``) finite numbers; ``None`` skips a check."""
    if a is not None:
        guards.real("a", a, lo=0.0, hi=1.0, lo_open=True, hi_open=True)
    if sigma is not None:
        guards.real("sigma", sigma, lo=0.0)
    if r is not None:
        guards.real("r", r, lo=0.0)
    for name, value in finite.items():
        if value is not None:
            guards.real(name, value)


def _u(u: np.ndarray | list[float]) -> np.ndarray:
    u = np.atleast_1d(guards.finite_array("u", u))
    if u.ndim != 1 or u.size == 0:
        raise ValueError(
            f"u must be a non-empty 1-D control sequence (length H), got shape {u.shape}"
        )
    return u


def state_mean(u: np.ndarray | list[float], *, x0: float, a: float) -> float:
    r""":math:`E[x_H] = (1-a)^H x_0 + a\sum_{k=0}^{H-1}(1-a)^{H-1-k}u_k` (H = len(u))."""
    _check(a=a, x0=x0)
    u = _u(u)
    horizon = u.size
    b = 1.0 - a
    c = b ** np.arange(horizon - 1, -1, -1)
    return float(b**horizon * x0 + a * np.dot(c, u))


def state_variance(H: int, *, a: float, sigma: float) -> float:
    r""":math:`\mathrm{Var}[x_H] = \sigma^2 \sum_{n=0}^{H-1} (1-a)^{2n}`."""
    H = guards.positive_int("H", H)
    _check(a=a, sigma=sigma)
    return float(sigma**2 * np.sum((1.0 - a) ** (2 * np.arange(H))))


def nbo_cost(u: np.ndarray | list[float], *, x0: float, a: float, r: float, target: float) -> float:
    r""":math:`J_{NBO} = r(m_H - T)^2 + \sum_k u_k^2` (all noise at its mean 0)."""
    _check(a=a, r=r, x0=x0, target=target)
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
    _check(r=r, target=target)
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
    guards.int_array("P", P, minimum=1)
    P = np.asarray(P)
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
    eps = guards.finite_array("eps", eps)
    if np.any(eps <= 0):
        raise ValueError(f"eps must be > 0, got {guards.show(eps)}")
    var = mhp_variance(P, u, x0=x0, a=a, r=r, target=target, sigma=sigma)
    out = np.minimum(1.0, np.asarray(var) / eps**2)
    return float(out) if out.ndim == 0 else out


def weighted_limit(
    u: np.ndarray | list[float], *, x0: float, a: float, r: float, target: float, sigma: float
) -> float:
    r"""Limit (P -> inf) of the likeliness-weighted non-overlapping estimator: :math:`J` at
    noise variance :math:`\sigma^2/2`, i.e. :math:`J - r v_H/2`."""
    _check(sigma=sigma)
    return exact_cost(u, x0=x0, a=a, r=r, target=target, sigma=sigma / np.sqrt(2.0))


def _coefficients(H: int, a: float) -> np.ndarray:
    """:math:`c_k = (1-a)^{H-1-k}`, k = 0..H-1: weight of :math:`a u_k + w_k` in :math:`x_H`
    (unchecked: the public callers check ``H`` and ``a`` once)."""
    return (1.0 - a) ** np.arange(H - 1, -1, -1, dtype=float)


def coefficients(H: int, a: float) -> np.ndarray:
    r""":math:`c_k = (1-a)^{H-1-k}`, k = 0..H-1, shape (H,): the weight of :math:`a u_k + w_k`
    in :math:`x_H`, so that the final state's noise is :math:`c^\top w`."""
    _check(a=a)
    return _coefficients(guards.positive_int("H", H), a)


def _optimal(H: int, x0: float, a: float, r: float, target: float) -> np.ndarray:
    """:func:`optimal_controls` without the argument checks."""
    c = _coefficients(H, a)
    return r * a * (target - (1.0 - a) ** H * x0) * c / (1.0 + r * a * a * np.dot(c, c))


def optimal_controls(H: int, *, x0: float, a: float, r: float, target: float) -> np.ndarray:
    r"""Exact open-loop optimum :math:`u^* = \arg\min_u J(u)`, shape (H,):
    :math:`u^* = r a (T - b^H x_0)\, c / (1 + r a^2 |c|^2)`. NBO's cost has the same
    minimiser (it differs from J by the constant :math:`r v_H`)."""
    _check(a=a, r=r, x0=x0, target=target)
    return _optimal(guards.positive_int("H", H), x0, a, r, target)


def optimal_cost(H: int, *, x0: float, a: float, r: float, target: float, sigma: float) -> float:
    r""":math:`J(u^*)`, the exact cost of the exact optimum :func:`optimal_controls` (the
    denominator of a relative regret)."""
    kw = {"x0": x0, "a": a, "r": r, "target": target}
    return exact_cost(optimal_controls(H, **kw), **kw, sigma=sigma)


def sample_argmin(
    noise: np.ndarray, weights: np.ndarray, *, x0: float, a: float, r: float, target: float
) -> np.ndarray:
    r"""Minimiser (H,) of the sample-average cost with the draws held fixed,

    .. math:: \hat J(u) = \frac{\sum_i \omega_i\, g(u, w^i)}{\sum_i \omega_i},\qquad
        g(u, w) = r\,(x_H(u, w) - T)^2 + |u|^2,\quad
        x_H(u, w) = b^H x_0 + a\, c^\top u + c^\top w,

    for noise sequences ``noise`` (n, H) (or (n, H, 1)) and weights ``weights`` (n,) >= 0 with
    a positive sum (self-normalised: uniform 1/n, quadrature weights and likeliness weights
    summing to n all fit). With :math:`\bar e = \sum_i \omega_i c^\top w^i / \sum_i
    \omega_i` the normal equations are :math:`(I + r a^2 c c^\top)\, u = r a (T - b^H x_0 -
    \bar e)\, c`, solved directly. NBO is the single draw :math:`w = 0`."""
    _check(a=a, r=r, x0=x0, target=target)
    w = np.asarray(noise, dtype=float)
    if w.ndim == 3 and w.shape[2] == 1:
        w = w[:, :, 0]
    if w.ndim != 2 or w.shape[0] < 1 or w.shape[1] < 1:
        raise ValueError(f"noise must have shape (n, H) with n, H >= 1, got {np.shape(noise)}")
    wt = np.asarray(weights, dtype=float)
    if wt.shape != (w.shape[0],):
        raise ValueError(f"weights must have shape ({w.shape[0]},), got {wt.shape}")
    if not (np.all(np.isfinite(w)) and np.all(np.isfinite(wt))):
        raise ValueError("noise and weights must be finite")
    if np.any(wt < 0) or not wt.sum() > 0:
        raise ValueError("weights must be >= 0 with a positive sum")
    H = w.shape[1]
    c = _coefficients(H, a)
    e_bar = float(np.dot(wt, w @ c) / wt.sum())
    lhs = np.eye(H) + r * a * a * np.outer(c, c)
    rhs = r * a * (target - (1.0 - a) ** H * x0 - e_bar) * c
    return np.linalg.solve(lhs, rhs)


def regret(u: np.ndarray | list[float], *, x0: float, a: float, r: float, target: float) -> float:
    r""":math:`J(u) - J(u^*) = (u - u^*)^\top (I + r a^2 c c^\top)(u - u^*) \ge 0` (exact
    quadratic form, free of the cancellation in a difference of two costs; independent of
    :math:`\sigma`)."""
    _check(a=a, r=r, x0=x0, target=target)
    u = _u(u)
    c = _coefficients(u.size, a)
    d = u - _optimal(u.size, x0, a, r, target)
    return float(np.dot(d, d) + r * a * a * np.dot(c, d) ** 2)


def regret_gain(H: int, *, a: float, r: float) -> float:
    r""":math:`\kappa = r^2 a^2 |c|^2 / (1 + r a^2 |c|^2)`: a sample-average argmin whose
    weighted mean final-state noise is :math:`\bar e` has regret :math:`\kappa\bar e^2`."""
    _check(a=a, r=r)
    cc = float(np.dot(c := _coefficients(guards.positive_int("H", H), a), c))
    return r * r * a * a * cc / (1.0 + r * a * a * cc)


def expected_regret(n_eff: int | np.ndarray, H: int, *, a: float, r: float, sigma: float):
    r"""Mean regret :math:`\kappa v_H / n` of a sample-average argmin whose :math:`\bar e`
    averages ``n_eff`` independent final-state noises with equal weights: n = P for P i.i.d.
    trajectories, n = N for the shared-draw tree with N draws per level. The regret is this
    mean times a :math:`\chi^2_1` variable."""
    guards.int_array("n_eff", n_eff, minimum=1)
    n = np.asarray(n_eff)
    out = regret_gain(H, a=a, r=r) * state_variance(H, a=a, sigma=sigma) / n
    return float(out) if np.ndim(out) == 0 else out


def weighted_regret_ratio(H: int) -> float:
    r""":math:`(4/3)^{H/2}/3`, computed as :math:`1/(3 \cdot 0.75^{H/2})`: the first-order mean
    regret of P likeliness-weighted i.i.d. trajectories over that of P uniformly weighted ones
    (below 1 for :math:`H \le 7`: the weighting helps)."""
    H = guards.positive_int("H", H)
    return 1.0 / (3.0 * 0.75 ** (H / 2))


def weighted_expected_regret(P: int, H: int, *, a: float, r: float, sigma: float) -> float:
    r"""First-order (large P) mean regret of the sample-average argmin over P i.i.d.
    trajectories with likeliness weights: :math:`\kappa v_H (4/3)^{H/2} / (3P)`, computed as
    :math:`\kappa v_H / (3 P\, 0.75^{H/2})`."""
    P = guards.positive_int("P", P)
    return expected_regret(1, H, a=a, r=r, sigma=sigma) / (3.0 * P * 0.75 ** (H / 2))


def regret_standard_error(mean: float, R: int) -> float:
    r"""Standard error :math:`\rho\sqrt{2/R}` of the mean of ``R`` independent regrets that
    are each ``mean`` (:math:`\rho`) times a :math:`\chi^2_1` variable (variance
    :math:`2\rho^2`), as the closed forms :func:`expected_regret` and
    :func:`weighted_expected_regret` describe."""
    R = guards.positive_int("R", R)
    return mean * np.sqrt(2.0 / R)


@dataclass(frozen=True)
class LQGModel:
    """The oven problem: its constants (a, r, T = ``target``, σ, x_0) and the system as a
    vectorized :class:`rsmhp.core.sampling.System` (state dim 1).

    The one definition of the model: experiments build it from the ``lqg.model`` config
    section (:meth:`from_config`), the closed forms of this module take its
    :meth:`closed_form_args`. ``x0`` only enters the closed forms (a sampler is given the
    initial state explicitly); its default 0 is the paper's."""

    a: float
    r: float
    target: float
    sigma: float
    x0: float = 0.0

    def __post_init__(self) -> None:
        _check(a=self.a, sigma=self.sigma, r=self.r, target=self.target, x0=self.x0)
        if self.sigma == 0:
            raise ValueError("sigma must be > 0 for sampling (the noise density is undefined)")
        # built (and checked, factorised) once: samplers ask for it at every tree and rollout
        object.__setattr__(self, "_noise", GaussianNoise(self.sigma**2))

    @classmethod
    def from_config(cls, model: Mapping[str, Any], a: float | None = None) -> Self:
        """From the ``lqg.model`` config section (a, x0, r, target, sigma), every value as a
        float; ``a`` given here overrides (and makes ``model["a"]`` unnecessary)."""
        return cls(
            a=float(model["a"] if a is None else a),
            r=float(model["r"]),
            target=float(model["target"]),
            sigma=float(model["sigma"]),
            x0=float(model["x0"]),
        )

    def closed_form_args(self, *, sigma: bool = True) -> dict[str, float]:
        """Keyword arguments of the closed forms: ``x0, a, r, target`` and, unless
        ``sigma=False`` (for :func:`nbo_cost`, :func:`optimal_controls`,
        :func:`sample_argmin`, :func:`regret`, which do not depend on the noise), ``sigma``."""
        kw = {"x0": self.x0, "a": self.a, "r": self.r, "target": self.target}
        return {**kw, "sigma": self.sigma} if sigma else kw

    @property
    def noise(self) -> GaussianNoise:
        return self._noise

    def step(self, x: np.ndarray, u_k: float, w: np.ndarray) -> np.ndarray:
        """:math:`x_{k+1} = (1-a)x_k + a u_k + w_k`, shapes (n, 1)."""
        return (1.0 - self.a) * x + self.a * u_k + w

    def stage_cost(self, x: np.ndarray, u_k: float) -> np.ndarray:
        """:math:`g(x_k, u_k) = u_k^2`, shape (n,)."""
        return np.full(x.shape[0], float(u_k) ** 2)

    def terminal_cost(self, x: np.ndarray) -> np.ndarray:
        """:math:`g_H(x_H) = r (x_H - T)^2`, shape (n,)."""
        return self.r * (x[:, 0] - self.target) ** 2
