r"""Linear-Gaussian systems with quadratic cost, and exact oracles for every estimator.

Model
-----
.. math::

    x_{k+1} = A x_k + B u_k + w_k,\quad w_k \sim \mathcal N(0, \Sigma),\quad k = 0..H-1,

    g = \sum_{k=0}^{H-1} \big(x_k^\top Q x_k + u_k^\top R u_k\big) + (x_H - t)^\top Q_f (x_H - t).

The paper's oven LQG is the scalar case ``A = 1-a, B = a, Σ = σ², Q = 0, R = 1, Q_f = r``.

Quadratic form in the noise
---------------------------
Stack the noise :math:`w = (w_0, \dots, w_{H-1}) \in \mathbb R^{Hd}`, :math:`w \sim \mathcal N(0,
S)` with :math:`S = I_H \otimes \Sigma`. Then :math:`x_k = m_k + L_k w` with the nominal (NBO)
states :math:`m_k = A^k x_0 + \sum_{j<k} A^{k-1-j} B u_j` and :math:`L_k = [A^{k-1}, \dots, A^0,
0, \dots, 0]`, so every trajectory cost is

.. math:: g(w) = c + b^\top w + w^\top K w

with :math:`c` the NBO cost, :math:`b = 2\sum_{k<H} L_k^\top Q m_k + 2 L_H^\top Q_f (m_H - t)`,
:math:`K = \sum_{k<H} L_k^\top Q L_k + L_H^\top Q_f L_H`. Everything below follows from
Gaussian moment identities (:math:`E[w^\top K w] = \mathrm{tr}(KS)`,
:math:`\mathrm{Var}(b^\top w + w^\top K w) = b^\top S b + 2\,\mathrm{tr}((KS)^2)`).
See :class:`QuadraticForm` for the oracles.

Exact tail of the sample mean
-----------------------------
:meth:`QuadraticForm.mean_error_tail` gives :math:`P(|\bar g_n - J| \ge \epsilon)` for the
mean of ``n`` independent trajectories exactly (numerical inversion of the characteristic
function, absolute error about 1e-12), the quantity that the paper's Prop. 3 bounds by Chebyshev's
inequality :math:`\mathrm{Var}(g)/(n\epsilon^2)`.

Linear dynamics, linear cost (paper Prop. 3)
--------------------------------------------
:class:`LinearCost` is the model of Prop. 3, :math:`g(x_k, u_k) = C x_k + D u_k`; its trajectory
cost is Gaussian, with the paper's variance :math:`C[\sum_k \mathcal A_k \Sigma
\mathcal A_k^\top]C^\top` (:meth:`LinearCost.prop3_variance`) and a :class:`QuadraticForm`
with :math:`K = 0` (:attr:`LinearCost.quadratic_form`).

Shared by the studies ``rsmhp.studies.estimators``, ``rsmhp.studies.horizon`` and
``rsmhp.studies.lqg`` (so it lives below them).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy  # scipy.integrate and scipy.special load on first use (scipy's lazy submodules)

from rsmhp.core import guards
from rsmhp.core.sampling import GaussianNoise
from rsmhp.models.lqg.oven import LQGModel

__all__ = ["LinearCost", "LinearQuadratic", "QuadraticForm"]


def _mat(x, name: str, shape: tuple[int, int] | None = None) -> np.ndarray:
    m = np.atleast_2d(guards.finite_array(name, x))
    if m.ndim != 2:
        raise ValueError(f"{name} must be a matrix (2-D), got shape {m.shape}")
    if shape is not None and m.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {m.shape}")
    return m


def _vec(x, name: str, d: int) -> np.ndarray:
    """A finite vector of ``d`` entries (any shape holding exactly ``d`` numbers)."""
    v = guards.finite_array(name, x)
    if v.size != d:
        raise ValueError(f"{name} must have {d} entries (the state dimension), got shape {v.shape}")
    return v.reshape(d)


# --- exact tail of the mean of n trajectory costs (numerical CF inversion) ------------------
_TRUNCATION = 1e-13
r"""Largest neglected part :math:`\frac2\pi\int_T^\infty |\varphi(u)|/u\,du` of the inversion
integral when it is cut at ``T`` (a rigorous bound, see :class:`_MeanErrorLaw`)."""
_QUAD_EPSABS = 1e-13
"""Absolute tolerance of every quadrature (the integrals are O(1))."""
_QUAD_EPSREL = 1e-12
"""Relative tolerance of every quadrature (QAWF uses only the absolute one)."""
_WARN_ERROR = 1e-9
"""A probability whose summed quadrature error estimate exceeds this triggers a warning."""
_U_CAP = 60.0
"""Longest standardised range integrated without the tail treatment of slowly decaying CFs."""
_CHEBYSHEV_ZERO = 1e5
r"""For :math:`\epsilon/\sigma_n \ge` this value Chebyshev gives :math:`P \le 10^{-10}`; 0 is
returned (the quadrature would only resolve round-off there)."""


_ATAN_SERIES = tuple((-1) ** k / (2 * k + 1) for k in range(8, 0, -1))
r"""Coefficients of :math:`(\arctan x - x)/x^3` in :math:`x^2`, highest power first."""


def _atan_minus_identity(x: np.ndarray) -> np.ndarray:
    r""":math:`\arctan x - x` without cancellation: its Taylor series
    :math:`\sum_{k=1}^{8} (-1)^k x^{2k+1}/(2k+1)` (relative error < 1e-17) for
    :math:`|x| < 0.1`, the direct difference elsewhere."""
    x = np.asarray(x, dtype=float)
    x2 = x * x
    poly = np.zeros_like(x)
    for c in _ATAN_SERIES:
        poly = poly * x2 + c
    return np.where(np.abs(x) < 0.1, x * x2 * poly, np.arctan(x) - x)


def _atan_minus_identity_scalar(x: float) -> float:
    """:func:`_atan_minus_identity` of one float (no numpy overhead inside quadratures)."""
    if abs(x) >= 0.1:
        return math.atan(x) - x
    x2 = x * x
    poly = 0.0
    for c in _ATAN_SERIES:
        poly = poly * x2 + c
    return x * x2 * poly


def _quad(f: Callable[[float], float], a: float, b: float, **kw) -> tuple[float, float, bool]:
    """:func:`scipy.integrate.quad` returning ``(value, error estimate, converged)`` instead of
    warning (``full_output`` silences QUADPACK's messages; ``ier != 0`` means not converged)."""
    kw.setdefault("epsrel", _QUAD_EPSREL)
    out = scipy.integrate.quad(f, a, b, full_output=1, epsabs=_QUAD_EPSABS, **kw)
    return float(out[0]), float(out[1]), len(out) == 3


class _MeanErrorLaw:
    r"""Characteristic function of the standardised mean error and its Gil-Pelaez inversion.

    In whitened, rotated coordinates a trajectory cost is :math:`g = c + \sum_j (\lambda_j y_j^2
    + \beta_j y_j)`, :math:`y \sim \mathcal N(0, I)`. The mean of ``n`` copies minus
    :math:`J = c + \sum_j\lambda_j` is :math:`X = \bar g_n - J`, with
    :math:`\sigma_n^2 = \mathrm{Var}(X) = \sum_j(2\lambda_j^2 + \beta_j^2)/n`. The class works
    with :math:`Y = X/\sigma_n` (frequency ``u`` = :math:`\sigma_n t`), so the scale is the
    same for every ``n``. With :math:`\kappa_j = 2\lambda_j/(n\sigma_n)`,
    :math:`\gamma_j = \beta_j^2/(2n\sigma_n^2)`, :math:`v_j = \kappa_j u`:

    .. math::

        \log\varphi_Y(u) = \sum_j \Big[-\tfrac n4\log(1+v_j^2) - \frac{\gamma_j u^2}{1+v_j^2}
        + i\Big(\tfrac n2(\arctan v_j - v_j) - \frac{\gamma_j v_j u^2}{1+v_j^2}\Big)\Big],

    the CF of :math:`\sum_j [(\lambda_j/n)\chi'^2_n(n\delta_j^2) - \lambda_j(1+\delta_j^2)]`,
    :math:`\delta_j = \beta_j/(2\lambda_j)`, written without completing the square (no
    :math:`\beta^2/\lambda` cancellation; :math:`\lambda_j = 0` gives the Gaussian part
    :math:`e^{-\gamma_j u^2}`). Everything is summed in log space: no under/overflow for any n.

    Gil-Pelaez for both tails at once (:math:`Y` has a density when :math:`\sigma_n > 0`):

    .. math::

        P(|Y| \ge e) = 1 - \frac2\pi\int_0^\infty \frac{\sin(eu)}{u}\,\mathrm{Re}\,\varphi_Y(u)\,du
        = 1 - \frac2\pi\Big[\mathrm{Si}(eT) + \int_0^T \sin(eu)\,
        \frac{\mathrm{Re}\,\varphi_Y(u) - 1}{u}\,du + \int_T^\infty\cdots\Big].

    The middle integral is QUADPACK's QAWO (sine weight, smooth non-oscillating amplitude).
    Cut-off: every factor's log-derivative in :math:`\log u` is non-increasing, so for
    :math:`u \ge T`, :math:`|\varphi_Y(u)| \le |\varphi_Y(T)|(u/T)^{-Q(T)}` with
    :math:`Q(T) = \sum_{\kappa_j\ne0}\tfrac n2\frac{v_j^2}{1+v_j^2} + 2T^2\sum_{\kappa_j=0}
    \gamma_j`, and the neglected tail is at most :math:`\frac2\pi|\varphi_Y(T)|/Q(T)`.
    ``T`` is the first point of a grid in [4, 60] where this is below 1e-13. If none is (small
    ``n``: :math:`|\varphi_Y| \sim u^{-n\,\mathrm{rank}/2}` decays slowly), the tail beyond
    :math:`T = 60` is integrated too: the terms already in their asymptotic regime
    (:math:`|v_j(T)| \ge 1`) oscillate like :math:`e^{-ix_0u}`, :math:`x_0 = \sum_j(\gamma_j/
    \kappa_j + n\kappa_j/2)` (the shifts of the completed squares), so with
    :math:`\psi = e^{ix_0u}\varphi_Y` (a slowly varying amplitude)

    .. math::

        \sin(eu)\,\mathrm{Re}\,\varphi_Y = \tfrac12\mathrm{Re}\,\psi\,[\sin\omega_+u +
        \sin\omega_-u] + \tfrac12\mathrm{Im}\,\psi\,[\cos\omega_-u - \cos\omega_+u],
        \quad \omega_\pm = e \pm x_0,

    four Fourier integrals on :math:`[T, \infty)` done by QAWF (after an ordinary quadrature up
    to 10 periods when :math:`\omega` is small).
    """

    def __init__(self, lam: np.ndarray, beta: np.ndarray, n: int) -> None:
        lam = np.asarray(lam, dtype=float)
        beta = np.asarray(beta, dtype=float)
        self.n = n
        self.sigma = math.sqrt(float(np.sum(2.0 * lam**2 + beta**2)) / n)
        gauss = lam == 0.0
        s2 = float(np.sum(beta[gauss] ** 2))  # all lambda = 0 directions: one Gaussian term
        lam, beta = lam[~gauss], beta[~gauss]
        if s2 > 0:
            lam, beta = np.append(lam, 0.0), np.append(beta, math.sqrt(s2))
        self.kappa = 2.0 * lam / (n * self.sigma)
        self.gamma = beta**2 / (2.0 * n * self.sigma**2)
        self._terms = [(float(k), float(g)) for k, g in zip(self.kappa, self.gamma, strict=True)]

    def log_cf(
        self, u: float | np.ndarray, asym: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        r"""Real and imaginary parts of :math:`\log\varphi_Y(u)` (``u`` any shape); with a
        boolean mask ``asym`` over the terms, of :math:`\log\psi(u)`: the linear phase
        :math:`(\gamma_j/\kappa_j + n\kappa_j/2)u` of those terms removed (imaginary part
        :math:`\tfrac n2\arctan v_j + \gamma_j u/(\kappa_j(1+v_j^2))`)."""
        u = np.asarray(u, dtype=float)[..., None]
        v = self.kappa * u
        q = 1.0 + v * v
        re = -0.25 * self.n * np.log1p(v * v) - self.gamma * u * u / q
        im = 0.5 * self.n * _atan_minus_identity(v) - self.gamma * v * u * u / q
        if asym is not None:
            g_over_k = np.divide(self.gamma, self.kappa, out=np.zeros_like(v), where=asym)
            im = np.where(asym, 0.5 * self.n * np.arctan(v) + g_over_k * u / q, im)
        return re.sum(axis=-1), im.sum(axis=-1)

    def _log_at(self, u: float, asym: tuple[bool, ...] | None = None) -> tuple[float, float]:
        """:meth:`log_cf` at one float ``u``: a plain loop over the terms (several times faster
        than numpy on the few terms of a trajectory cost; numpy beyond 32 terms)."""
        if len(self._terms) > 32:
            re, im = self.log_cf(u, None if asym is None else np.array(asym))
            return float(re), float(im)
        half_n = 0.5 * self.n
        uu = u * u
        re = im = 0.0
        for j, (k, g) in enumerate(self._terms):
            v = k * u
            q = 1.0 + v * v
            re -= 0.5 * half_n * math.log1p(v * v) + g * uu / q
            if asym is not None and asym[j]:
                im += half_n * math.atan(v) + g / k * u / q
            else:
                im += half_n * _atan_minus_identity_scalar(v) - g * v * uu / q
        return re, im

    def _amplitude(self, u: float) -> float:
        r""":math:`(\mathrm{Re}\,\varphi_Y(u) - 1)/u`, computed as :math:`(\mathrm{expm1}(a)
        \cos b - 2\sin^2(b/2))/u` for :math:`\log\varphi = a + ib` (0 at ``u = 0``)."""
        if u == 0.0:
            return 0.0
        a, b = self._log_at(u)
        return (math.expm1(a) * math.cos(b) - 2.0 * math.sin(0.5 * b) ** 2) / u

    def cutoff(self) -> tuple[float, bool]:
        """``(T, tail_needed)``: the first grid point whose neglected tail is below
        :data:`_TRUNCATION`, or ``(_U_CAP, True)``."""
        grid = np.geomspace(4.0, _U_CAP, 40)
        re, _ = self.log_cf(grid)
        nz = self.kappa != 0.0
        v2 = (self.kappa[nz] * grid[:, None]) ** 2
        rate = 0.5 * self.n * np.sum(v2 / (1.0 + v2), axis=1)
        rate = rate + 2.0 * float(np.sum(self.gamma[~nz])) * grid**2
        bound = 2.0 / math.pi * np.exp(re) / rate
        ok = np.flatnonzero(bound <= _TRUNCATION)
        return (float(grid[ok[0]]), False) if ok.size else (_U_CAP, True)

    def tail(self, e: float, cut: tuple[float, bool]) -> tuple[float, float, bool]:
        """``(P(|Y| >= e), error estimate, converged)`` for a standardised ``e >= 0``."""
        if e == 0.0:
            return 1.0, 0.0, True
        if e >= _CHEBYSHEV_ZERO:
            return 0.0, 1.0 / e**2, True
        T, tail_needed = cut
        total, err, ok = _quad(self._amplitude, 0.0, T, weight="sin", wvar=e, limit=2000)
        total += float(scipy.special.sici(e * T)[0])
        if tail_needed:
            t_val, t_err, t_ok = self._tail_integral(e, T)
            total, err, ok = total + t_val, err + t_err, ok and t_ok
        p = 1.0 - 2.0 / math.pi * total
        return min(1.0, max(0.0, p)), 2.0 / math.pi * err, ok

    def _tail_integral(self, e: float, T: float) -> tuple[float, float, bool]:
        r""":math:`\int_T^\infty \sin(eu)\,\mathrm{Re}\,\varphi_Y(u)/u\,du` (see the class)."""
        kappa, gamma, n = self.kappa, self.gamma, self.n
        mask = (kappa != 0.0) & (np.abs(kappa) * T >= 1.0)
        x0 = float(np.sum(gamma[mask] / kappa[mask] + 0.5 * n * kappa[mask]))
        asym = tuple(bool(a) for a in mask)

        def re_psi(u: float) -> float:
            if u > 1e100:  # |psi| <= |psi(T)| (u/T)^-Q: nothing left
                return 0.0
            a, b = self._log_at(u, asym)
            return math.exp(a) * math.cos(b) / (2.0 * u)

        def im_psi(u: float) -> float:
            if u > 1e100:
                return 0.0
            a, b = self._log_at(u, asym)
            return math.exp(a) * math.sin(b) / (2.0 * u)

        total, err, ok = 0.0, 0.0, True
        pieces = ((e + x0, re_psi, "sin", 1.0), (e - x0, re_psi, "sin", 1.0))
        pieces += ((e - x0, im_psi, "cos", 1.0), (e + x0, im_psi, "cos", -1.0))
        for omega, f, weight, sign in pieces:
            val, er, good = _fourier_tail(f, T, omega, weight)
            total, err, ok = total + sign * val, err + er, ok and good
        return total, err, ok


def _fourier_tail(
    f: Callable[[float], float], T: float, omega: float, weight: str
) -> tuple[float, float, bool]:
    r""":math:`\int_T^\infty f(u)\,w(\omega u)\,du`, :math:`w` = sin or cos, ``f`` smooth and
    decaying: QAWF from :math:`U = \max(T, 20\pi/|\omega|)`, an ordinary quadrature in
    :math:`\log u` on :math:`[T, U]`; :math:`\omega = 0` by QAGI."""
    if abs(omega) <= 1e-13:
        if weight == "sin":
            return 0.0, 0.0, True
        return _quad(f, T, np.inf, limit=500)
    trig = math.sin if weight == "sin" else math.cos
    U = max(T, 20.0 * math.pi / abs(omega))
    val, err, ok = 0.0, 0.0, True
    if U > T:

        def head(s: float) -> float:
            u = T * math.exp(s)
            return f(u) * trig(omega * u) * u

        val, err, ok = _quad(head, 0.0, math.log(U / T), limit=1000)
    v2, e2, ok2 = _quad(f, U, np.inf, weight=weight, wvar=abs(omega), limlst=200, limit=500)
    if weight == "sin" and omega < 0:
        v2 = -v2
    return val + v2, err + e2, ok and ok2


@dataclass(frozen=True, eq=False)
class QuadraticForm:
    r"""Trajectory cost as a function of the stacked noise: :math:`g(w) = c + b^\top w +
    w^\top K w`, :math:`w \sim \mathcal N(0, S)`, :math:`S = I_H \otimes \Sigma`.

    Attributes: ``c`` (scalar), ``b`` (Hd,), ``K`` (Hd, Hd) symmetric, ``sigma`` (d, d), ``H``.
    """

    c: float
    b: np.ndarray
    K: np.ndarray
    sigma: np.ndarray
    H: int

    def __post_init__(self) -> None:
        guards.positive_int("H", self.H)
        guards.real("c", self.c)
        sigma = guards.spd_matrix("sigma", self.sigma, semi=True)
        n = self.H * sigma.shape[0]
        guards.finite_array("b", self.b, shape=(n,))
        guards.finite_array("K", self.K, shape=(n, n))

    @property
    def d(self) -> int:
        return self.sigma.shape[0]

    @cached_property
    def S(self) -> np.ndarray:
        """Covariance of the stacked noise, :math:`I_H \\otimes \\Sigma`."""
        return np.kron(np.eye(self.H), self.sigma)

    def evaluate(self, w: np.ndarray) -> np.ndarray:
        """:math:`g(w)` for stacked noise ``w`` of shape ``(..., H d)`` (or ``(..., H, d)``)."""
        w = np.asarray(w, dtype=float)
        n = self.H * self.d
        if w.ndim == 0 or not (w.shape[-1] == n or w.shape[-2:] == (self.H, self.d)):
            raise ValueError(
                f"w must have shape (..., {n}) or (..., {self.H}, {self.d}), got {w.shape}"
            )
        w = w.reshape(*w.shape[: w.ndim - (2 if w.shape[-2:] == (self.H, self.d) else 1)], -1)
        return self.c + w @ self.b + np.einsum("...i,ij,...j->...", w, self.K, w)

    def _block(self, k: int, ell: int) -> np.ndarray:
        d = self.d
        return self.K[k * d : (k + 1) * d, ell * d : (ell + 1) * d]

    def _var(self, b: np.ndarray, K: np.ndarray, S: np.ndarray) -> float:
        KS = K @ S
        return float(b @ S @ b + 2.0 * np.trace(KS @ KS))

    # --- exact values -------------------------------------------------------------------
    def mean(self, scale: float = 1.0) -> float:
        r""":math:`E[g]` under :math:`w \sim \mathcal N(0, \text{scale}\cdot S)`:
        :math:`c + \text{scale}\,\mathrm{tr}(KS)`. ``scale=1`` is the exact J."""
        guards.real("scale", scale, lo=0.0)
        return float(self.c + scale * np.trace(self.K @ self.S))

    def nominal(self) -> float:
        """NBO cost :math:`g(0) = c`."""
        return float(self.c)

    def variance(self) -> float:
        r""":math:`\mathrm{Var}(g) = b^\top S b + 2\,\mathrm{tr}((KS)^2)`."""
        return self._var(self.b, self.K, self.S)

    @cached_property
    def _whitened(self) -> tuple[np.ndarray, np.ndarray]:
        r"""``(lam, beta)``: :math:`g = c + \sum_j(\lambda_j y_j^2 + \beta_j y_j)`,
        :math:`y \sim \mathcal N(0, I_r)`.

        :math:`\Sigma = U\,\mathrm{diag}(s)\,U^\top`; the directions with :math:`s_i >
        10^{-12}\max s` give :math:`\Sigma^{1/2} = U_+\mathrm{diag}(s_+^{1/2})` (d, r_Σ), also for
        a singular Σ (then :math:`w = (I_H \otimes \Sigma^{1/2}) y` exactly in law),
        :math:`R = I_H \otimes \Sigma^{1/2}`. The whitened form has :math:`M = R^\top K_s R`
        (:math:`K_s` the symmetric part of K) and linear term :math:`R^\top b`;
        :math:`M = V\mathrm{diag}(\lambda)V^\top` and :math:`\beta = V^\top R^\top b`.
        Eigenvalues below :math:`10^{-13}\max|\lambda|` (round-off of a rank-deficient K) are set
        to 0 (directions of the Gaussian part).
        """
        s, U = np.linalg.eigh(0.5 * (self.sigma + self.sigma.T))
        keep = s > 1e-12 * max(float(s.max()), 0.0)
        root = U[:, keep] * np.sqrt(s[keep])
        R = np.kron(np.eye(self.H), root)
        Ks = 0.5 * (self.K + self.K.T)
        lam, V = np.linalg.eigh(R.T @ Ks @ R)
        beta = V.T @ (R.T @ self.b)
        if lam.size:
            lam = np.where(np.abs(lam) <= 1e-13 * np.abs(lam).max(), 0.0, lam)
        return lam, beta

    def mean_error_tail(self, n: int, eps: float | np.ndarray) -> float | np.ndarray:
        r"""Exact :math:`P(|\bar g_n - J| \ge \epsilon)`, :math:`\bar g_n` the mean of ``n``
        independent copies of :math:`g`, :math:`J = E[g]` (:meth:`mean`).

        The quantity Chebyshev bounds by :math:`\mathrm{Var}(g)/(n\epsilon^2)` in the paper's
        Prop. 3. Whitening the noise and diagonalising the whitened K (:attr:`_whitened`),
        :math:`g = c + \sum_j(\lambda_j z_j^2 + \beta_j z_j)`, :math:`z \sim \mathcal N(0, I)`.
        Completing the square for :math:`\lambda_j \ne 0` (:math:`\delta_j = \beta_j /
        (2\lambda_j)`) and summing n copies,

        .. math::

            \bar g_n - J = \sum_{\lambda_j\ne0}\Big[\frac{\lambda_j}{n}\,\chi'^2_n(n\delta_j^2)
            - \lambda_j(1 + \delta_j^2)\Big] + \mathcal N\Big(0, \frac{s^2}{n}\Big),
            \qquad s^2 = \sum_{\lambda_j = 0}\beta_j^2,

        a generalized chi-square with independent terms. Its CDF is obtained by Gil-Pelaez
        inversion of the characteristic function on the scale
        :math:`\sigma_n = \sqrt{\mathrm{Var}(g)/n}` with :func:`scipy.integrate.quad` (QAWO and,
        for slowly decaying CFs at small ``n``, QAWF), a rigorous truncation bound and log-space
        products; see :class:`_MeanErrorLaw`. Absolute error about 1e-12 (compared with scipy's
        ``ncx2``/``chi2`` for n = 1 to 1e6; the target is 1e-7); a :class:`RuntimeWarning` is
        issued if QUADPACK reports non-convergence or an error estimate above 1e-9. For
        :math:`\epsilon \ge 10^5\sigma_n` it returns 0 (Chebyshev: the tail is below 1e-10).

        Exact special cases: :math:`K = 0` (after whitening): :math:`\bar g_n` is Gaussian,
        :math:`2\Phi(-\epsilon/s_n)`, :math:`s_n^2 = b^\top S b/n`; :math:`\mathrm{Var}(g) = 0`:
        1 at :math:`\epsilon = 0`, else 0. Always 1 at :math:`\epsilon = 0`.

        Parameters
        ----------
        n : number of independent trajectories, an integer >= 1.
        eps : :math:`\epsilon \ge 0`, finite; a scalar or an array of any shape.

        Returns
        -------
        float for a scalar ``eps``, else an array of the shape of ``eps``.
        """
        n = guards.positive_int("n", n)
        e = guards.finite_array("eps", eps)
        if (e < 0).any():
            first = tuple(int(i) for i in np.argwhere(e < 0)[0])
            where = f" at index {first if len(first) != 1 else first[0]}" if e.ndim else ""
            raise ValueError(f"eps must be >= 0, got {float(e[first])!r}{where}")
        flat = e.reshape(-1)
        lam, beta = self._whitened
        var = float(np.sum(2.0 * lam**2 + beta**2))
        if var == 0.0:
            out = (flat == 0.0).astype(float)
        elif not np.any(lam):
            sd = math.sqrt(var / n)  # var = b^T S b here (sum of beta^2: no lambda part)
            out = scipy.special.erfc(flat / (sd * math.sqrt(2.0)))  # 2 Phi(-eps/sd)
        else:
            law = _MeanErrorLaw(lam, beta, n)
            cut = law.cutoff()
            out = np.empty(flat.shape)
            for i, value in enumerate(flat):
                p, err, ok = law.tail(float(value) / law.sigma, cut)
                if not ok or err > _WARN_ERROR:
                    warnings.warn(
                        f"mean_error_tail(n={n}, eps={float(value)!r}): the numerical inversion "
                        f"did not reach its tolerance (error estimate {err:.2g})",
                        RuntimeWarning,
                        stacklevel=2,
                    )
                out[i] = p
        out = out.reshape(e.shape)
        return float(out) if out.ndim == 0 else out

    def weighted_limit(self) -> float:
        r"""Limit of every likeliness-weighted estimator (non-overlapping or tree, shared draws):
        weighting a draw by its density :math:`\phi_\Sigma` tilts :math:`\mathcal N(0,\Sigma)` to
        :math:`\phi_\Sigma^2 \propto \mathcal N(0, \Sigma/2)`, so the limit is
        :math:`c + \mathrm{tr}(KS)/2`."""
        return self.mean(scale=0.5)

    def grid_average(self, draws: list[np.ndarray], weights: list[np.ndarray] | None = None):
        r"""Exact (weighted) average of :math:`g` over the product grid of per-level draws.

        This is the shared-draw tree estimator (paper Fig. 1a) evaluated without enumerating the
        :math:`\prod_k N_k` leaves. With per-level normalized weights :math:`\omega_{k,i}`
        (uniform, or the draws' densities for the weighted estimator, whose product weights
        factorize), :math:`\bar w_k = \sum_i \omega_{k,i} w_k^i`, :math:`M_k = \sum_i
        \omega_{k,i} w_k^i w_k^{i\top}`:

        .. math:: T = c + b^\top\bar w + \bar w^\top K\bar w + \sum_k \mathrm{tr}\big(
                  K_{kk}(M_k - \bar w_k\bar w_k^\top)\big).

        ``draws[k]`` has shape (N_k, d); ``weights[k]`` shape (N_k,) (any positive scale).
        """
        if len(draws) != self.H:
            raise ValueError(f"need draws for {self.H} levels, got {len(draws)}")
        if weights is not None and len(weights) != self.H:
            raise ValueError(f"need weights for {self.H} levels, got {len(weights)}")
        for k, wk in enumerate(draws):
            wk = guards.finite_array(f"draws[{k}]", wk, ndim=(1, 2), nonempty=True)
            if wk.size != len(wk) * self.d:
                raise ValueError(f"draws[{k}] must have shape (N_k, {self.d}), got {wk.shape}")
            if weights is not None:
                om = guards.finite_array(f"weights[{k}]", weights[k], shape=(len(wk),))
                if np.any(om < 0) or not om.sum() > 0:
                    raise ValueError(
                        f"weights[{k}] must be >= 0 with a positive sum, got {guards.show(om)}"
                    )
        means, extra = [], 0.0
        for k, wk in enumerate(draws):
            wk = np.asarray(wk, dtype=float).reshape(len(wk), self.d)
            om = (
                np.full(len(wk), 1.0 / len(wk))
                if weights is None
                else weights[k] / np.sum(weights[k])
            )
            mean = om @ wk
            second = (wk * om[:, None]).T @ wk
            extra += float(np.trace(self._block(k, k) @ (second - np.outer(mean, mean))))
            means.append(mean)
        wbar = np.concatenate(means)
        return float(self.c + self.b @ wbar + wbar @ self.K @ wbar + extra)

    # --- estimator variances ------------------------------------------------------------
    def independent_variance(self, n: int) -> float:
        """Uniform average of ``n`` independent trajectories: ``Var(g)/n``."""
        guards.positive_int("n", n)
        return self.variance() / n

    def antithetic_variance(self, n: int) -> float:
        r"""``n/2`` antithetic pairs :math:`(w, -w)`: the pair mean :math:`c + w^\top K w` cancels
        the linear term, so the variance is :math:`2\,\mathrm{tr}((KS)^2)/(n/2)`."""
        guards.positive_int("n", n)
        if n % 2:
            raise ValueError(f"antithetic sampling needs an even number of trajectories, got {n}")
        KS = self.K @ self.S
        return float(2.0 * np.trace(KS @ KS) / (n / 2))

    def tree_variance(self, N: int) -> float:
        r"""Uniform average over the unpruned tree with shared draws (paper Fig. 1a).

        Each level ``k`` draws :math:`w_k^1..w_k^N` used by every node, and the :math:`N^H`
        leaves are all combinations. Averaging the quadratic form over the product grid gives
        :math:`T = c + b^\top\bar w + \bar w^\top K \bar w + \frac{N-1}{N}\sum_k
        \mathrm{tr}(K_{kk}\hat\Sigma_k)` with per-level means :math:`\bar w_k \sim
        \mathcal N(0,\Sigma/N)` and unbiased sample covariances :math:`\hat\Sigma_k`
        (independent of :math:`\bar w`, :math:`(N-1)\hat\Sigma_k \sim W(\Sigma, N-1)`), hence

        .. math:: \mathrm{Var}(T) = \frac{b^\top S b}{N} + \frac{2\,\mathrm{tr}((KS)^2)}{N^2}
                  + \frac{2(N-1)}{N^2}\sum_k \mathrm{tr}\big((K_{kk}\Sigma)^2\big).

        It decays like 1/N, not like :math:`1/N^H` as for :math:`N^H` independent
        trajectories: the leaves share their draws.
        """
        guards.integer("N", N, minimum=2)  # the formula needs N >= 2
        KS = self.K @ self.S
        diag = sum(
            float(np.trace((self._block(k, k) @ self.sigma) @ (self._block(k, k) @ self.sigma)))
            for k in range(self.H)
        )
        return float(
            self.b @ self.S @ self.b / N
            + 2.0 * np.trace(KS @ KS) / N**2
            + 2.0 * (N - 1) / N**2 * diag
        )

    def prefix_covariance(self, m: int) -> float:
        r"""Covariance of the costs of two trajectories that share exactly their first ``m``
        draws: :math:`\mathrm{Var}(E[g\mid w_{<m}]) = b_A^\top S_A b_A + 2\,\mathrm{tr}((K_{AA}
        S_A)^2)` with ``A`` the first ``m`` blocks."""
        guards.integer("m", m, minimum=0, maximum=self.H)
        if m == 0:
            return 0.0
        n = m * self.d
        return self._var(self.b[:n], self.K[:n, :n], self.S[:n, :n])

    def pernode_tree_variance(self, N: int) -> float:
        r"""Uniform average over an unpruned tree whose every node draws its own ``N`` children.

        Two leaves whose paths split after ``m`` common draws have covariance
        :meth:`prefix_covariance` (m); each leaf has :math:`N^{H-m} - N^{H-m-1}` partners
        splitting at ``m`` (``0 < m < H``), so
        :math:`\mathrm{Var} = N^{-H}\,[\mathrm{Var}(g) + \sum_{m=1}^{H-1}(N^{H-m}-N^{H-m-1})
        C_m]`.
        """
        guards.positive_int("N", N)
        H = self.H
        total = self.variance() + sum(
            (N ** (H - m) - N ** (H - m - 1)) * self.prefix_covariance(m) for m in range(1, H)
        )
        return float(total / N**H)


class _LinearDynamics:
    """What :class:`LinearQuadratic` and :class:`LinearCost` share: the horizon, the state
    dimension, the noise and the step :math:`x_{k+1} = A x_k + B u_k + w_k` of the
    :class:`rsmhp.core.sampling.System` protocol (from the fields ``A``, ``B``, ``Sigma``,
    ``u``)."""

    A: np.ndarray
    B: np.ndarray
    Sigma: np.ndarray
    u: np.ndarray

    @property
    def H(self) -> int:
        return int(self.u.shape[0])

    @property
    def d(self) -> int:
        return int(self.A.shape[0])

    @cached_property
    def noise(self) -> GaussianNoise:
        return GaussianNoise(self.Sigma)

    def step(self, x: np.ndarray, u_k: np.ndarray, w: np.ndarray) -> np.ndarray:
        """:math:`x_{k+1} = A x_k + B u_k + w_k`; ``x``, ``w`` shape (n, d)."""
        return x @ self.A.T + np.asarray(u_k) @ self.B.T + w


@dataclass(frozen=True, eq=False)
class LinearQuadratic(_LinearDynamics):
    """A linear-Gaussian system with quadratic cost and a fixed control sequence.

    Implements :class:`rsmhp.core.sampling.System` (vectorized ``step``/``stage_cost``/
    ``terminal_cost``) and exposes the exact :class:`QuadraticForm` of its trajectory cost.

    Shapes: ``A`` (d, d), ``B`` (d, m), ``Sigma`` (d, d), ``Q`` (d, d), ``R`` (m, m),
    ``Qf`` (d, d), ``target`` (d,), ``x0`` (d,), ``u`` (H, m).
    """

    A: np.ndarray
    B: np.ndarray
    Sigma: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    Qf: np.ndarray
    target: np.ndarray
    x0: np.ndarray
    u: np.ndarray

    def __post_init__(self) -> None:
        A = _mat(self.A, "A")
        d = A.shape[0]
        if A.shape != (d, d):
            raise ValueError(f"A must be square, got {A.shape}")
        B = _mat(self.B, "B")
        if B.shape[0] != d:
            raise ValueError(f"B must have {d} rows, got {B.shape}")
        m = B.shape[1]
        u = guards.finite_array("u", self.u)
        u = u.reshape(-1, m) if u.ndim <= 1 else u
        if u.ndim != 2 or u.shape[1] != m or u.shape[0] < 1:
            raise ValueError(f"u must have shape (H, {m}) with H >= 1, got {np.shape(self.u)}")
        fields = {
            "A": A,
            "B": B,
            "Sigma": _mat(self.Sigma, "Sigma", (d, d)),
            "Q": _mat(self.Q, "Q", (d, d)),
            "R": _mat(self.R, "R", (m, m)),
            "Qf": _mat(self.Qf, "Qf", (d, d)),
            "target": _vec(self.target, "target", d),
            "x0": _vec(self.x0, "x0", d),
            "u": u,
        }
        guards.spd_matrix("Sigma", fields["Sigma"], semi=True)
        for key in ("Q", "R", "Qf"):
            M = fields[key]
            if not np.allclose(M, M.T):
                raise ValueError(f"{key} must be symmetric positive semi-definite, got {M}")
            if (low := np.linalg.eigvalsh(M).min()) < -1e-12:
                raise ValueError(
                    f"{key} must be symmetric positive semi-definite, got smallest eigenvalue "
                    f"{low:.6g}"
                )
        for key, val in fields.items():
            object.__setattr__(self, key, val)

    @classmethod
    def from_lqg(cls, model: LQGModel, u) -> LinearQuadratic:
        """The oven problem :class:`rsmhp.models.lqg.oven.LQGModel` with controls ``u`` (H,) in this
        general form: ``A = 1-a, B = a, Σ = σ², Q = 0, R = 1, Q_f = r``, target and x0."""
        return cls(
            A=[[1 - model.a]],
            B=[[model.a]],
            Sigma=[[model.sigma**2]],
            Q=[[0.0]],
            R=[[1.0]],
            Qf=[[model.r]],
            target=[model.target],
            x0=[model.x0],
            u=np.reshape(u, (-1, 1)),
        )

    @classmethod
    def scalar_lqg(
        cls, u, *, x0: float, a: float, r: float, target: float, sigma: float
    ) -> LinearQuadratic:
        """The paper's oven problem from its constants: :meth:`from_lqg` of
        :class:`rsmhp.models.lqg.oven.LQGModel` (which checks them)."""
        return cls.from_lqg(LQGModel(a=a, r=r, target=target, sigma=sigma, x0=x0), u)

    # --- System protocol (vectorized over n trajectories): H, d, noise, step from
    # _LinearDynamics
    def stage_cost(self, x: np.ndarray, u_k: np.ndarray) -> np.ndarray:
        """:math:`x_k^\\top Q x_k + u_k^\\top R u_k`, shape (n,)."""
        u_k = np.asarray(u_k)
        return np.einsum("ni,ij,nj->n", x, self.Q, x) + float(u_k @ self.R @ u_k)

    def terminal_cost(self, x: np.ndarray) -> np.ndarray:
        """:math:`(x_H - t)^\\top Q_f (x_H - t)`, shape (n,)."""
        e = x - self.target
        return np.einsum("ni,ij,nj->n", e, self.Qf, e)

    # --- exact structure ----------------------------------------------------------------
    @cached_property
    def quadratic_form(self) -> QuadraticForm:
        """The exact :class:`QuadraticForm` of the trajectory cost (see the module docstring)."""
        d, H = self.d, self.H
        powers = [np.eye(d)]
        for _ in range(H):
            powers.append(self.A @ powers[-1])
        m = [self.x0]
        for k in range(H):
            m.append(self.A @ m[-1] + self.B @ self.u[k])
        L = []
        for k in range(H + 1):
            Lk = np.zeros((d, H * d))
            for j in range(k):
                Lk[:, j * d : (j + 1) * d] = powers[k - 1 - j]
            L.append(Lk)
        Qs, Qfs = (self.Q + self.Q.T) / 2, (self.Qf + self.Qf.T) / 2
        eH = m[H] - self.target
        c = sum(m[k] @ Qs @ m[k] + self.u[k] @ self.R @ self.u[k] for k in range(H)) + eH @ Qfs @ eH
        b = 2 * sum(L[k].T @ Qs @ m[k] for k in range(H)) + 2 * L[H].T @ Qfs @ eH
        K = sum(L[k].T @ Qs @ L[k] for k in range(H)) + L[H].T @ Qfs @ L[H]
        return QuadraticForm(c=float(c), b=np.asarray(b), K=(K + K.T) / 2, sigma=self.Sigma, H=H)

    def exact_cost(self) -> float:
        """Exact :math:`J = E[g]`."""
        return self.quadratic_form.mean()

    def nbo_cost(self) -> float:
        """NBO cost (all noise at its mean 0)."""
        return self.quadratic_form.nominal()


def _row(x, name: str, k: int, what: str) -> np.ndarray:
    """A finite row of ``k`` entries given as shape ``(1, k)`` or ``(k,)``, returned as ``(k,)``."""
    v = guards.finite_array(name, x)
    if v.shape not in ((k,), (1, k)):
        raise ValueError(f"{name} must have shape (1, {k}) or ({k},) ({what}), got {v.shape}")
    return v.reshape(k)


@dataclass(frozen=True, eq=False)
class LinearCost(_LinearDynamics):
    r"""Linear dynamics with a linear cost: the model of the paper's Prop. 3 (eq. linstate).

    .. math::

        x_{k+1} = A x_k + B u_k + w_k,\quad w_k \sim \mathcal N(0, \Sigma),\quad
        x_0 \text{ known},

        p = \sum_{k=0}^{H-1} (C x_k + D u_k) + C x_H.

    With the nominal states :math:`m_k = E[x_k]`, :math:`x_k - m_k = \sum_{j<k} A^{k-1-j}w_j`,
    so (:math:`x_0` being deterministic) :math:`p - E[p] = C\sum_{k=0}^{H-1}\mathcal A_k w_k`,
    :math:`\mathcal A_k = \sum_{q=0}^{H-k-1} A^q`: the paper's eq. (pEp) (whose sum over
    :math:`k = 1..H` differs from this one only by the deterministic :math:`C x_0 + D u_0`
    and :math:`D u_H` terms). :math:`p` is Gaussian with

    .. math:: E[p] = \sum_{k<H}(C m_k + D u_k) + C m_H,\qquad
              \mathrm{Var}(p) = C\Big[\sum_{k=0}^{H-1}\mathcal A_k\Sigma\mathcal A_k^\top\Big]
              C^\top.

    Implements :class:`rsmhp.core.sampling.System` (vectorized ``step``/``stage_cost``/
    ``terminal_cost``, ``noise``), so the samplers of :mod:`rsmhp.core.sampling` simulate it.

    Shapes: ``A`` (d, d), ``B`` (d, m), ``Sigma`` (d, d) symmetric positive semidefinite
    (definite for simulation), ``C`` (1, d) or (d,), ``D`` (1, m) or (m,), ``x0`` (d,),
    ``u`` (H, m) (or (H,) when m = 1). Stored normalized: ``C`` (d,), ``D`` (m,), ``u`` (H, m).
    """

    A: np.ndarray
    B: np.ndarray
    Sigma: np.ndarray
    C: np.ndarray
    D: np.ndarray
    x0: np.ndarray
    u: np.ndarray

    def __post_init__(self) -> None:
        A = _mat(self.A, "A")
        d = A.shape[0]
        if A.shape != (d, d):
            raise ValueError(f"A must be square, got {A.shape}")
        B = _mat(self.B, "B")
        if B.shape[0] != d:
            raise ValueError(f"B must have {d} rows, got {B.shape}")
        m = B.shape[1]
        u = guards.finite_array("u", self.u)
        u = u.reshape(-1, m) if u.ndim <= 1 and (m == 1 or u.size == 0) else u
        if u.ndim != 2 or u.shape[1] != m or u.shape[0] < 1:
            raise ValueError(f"u must have shape (H, {m}) with H >= 1, got {np.shape(self.u)}")
        fields = {
            "A": A,
            "B": B,
            "Sigma": _mat(self.Sigma, "Sigma", (d, d)),
            "C": _row(self.C, "C", d, "the state dimension"),
            "D": _row(self.D, "D", m, "the control dimension"),
            "x0": _vec(self.x0, "x0", d),
            "u": u,
        }
        guards.spd_matrix("Sigma", fields["Sigma"], semi=True)
        for key, val in fields.items():
            object.__setattr__(self, key, val)

    @classmethod
    def example(cls, H: int) -> LinearCost:
        r"""The fixed example problem of the pipeline: a damped oscillator.

        .. math::

            A = 0.9\begin{pmatrix}\cos\theta & \sin\theta\\ -\sin\theta & \cos\theta
            \end{pmatrix},\ \theta = \pi/6,\quad B = \begin{pmatrix}0\\1\end{pmatrix},\quad
            \Sigma = \begin{pmatrix}0.10 & 0.03\\ 0.03 & 0.05\end{pmatrix},

            C = (1, 0.5),\quad D = (0.2),\quad x_0 = (1, 0),\quad u_k = 0.5\ (k < H).

        ``A`` rotates by 30 degrees and contracts by 0.9 (spectral radius 0.9 < 1: stable,
        oscillating); Σ is correlated (non-diagonal). ``H`` is the horizon (>= 1).
        """
        H = guards.positive_int("H", H)
        theta = np.pi / 6
        rot = np.array([[np.cos(theta), np.sin(theta)], [-np.sin(theta), np.cos(theta)]])
        return cls(
            A=0.9 * rot,
            B=[[0.0], [1.0]],
            Sigma=[[0.10, 0.03], [0.03, 0.05]],
            C=[1.0, 0.5],
            D=[0.2],
            x0=[1.0, 0.0],
            u=np.full((H, 1), 0.5),
        )

    # --- System protocol (vectorized over n trajectories): H, d, noise, step from
    # _LinearDynamics
    def stage_cost(self, x: np.ndarray, u_k: np.ndarray) -> np.ndarray:
        """:math:`C x_k + D u_k`, shape (n,)."""
        return x @ self.C + float(self.D @ np.asarray(u_k))

    def terminal_cost(self, x: np.ndarray) -> np.ndarray:
        """:math:`C x_H`, shape (n,)."""
        return x @ self.C

    # --- exact structure ----------------------------------------------------------------
    def prop3_variance(self) -> float:
        r"""The paper's Prop. 3 formula, literally: :math:`C\big[\sum_{k=0}^{H-1}\mathcal A_k
        \Sigma\mathcal A_k^\top\big]C^\top`, :math:`\mathcal A_k = \sum_{q=0}^{H-k-1} A^q`."""
        d, H = self.d, self.H
        powers = [np.eye(d)]
        for _ in range(H - 1):
            powers.append(self.A @ powers[-1])
        total = np.zeros((d, d))
        for k in range(H):
            calA = sum(powers[q] for q in range(H - k))
            total += calA @ self.Sigma @ calA.T
        return float(self.C @ total @ self.C)

    @cached_property
    def quadratic_form(self) -> QuadraticForm:
        r"""The exact :class:`QuadraticForm` of :math:`p`: :math:`K = 0`,
        :math:`c = \sum_{k<H}(C m_k + D u_k) + C m_H` (the nominal cost) and
        :math:`b = \sum_{k=1}^{H} L_k^\top C^\top` with the stacked state maps
        :math:`x_k - m_k = L_k w`, :math:`L_k = [A^{k-1}, \dots, A^0, 0, \dots, 0]`.

        Its :meth:`~QuadraticForm.variance` :math:`b^\top S b` is a second derivation of
        :meth:`prop3_variance`, its :meth:`~QuadraticForm.mean_error_tail` the exact
        (Gaussian) tail of the mean of n trajectory costs.
        """
        d, H = self.d, self.H
        m = [self.x0]
        for k in range(H):
            m.append(self.A @ m[-1] + self.B @ self.u[k])
        c = sum(float(self.C @ m[k] + self.D @ self.u[k]) for k in range(H)) + float(self.C @ m[H])
        b = np.zeros(H * d)
        L = np.zeros((d, H * d))  # L_0 = 0
        for k in range(1, H + 1):
            L = self.A @ L  # L_k = A L_{k-1} + [0 .. I (block k-1) .. 0]
            L[:, (k - 1) * d : k * d] += np.eye(d)
            b += L.T @ self.C
        return QuadraticForm(c=c, b=b, K=np.zeros((H * d, H * d)), sigma=self.Sigma, H=H)

    def exact_cost(self) -> float:
        """Exact :math:`E[p]`, the nominal cost (the cost is linear in the noise)."""
        return self.quadratic_form.mean()
