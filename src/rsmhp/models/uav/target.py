r"""Near-constant-velocity (NCV) target and its sampled future hypotheses.

State :math:`x = (p_x, p_y, v_x, v_y)` (m, m/s), :math:`x_{k+1} = F x_k + w_k`,
:math:`w_k \sim \mathcal N(0, Q)` with

.. math::
    F = \begin{bmatrix} I_2 & \Delta t\, I_2 \\ 0 & I_2 \end{bmatrix}, \qquad
    Q = q \begin{bmatrix} \tfrac{\Delta t^3}{3} I_2 & \tfrac{\Delta t^2}{2} I_2 \\
    \tfrac{\Delta t^2}{2} I_2 & \Delta t\, I_2 \end{bmatrix}
    \quad (q \text{ in m}^2/\text{s}^3).

Planner hypotheses are arrays of future target states ``(n_traj, H, 4)``: entry ``j`` is the
state ``j + 1`` steps ahead. Three generators:

* :func:`nominal` (NBO): one trajectory, :math:`x_j = F^j \hat x` (all noise at its mean 0).
* :func:`sample_independent` (RS-MHP, non-overlapping): ``n`` trajectories,
  :math:`x_0^i \sim \mathcal N(\hat x, \hat P)`, :math:`x_j^i = F x_{j-1}^i + w_j^i`.
* :func:`pruned_tree` (RS-MHP, tree with pruning): level 0 draws ``N`` initial states, every
  later level draws ``N`` process-noise values shared by all nodes of the level and branches
  every node ``N`` ways; after each level only the ``M`` trajectories of highest likeliness
  survive. Likeliness of a draw is its Gaussian density (of :math:`x_0` under
  :math:`\mathcal N(\hat x, \hat P)`, of :math:`w` under :math:`\mathcal N(0, Q)`); a
  trajectory's likeliness is the product, kept as a sum of logs. This is the convention of
  :mod:`rsmhp.core.sampling`, with the initial-state draw as an extra tree level.

  With shared draws the pruning depends only on the likeliness of the draws, never on the
  states, so :func:`pruned_tree` runs the expansion, pruning and propagation of the kept
  nodes in one compiled routine (numba, on-disk cache); :func:`pruned_tree_reference`, the
  generic :func:`rsmhp.core.sampling.sample_tree`, is its test oracle (same random stream, same
  likeliness values bit for bit, same kept leaves in the same order, states equal up to the
  rounding of the 4 x 4 product).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from numba import njit

from rsmhp.core import guards
from rsmhp.core.sampling import GaussianNoise, sample_tree, top_m

__all__ = [
    "HypothesisNoise",
    "TargetModel",
    "draw_independent",
    "from_normals",
    "nominal",
    "process_noise",
    "pruned_tree",
    "pruned_tree_reference",
    "sample_independent",
    "transition_matrix",
    "warm_up",
]


def transition_matrix(dt: float) -> np.ndarray:
    """NCV transition matrix F (4, 4); ``dt`` > 0."""
    guards.real("dt", dt, lo=0.0, lo_open=True)
    return _transition_matrix(dt)


def _transition_matrix(dt: float) -> np.ndarray:
    F = np.eye(4)
    F[0, 2] = F[1, 3] = dt
    return F


def process_noise(dt: float, q: float) -> np.ndarray:
    """NCV process-noise covariance Q (4, 4), white-noise acceleration of intensity ``q``
    (``dt`` > 0, ``q`` >= 0)."""
    guards.real("dt", dt, lo=0.0, lo_open=True)
    guards.real("q", q, lo=0.0)
    return _process_noise(dt, q)


def _process_noise(dt: float, q: float) -> np.ndarray:
    Q = np.zeros((4, 4))
    for i in range(2):
        Q[i, i] = dt**3 / 3
        Q[i, i + 2] = Q[i + 2, i] = dt**2 / 2
        Q[i + 2, i + 2] = dt
    return q * Q


@dataclass(frozen=True)
class TargetModel:
    """NCV model with time step ``dt`` (s) and noise intensity ``q`` (m²/s³)."""

    dt: float
    q: float

    def __post_init__(self) -> None:
        guards.real("TargetModel.dt", self.dt, lo=0.0, lo_open=True)
        # q = 0 makes Q singular: no Cholesky factor for the truth noise and the hypotheses
        guards.real("TargetModel.q", self.q, lo=0.0, lo_open=True)

    @classmethod
    def from_config(cls, uav: Mapping[str, Any]) -> TargetModel:
        return cls(dt=float(uav["dt"]), q=float(uav["target"]["q"]))

    @property
    def F(self) -> np.ndarray:
        return _transition_matrix(self.dt)

    @property
    def Q(self) -> np.ndarray:
        return _process_noise(self.dt, self.q)

    @cached_property
    def noise(self) -> GaussianNoise:
        r""":math:`\mathcal N(0, Q)` with its Cholesky factor (built once per model)."""
        return HypothesisNoise(self.Q)


class HypothesisNoise(GaussianNoise):
    r""":class:`rsmhp.core.sampling.GaussianNoise` whose log-density solves :math:`L y = w` by
    forward substitution, column by column over the whole batch,
    :math:`y_i = (w_i - \sum_{j<i} L_{ij} y_j) / L_{ii}`, instead of a general LU solve:
    several times faster for the tree's hundreds of 4-D draws per level, and every row's
    value independent of the batch it is evaluated in (a batched LAPACK solve is not)."""

    @property
    def rowwise(self) -> bool:
        return True

    def logpdf(self, w: np.ndarray) -> np.ndarray:
        w = np.asarray(w, dtype=float)
        flat = w.reshape(-1, self.dim)
        L = self.chol
        y = np.empty_like(flat)
        quad = np.zeros(flat.shape[0])
        for i in range(self.dim):
            acc = flat[:, i].copy()
            for j in range(i):
                acc -= L[i, j] * y[:, j]
            y[:, i] = acc / L[i, i]
            quad += y[:, i] * y[:, i]
        return (self._log_norm - 0.5 * quad).reshape(w.shape[:-1])


def _chol(P: np.ndarray) -> np.ndarray:
    """Cholesky factor of the symmetrised covariance."""
    return np.linalg.cholesky(0.5 * (P + P.T))


def _propagate(x0: np.ndarray, w: np.ndarray, F: np.ndarray) -> np.ndarray:
    """``x0`` (n, 4), ``w`` (n, H, 4) -> states (n, H, 4) with x_j = F x_{j-1} + w_j."""
    return _propagate_kernel(
        np.ascontiguousarray(x0, dtype=float),
        np.ascontiguousarray(w, dtype=float),
        np.ascontiguousarray(F, dtype=float),
        np.empty(np.shape(w)),
    )


@njit(cache=True, nogil=True)
def _propagate_kernel(x0, w, F, out):  # pragma: no cover - compiled
    """:func:`_propagate` in compiled loops: (F x)_r = sum_c F[r, c] x_c in order c = 0..3
    (a small-matrix product written out; numpy's may sum in another order, so the two agree
    to rounding)."""
    for i in range(w.shape[0]):
        c0, c1, c2, c3 = x0[i, 0], x0[i, 1], x0[i, 2], x0[i, 3]
        for j in range(w.shape[1]):
            n0 = F[0, 0] * c0 + F[0, 1] * c1 + F[0, 2] * c2 + F[0, 3] * c3 + w[i, j, 0]
            n1 = F[1, 0] * c0 + F[1, 1] * c1 + F[1, 2] * c2 + F[1, 3] * c3 + w[i, j, 1]
            n2 = F[2, 0] * c0 + F[2, 1] * c1 + F[2, 2] * c2 + F[2, 3] * c3 + w[i, j, 2]
            n3 = F[3, 0] * c0 + F[3, 1] * c1 + F[3, 2] * c2 + F[3, 3] * c3 + w[i, j, 3]
            c0, c1, c2, c3 = n0, n1, n2, n3
            out[i, j, 0], out[i, j, 1], out[i, j, 2], out[i, j, 3] = c0, c1, c2, c3
    return out


def _check_estimate(
    x_hat: np.ndarray, P_hat: np.ndarray | None, horizon: int, model: TargetModel
) -> int:
    """The arguments every hypothesis generator shares; returns ``horizon`` (an int)."""
    guards.finite_array("x_hat", x_hat, shape=(4,))
    if P_hat is not None:
        guards.spd_matrix("P_hat", P_hat, size=4)
    guards.instance_of("model", model, TargetModel)
    return guards.positive_int("horizon", horizon)


def nominal(
    x_hat: np.ndarray, horizon: int, model: TargetModel, *, check: bool = True
) -> np.ndarray:
    """NBO hypothesis: ``(1, H, 4)`` with :math:`x_j = F^j \\hat x`.

    ``check=False`` skips the argument checks (the closed loop, whose inputs are checked
    once per run, plans with it)."""
    if check:
        horizon = _check_estimate(x_hat, None, horizon, model)
    x0 = np.asarray(x_hat, dtype=float).reshape(1, 4)
    return _propagate(x0, np.zeros((1, horizon, 4)), model.F)


def sample_independent(
    x_hat: np.ndarray,
    P_hat: np.ndarray,
    horizon: int,
    n: int,
    model: TargetModel,
    rng: np.random.Generator,
    *,
    check: bool = True,
) -> np.ndarray:
    """``n`` non-overlapping hypotheses ``(n, H, 4)``.

    Stream order: ``n x 4`` standard normals for the initial states, then ``n x H x 4`` for the
    process noise. ``check=False`` skips the argument checks (see :func:`nominal`).
    """
    return draw_independent(x_hat, P_hat, horizon, n, model, rng, check=check)[0]


def draw_independent(
    x_hat: np.ndarray,
    P_hat: np.ndarray,
    horizon: int,
    n: int,
    model: TargetModel,
    rng: np.random.Generator,
    *,
    check: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`sample_independent` with its draws: ``(states (n, H, 4), noise (n, H + 1, 4))``,
    ``noise[:, 0]`` the initial-state deviation :math:`x_0 - \\hat x`, ``noise[:, j]`` the
    process noise :math:`w_j` (same stream, same states)."""
    if check:
        horizon = _check_estimate(x_hat, P_hat, horizon, model)
        n = guards.positive_int("n", n)
        guards.generator("rng", rng)
    z0 = rng.standard_normal((n, 4))
    dev = z0 @ _chol(P_hat).T
    x0 = np.asarray(x_hat, dtype=float) + dev
    # one (n H, 4) x (4, 4) product (a batched (n, H, 4) product is n small ones: 10x slower)
    w = (rng.standard_normal((n * horizon, 4)) @ model.noise.chol.T).reshape(n, horizon, 4)
    return _propagate(x0, w, model.F), np.concatenate([dev[:, None, :], w], axis=1)


def from_normals(
    x_hat: np.ndarray,
    P_hat: np.ndarray,
    z: np.ndarray,
    model: TargetModel,
    *,
    check: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    r"""Hypotheses from standard-normal coordinates ``z`` (n, H + 1, 4), for point sets other
    than i.i.d. draws (quasi-Monte Carlo, antithetic pairs, sigma points): the initial
    deviation :math:`x_0 - \hat x = L_P z_0` with :math:`L_P L_P^\top = \hat P`, the process
    noise :math:`w_j = L_Q z_j` with :math:`L_Q L_Q^\top = Q`, and :math:`x_j = F x_{j-1} +
    w_j`. Returns ``(states (n, H, 4), noise (n, H + 1, 4))`` as :func:`draw_independent`
    does; ``z`` drawn i.i.d. standard normal gives hypotheses with exactly its distribution.
    A point set whose weighted mean is 0 and weighted second moment the identity gives
    hypotheses whose weighted mean and covariance are those of the belief's (the map is
    linear)."""
    z = np.asarray(z, dtype=float)
    if check:
        if z.ndim != 3 or z.shape[0] == 0 or z.shape[1] < 2 or z.shape[2] != 4:
            raise ValueError(f"z must have shape (n, H + 1, 4) with n, H >= 1, got {z.shape}")
        _check_estimate(x_hat, P_hat, z.shape[1] - 1, model)
        guards.finite_array("z", z)
    n, h1 = z.shape[0], z.shape[1]
    dev = z[:, 0] @ _chol(P_hat).T
    x0 = np.asarray(x_hat, dtype=float) + dev
    w = (z[:, 1:].reshape(n * (h1 - 1), 4) @ model.noise.chol.T).reshape(n, h1 - 1, 4)
    return _propagate(x0, w, model.F), np.concatenate([dev[:, None, :], w], axis=1)


@dataclass(frozen=True)
class _Hypotheses:
    r"""Target hypotheses as a :class:`rsmhp.core.sampling.System` for the shared tree sampler.

    Level 0 (control index ``u_0 = 0``) draws the current state: :math:`x = \hat x + w_0`,
    :math:`w_0 \sim \mathcal N(0, \hat P)`; levels ``j >= 1`` propagate :math:`x \leftarrow
    F x + w_j`, :math:`w_j \sim \mathcal N(0, Q)`. Costs are zero (the planner evaluates
    hypotheses with its own kernel).
    """

    F: np.ndarray
    noise: GaussianNoise

    def step(self, x: np.ndarray, u_k: float, w: np.ndarray) -> np.ndarray:
        return x + w if u_k == 0 else x @ self.F.T + w

    def stage_cost(self, x: np.ndarray, u_k: float) -> np.ndarray:
        return np.zeros(x.shape[0])

    def terminal_cost(self, x: np.ndarray) -> np.ndarray:
        return np.zeros(x.shape[0])


def _tree_levels(
    P_hat: np.ndarray, horizon: int, n_branch: int, max_keep: int, model: TargetModel
) -> list[GaussianNoise]:
    """Checked arguments; the noise model of every level (H + 1): initial state, then Q."""
    guards.positive_int("horizon", horizon)
    guards.positive_int("N (draws per level)", n_branch)
    guards.positive_int("M (trajectories kept)", max_keep)
    P_hat = np.asarray(P_hat, dtype=float)
    if P_hat.shape != (4, 4):
        raise ValueError(f"P_hat must have shape (4, 4), got {P_hat.shape}")
    return [HypothesisNoise(0.5 * (P_hat + P_hat.T))] + [model.noise] * horizon


def _check_tree(x_hat, P_hat, horizon, n_branch, max_keep, model, rng) -> tuple[int, int, int]:
    """The tree generators' arguments; returns ``(horizon, N, M)`` as integers."""
    horizon = _check_estimate(x_hat, None, horizon, model)
    n_branch = guards.positive_int("N (draws per level)", n_branch)
    max_keep = guards.positive_int("M (trajectories kept)", max_keep)
    guards.spd_matrix("P_hat", P_hat, size=4)
    guards.generator("rng", rng)
    return horizon, n_branch, max_keep


@njit(cache=True, inline="always")
def _keep_top(child_ll, max_keep):  # pragma: no cover - compiled
    """Indices (ascending) of the ``max_keep`` largest entries, ties broken by lower index
    (the set a stable descending sort would keep); linear time via a partition."""
    n = child_ll.shape[0]
    thr = -np.partition(-child_ll, max_keep - 1)[max_keep - 1]  # the max_keep-th largest
    n_above = 0
    for c in range(n):
        if child_ll[c] > thr:
            n_above += 1
    room = max_keep - n_above  # entries equal to the threshold still kept, first ones first
    keep = np.empty(max_keep, dtype=np.int64)
    r = 0
    for c in range(n):
        v = child_ll[c]
        if v > thr:
            keep[r] = c
            r += 1
        elif v == thr and room > 0:
            keep[r] = c
            r += 1
            room -= 1
    return keep


@njit(cache=True, nogil=True)
def _pruned_tree_kernel(x_hat, F, z, chols, log_norms, max_keep):  # pragma: no cover
    """The tree from standard normals ``z`` (L, N, 4): level draws :math:`w = L_k z`, their
    log-densities by forward substitution (as :class:`HypothesisNoise`), expansion, pruning
    to the ``max_keep`` most likely (ties by tree order) and propagation of the kept nodes;
    returns the kept leaves' paths (m, L, 4) in tree order and their log-likeliness (m,)."""
    n_lv, n_b = z.shape[0], z.shape[1]
    w = np.empty((n_lv, n_b, 4))
    ll_w = np.empty((n_lv, n_b))
    y = np.empty(4)
    for k in range(n_lv):
        L = chols[k]
        for j in range(n_b):
            for a in range(4):
                acc = 0.0
                for b in range(a + 1):
                    acc += z[k, j, b] * L[a, b]
                w[k, j, a] = acc
            quad = 0.0
            for a in range(4):
                acc = w[k, j, a]
                for b in range(a):
                    acc -= L[a, b] * y[b]
                y[a] = acc / L[a, a]
                quad += y[a] * y[a]
            ll_w[k, j] = log_norms[k] - 0.5 * quad
    cap = 1
    for _ in range(n_lv):
        cap = min(cap * n_b, max_keep)
    states = np.empty((n_lv, cap, 4))
    parents = np.empty((n_lv, cap), dtype=np.int64)
    ll = np.zeros(1)
    n = 1
    for k in range(n_lv):
        n_child = n * n_b
        child_ll = np.empty(n_child)
        for i in range(n):
            for j in range(n_b):
                child_ll[i * n_b + j] = ll[i] + ll_w[k, j]
        if n_child > max_keep:
            keep = _keep_top(child_ll, max_keep)
        else:
            keep = np.arange(n_child)
        m = keep.shape[0]
        new_ll = np.empty(m)
        for r in range(m):
            c = keep[r]
            i, j = c // n_b, c % n_b
            parents[k, r] = i
            new_ll[r] = child_ll[c]
            for a in range(4):
                if k == 0:
                    states[k, r, a] = x_hat[a] + w[k, j, a]
                else:
                    acc = 0.0
                    for b in range(4):
                        acc += F[a, b] * states[k - 1, i, b]
                    states[k, r, a] = acc + w[k, j, a]
        ll = new_ll
        n = m
    paths = np.empty((n, n_lv, 4))
    for r in range(n):
        node = r
        for k in range(n_lv - 1, -1, -1):
            paths[r, k] = states[k, node]
            node = parents[k, node]
    return paths, ll


def pruned_tree(
    x_hat: np.ndarray,
    P_hat: np.ndarray,
    horizon: int,
    n_branch: int,
    max_keep: int,
    model: TargetModel,
    rng: np.random.Generator,
    *,
    check: bool = True,
) -> tuple[np.ndarray, np.ndarray]:
    r"""Pruned tree of hypotheses: ``(states (m, H, 4), log_likeliness (m,))``, ``m <= M``.

    The tree of :func:`rsmhp.core.sampling.sample_tree` with ``H + 1`` levels (paper Fig. 1a,
    shared draws): level 0 draws ``N`` initial states from :math:`\mathcal N(\hat x, \hat
    P)`, levels ``1..H`` draw ``N`` process-noise values :math:`w \sim \mathcal N(0, Q)`
    shared by all nodes; after every level the ``M`` most likely trajectories are kept.
    Survivors are returned sorted by decreasing likeliness (ties by tree order). Compiled;
    equal to :func:`pruned_tree_reference` (see the module docstring). ``check=False``
    skips the checks of ``x_hat``, ``P_hat`` (finite, positive definite), ``model`` and
    ``rng`` (see :func:`nominal`).
    """
    if check:
        horizon, n_branch, max_keep = _check_tree(
            x_hat, P_hat, horizon, n_branch, max_keep, model, rng
        )
    levels = _tree_levels(P_hat, horizon, n_branch, max_keep, model)
    # one call draws the same stream as the reference's level-by-level calls
    z = rng.standard_normal((horizon + 1, n_branch, 4))
    chols = np.stack([lv.chol for lv in levels])
    log_norms = np.array([lv.log_norm for lv in levels])
    x_hat = np.asarray(x_hat, dtype=float).reshape(4)
    paths, ll = _pruned_tree_kernel(x_hat, model.F, z, chols, log_norms, int(max_keep))
    order = top_m(ll, len(ll))
    # paths[:, 0] is the drawn current state, then H steps ahead
    return paths[order, 1:], ll[order]


def pruned_tree_reference(
    x_hat: np.ndarray,
    P_hat: np.ndarray,
    horizon: int,
    n_branch: int,
    max_keep: int,
    model: TargetModel,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`pruned_tree` through the generic :func:`rsmhp.core.sampling.sample_tree` (the
    plain reference implementation, used as the test oracle)."""
    horizon, n_branch, max_keep = _check_tree(x_hat, P_hat, horizon, n_branch, max_keep, model, rng)
    levels = _tree_levels(P_hat, horizon, n_branch, max_keep, model)
    system = _Hypotheses(F=model.F, noise=model.noise)
    tree = sample_tree(
        system,
        np.asarray(x_hat, dtype=float),
        np.arange(horizon + 1),
        n_branch,
        rng,
        max_keep=max_keep,
        level_noise=levels,
    )
    order = top_m(tree.leaves.log_likeliness, len(tree.leaves))
    # states[:, 0] is x_hat, states[:, 1] the drawn current state, then H steps ahead
    return tree.leaves.states[order, 2:], tree.leaves.log_likeliness[order]


def warm_up() -> float:
    """Compile (or load from the cache) the hypotheses' kernels (:func:`pruned_tree`,
    :func:`nominal`); returns the seconds it took."""
    import time

    t0 = time.perf_counter()
    model = TargetModel(1.0, 1.0)
    pruned_tree(np.zeros(4), np.eye(4), 1, 2, 1, model, np.random.default_rng(0))
    nominal(np.zeros(4), 2, model)
    return time.perf_counter() - t0
