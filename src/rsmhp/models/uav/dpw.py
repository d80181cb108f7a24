r"""Tree search with double progressive widening over the Kalman belief MDP (PFT-DPW with
Gaussian beliefs), compiled.

The belief MDP of the tracking problem: a belief node holds the UAV state ``s`` (4,), the
tracker's estimate :math:`\hat x` (4,) and covariance :math:`P` (4, 4). An action is a
normalised control :math:`a \in [-1, 1]^2` (times ``scale``: acceleration m/s², bank angle
rad). The generative model :math:`G(b, a)` draws a target state :math:`x \sim \mathcal
N(\hat x, P)`, then runs one closed-loop step exactly as the simulation does
(:func:`rsmhp.models.uav.stepper._advance`: aircraft, target :math:`x' = F x + w`, tracker predict,
detection, measurement in the true geometry, Joseph update with R at the estimate) and gives
the child belief :math:`b'` with reward :math:`r = -\mathrm{tr}\,P' / c_0`, where
:math:`c_0 = \mathrm{tr}\,\hat P_{\rm root}` makes values O(1) per step. The planning
objective is the expected :math:`\sum_{j=1}^H \mathrm{tr}\,P_j` of the next H steps, as for
the sampled-cost planners, but over the tracker's own beliefs (R at the estimate, random
detections) instead of fixed target hypotheses.

Search (Sunberg & Kochenderfer's PFT-DPW, one simulation = one path from the root, depth at
most H, ``n_sims`` simulations per planning step; constants ``(c, k_a, alpha_a, k_o,
alpha_o)`` and the rollout policy are the caller's, see
:mod:`rsmhp.models.uav.methods.tree_search`):

* action widening: a belief node visited :math:`N` times gets a new action while it has at most
  :math:`k_a \max(N, 1)^{\alpha_a}` of them; the first action at depth :math:`d` is the warm
  start's control :math:`d` (the shifted previous plan: continuity), with rollout
  ``"pursuit"`` the second is the pursuit action :math:`\pi(b)` at the node's belief, later
  ones are uniform in the box;
* selection: UCB1, :math:`\arg\max_a Q(a) + c \sqrt{\ln N / N(a)}` (unvisited first);
* observation widening: an action node visited :math:`N(a)` times gets a new child belief
  from :math:`G` while it has at most :math:`k_o \max(N(a), 1)^{\alpha_o}` children (the
  simulation *leaves the tree* there and continues with a rollout), otherwise an existing
  child is chosen with probability proportional to its visits and the simulation descends
  into it. With ``<=`` (as in PFT-DPW) an action node keeps at least
  :math:`\lfloor k_o\rfloor + 1` children before any descent: one child per action (a
  deterministic-transition tree) needs :math:`k_o < 1`, :math:`\alpha_o = 0`;
* rollout from the new belief to depth H through :math:`G`: ``"warm"`` applies the warm
  start's remaining controls (blind to the belief), ``"pursuit"`` the pursuit action
  :math:`\pi(b)` of each simulated belief;
* back-up: :math:`Q(a) \leftarrow Q(a) + (q - Q(a)) / N(a)` with the simulation's return
  :math:`q`.

Pursuit policy :math:`\pi(b)` (normalised; UAV state :math:`(p_x, p_y, s, \psi)`, estimate
:math:`\hat x = (\hat p_x, \hat p_y, \hat v_x, \hat v_y)`): steer toward the estimated target
and hold a speed that matches the target's and closes the range,

.. math::
    e = \mathrm{wrap}_{(-\pi, \pi]}\big(\mathrm{atan2}(\hat p_y - p_y, \hat p_x - p_x) - \psi
    \big), \qquad \pi_\phi = \mathrm{clip}\big(e / (\pi/2), -1, 1\big),

.. math::
    v_{\rm ref} = \mathrm{clip}\big(\|\hat v\| + \rho / \tau,\ s_{\min}, s_{\max}\big),
    \qquad \pi_a = \mathrm{clip}\big((v_{\rm ref} - s) / (a_{\max} \Delta t), -1, 1\big)

(full bank at a bearing error of 90 degrees or more, positive bank turns left toward a target
on the left; :math:`\rho` the horizontal range to the estimate, :math:`\tau` =
:data:`PURSUIT_TAU` = 10 s; :math:`\pi_a = 0` if :math:`a_{\max} = 0`). Why this speed: the
measurement noise grows with the range, so the policy should close it (fast when far) and
then stay close, which a fixed-wing aircraft does best by flying no faster than it must to
keep up with the target (its turn radius grows as :math:`s^2`). Neither a fixed speed
nor holding the speed does both; "keep the speed" and :math:`s_{\min} + (s_{\max} -
s_{\min})/4` were the alternatives. :math:`\tau` is a round value, not tuned on the study:
the pursuit policy alone (no search) on 30 runs of the paper model with a seed the study does
not use (12345) gave mean :math:`\mathrm{tr}\,P` 177, 181, 205 m² for :math:`\tau` = 5, 10,
20 s against 240 m² for holding the speed and 292 m² for :math:`s_{\min} + (s_{\max} -
s_{\min})/4`.

The plan: the most visited action from the root, then the most visited child belief, and so
on down the tree; ``plan_depth`` of its H steps come from this path. The rest, the *tail*:
with rollout ``"warm"`` it keeps the warm start (the search as first built); with
``"pursuit"`` it continues from the last belief :math:`b_D` on the path (depth
:math:`D` = ``plan_depth``) with the pursuit policy on the nominal, noise-free propagation,
:math:`u_j = \pi(b_j)`, :math:`s_{j+1} = f(s_j, u_j)` (the aircraft kinematics),
:math:`\hat x_{j+1} = F \hat x_j` (the covariance plays no part), for :math:`j = D, \dots,
H-1`; each of the :math:`H - D - 1` propagations counts as one model step. With no simulation
the root has no action (:math:`D = 0`) and the whole plan is this tail from the belief:
:func:`pursuit_plan`, the plan of the pursuit policy alone
(:mod:`rsmhp.models.uav.methods.pursuit`) and of the sampled-cost planners' pursuit start.

Counters: ``work`` is the number of calls of :math:`G` (each tree expansion and each rollout
step; one model step each, as :attr:`rsmhp.models.uav.planner.PlanResult.work` counts) plus the
tail's propagations. Depths: the root is depth 0, a child belief of a root action depth 1; a
simulation that expands a belief at depth :math:`e` makes :math:`1 + (H - e)` calls of
:math:`G`, one that reaches depth H inside the tree makes none. Random numbers come from the
planning step's numpy ``Generator`` (passed into the compiled code), so a plan depends only on
the step's stream key; the pursuit action and the tail draw none, so with rollout ``"warm"``
the search draws and returns exactly what it did before the pursuit policy existed.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from rsmhp.core import numba_cache
from rsmhp.models.uav import stepper as _stepper
from rsmhp.models.uav.stepper import _advance

__all__ = [
    "PURSUIT_TAU",
    "ROLLOUTS",
    "SearchResult",
    "pursuit",
    "pursuit_plan",
    "pursuit_search",
    "search",
    "warm_up",
]

#: the rollout policies: index = the compiled code's mode (0 warm start, 1 pursuit)
ROLLOUTS = ("warm", "pursuit")
#: s, the pursuit policy's range-closing time (see the module docstring)
PURSUIT_TAU = 10.0
#: the stream :func:`pursuit_plan` passes to the compiled search, which draws nothing from it
#: with no simulation (a test checks that its state never moves)
_NO_DRAWS = np.random.default_rng(0)


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
def _pursuit(uav, xh, ucfg, tau, out):  # pragma: no cover - compiled
    """The pursuit action (normalised) at belief (uav, xh) into ``out`` (2,); ``ucfg`` =
    (dt, g, a_max, phi_max, s_min, s_max)."""
    dt, amax, smin, smax = ucfg[0], ucfg[2], ucfg[4], ucfg[5]
    dx = xh[0] - uav[0]
    dy = xh[1] - uav[1]
    e = math.atan2(dy, dx) - uav[3]
    e -= 2.0 * math.pi * math.ceil((e - math.pi) / (2.0 * math.pi))  # into (-pi, pi]
    out[1] = min(max(e / (0.5 * math.pi), -1.0), 1.0)
    vref = min(max(math.hypot(xh[2], xh[3]) + math.hypot(dx, dy) / tau, smin), smax)
    da = amax * dt
    out[0] = min(max((vref - uav[2]) / da, -1.0), 1.0) if da > 0.0 else 0.0


@njit(cache=True, nogil=True, error_model="numpy")
def _nominal(uav, xh, P, act, scale, F, Q, ucfg, sens, xt, w, zeta, ctrl):
    # pragma: no cover - compiled
    """One noise-free step in place on (uav, xh): the closed-loop step with the target at the
    estimate and no noise, so the innovation is 0 and :math:`\\hat x' = F \\hat x` exactly;
    ``P`` is scratch (it plays no part in the mean)."""
    for r in range(4):
        xt[r] = xh[r]
        w[r] = 0.0
    zeta[0] = 0.0
    zeta[1] = 0.0
    ctrl[0] = act[0] * scale[0]
    ctrl[1] = act[1] * scale[1]
    _advance(uav, xt, xh, P, ctrl, w, zeta, 0.0, F, Q, ucfg, sens)


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
    uav0, xh0, P0, warm, scale, n_sims, c_ucb, k_a, alpha_a, k_o, alpha_o, mode, tau,
    F, Q, Lq, ucfg, sens, rng,
):  # pragma: no cover - compiled  # fmt: skip
    H = warm.shape[0]
    pursue = mode == 1
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
    act = np.empty(2)
    su = np.empty(4)
    sx = np.empty(4)
    sP = np.empty((4, 4))
    path_b = np.empty(H + 1, np.int64)
    path_a = np.empty(H, np.int64)
    path_r = np.zeros(H)
    # statistics: end_hist[e] simulations that expanded a belief at depth e (1..H),
    # end_hist[0] those that reached depth H inside the tree; G calls of the search
    end_hist = np.zeros(H + 1, np.int64)
    max_depth = 0
    n_gen = 0

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
        expanded = False
        while depth < H:
            path_b[depth] = b
            # action widening
            if b_nact[b] <= k_a * max(b_N[b], 1) ** alpha_a:
                a = na
                na += 1
                if b_nact[b] == 0:
                    a_u[a, 0] = warm[depth, 0]
                    a_u[a, 1] = warm[depth, 1]
                elif pursue and b_nact[b] == 1:
                    _pursuit(b_uav[b], b_xh[b], ucfg, tau, act)
                    a_u[a, 0] = act[0]
                    a_u[a, 1] = act[1]
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
                n_gen += 1
                b_r[c] = -tr / c0
                b_next[c] = a_first[a]
                a_first[a] = c
                a_nch[a] += 1
                b_cnt[c] += 1
                path_r[depth] = b_r[c]
                end_hist[depth + 1] += 1
                max_depth = max(max_depth, depth + 1)
                expanded = True
                # rollout to depth H: the warm start's remaining controls, or pursuit
                su[:] = b_uav[c]
                sx[:] = b_xh[c]
                sP[:, :] = b_P[c]
                q_tail = 0.0
                for d in range(depth + 1, H):
                    if pursue:
                        _pursuit(su, sx, ucfg, tau, act)
                    else:
                        act[0] = warm[d, 0]
                        act[1] = warm[d, 1]
                    tr = _generate(su, sx, sP, act, scale, F, Q, Lq, ucfg, sens, rng,
                                   L, x, w, zeta, ctrl)  # fmt: skip
                    n_gen += 1
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
        if not expanded:
            end_hist[0] += 1
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
    plan_depth = 0
    dangling = -1  # the path's last action if it has no child belief (never in practice)
    while depth < H and b_first[b] >= 0:
        best = -1
        a = b_first[b]
        while a >= 0:
            if best < 0 or a_N[a] > a_N[best] or (a_N[a] == a_N[best] and a_Q[a] > a_Q[best]):
                best = a
            a = a_next[a]
        plan[depth, 0] = a_u[best, 0]
        plan[depth, 1] = a_u[best, 1]
        plan_depth = depth + 1
        if depth == 0:
            root_q = a_Q[best]
            root_n = a_N[best]
        c = a_first[best]
        if c < 0:
            dangling = best
            break
        bc = c
        while c >= 0:
            if b_cnt[c] > b_cnt[bc]:
                bc = c
            c = b_next[c]
        b = bc
        depth += 1
    # the tail: pursuit on the nominal propagation from the path's last belief
    n_tail = 0
    if pursue and plan_depth < H:
        su[:] = b_uav[b]
        sx[:] = b_xh[b]
        sP[:, :] = b_P[b]
        if dangling >= 0:
            _nominal(su, sx, sP, a_u[dangling], scale, F, Q, ucfg, sens, x, w, zeta, ctrl)
            n_tail += 1
        for t in range(plan_depth, H):
            if t > plan_depth:
                _nominal(su, sx, sP, act, scale, F, Q, ucfg, sens, x, w, zeta, ctrl)
                n_tail += 1
            _pursuit(su, sx, ucfg, tau, act)
            plan[t, 0] = act[0]
            plan[t, 1] = act[1]
    return (
        plan, -root_q * c0, nb, na, b_nact[0], root_n, -best_q * c0,
        max_depth, end_hist, plan_depth, n_gen, n_tail,
    )  # fmt: skip


class SearchResult(NamedTuple):
    """What one planning step of :func:`search` gives."""

    #: (H, 2) normalised controls: ``plan_depth`` steps from the most visited path, the tail
    plan: np.ndarray
    #: the search's estimate of the chosen root action's expected cost (m²)
    cost: float
    belief_nodes: int
    action_nodes: int
    root_actions: int
    #: visits of the chosen root action
    chosen_visits: int
    #: the lowest estimated cost of any visited root action (m²)
    best_root_cost: float
    #: depth of the deepest belief node (root = 0)
    max_depth: int
    #: (H + 1,) ``end_depths[e]``: simulations that expanded a belief at depth e (1..H);
    #: ``end_depths[0]``: simulations that reached depth H inside the tree
    end_depths: np.ndarray
    #: steps of the plan that come from the most visited path (the rest is the tail)
    plan_depth: int
    #: calls of the generative model G in the search (expansions and rollout steps)
    search_calls: int
    #: nominal propagations made to build the tail (0 with rollout "warm")
    tail_steps: int

    @property
    def work(self) -> int:
        """Model steps: :attr:`search_calls` + :attr:`tail_steps`."""
        return int(self.search_calls) + int(self.tail_steps)


def pursuit(uav: np.ndarray, x_hat: np.ndarray, stepper, tau: float = PURSUIT_TAU) -> np.ndarray:
    """The pursuit action (normalised, (2,)) at UAV state ``uav`` and target estimate ``x_hat``
    (see the module docstring); ``stepper`` a :class:`rsmhp.models.uav.stepper.Stepper`."""
    out = np.empty(2)
    _pursuit(
        np.ascontiguousarray(uav, dtype=float),
        np.ascontiguousarray(x_hat, dtype=float),
        stepper.ucfg,
        float(tau),
        out,
    )
    return out


def pursuit_plan(
    uav: np.ndarray,
    x_hat: np.ndarray,
    P_hat: np.ndarray,
    stepper,
    scale: np.ndarray,
    horizon: int,
) -> np.ndarray:
    r"""The pursuit policy's plan from the belief (``uav``, ``x_hat``, ``P_hat``) over
    ``horizon`` steps, normalised (H, 2) in :math:`[-1, 1]^2` (controls: the plan times
    ``scale``). With :math:`s_0` = ``uav``, :math:`\hat x_0` = ``x_hat``, for
    :math:`j = 0, \dots, H-1`

    .. math::
        u_j = \pi(s_j, \hat x_j), \qquad s_{j+1} = f(s_j, u_j \cdot \mathrm{scale}), \qquad
        \hat x_{j+1} = F \hat x_j,

    :math:`\pi` the pursuit action (:func:`pursuit`), :math:`f` the aircraft kinematics
    (:func:`rsmhp.models.uav.kinematics.step`), the estimate propagated without noise (the
    closed-loop step with the target at the estimate and no noise: the innovation is 0;
    ``P_hat`` plays no part in the plan). This is exactly the tail of :func:`search` from the
    root: :func:`search` with no simulation (the root gets no action, ``plan_depth`` 0), which
    spends H - 1 nominal propagations (``tail_steps``, its ``work``) and draws no random
    number (it is passed a stream it never reads). ``stepper`` a
    :class:`rsmhp.models.uav.stepper.Stepper` of the planning model. Unchecked."""
    return pursuit_search(uav, x_hat, P_hat, stepper, scale, horizon).plan


def pursuit_search(
    uav: np.ndarray,
    x_hat: np.ndarray,
    P_hat: np.ndarray,
    stepper,
    scale: np.ndarray,
    horizon: int,
) -> SearchResult:
    """:func:`search` with no simulation, rollout ``"pursuit"``: the :class:`SearchResult`
    whose plan is :func:`pursuit_plan` (``plan_depth`` 0, ``tail_steps`` H - 1, ``work`` the
    same)."""
    return search(
        uav, x_hat, P_hat, np.zeros((int(horizon), 2)), scale, 0, (0.0, 0.0, 0.0, 0.0, 0.0),
        stepper, _NO_DRAWS, "pursuit",
    )  # fmt: skip


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
    rollout: str = "pursuit",
) -> SearchResult:
    """One planning step (:class:`SearchResult`). ``warm`` (H, 2) normalised warm start;
    ``params`` = (c, k_a, alpha_a, k_o, alpha_o); ``stepper`` a
    :class:`rsmhp.models.uav.stepper.Stepper` of the planning model; ``rng`` the step's stream;
    ``rollout`` one of :data:`ROLLOUTS`. Unchecked (the member checks its constants)."""
    c, k_a, alpha_a, k_o, alpha_o = (float(v) for v in params)
    out = _search(
        np.ascontiguousarray(uav, dtype=float),
        np.ascontiguousarray(x_hat, dtype=float),
        np.ascontiguousarray(P_hat, dtype=float),
        np.ascontiguousarray(warm, dtype=float),
        np.ascontiguousarray(scale, dtype=float),
        int(n_sims),
        c, k_a, alpha_a, k_o, alpha_o, ROLLOUTS.index(rollout), PURSUIT_TAU,
        stepper.F, stepper.Q, np.linalg.cholesky(stepper.Q), stepper.ucfg, stepper.sens,
        rng,
    )  # fmt: skip
    plan, cost, nb, na, n_root, n_chosen, best, max_depth, hist, depth, n_gen, n_tail = out
    return SearchResult(
        plan, float(cost), int(nb), int(na), int(n_root), int(n_chosen), float(best),
        int(max_depth), hist, int(depth), int(n_gen), int(n_tail),
    )  # fmt: skip


def warm_up() -> float:
    """Compile (or load from the cache) the tree search (:func:`search`, which links the
    closed-loop step of :mod:`rsmhp.models.uav.stepper`) and :func:`pursuit`; returns the seconds
    it took."""
    import time

    from rsmhp.models.uav.kinematics import UAVParams
    from rsmhp.models.uav.sensor import SensorModel
    from rsmhp.models.uav.target import TargetModel

    t0 = time.perf_counter()
    step = _stepper.Stepper(
        UAVParams(1.0, 9.81, 3.0, 0.7, 10.0, 35.0, 100.0),
        TargetModel(1.0, 1.0),
        SensorModel(0.05, 0.1, 100.0),
    )
    uav, x_hat = np.array([0.0, 0.0, 20.0, 0.0]), np.array([50.0, 0.0, 1.0, 0.0])
    scale = np.array([3.0, 0.7])
    search(uav, x_hat, np.eye(4), np.zeros((2, 2)), scale, 4, (1.0, 1.0, 0.5, 1.0, 0.5), step,
           np.random.default_rng(0))  # fmt: skip
    pursuit(uav, x_hat, step)
    return time.perf_counter() - t0


# the compiled search links the closed-loop step of rsmhp.models.uav.stepper into its cached code:
# drop that cache when stepper.py changes (numba only watches this file)
numba_cache.invalidate_if_changed(_search, [_stepper])
