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
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rsmhp import guards
from rsmhp.lqg import LQGModel
from rsmhp.sampling import GaussianNoise

__all__ = ["LinearQuadratic", "QuadraticForm"]


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


@dataclass(frozen=True, eq=False)
class LinearQuadratic:
    """A linear-Gaussian system with quadratic cost and a fixed control sequence.

    Implements :class:`rsmhp.sampling.System` (vectorized ``step``/``stage_cost``/
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
        """The oven problem :class:`rsmhp.lqg.LQGModel` with controls ``u`` (H,) in this
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
        :class:`rsmhp.lqg.LQGModel` (which checks them)."""
        return cls.from_lqg(LQGModel(a=a, r=r, target=target, sigma=sigma, x0=x0), u)

    @property
    def H(self) -> int:
        return int(self.u.shape[0])

    @property
    def d(self) -> int:
        return int(self.A.shape[0])

    @cached_property
    def noise(self) -> GaussianNoise:
        return GaussianNoise(self.Sigma)

    # --- System protocol (vectorized over n trajectories) -------------------------------
    def step(self, x: np.ndarray, u_k: np.ndarray, w: np.ndarray) -> np.ndarray:
        """:math:`x_{k+1} = A x_k + B u_k + w_k`; ``x``, ``w`` shape (n, d)."""
        return x @ self.A.T + np.asarray(u_k) @ self.B.T + w

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
