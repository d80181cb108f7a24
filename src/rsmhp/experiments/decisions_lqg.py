r"""LQG decision study: the regret of choosing controls by each method's cost estimate.

For the scalar oven problem (:mod:`rsmhp.lqg`) with open-loop controls :math:`u \in \mathbb
R^H`, every method turns a sample of noise sequences into a cost estimate
:math:`\hat J(u) = \sum_i \omega_i\, g(u, w^i)`; holding the sample fixed (sample-average
approximation) we minimise :math:`\hat J` over :math:`u` exactly
(:func:`rsmhp.lqg.sample_argmin`, normal equations) and score the minimiser :math:`\hat u`
under the exact cost: regret :math:`J(\hat u) - J(u^*) \ge 0`
(:func:`rsmhp.lqg.regret`). Methods (the sample each one draws):

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
``job_rng(seed, "decisions_lqg", H=, method=, N=, M=, P=, replicate=r)``: the same draws for
every a (common random numbers; the a values differ only in the coefficients c). nbo and
cubature are deterministic (one replicate).

Speed: the sample-average argmin depends on a sample only through its weighted mean
final-state noise :math:`\bar e`, so each replicate computes :math:`\bar e` for every a and
weighting and the argmins and regrets of all replicates follow in closed form at once. The
full shared-draw tree's :math:`\bar e` separates by level (no enumeration of its N^H
leaves); the pruned tree runs in compiled code (:func:`_pruned_leaves`, tested against
:func:`rsmhp.sampling.sample_tree`).
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

from rsmhp import designs, lqg
from rsmhp.contracts import Contract
from rsmhp.cost_estimators import likeliness_weights
from rsmhp.parallel import parallel_map
from rsmhp.sampling import GaussianNoise
from rsmhp.seeding import job_rngs

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
    """The (H, method, N, M, P) of a regret cell without ``a``: its draws serve every ``a``
    (common random numbers across the a values; only the coefficients c(a) differ)."""

    H: int
    method: str
    N: int = 0
    M: int = 0
    P: int = 1

    @classmethod
    def of(cls, cell: RegretCell) -> DrawCell:
        return cls(cell.H, cell.method, cell.N, cell.M, cell.P)


def draw_cells(cfg: Mapping[str, Any]) -> list[DrawCell]:
    """The distinct :class:`DrawCell` of :func:`regret_cells`, in first-seen order."""
    return list(dict.fromkeys(DrawCell.of(c) for c in regret_cells(cfg)))


@njit(cache=True, nogil=True)
def _pruned_leaves(w, ll_w, C, max_keep):  # pragma: no cover - compiled
    """The pruned shared-draw tree of :func:`rsmhp.sampling.sample_tree` (``max_keep`` = M)
    on the draws ``w`` (H, N) with log-densities ``ll_w`` (H, N): at level k every kept node
    branches N ways (child index parent * N + i, log-likeliness parent + ll_w[k, i]); when
    there are more than M children the M most likely are kept (ties by index: a stable sort,
    as :func:`rsmhp.sampling.top_m`), in tree order. Returns the leaves' log-likeliness (n,)
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
            neg = -llc
            kth = np.partition(neg, max_keep - 1)[max_keep - 1]
            above = np.flatnonzero(neg < kth)
            tied = np.flatnonzero(neg == kth)[: max_keep - above.size]
            keep = np.sort(np.concatenate((above, tied)))
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
    cell: DrawCell, C: np.ndarray, noise: GaussianNoise, rng: np.random.Generator | None
) -> tuple[int, dict[str, np.ndarray]]:
    r"""One replicate's draws of ``cell`` and, per weighting, the weighted mean final-state
    noise :math:`\bar e = \sum_i \omega_i c^\top w^i / \sum_i \omega_i` for every row c of
    ``C`` (A, H): (number of sequences, {weighting: (A,)})."""
    H, chol = cell.H, noise.chol
    if cell.method in ("tree", "pruned"):
        # N draws per level shared by every node (sample_tree's order: level by level)
        w = np.stack([noise.sample(rng, cell.N)[:, 0] for _ in range(H)])  # (H, N)
        ll_w = noise.logpdf(w[:, :, None])  # (H, N)
        if cell.method == "tree":
            # every level's draw sits in N^(H-1) of the N^H leaves, and a leaf's likeliness
            # is a product over levels: both weighted means separate by level (exactly)
            lik = likeliness_weights(ll_w, axis=1)
            uniform = C @ w.mean(axis=1)
            weighted = C @ ((lik * w).sum(axis=1) / lik.sum(axis=1))
            return cell.N**H, {"uniform": uniform, "likeliness": weighted}
        ll, e = _pruned_leaves(w, ll_w, np.ascontiguousarray(C), cell.M)
        lik = likeliness_weights(ll)
        return ll.size, {"uniform": e.mean(axis=1), "likeliness": e @ lik / lik.sum()}
    if cell.method == "nbo":
        return 1, {"uniform": np.zeros(C.shape[0])}
    if cell.method == "cubature":
        w, wt = designs.cubature(H, chol)
    elif cell.method in ("antithetic", "sobol"):
        w, wt = getattr(designs, cell.method)(rng, cell.P, H, chol)
    elif cell.method == "mc":
        w, wt = designs.monte_carlo(rng, cell.P, H, chol)
    else:
        raise ValueError(f"unknown method {cell.method!r}")
    e = w[:, :, 0] @ C.T  # (n, A)
    out = {"uniform": wt @ e / wt.sum()}
    if cell.method in WEIGHTED:
        lik = likeliness_weights(noise.logpdf(w).sum(axis=1))
        out["likeliness"] = lik @ e / lik.sum()
    return w.shape[0], out


def cell_rows(
    cell: DrawCell, a_values: list[float], params: Mapping[str, float], seed: int, reps: int
) -> dict[RegretCell, pd.DataFrame]:
    r"""The rows of ``cell`` for every ``a`` in ``a_values``: per replicate and weighting the
    regret of the sample-average argmin, the shift :math:`\bar e` and the argmin's
    components. ``params`` is the ``lqg.model`` config section (x0, r, target, sigma).

    The sample-average argmin depends on the draws only through :math:`\bar e`
    (:func:`rsmhp.lqg.sample_argmin`): :math:`\hat u = r a (T - b^H x_0 - \bar e)\, c / (1 +
    r a^2 |c|^2)` (Sherman-Morrison), and its regret is the exact quadratic form of
    :func:`rsmhp.lqg.regret`; both are evaluated for all replicates at once."""
    A = len(a_values)
    H = cell.H
    noise = lqg.LQGModel.from_config(params, a=float(a_values[0])).noise
    C = np.stack([lqg.coefficients(H, float(a)) for a in a_values])  # (A, H)
    n_reps = 1 if cell.method in DETERMINISTIC else reps
    rngs = job_rngs(
        seed, "decisions_lqg", "replicate", range(n_reps),
        H=H, method=cell.method, N=cell.N, M=cell.M, P=cell.P,
    )  # fmt: skip
    weightings = ("uniform", "likeliness") if cell.method in WEIGHTED else ("uniform",)
    shifts = np.empty((n_reps, len(weightings), A))
    n_seq = 0
    for rep, rng in enumerate(rngs):
        n_seq, got = _shifts(cell, C, noise, None if cell.method in DETERMINISTIC else rng)
        for j, weighting in enumerate(weightings):
            shifts[rep, j] = got[weighting]
    out: dict[RegretCell, pd.DataFrame] = {}
    x0, r, target = params["x0"], params["r"], params["target"]
    for ia, a in enumerate(a_values):
        a = float(a)
        c = C[ia]
        cc = float(np.dot(c, c))
        e_bar = shifts[:, :, ia]  # (reps, weightings)
        gain = r * a / (1.0 + r * a * a * cc)
        u_hat = (gain * (target - (1.0 - a) ** H * x0 - e_bar))[..., None] * c  # (reps, W, H)
        d = u_hat - lqg.optimal_controls(H, x0=x0, a=a, r=r, target=target)
        regret = (d * d).sum(axis=-1) + r * a * a * (d @ c) ** 2
        key = RegretCell(a, H, cell.method, cell.N, cell.M, cell.P)
        n_rows = n_reps * len(weightings)  # replicate-major, then weighting
        frame = {
            "problem": [key.problem] * n_rows,
            "a": np.full(n_rows, a),
            "H": np.full(n_rows, H),
            "method": [cell.method] * n_rows,
            "weighting": list(weightings) * n_reps,
            "N": np.full(n_rows, cell.N),
            "M": np.full(n_rows, cell.M),
            "P": np.full(n_rows, n_seq),
            "replicate": np.repeat(np.arange(n_reps), len(weightings)),
            "regret": regret.ravel(),
            "shift": e_bar.ravel(),
        }
        frame.update({f"u_hat_{k}": u_hat[:, :, k].ravel() for k in range(H)})
        out[key] = pd.DataFrame(frame)
    return out


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
    cost = [(1 if c.method in DETERMINISTIC else reps) * c.P * c.H for c in groups]
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
