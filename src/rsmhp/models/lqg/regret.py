r"""LQG decision study: the regret of choosing controls by each method's cost estimate.

For the scalar oven problem (:mod:`rsmhp.models.lqg.oven`) with open-loop controls :math:`u \in
\mathbb R^H`, every method turns a sample of noise sequences into a cost estimate
:math:`\hat J(u) = \sum_i \omega_i\, g(u, w^i)`; holding the sample fixed (sample-average
approximation) we minimise :math:`\hat J` over :math:`u` exactly
(:func:`rsmhp.models.lqg.oven.sample_argmin`, normal equations) and score the minimiser :math:`\hat
u` under the exact cost: regret :math:`J(\hat u) - J(u^*) \ge 0`
(:func:`rsmhp.models.lqg.oven.regret`). Methods (the sample each one draws):

=================  ======================================================  ==================
method             sample                                                  P (trajectories)
=================  ======================================================  ==================
``nbo``            the nominal sequence :math:`w = 0`                      1
``mc``             P i.i.d. sequences (the paper's non-overlapping MHP)    P
``antithetic``     P/2 i.i.d. sequences and their negatives                P
``sobol``          scrambled Sobol' points through :math:`\Phi^{-1}`       power of 2 nearest
                                                                           each P (log scale)
``cubature``       the 2H symmetric sigma points                           2H
``tree``           N draws per step shared by every node of a level        N^H
``pruned``         N draws per step, the M most likely nodes kept          M
=================  ======================================================  ==================

``weighting`` is ``uniform`` (:math:`\omega_i = 1/P`, or the rule's weights for sobol and
cubature) or ``likeliness`` (:math:`\omega_i \propto` the sequence's density, for mc, tree
and pruned; the two weightings of one replicate use the same draws).

Replicate ``r`` of cell (a, H, method, N, M, P) draws from
``job_rng(seed, "decisions_lqg", method=, N=, M=, P=, replicate=r)`` (P = 0 for the full tree,
whose P = N^H depends on H): draws for the longest horizon of the config, of which a cell of
horizon H uses the first H steps, shared by every a (common random numbers; the a values
differ only in the coefficients c, the horizons in how many steps they use). nbo and cubature
are deterministic (one replicate).

Speed: the sample-average argmin depends on a sample only through its weighted mean
final-state noise :math:`\bar e`, so each replicate computes :math:`\bar e` for every a and
weighting and the argmins and regrets of all replicates follow in closed form at once. The
full shared-draw tree's :math:`\bar e` separates by level (no enumeration of its N^H
leaves); the pruned tree runs in compiled code (:func:`_pruned_leaves`, tested against
:func:`rsmhp.core.sampling.sample_tree`).

Shared by the studies ``rsmhp.studies.decisions`` and ``rsmhp.studies.horizon`` (so it lives
below them).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from numba import njit

from rsmhp.core import designs
from rsmhp.core.cost_estimators import likeliness_weights
from rsmhp.core.sampling import GaussianNoise
from rsmhp.core.seeding import job_rngs
from rsmhp.models.lqg import oven as lqg
from rsmhp.pipeline.contracts import Contract
from rsmhp.pipeline.parallel import parallel_map

__all__ = [
    "LQG_REGRET_COLUMNS",
    "METHODS",
    "DrawCell",
    "RegretCell",
    "cell_rows",
    "draw_cells",
    "regret_cells",
    "run_lqg_regret",
    "sobol_budget",
    "warm_up",
]

log = logging.getLogger(__name__)

METHODS = ("nbo", "mc", "antithetic", "sobol", "cubature", "tree", "pruned")
WEIGHTED = ("mc", "tree", "pruned")  # methods that also get the likeliness weighting
DETERMINISTIC = ("nbo", "cubature")


@dataclass(frozen=True)
class RegretCell:
    """One (a, H, method, N, M, P) cell; N and M are 0 where they do not apply."""

    a: float
    H: int
    method: str
    N: int = 0
    M: int = 0
    P: int = 1

    @property
    def problem(self) -> str:
        return f"lqg_a{self.a:g}_h{self.H}"


def sobol_budget(P: int) -> int:
    """The power of two nearest ``P`` on a log scale (Sobol' points keep their balance
    properties only for n = 2^m)."""
    if P < 1:
        raise ValueError(f"P must be >= 1, got {P}")
    return 2 ** max(1, round(math.log2(P)))


def regret_cells(cfg: Mapping[str, Any]) -> list[RegretCell]:
    """Every cell of the ``decisions.lqg`` config section, in a stable order."""
    cells: list[RegretCell] = []
    max_leaves = int(cfg["max_leaves"])
    n_pruned = int(cfg["pruned_N"])
    for a in cfg["a_values"]:
        for H in cfg["H_values"]:
            a, H = float(a), int(H)
            for method in cfg["methods"]:
                if method == "nbo":
                    cells.append(RegretCell(a, H, "nbo"))
                elif method in ("mc", "antithetic"):
                    cells += [RegretCell(a, H, method, P=int(p)) for p in cfg["P"]]
                elif method == "sobol":
                    ps = sorted({sobol_budget(int(p)) for p in cfg["P"]})
                    cells += [RegretCell(a, H, "sobol", P=p) for p in ps]
                elif method == "cubature":
                    cells.append(RegretCell(a, H, "cubature", P=2 * H))
                elif method == "tree":
                    cells += [
                        RegretCell(a, H, "tree", N=int(n), P=int(n) ** H)
                        for n in cfg["tree_N"]
                        if int(n) ** H <= max_leaves
                    ]
                elif method == "pruned":
                    # only M below the full tree's N^H leaves prune anything
                    cells += [
                        RegretCell(a, H, "pruned", N=n_pruned, M=int(m), P=int(m))
                        for m in cfg["P"]
                        if int(m) < n_pruned**H
                    ]
                else:
                    raise ValueError(
                        f"decisions.lqg.methods: unknown method {method!r}; allowed: {METHODS}"
                    )
    return cells


@dataclass(frozen=True)
class DrawCell:
    """Regret cells that share their draws: one (method, N, M, P) for every ``a`` and every
    horizon in ``H`` (a cell of horizon H uses the first H steps of draws made for the
    longest; the full tree's P = N^H is per horizon, so its ``P`` here is 0). Common random
    numbers across a and H: each cell's sample is distributed as before, cells of one
    (method, N, M, P) are correlated, which no statistic of the study pools over."""

    method: str
    N: int = 0
    M: int = 0
    P: int = 1
    H: tuple[int, ...] = ()

    @staticmethod
    def key(cell: RegretCell) -> tuple[str, int, int, int]:
        return (cell.method, cell.N, cell.M, 0 if cell.method == "tree" else cell.P)


def draw_cells(cfg: Mapping[str, Any]) -> list[DrawCell]:
    """The :class:`DrawCell` groups of :func:`regret_cells`, in first-seen order."""
    groups: dict[tuple[str, int, int, int], set[int]] = {}
    for c in regret_cells(cfg):
        groups.setdefault(DrawCell.key(c), set()).add(c.H)
    return [DrawCell(*k, H=tuple(sorted(hs))) for k, hs in groups.items()]


@njit(cache=True, nogil=True)
def _pruned_leaves(w, ll_w, C, max_keep):  # pragma: no cover - compiled
    """The pruned shared-draw tree of :func:`rsmhp.core.sampling.sample_tree` (``max_keep`` = M)
    on the draws ``w`` (H, N) with log-densities ``ll_w`` (H, N): at level k every kept node
    branches N ways (child index parent * N + i, log-likeliness parent + ll_w[k, i]); when
    there are more than M children the M most likely are kept (ties by index: a stable sort,
    as :func:`rsmhp.core.sampling.top_m`), in tree order. Returns the leaves' log-likeliness (n,)
    and final-state noise e = sum_k C[a, k] w[k, i_k] for every row of ``C`` (A, H): (A, n)."""
    H, N = w.shape
    A = C.shape[0]
    ll = np.zeros(1)
    e = np.zeros((A, 1))
    for k in range(H):
        n_child = ll.size * N
        llc = np.empty(n_child)
        for p in range(ll.size):
            for i in range(N):
                llc[p * N + i] = ll[p] + ll_w[k, i]
        if n_child > max_keep:
            # top_m's set in O(n): every entry above the M-th largest value, then of those
            # equal to it the first ones in index order (top_m breaks ties by index), in
            # tree order
            kth = np.partition(llc, n_child - max_keep)[n_child - max_keep]
            keep = np.empty(max_keep, dtype=np.int64)
            n_above = 0
            for j in range(n_child):
                n_above += llc[j] > kth
            n_tied = max_keep - n_above  # of the entries equal to kth, the first ones
            m = 0
            for j in range(n_child):  # one pass in index order: tree order, no sort
                if llc[j] > kth:
                    keep[m] = j
                    m += 1
                elif llc[j] == kth and n_tied > 0:
                    keep[m] = j
                    m += 1
                    n_tied -= 1
        else:
            keep = np.arange(n_child)
        e_new = np.empty((A, keep.size))
        for j in range(keep.size):
            p, i = keep[j] // N, keep[j] % N
            for r in range(A):
                e_new[r, j] = e[r, p] + C[r, k] * w[k, i]
        ll = llc[keep]
        e = e_new
    return ll, e


def _shifts(
    cell: DrawCell,
    C: Mapping[int, np.ndarray],
    noise: GaussianNoise,
    rng: np.random.Generator | None,
) -> dict[int, tuple[int, dict[str, np.ndarray]]]:
    r"""One replicate's draws of ``cell`` (for its longest horizon) and, for every horizon H
    of ``C`` (H -> coefficient rows (A, H), one per a) and weighting, the weighted mean
    final-state noise :math:`\bar e = \sum_i \omega_i c^\top w^i / \sum_i \omega_i` of the
    first H steps: {H: (number of sequences, {weighting: (A,)})}."""
    H_max, chol = max(C), noise.chol
    out: dict[int, tuple[int, dict[str, np.ndarray]]] = {}
    if cell.method in ("tree", "pruned"):
        # N draws per level shared by every node (sample_tree's order: level by level)
        w = np.stack([noise.sample(rng, cell.N)[:, 0] for _ in range(H_max)])  # (H, N)
        ll_w = noise.logpdf(w[:, :, None])  # (H, N)
        lik = likeliness_weights(ll_w, axis=1)
        level_mean = w.mean(axis=1)
        level_weighted = (lik * w).sum(axis=1) / lik.sum(axis=1)
        for H, CH in C.items():
            if cell.method == "tree":
                # every level's draw sits in N^(H-1) of the N^H leaves, and a leaf's
                # likeliness is a product over levels: both weighted means separate by level
                got = {"uniform": CH @ level_mean[:H], "likeliness": CH @ level_weighted[:H]}
                out[H] = (cell.N**H, got)
                continue
            # the pruning of the first H levels does not depend on later levels
            ll, e = _pruned_leaves(w[:H], ll_w[:H], np.ascontiguousarray(CH), cell.M)
            q = likeliness_weights(ll)
            out[H] = (ll.size, {"uniform": e.mean(axis=1), "likeliness": e @ q / q.sum()})
        return out
    if cell.method == "nbo":
        return {H: (1, {"uniform": np.zeros(CH.shape[0])}) for H, CH in C.items()}
    if cell.method == "cubature":  # 2H points of its own per horizon (one horizon per cell)
        (H,) = C
        w, wt = designs.cubature(H, chol)
    elif cell.method in ("antithetic", "sobol"):
        w, wt = getattr(designs, cell.method)(rng, cell.P, H_max, chol)
    elif cell.method == "mc":
        w, wt = designs.monte_carlo(rng, cell.P, H_max, chol)
    else:
        raise ValueError(f"unknown method {cell.method!r}")
    w = w[:, :, 0]  # (n, H_max); a sequence of the first H steps is w[:, :H]
    if cell.method in WEIGHTED:
        loglik = np.cumsum(noise.logpdf(w[:, :, None]), axis=1)  # (n, H_max)
    for H, CH in C.items():
        e = w[:, :H] @ CH.T  # (n, A)
        got = {"uniform": wt @ e / wt.sum()}
        if cell.method in WEIGHTED:
            q = likeliness_weights(loglik[:, H - 1])
            got["likeliness"] = q @ e / q.sum()
        out[H] = (w.shape[0], got)
    return out


def cell_rows(
    cell: DrawCell, a_values: list[float], params: Mapping[str, float], seed: int, reps: int
) -> dict[RegretCell, pd.DataFrame]:
    r"""The rows of ``cell`` for every ``a`` in ``a_values`` and every horizon of the cell:
    per replicate and weighting the regret of the sample-average argmin, the shift
    :math:`\bar e` and the argmin's components. ``params`` is the ``lqg.model`` config
    section (x0, r, target, sigma).

    The sample-average argmin depends on the draws only through :math:`\bar e`
    (:func:`rsmhp.models.lqg.oven.sample_argmin`): :math:`\hat u = r a (T - b^H x_0 - \bar e)\, c /
    (1 + r a^2 |c|^2)` (Sherman-Morrison), and its regret is the exact quadratic form of
    :func:`rsmhp.models.lqg.oven.regret`; both are evaluated for all replicates at once."""
    noise = lqg.LQGModel.from_config(params, a=float(a_values[0])).noise
    C = {H: np.stack([lqg.coefficients(H, float(a)) for a in a_values]) for H in cell.H}
    n_reps = 1 if cell.method in DETERMINISTIC else reps
    rngs = job_rngs(
        seed, "decisions_lqg", "replicate", range(n_reps),
        method=cell.method, N=cell.N, M=cell.M, P=cell.P,
    )  # fmt: skip
    weightings = ("uniform", "likeliness") if cell.method in WEIGHTED else ("uniform",)
    shifts = {H: np.empty((n_reps, len(weightings), len(a_values))) for H in cell.H}
    n_seq = dict.fromkeys(cell.H, 0)
    for rep, rng in enumerate(rngs):
        got = _shifts(cell, C, noise, None if cell.method in DETERMINISTIC else rng)
        for H, (n, by_weighting) in got.items():
            n_seq[H] = n
            for j, weighting in enumerate(weightings):
                shifts[H][rep, j] = by_weighting[weighting]
    out: dict[RegretCell, pd.DataFrame] = {}
    for H in cell.H:
        for ia, a in enumerate(a_values):
            key = RegretCell(float(a), H, cell.method, cell.N, cell.M, n_seq[H])
            out[key] = _frame(key, C[H][ia], shifts[H][:, :, ia], weightings, params)
    return out


def _frame(
    cell: RegretCell,
    c: np.ndarray,
    e_bar: np.ndarray,
    weightings: tuple[str, ...],
    params: Mapping[str, float],
) -> pd.DataFrame:
    """The rows of one regret cell from its shifts ``e_bar`` (replicates, weightings)."""
    a, H = cell.a, cell.H
    x0, r, target = params["x0"], params["r"], params["target"]
    gain = r * a / (1.0 + r * a * a * float(np.dot(c, c)))
    u_hat = (gain * (target - (1.0 - a) ** H * x0 - e_bar))[..., None] * c  # (reps, W, H)
    d = u_hat - lqg.optimal_controls(H, x0=x0, a=a, r=r, target=target)
    regret = (d * d).sum(axis=-1) + r * a * a * (d @ c) ** 2
    n_reps = e_bar.shape[0]
    n_rows = n_reps * len(weightings)  # replicate-major, then weighting
    frame = {
        "problem": [cell.problem] * n_rows,
        "a": np.full(n_rows, a),
        "H": np.full(n_rows, H),
        "method": [cell.method] * n_rows,
        "weighting": list(weightings) * n_reps,
        "N": np.full(n_rows, cell.N),
        "M": np.full(n_rows, cell.M),
        "P": np.full(n_rows, cell.P),
        "replicate": np.repeat(np.arange(n_reps), len(weightings)),
        "regret": regret.ravel(),
        "shift": e_bar.ravel(),
    }
    frame.update({f"u_hat_{k}": u_hat[:, :, k].ravel() for k in range(H)})
    return pd.DataFrame(frame)


def _task(job: tuple[list[DrawCell], list[float], Mapping[str, float], int, int]) -> list:
    cells, a_values, params, seed, reps = job
    return [cell_rows(cell, a_values, params, seed, reps) for cell in cells]


def _columns(max_H: int) -> list[str]:
    return [*LQG_REGRET_COLUMNS, *(f"u_hat_{k}" for k in range(max_H))]


LQG_REGRET_COLUMNS = [
    "problem",
    "a",
    "H",
    "method",
    "weighting",
    "N",
    "M",
    "P",
    "replicate",
    "regret",
    "shift",
]


def regret_contract(cfg: Mapping[str, Any]) -> Contract:
    """What ``results/decisions/lqg_regret.csv`` must hold for the ``decisions.lqg`` config
    section: one row per (cell, weighting, replicate) of :func:`regret_cells`, one replicate
    for the deterministic methods, finite regrets."""
    reps = int(cfg["replicates"])
    names = ["problem", "method", "weighting", "N", "M", "P", "replicate"]
    keys = [
        (c.problem, c.method, w, c.N, c.M, c.P, r)
        for c in regret_cells(cfg)
        for r in range(1 if c.method in DETERMINISTIC else reps)
        for w in (("uniform", "likeliness") if c.method in WEIGHTED else ("uniform",))
    ]
    return Contract(
        rule="decisions_lqg",
        columns=LQG_REGRET_COLUMNS,
        text=("problem", "method", "weighting"),
        integer=("H", "N", "M", "P", "replicate"),
        keys=names,
        expected=pd.DataFrame(keys, columns=names),
    )


def run_lqg_regret(
    cfg: Mapping[str, Any], model: Mapping[str, Any], seed: int, n_jobs: int = 1
) -> pd.DataFrame:
    """The whole ``decisions.lqg`` grid: one row per (cell, weighting, replicate) with the
    regret, the effective target shift :math:`\\bar e` and the argmin's components
    ``u_hat_0..u_hat_{H-1}`` (empty beyond H). ``model`` is the ``lqg.model`` config section
    (x0, r, target, sigma; ``a`` comes from ``cfg["a_values"]``)."""
    params = {k: float(model[k]) for k in ("x0", "r", "target", "sigma")}
    cells = regret_cells(cfg)
    groups = draw_cells(cfg)
    a_values = [float(a) for a in cfg["a_values"]]
    reps = int(cfg["replicates"])
    cost = [
        (1 if g.method in DETERMINISTIC else reps) * max(g.P, g.N ** max(g.H)) * sum(g.H)
        for g in groups
    ]
    # expensive cells first, dealt round-robin into tasks (never changes a number)
    ordered = [groups[i] for i in sorted(range(len(groups)), key=lambda i: -cost[i])]
    n_tasks = max(1, min(len(groups), 2 * n_jobs))
    jobs = [(ordered[i::n_tasks], a_values, params, seed, reps) for i in range(n_tasks)]
    log.info(
        "decisions_lqg: %d cells (%d draw cells shared by %d values of a) x %d replicates "
        "in %d tasks on %d workers",
        len(cells),
        len(groups),
        len(a_values),
        reps,
        len(jobs),
        n_jobs,
    )
    by_cell: dict[RegretCell, pd.DataFrame] = {}
    for task in parallel_map(_task, jobs, n_jobs, desc="regret tasks"):
        for part in task:
            by_cell.update(part)
    max_H = max(int(h) for h in cfg["H_values"])
    # rows in cell order (as regret_cells lists them), then replicate, then weighting
    out = pd.concat([by_cell[cell] for cell in cells], ignore_index=True)
    return out.reindex(columns=_columns(max_H))


def warm_up() -> float:
    """Compile (or load from the cache) the pruned-tree kernel; returns the seconds it took."""
    import time

    t0 = time.perf_counter()
    _pruned_leaves(np.zeros((2, 2)), np.zeros((2, 2)), np.ones((1, 2)), 3)
    return time.perf_counter() - t0
