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

"with pruning" / "without pruning" is a property of the sample (see :mod:`rsmhp.core.sampling`),
not of the estimator: the same two estimators apply to every sample.
"""

from __future__ import annotations

import numpy as np

from rsmhp.core import guards
from rsmhp.core.sampling import System, check_controls, check_initial_state

__all__ = ["likeliness_weights", "nbo_estimate", "uniform_estimate", "weighted_estimate"]


def _axis(name: str, a: np.ndarray, axis: int) -> None:
    """``axis`` is an integer axis of ``a`` (at least 1-D) along which there is something."""
    guards.integer("axis", axis)
    if a.ndim == 0 or not -a.ndim <= axis < a.ndim:
        raise ValueError(f"axis must be a valid axis of {name} (shape {a.shape}), got {axis}")
    if a.shape[axis] == 0:
        raise ValueError(f"cannot average zero trajectories ({name} has shape {a.shape})")


def _log_likeliness(log_likeliness: np.ndarray, axis: int) -> np.ndarray:
    """Log-likeliness as floats: no NaN or +inf (-inf, a zero likeliness, is allowed), not
    -inf everywhere along ``axis``."""
    ll = guards.float_array("log_likeliness", log_likeliness)
    _axis("log_likeliness", ll, axis)
    if np.isnan(ll).any() or np.isposinf(ll).any():
        bad = ll[np.isnan(ll) | np.isposinf(ll)]
        raise ValueError(
            f"log_likeliness must be finite or -inf (zero likeliness), got {bad[0]} "
            f"({bad.size} such entries)"
        )
    if np.isneginf(ll.max(axis=axis)).any():
        raise ValueError(
            "log_likeliness must not be -inf for every trajectory along the axis "
            "(zero total likeliness: the weights are undefined)"
        )
    return ll


def uniform_estimate(cost: np.ndarray, axis: int = -1) -> np.ndarray:
    r"""Sample average :math:`\frac1n\sum_i g_i` along ``axis``."""
    cost = guards.finite_array("cost", cost)
    _axis("cost", cost, axis)
    return cost.mean(axis=axis)


def likeliness_weights(log_likeliness: np.ndarray, axis: int = -1) -> np.ndarray:
    r"""Normalized likeliness :math:`q_i = n L_i / \sum_j L_j`, so that :math:`\sum_i q_i = n`.

    Computed from log-likeliness with the max subtracted first (no under/overflow even for
    products of hundreds of densities).
    """
    ll = _log_likeliness(log_likeliness, axis)
    shifted = np.exp(ll - ll.max(axis=axis, keepdims=True))
    n = ll.shape[axis]
    return n * shifted / shifted.sum(axis=axis, keepdims=True)


def weighted_estimate(cost: np.ndarray, log_likeliness: np.ndarray, axis: int = -1) -> np.ndarray:
    r"""Likeliness-weighted average :math:`\frac1n\sum_i q_i g_i = \sum_i L_i g_i / \sum_i L_i`."""
    cost = guards.finite_array("cost", cost)
    ll = guards.float_array("log_likeliness", log_likeliness)
    if cost.shape != ll.shape:
        raise ValueError(
            f"cost and log_likeliness must have the same shape, got {cost.shape} and {ll.shape}"
        )
    q = likeliness_weights(ll, axis=axis)
    return np.mean(q * cost, axis=axis)


def nbo_estimate(system: System, x0: np.ndarray, u: np.ndarray | list[float]) -> float:
    r"""NBO cost: the cost of the single trajectory with every noise at its mean,
    :math:`\tilde x_{k+1} = f(\tilde x_k, u_k, \bar w_k)`, :math:`J_{NBO} = \sum_k g(\tilde x_k,
    u_k) + g_H(\tilde x_H)`."""
    u = check_controls(u)
    check_initial_state(system, x0)
    x = np.atleast_1d(np.asarray(x0, dtype=float))[None, :]
    w = system.noise.mean[None, :]
    total = 0.0
    for k in range(u.shape[0]):
        total += float(system.stage_cost(x, u[k])[0])
        x = system.step(x, u[k], w)
    return total + float(system.terminal_cost(x)[0])
