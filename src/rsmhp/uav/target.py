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
* :func:`sample_tree` (RS-MHP, tree with pruning): level 0 draws ``N`` initial states, every
  later level draws ``N`` process-noise values shared by all nodes of the level and branches
  every node ``N`` ways; after each level only the ``M`` trajectories of highest likeliness
  survive. Likeliness of a draw is its Gaussian density (of :math:`x_0` under
  :math:`\mathcal N(\hat x, \hat P)`, of :math:`w` under :math:`\mathcal N(0, Q)`); a
  trajectory's likeliness is the product, kept as a sum of logs. This is the convention of
  :mod:`rsmhp.sampling`, with the initial-state draw as an extra tree level.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from rsmhp.sampling import GaussianNoise, top_m
from rsmhp.sampling import sample_tree as _sample_tree

__all__ = [
    "HypothesisNoise",
    "TargetModel",
    "nominal",
    "process_noise",
    "sample_independent",
    "sample_tree",
    "transition_matrix",
]


def transition_matrix(dt: float) -> np.ndarray:
    """NCV transition matrix F (4, 4)."""
    F = np.eye(4)
    F[0, 2] = F[1, 3] = dt
    return F


def process_noise(dt: float, q: float) -> np.ndarray:
    """NCV process-noise covariance Q (4, 4), white-noise acceleration of intensity ``q``."""
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

    @classmethod
    def from_config(cls, uav: Mapping[str, Any]) -> TargetModel:
        return cls(dt=float(uav["dt"]), q=float(uav["target"]["q"]))

    @property
    def F(self) -> np.ndarray:
        return transition_matrix(self.dt)

    @property
    def Q(self) -> np.ndarray:
        return process_noise(self.dt, self.q)

    @cached_property
    def noise(self) -> GaussianNoise:
        r""":math:`\mathcal N(0, Q)` with its Cholesky factor (built once per model)."""
        return HypothesisNoise(self.Q)


class HypothesisNoise(GaussianNoise):
    r""":class:`rsmhp.sampling.GaussianNoise` whose log-density solves :math:`L y = w` by
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
    out = np.empty_like(w)
    cur = x0
    for j in range(w.shape[1]):
        cur = cur @ F.T + w[:, j]
        out[:, j] = cur
    return out


def nominal(x_hat: np.ndarray, horizon: int, model: TargetModel) -> np.ndarray:
    """NBO hypothesis: ``(1, H, 4)`` with :math:`x_j = F^j \\hat x`."""
    x0 = np.asarray(x_hat, dtype=float).reshape(1, 4)
    return _propagate(x0, np.zeros((1, horizon, 4)), model.F)


def sample_independent(
    x_hat: np.ndarray,
    P_hat: np.ndarray,
    horizon: int,
    n: int,
    model: TargetModel,
    rng: np.random.Generator,
) -> np.ndarray:
    """``n`` non-overlapping hypotheses ``(n, H, 4)``.

    Stream order: ``n x 4`` standard normals for the initial states, then ``n x H x 4`` for the
    process noise.
    """
    z0 = rng.standard_normal((n, 4))
    x0 = np.asarray(x_hat, dtype=float) + z0 @ _chol(P_hat).T
    w = rng.standard_normal((n, horizon, 4)) @ _chol(model.Q).T
    return _propagate(x0, w, model.F)


@dataclass(frozen=True)
class _Hypotheses:
    r"""Target hypotheses as a :class:`rsmhp.sampling.System` for the shared tree sampler.

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


def sample_tree(
    x_hat: np.ndarray,
    P_hat: np.ndarray,
    horizon: int,
    n_branch: int,
    max_keep: int,
    model: TargetModel,
    rng: np.random.Generator,
) -> tuple[np.ndarray, np.ndarray]:
    r"""Pruned tree of hypotheses: ``(states (m, H, 4), log_likeliness (m,))``, ``m <= M``.

    :func:`rsmhp.sampling.sample_tree` with ``H + 1`` levels (paper Fig. 1a, shared draws):
    level 0 draws ``N`` initial states from :math:`\mathcal N(\hat x, \hat P)`, levels
    ``1..H`` draw ``N`` process-noise values :math:`w \sim \mathcal N(0, Q)` shared by all
    nodes; after every level the ``M`` most likely trajectories are kept. Survivors are
    returned sorted by decreasing likeliness (ties by tree order).
    """
    noise = model.noise
    system = _Hypotheses(F=model.F, noise=noise)
    levels = [HypothesisNoise(0.5 * (P_hat + P_hat.T))] + [noise] * horizon
    tree = _sample_tree(
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
