r"""Trajectory sampling for RS-MHP: non-overlapping, tree, and pruned tree.

Conventions (used everywhere in this project)
---------------------------------------------
A system evolves as :math:`x_{k+1} = f(x_k, u_k, w_k)` for :math:`k = 0, \dots, H-1` with
i.i.d. Gaussian noise :math:`w_k \sim \mathcal N(0, \Sigma)`. A trajectory therefore has
``H`` noise draws and ``H + 1`` states :math:`x_0, \dots, x_H`; its cost is

.. math:: g_i = \sum_{k=0}^{H-1} g(x_k^i, u_k) + g_H(x_H^i).

* **Non-overlapping sampling** (paper Fig. 1b): ``P`` independent trajectories, no shared nodes.
* **Tree sampling** (paper Fig. 1a): at every step ``k`` draw ``N`` noise values
  :math:`w_k^1..w_k^N` and branch every current node ``N`` ways. With ``shared_draws=True``
  (the paper's construction, :math:`x_2^{i,j} = f(x_1^i, u_1, w_1^j)`) the same ``N`` values
  are used by every node of level ``k``; with ``shared_draws=False`` each node draws its own
  ``N`` children. Without pruning the tree has :math:`N^H` leaves (one branching per noise
  draw; the paper counts :math:`N^{H-1}` because its stage costs stop at :math:`x_{H-1}`).
* **Likeliness** of a noise sample is its probability density :math:`\phi_\Sigma(w)`; the
  likeliness of a trajectory is the product over its steps, stored as the sum of log-densities.
* **Pruning to M**: after each branching, if more than ``M`` nodes exist, keep the ``M`` with the
  highest trajectory likeliness (ties broken by lower index) and drop the rest.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from rsmhp.core import guards

__all__ = [
    "GaussianNoise",
    "System",
    "Trajectories",
    "TreeLevel",
    "TreeSample",
    "check_controls",
    "check_initial_state",
    "rollout",
    "rollout_cost",
    "sample_independent",
    "sample_tree",
    "sample_tree_batch",
    "top_m",
]


class GaussianNoise:
    r"""Zero-mean Gaussian noise :math:`w \sim \mathcal N(0, \Sigma)` of dimension ``d``.

    Parameters
    ----------
    cov : (d, d) array_like or scalar variance
        Covariance :math:`\Sigma` (symmetric positive definite). A scalar means ``d = 1``.
    """

    def __init__(self, cov: float | np.ndarray) -> None:
        cov = np.atleast_2d(guards.finite_array("noise covariance cov", cov))
        if cov.ndim != 2 or cov.shape[0] != cov.shape[1] or cov.shape[0] == 0:
            raise ValueError(
                f"noise covariance cov must be a non-empty square matrix, got shape {cov.shape}"
            )
        if not (np.array_equal(cov, cov.T) or np.allclose(cov, cov.T)):
            raise ValueError(
                f"noise covariance cov must be symmetric, got max |cov - cov^T| = "
                f"{np.abs(cov - cov.T).max():.3g}"
            )
        self.cov = cov
        self.dim = cov.shape[0]
        try:
            self._chol = np.linalg.cholesky(cov)
        except np.linalg.LinAlgError:
            low = np.linalg.eigvalsh(0.5 * (cov + cov.T))[0]
            raise guards.NotPositiveDefiniteError(
                f"noise covariance cov must be positive definite, got smallest eigenvalue {low:.6g}"
            ) from None
        self._log_norm = -0.5 * (self.dim * np.log(2 * np.pi)) - np.sum(np.log(np.diag(self._chol)))

    @property
    def rowwise(self) -> bool:
        """Whether :meth:`logpdf` of a row is independent of the rest of the batch, bit for bit
        (then the tree evaluates each shared draw once). True for ``d = 1`` (elementwise); a
        batched LAPACK solve (``d > 1``) may round a row differently in batches of other sizes.
        """
        return self.dim == 1

    @property
    def chol(self) -> np.ndarray:
        r"""Lower Cholesky factor :math:`L`, :math:`L L^\top = \Sigma`, shape (d, d)."""
        return self._chol

    @property
    def log_norm(self) -> float:
        r"""Log normalising constant :math:`-\tfrac d2 \log 2\pi - \sum_i \log L_{ii}`."""
        return float(self._log_norm)

    @property
    def mean(self) -> np.ndarray:
        """The nominal noise value used by NBO, :math:`\\bar w = 0`, shape (d,)."""
        return np.zeros(self.dim)

    def sample(self, rng: np.random.Generator, size: int | tuple[int, ...]) -> np.ndarray:
        """Draw noise, shape ``(*size, d)``: :math:`w = L z`, :math:`z \\sim \\mathcal N(0, I)`."""
        size = (size,) if isinstance(size, (int, np.integer)) else tuple(size)
        z = rng.standard_normal((*size, self.dim))
        return z @ self._chol.T

    def logpdf(self, w: np.ndarray) -> np.ndarray:
        r"""Log density :math:`\log\phi_\Sigma(w)`; ``w`` shape ``(..., d)``, result ``(...)``."""
        w = np.asarray(w, dtype=float)
        # solve L y = w  =>  w^T Sigma^{-1} w = |y|^2
        flat = w.reshape(-1, self.dim)
        y = np.linalg.solve(self._chol, flat.T).T if self.dim > 1 else flat / self._chol[0, 0]
        return (self._log_norm - 0.5 * np.sum(y * y, axis=-1)).reshape(w.shape[:-1])


class System(Protocol):
    """A discrete-time stochastic system with additive-or-not Gaussian noise, vectorized.

    ``x`` has shape ``(n, dx)``, ``w`` shape ``(n, dw)``, ``u_k`` the control at step ``k``.
    """

    noise: GaussianNoise

    def step(self, x: np.ndarray, u_k: np.ndarray, w: np.ndarray) -> np.ndarray:
        """:math:`x_{k+1} = f(x_k, u_k, w_k)`, shape (n, dx)."""
        ...

    def stage_cost(self, x: np.ndarray, u_k: np.ndarray) -> np.ndarray:
        """:math:`g(x_k, u_k)`, shape (n,)."""
        ...

    def terminal_cost(self, x: np.ndarray) -> np.ndarray:
        """:math:`g_H(x_H)`, shape (n,)."""
        ...


@dataclass(frozen=True)
class Trajectories:
    """A set of sampled trajectories.

    Attributes
    ----------
    states : (n, H+1, dx)  states :math:`x_0..x_H` of every trajectory
    noise : (n, H, dw)     noise draws :math:`w_0..w_{H-1}`
    log_likeliness : (n,)  :math:`\\sum_k \\log\\phi(w_k)` (log of the trajectory likeliness)
    cost : (n,)            :math:`g_i`, the cumulative cost of every trajectory
    """

    states: np.ndarray
    noise: np.ndarray
    log_likeliness: np.ndarray
    cost: np.ndarray

    def __len__(self) -> int:
        return int(self.cost.shape[0])


@dataclass(frozen=True)
class TreeLevel:
    """One level ``k+1`` of a sampled tree, *before* pruning.

    Attributes
    ----------
    states : (n_children, dx)  :math:`x_{k+1}` of every child
    parent : (n_children,)     index of the parent among the *kept* nodes of level ``k``
    log_likeliness : (n_children,)
    kept : (n_children,) bool  survived pruning at this level
    """

    states: np.ndarray
    parent: np.ndarray
    log_likeliness: np.ndarray
    kept: np.ndarray


@dataclass(frozen=True)
class TreeSample:
    """Leaves of a (possibly pruned) tree and, optionally, its level-by-level history."""

    leaves: Trajectories
    history: list[TreeLevel] = field(default_factory=list)


def check_controls(u: np.ndarray | list[float]) -> np.ndarray:
    """The control sequence ``u`` as a finite float array of shape ``(H,)`` or ``(H, m)``,
    ``H >= 1`` (raises ``ValueError`` otherwise)."""
    u = guards.finite_array("u", u)
    if u.ndim == 0 or u.shape[0] == 0:
        raise ValueError(
            f"control sequence u must have at least one step (length H >= 1), got shape {u.shape}"
        )
    if u.ndim > 2:
        raise ValueError(f"control sequence u must have shape (H,) or (H, m), got {u.shape}")
    return u


def check_initial_state(system: System, x0: np.ndarray) -> None:
    """Raise ``ValueError`` unless ``x0`` is a finite scalar or 1-D state (of the system's
    dimension ``d`` when it has one)."""
    x = guards.finite_array("x0", x0, ndim=(0, 1), nonempty=True)
    d = getattr(system, "d", None)
    if isinstance(d, int) and x.size != d:
        raise ValueError(f"x0 must have {d} entries (the state dimension), got shape {x.shape}")


def top_m(log_likeliness: np.ndarray, m: int) -> np.ndarray:
    """Indices of the ``m`` largest entries, sorted by decreasing likeliness, ties by index.

    Returns all indices (in that order) when ``m >= len(log_likeliness)``.
    """
    m = guards.positive_int("M", m)
    neg = -np.asarray(log_likeliness, dtype=float)
    if m >= neg.size or np.isnan(neg).any():
        return np.argsort(neg, kind="stable")[:m]
    # the same indices as the stable full sort, in O(n): every entry up to the m-th smallest
    # value (ties at the boundary included, in index order), then a stable sort of those
    kth = np.partition(neg, m - 1)[m - 1]
    cand = np.flatnonzero(neg <= kth)
    return cand[np.argsort(neg[cand], kind="stable")][:m]


def _propagate(
    system: System, x0: np.ndarray, u: np.ndarray, noise: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """States (n, H+1, dx) and costs (n,) of given noise sequences (n, H, dw)."""
    horizon = u.shape[0]
    if noise.ndim != 3 or noise.shape[1] != horizon or noise.shape[2] != system.noise.dim:
        raise ValueError(
            f"noise must have shape (n, H={horizon}, dw={system.noise.dim}), got {noise.shape}"
        )
    n = noise.shape[0]
    x0 = np.atleast_1d(np.asarray(x0, dtype=float))
    x = np.broadcast_to(x0, (n, x0.size)).copy()
    states = np.empty((n, horizon + 1, x.shape[1]))
    states[:, 0] = x
    cost = np.zeros(n)
    for k in range(horizon):
        cost += system.stage_cost(x, u[k])
        x = system.step(x, u[k], noise[:, k])
        states[:, k + 1] = x
    cost += system.terminal_cost(x)
    return states, cost


def rollout(
    system: System, x0: np.ndarray, u: np.ndarray | list[float], noise: np.ndarray
) -> Trajectories:
    """Propagate given noise sequences: ``noise`` has shape ``(n, H, dw)`` with ``H = len(u)``.

    Every sampler (plain Monte Carlo, antithetic, quasi-Monte Carlo, quadrature nodes) produces
    noise sequences and calls this; the trajectory costs it returns are then averaged.
    """
    check_initial_state(system, x0)
    noise = np.asarray(noise, dtype=float)
    states, cost = _propagate(system, x0, check_controls(u), noise)
    loglik = system.noise.logpdf(noise).sum(axis=1)
    return Trajectories(states=states, noise=noise, log_likeliness=loglik, cost=cost)


def rollout_cost(
    system: System, x0: np.ndarray, u: np.ndarray | list[float], noise: np.ndarray
) -> np.ndarray:
    """Only the costs (n,) of :func:`rollout` (same arithmetic), without the likeliness, for
    estimators that do not weight by it."""
    check_initial_state(system, x0)
    return _propagate(system, x0, check_controls(u), np.asarray(noise, dtype=float))[1]


def sample_independent(
    system: System, x0: np.ndarray, u: np.ndarray | list[float], n: int, rng: np.random.Generator
) -> Trajectories:
    """Non-overlapping sampling (Fig. 1b): ``n`` independent trajectories from ``x0`` under ``u``.

    Noise is drawn as one ``(n, H, dw)`` block from ``rng`` and propagated by :func:`rollout`.
    """
    u = check_controls(u)
    n = guards.positive_int("n (number of trajectories)", n)
    guards.generator("rng", rng)
    check_initial_state(system, x0)
    return rollout(system, x0, u, system.noise.sample(rng, (n, u.shape[0])))


def sample_tree(
    system: System,
    x0: np.ndarray,
    u: np.ndarray | list[float],
    n_branch: int,
    rng: np.random.Generator,
    *,
    max_keep: int | None = None,
    shared_draws: bool = True,
    keep_history: bool = False,
    level_noise: Sequence[GaussianNoise] | None = None,
) -> TreeSample:
    """Tree sampling with ``N = n_branch`` draws per step (Fig. 1a), optionally pruned to ``M``.

    At step ``k`` the kept nodes (``n_k`` of them) branch ``N`` ways; the ``n_k N`` children get
    likeliness ``parent * phi(w)``; if ``max_keep`` is set and ``n_k N > M`` only the top ``M``
    children (by likeliness) are kept. Without pruning there are ``N^H`` leaves.

    Parameters
    ----------
    shared_draws : the paper's tree (same ``N`` noise values for every node of a level) if True,
        otherwise every node draws its own ``N`` children.
    keep_history : record every level before pruning (for recordings/diagnostics).
    level_noise : optional noise model of every level (length H), e.g. an initial-state
        level with its own covariance; default ``system.noise`` at every level. The noise
        paths in the result then need a common dimension.
    """
    u = check_controls(u)
    n_branch = guards.positive_int("N (draws per step)", n_branch)
    if max_keep is not None:
        max_keep = guards.positive_int("M (trajectories kept)", max_keep)
    guards.generator("rng", rng)
    check_initial_state(system, x0)
    horizon = u.shape[0]
    if max_keep is None and n_branch**horizon > 20_000_000:
        raise ValueError(
            f"an unpruned tree with N={n_branch}, H={horizon} has {n_branch**horizon} leaves; "
            "set M (pruning) or reduce N/H"
        )
    levels = [system.noise] * u.shape[0] if level_noise is None else list(level_noise)
    if len(levels) != u.shape[0]:
        raise ValueError(
            f"level_noise needs one noise model per level ({u.shape[0]}), got {len(levels)}"
        )
    for k, level in enumerate(levels):
        guards.instance_of(f"level_noise[{k}]", level, GaussianNoise)
    noise = levels[0]
    x = np.atleast_1d(np.asarray(x0, dtype=float))[None, :]
    paths = x[:, None, :]  # (n, k+1, dx)
    w_paths = np.empty((1, 0, noise.dim))
    loglik = np.zeros(1)
    cost = np.zeros(1)
    history: list[TreeLevel] = []
    for k in range(horizon):
        noise = levels[k]
        n_nodes = x.shape[0]
        if shared_draws:
            w_new = noise.sample(rng, n_branch)  # (N, dw)
            w_child = np.tile(w_new, (n_nodes, 1))
            # the same N densities for every node: evaluate them once where that is exact
            ll_w = np.tile(noise.logpdf(w_new), n_nodes) if noise.rowwise else None
        else:
            w_child = noise.sample(rng, (n_nodes, n_branch)).reshape(-1, noise.dim)
            ll_w = None
        if ll_w is None:
            ll_w = noise.logpdf(w_child)
        parent = np.repeat(np.arange(n_nodes), n_branch)
        cost_parent = cost + system.stage_cost(x, u[k])
        x_child = system.step(x[parent], u[k], w_child)
        ll_child = loglik[parent] + ll_w
        if max_keep is not None and x_child.shape[0] > max_keep:
            keep = np.sort(top_m(ll_child, max_keep))  # keep tree order for readability
        else:
            keep = np.arange(x_child.shape[0])
        if keep_history:
            kept_mask = np.zeros(x_child.shape[0], dtype=bool)
            kept_mask[keep] = True
            history.append(TreeLevel(x_child, parent, ll_child, kept_mask))
        sel = parent[keep]
        paths = np.concatenate([paths[sel], x_child[keep][:, None, :]], axis=1)
        w_paths = np.concatenate([w_paths[sel], w_child[keep][:, None, :]], axis=1)
        x, loglik, cost = x_child[keep], ll_child[keep], cost_parent[sel]
    cost = cost + system.terminal_cost(x)
    leaves = Trajectories(states=paths, noise=w_paths, log_likeliness=loglik, cost=cost)
    return TreeSample(leaves=leaves, history=history)


def sample_tree_batch(
    system: System,
    x0: np.ndarray,
    u: np.ndarray | list[float],
    n_branch: int,
    rngs: Sequence[np.random.Generator],
    *,
    max_keep: int | None = None,
    shared_draws: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """``R = len(rngs)`` independent trees at once: leaf costs and log-likeliness, (R, m) each.

    Tree ``r`` is :func:`sample_tree` with generator ``rngs[r]`` (same draws in the same
    order, same pruning, ties broken the same way); only the arithmetic runs on all trees
    together. When the system's step and costs act row by row and ``system.noise.rowwise``
    holds (every scalar problem here), the result equals :func:`sample_tree` bit for bit
    (tested); otherwise it agrees up to rounding. Leaves are in tree order, as in
    :func:`sample_tree`.
    """
    u = check_controls(u)
    n_branch = guards.positive_int("N (draws per step)", n_branch)
    if max_keep is not None:
        max_keep = guards.positive_int("M (trajectories kept)", max_keep)
    rngs = list(rngs)
    if not rngs:
        raise ValueError("need at least one generator (one tree per generator)")
    for r, g in enumerate(rngs):
        guards.generator(f"rngs[{r}]", g)
    check_initial_state(system, x0)
    horizon, noise = u.shape[0], system.noise
    n_trees, dw = len(rngs), noise.dim
    x0 = np.atleast_1d(np.asarray(x0, dtype=float))
    dx = x0.size
    x = np.broadcast_to(x0, (n_trees, 1, dx)).copy()
    loglik = np.zeros((n_trees, 1))
    cost = np.zeros((n_trees, 1))
    for k in range(horizon):
        n_nodes = x.shape[1]
        n_child = n_nodes * n_branch
        if shared_draws:
            w_new = np.stack([noise.sample(g, n_branch) for g in rngs])  # (R, N, dw)
            w_child = np.tile(w_new, (1, n_nodes, 1))
            if noise.rowwise:
                ll_w = np.tile(noise.logpdf(w_new), (1, n_nodes))
            else:
                ll_w = noise.logpdf(w_child)
        else:
            w_child = np.stack([noise.sample(g, (n_nodes, n_branch)).reshape(-1, dw) for g in rngs])
            ll_w = noise.logpdf(w_child)
        parent = np.repeat(np.arange(n_nodes), n_branch)
        stage = system.stage_cost(x.reshape(-1, dx), u[k]).reshape(n_trees, n_nodes)
        cost_parent = cost + stage
        x_child = system.step(x[:, parent].reshape(-1, dx), u[k], w_child.reshape(-1, dw)).reshape(
            n_trees, n_child, dx
        )
        ll_child = loglik[:, parent] + ll_w
        if max_keep is not None and n_child > max_keep:
            order = np.argsort(-ll_child, axis=1, kind="stable")[:, :max_keep]
            keep = np.sort(order, axis=1)
        else:
            keep = np.broadcast_to(np.arange(n_child), (n_trees, n_child))
        x = np.take_along_axis(x_child, keep[..., None], axis=1)
        loglik = np.take_along_axis(ll_child, keep, axis=1)
        cost = np.take_along_axis(cost_parent[:, parent], keep, axis=1)
    m = x.shape[1]
    cost = cost + system.terminal_cost(x.reshape(-1, dx)).reshape(n_trees, m)
    return cost, loglik
