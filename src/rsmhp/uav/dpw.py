r"""Tree search with double progressive widening over the Kalman belief MDP (PFT-DPW with
Gaussian beliefs), compiled.

The belief MDP of the tracking problem: a belief node holds the UAV state ``s`` (4,), the
tracker's estimate :math:`\hat x` (4,) and covariance :math:`P` (4, 4). An action is a
normalised control :math:`a \in [-1, 1]^2` (times ``scale``: acceleration m/s², bank angle
rad). The generative model :math:`G(b, a)` draws a target state :math:`x \sim \mathcal
N(\hat x, P)`, then runs one closed-loop step exactly as the simulation does
(:func:`rsmhp.uav.stepper._advance`: aircraft, target :math:`x' = F x + w`, tracker predict,
detection, measurement in the true geometry, Joseph update with R at the estimate) and gives
the child belief :math:`b'` with reward :math:`r = -\mathrm{tr}\,P' / c_0`, where
:math:`c_0 = \mathrm{tr}\,\hat P_{\rm root}` makes values O(1) per step. The planning
objective is the expected :math:`\sum_{j=1}^H \mathrm{tr}\,P_j` of the next H steps, as for
the sampled-cost planners, but over the tracker's own beliefs (R at the estimate, random
detections) instead of fixed target hypotheses.

Search (Sunberg & Kochenderfer's PFT-DPW, one simulation = one path from the root, depth at
most H, ``n_sims`` simulations per planning step):

* action widening: a belief node visited :math:`N` times gets a new action while it has at most
  :math:`k_a N^{\alpha_a}` of them; the first action at depth :math:`d` is the warm start's
  control :math:`d` (the shifted previous plan), later ones are uniform in the box;
* selection: UCB1, :math:`\arg\max_a Q(a) + c \sqrt{\ln N / N(a)}` (unvisited first);
* observation widening: an action node visited :math:`N(a)` times gets a new child belief
  from :math:`G` while it has at most :math:`k_o N(a)^{\alpha_o}` children (and the
  simulation continues with a rollout), otherwise an existing child is chosen with
  probability proportional to its visits and the simulation descends into it;
* rollout: the warm start's remaining controls through :math:`G`;
* back-up: :math:`Q(a) \leftarrow Q(a) + (q - Q(a)) / N(a)` with the simulation's return
  :math:`q`.

The plan returned follows the most visited action from the root, then the most visited child
belief, and so on; steps below the tree's depth keep the warm start. Random numbers come from
the planning step's numpy ``Generator`` (passed into the compiled code), so a plan depends
only on the step's stream key.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from rsmhp import numba_cache
from rsmhp.uav import stepper as _stepper
from rsmhp.uav.stepper import _advance

__all__ = ["search"]


@njit(cache=True, nogil=True, error_model="numpy")
def _chol4(P, L):  # pragma: no cover - compiled
    """Cholesky factor of the symmetrised 4x4 ``P`` into ``L`` (lower); a pivot <= 0 (a
    covariance that lost definiteness to rounding) is clipped to 0."""
    for i in range(4):
        for j in range(4):
            L[i, j] = 0.0
    for j in range(4):
        s = 0.5 * (P[j, j] + P[j, j])
        for k in range(j):
            s -= L[j, k] * L[j, k]
        d = math.sqrt(s) if s > 0.0 else 0.0
        L[j, j] = d
        for i in range(j + 1, 4):
            s = 0.5 * (P[i, j] + P[j, i])
            for k in range(j):
                s -= L[i, k] * L[j, k]
            L[i, j] = s / d if d > 0.0 else 0.0


@njit(cache=True, nogil=True, error_model="numpy")
def _generate(uav, xh, P, act, scale, F, Q, Lq, ucfg, sens, rng, L, x, w, zeta, ctrl):
    # pragma: no cover - compiled
    """G(b, a) in place on (uav, xh, P); returns tr P'."""
    _chol4(P, L)
    z = rng.standard_normal(4)
    for r in range(4):
        s = xh[r]
        for c in range(r + 1):
            s += L[r, c] * z[c]
        x[r] = s
    z = rng.standard_normal(4)
    for r in range(4):
        s = 0.0
        for c in range(r + 1):
            s += Lq[r, c] * z[c]
        w[r] = s
    zeta[0] = rng.standard_normal()
    zeta[1] = rng.standard_normal()
    det_u = rng.random()
    ctrl[0] = act[0] * scale[0]
    ctrl[1] = act[1] * scale[1]
    _, _, tr = _advance(uav, x, xh, P, ctrl, w, zeta, det_u, F, Q, ucfg, sens)
    return tr


@njit(cache=True, nogil=True, error_model="numpy")
def _search(
    uav0, xh0, P0, warm, scale, n_sims, c_ucb, k_a, alpha_a, k_o, alpha_o, F, Q, Lq, ucfg, sens, rng
):  # pragma: no cover - compiled
    H = warm.shape[0]
    nb_max = n_sims + 1
    na_max = n_sims * H + 1
    # belief nodes
    b_uav = np.empty((nb_max, 4))
    b_xh = np.empty((nb_max, 4))
    b_P = np.empty((nb_max, 4, 4))
    b_N = np.zeros(nb_max, np.int64)
    b_nact = np.zeros(nb_max, np.int64)
    b_first = np.full(nb_max, -1, np.int64)  # first action child
    b_next = np.full(nb_max, -1, np.int64)  # next sibling under the same action
    b_r = np.zeros(nb_max)  # reward of reaching this belief
    b_cnt = np.zeros(nb_max, np.int64)  # transitions into this belief
    # action nodes
    a_u = np.empty((na_max, 2))
    a_N = np.zeros(na_max, np.int64)
    a_Q = np.zeros(na_max)
    a_nch = np.zeros(na_max, np.int64)
    a_first = np.full(na_max, -1, np.int64)  # first child belief
    a_next = np.full(na_max, -1, np.int64)  # next action of the same belief
    # scratch
    L = np.empty((4, 4))
    x = np.empty(4)
    w = np.empty(4)
    zeta = np.empty(2)
    ctrl = np.empty(2)
    su = np.empty(4)
    sx = np.empty(4)
    sP = np.empty((4, 4))
    path_b = np.empty(H + 1, np.int64)
    path_a = np.empty(H, np.int64)
    path_r = np.zeros(H)

    c0 = P0[0, 0] + P0[1, 1] + P0[2, 2] + P0[3, 3]
    b_uav[0] = uav0
    b_xh[0] = xh0
    b_P[0] = P0
    nb = 1
    na = 0
    for _ in range(n_sims):
        b = 0
        depth = 0
        q_tail = 0.0
        n_path = 0
        while depth < H:
            path_b[depth] = b
            # action widening
            if b_nact[b] <= k_a * max(b_N[b], 1) ** alpha_a:
                a = na
                na += 1
                if b_nact[b] == 0:
                    a_u[a, 0] = warm[depth, 0]
                    a_u[a, 1] = warm[depth, 1]
                else:
                    a_u[a, 0] = 2.0 * rng.random() - 1.0
                    a_u[a, 1] = 2.0 * rng.random() - 1.0
                a_next[a] = b_first[b]
                b_first[b] = a
                b_nact[b] += 1
            # UCB1
            best = -1
            best_v = -np.inf
            lnN = math.log(max(b_N[b], 1))
            a = b_first[b]
            while a >= 0:
                if a_N[a] == 0:
                    v = np.inf
                else:
                    v = a_Q[a] + c_ucb * math.sqrt(lnN / a_N[a])
                if v > best_v:
                    best_v = v
                    best = a
                a = a_next[a]
            a = best
            path_a[depth] = a
            n_path = depth + 1
            # observation widening
            if a_nch[a] <= k_o * max(a_N[a], 1) ** alpha_o:
                c = nb
                nb += 1
                b_uav[c] = b_uav[b]
                b_xh[c] = b_xh[b]
                b_P[c] = b_P[b]
                tr = _generate(
                    b_uav[c], b_xh[c], b_P[c], a_u[a], scale, F, Q, Lq, ucfg, sens, rng,
                    L, x, w, zeta, ctrl,
                )  # fmt: skip
                b_r[c] = -tr / c0
                b_next[c] = a_first[a]
                a_first[a] = c
                a_nch[a] += 1
                b_cnt[c] += 1
                path_r[depth] = b_r[c]
                # rollout with the warm start's remaining controls
                su[:] = b_uav[c]
                sx[:] = b_xh[c]
                sP[:, :] = b_P[c]
                q_tail = 0.0
                for d in range(depth + 1, H):
                    tr = _generate(su, sx, sP, warm[d], scale, F, Q, Lq, ucfg, sens, rng,
                                   L, x, w, zeta, ctrl)  # fmt: skip
                    q_tail -= tr / c0
                path_b[depth + 1] = c
                break
            # an existing child, with probability proportional to its visits
            total = 0
            c = a_first[a]
            while c >= 0:
                total += b_cnt[c]
                c = b_next[c]
            pick = rng.random() * total
            c = a_first[a]
            acc = 0.0
            chosen = c
            while c >= 0:
                acc += b_cnt[c]
                chosen = c
                if pick < acc:
                    break
                c = b_next[c]
            c = chosen
            b_cnt[c] += 1
            path_r[depth] = b_r[c]
            b = c
            depth += 1
            q_tail = 0.0
        # back-up along the path (returns from each depth)
        q = q_tail
        for d in range(n_path - 1, -1, -1):
            q += path_r[d]
            a = path_a[d]
            bb = path_b[d]
            b_N[bb] += 1
            a_N[a] += 1
            a_Q[a] += (q - a_Q[a]) / a_N[a]
    # the plan: most visited action, then its most visited child, ...
    plan = warm.copy()
    b = 0
    depth = 0
    root_q = 0.0
    root_n = 0
    best_q = -np.inf
    a = b_first[0]
    while a >= 0:
        if a_N[a] > 0 and a_Q[a] > best_q:
            best_q = a_Q[a]
        a = a_next[a]
    while depth < H and b_first[b] >= 0:
        best = -1
        a = b_first[b]
        while a >= 0:
            if best < 0 or a_N[a] > a_N[best] or (a_N[a] == a_N[best] and a_Q[a] > a_Q[best]):
                best = a
            a = a_next[a]
        plan[depth, 0] = a_u[best, 0]
        plan[depth, 1] = a_u[best, 1]
        if depth == 0:
            root_q = a_Q[best]
            root_n = a_N[best]
        c = a_first[best]
        if c < 0:
            break
        bc = c
        while c >= 0:
            if b_cnt[c] > b_cnt[bc]:
                bc = c
            c = b_next[c]
        b = bc
        depth += 1
    return plan, -root_q * c0, nb, na, b_nact[0], root_n, -best_q * c0


def search(
    uav: np.ndarray,
    x_hat: np.ndarray,
    P_hat: np.ndarray,
    warm: np.ndarray,
    scale: np.ndarray,
    n_sims: int,
    params: tuple[float, float, float, float, float],
    stepper,
    rng: np.random.Generator,
) -> tuple[np.ndarray, float, int, int, int, int, float]:
    """One planning step: ``(plan (H, 2) normalised, the search's estimate of the chosen root
    action's expected cost (m²), belief nodes, action nodes, root actions, visits of the
    chosen root action, the lowest estimated cost of any visited root action (m²))``. ``warm``
    (H, 2) normalised warm start; ``params`` = (c, k_a, alpha_a, k_o, alpha_o); ``stepper`` a
    :class:`rsmhp.uav.stepper.Stepper` of the planning model; ``rng`` the step's stream."""
    c, k_a, alpha_a, k_o, alpha_o = (float(v) for v in params)
    return _search(
        np.ascontiguousarray(uav, dtype=float),
        np.ascontiguousarray(x_hat, dtype=float),
        np.ascontiguousarray(P_hat, dtype=float),
        np.ascontiguousarray(warm, dtype=float),
        np.ascontiguousarray(scale, dtype=float),
        int(n_sims),
        c, k_a, alpha_a, k_o, alpha_o,
        stepper.F, stepper.Q, np.linalg.cholesky(stepper.Q), stepper.ucfg, stepper.sens,
        rng,
    )  # fmt: skip


# the compiled search links the closed-loop step of rsmhp.uav.stepper into its cached code:
# drop that cache when stepper.py changes (numba only watches this file)
numba_cache.invalidate_if_changed(_search, [_stepper])
