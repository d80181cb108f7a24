r"""Estimators of :math:`J(u) = E[g]` from sampled trajectory costs :math:`g_1..g_n`.

Naming used throughout this project (the paper swaps bars and tildes between its
Sections II and II-A, so we name estimators by what they do):

=====================  ==========================================  ===========================
ours                   definition                                   paper
=====================  ==========================================  ===========================
``uniform``            :math:`\frac1n\sum_i g_i`                    tree: J~_NP / J~_P;
                                                                    non-overlapping: J-_N
``weighted``           :math:`\frac1n\sum_i q_i g_i`,               tree: J-_NP / J-_P;
                       :math:`q_i = n L_i / \sum_j L_j`             non-overlapping: J~_N
``nbo``                cost of the nominal trajectory               J_NBO
                       (:math:`w_k = \bar w_k = 0`)
=====================  ==========================================  ===========================

"with pruning" / "without pruning" is a property of the sample (see :mod:`rsmhp.sampling`),
not of the estimator: the same two estimators apply to every sample.
"""

from __future__ import annotations

import numpy as np

from rsmhp.sampling import System

__all__ = ["likeliness_weights", "nbo_estimate", "uniform_estimate", "weighted_estimate"]


def uniform_estimate(cost: np.ndarray, axis: int = -1) -> np.ndarray:
    r"""Sample average :math:`\frac1n\sum_i g_i` along ``axis``."""
    cost = np.asarray(cost, dtype=float)
    if cost.shape[axis] == 0:
        raise ValueError("cannot average zero trajectories")
    return cost.mean(axis=axis)


def likeliness_weights(log_likeliness: np.ndarray, axis: int = -1) -> np.ndarray:
    r"""Normalized likeliness :math:`q_i = n L_i / \sum_j L_j`, so that :math:`\sum_i q_i = n`.

    Computed from log-likeliness with the max subtracted first (no under/overflow even for
    products of hundreds of densities).
    """
    ll = np.asarray(log_likeliness, dtype=float)
    shifted = np.exp(ll - ll.max(axis=axis, keepdims=True))
    n = ll.shape[axis]
    return n * shifted / shifted.sum(axis=axis, keepdims=True)


def weighted_estimate(cost: np.ndarray, log_likeliness: np.ndarray, axis: int = -1) -> np.ndarray:
    r"""Likeliness-weighted average :math:`\frac1n\sum_i q_i g_i = \sum_i L_i g_i / \sum_i L_i`."""
    q = likeliness_weights(log_likeliness, axis=axis)
    return np.mean(q * np.asarray(cost, dtype=float), axis=axis)


def nbo_estimate(system: System, x0: np.ndarray, u: np.ndarray | list[float]) -> float:
    r"""NBO cost: the cost of the single trajectory with every noise at its mean,
    :math:`\tilde x_{k+1} = f(\tilde x_k, u_k, \bar w_k)`, :math:`J_{NBO} = \sum_k g(\tilde x_k,
    u_k) + g_H(\tilde x_H)`."""
    u = np.asarray(u, dtype=float)
    x = np.atleast_1d(np.asarray(x0, dtype=float))[None, :]
    w = system.noise.mean[None, :]
    total = 0.0
    for k in range(u.shape[0]):
        total += float(system.stage_cost(x, u[k])[0])
        x = system.step(x, u[k], w)
    return total + float(system.terminal_cost(x)[0])
