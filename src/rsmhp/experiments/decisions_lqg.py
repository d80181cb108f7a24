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
``job_rng(seed, "decisions_lqg", a=, H=, method=, N=, M=, P=, replicate=r)``; nbo and
cubature are deterministic (one replicate).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from rsmhp import designs, lqg
from rsmhp.contracts import Contract
from rsmhp.cost_estimators import likeliness_weights
from rsmhp.parallel import parallel_map
from rsmhp.sampling import sample_tree
from rsmhp.seeding import job_rngs

__all__ = [
    "LQG_REGRET_COLUMNS",
    "METHODS",
    "RegretCell",
    "cell_rows",
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


def _sample(
    cell: RegretCell, model: lqg.LQGModel, rng: np.random.Generator | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """(noise (P, H), design weights (P,), log-likeliness (P,) or None)."""
    chol = np.array([[model.sigma]])
    H = cell.H
    if cell.method == "nbo":
        return np.zeros((1, H)), np.ones(1), None
    if cell.method == "cubature":
        w, wt = designs.cubature(H, chol)
        return w[:, :, 0], wt, None
    if cell.method in ("antithetic", "sobol"):
        w, wt = getattr(designs, cell.method)(rng, cell.P, H, chol)
        return w[:, :, 0], wt, None
    if cell.method == "mc":
        w, wt = designs.monte_carlo(rng, cell.P, H, chol)
        return w[:, :, 0], wt, model.noise.logpdf(w).sum(axis=1)
    if cell.method in ("tree", "pruned"):
        tree = sample_tree(
            model,
            [0.0],
            np.zeros(H),
            cell.N,
            rng,
            max_keep=cell.M if cell.method == "pruned" else None,
        )
        leaves = tree.leaves
        n = leaves.noise.shape[0]
        return leaves.noise[:, :, 0], np.full(n, 1.0 / n), leaves.log_likeliness
    raise ValueError(f"unknown method {cell.method!r}")


def cell_rows(
    cell: RegretCell, params: Mapping[str, float], seed: int, reps: int
) -> Iterator[dict[str, Any]]:
    """The rows of one cell: per replicate and weighting the regret of the sample-average
    argmin, the shift :math:`\bar e` and the argmin's components. ``params`` is the
    ``lqg.model`` config section (x0, r, target, sigma); ``a`` is the cell's."""
    model = lqg.LQGModel.from_config(params, a=cell.a)
    kw = model.closed_form_args(sigma=False)
    c = lqg.coefficients(cell.H, cell.a)
    n_reps = 1 if cell.method in DETERMINISTIC else reps
    rngs = job_rngs(
        seed,
        "decisions_lqg",
        "replicate",
        range(n_reps),
        a=cell.a,
        H=cell.H,
        method=cell.method,
        N=cell.N,
        M=cell.M,
        P=cell.P,
    )
    for rep, rng in enumerate(rngs):
        noise, wts, loglik = _sample(cell, model, None if cell.method in DETERMINISTIC else rng)
        weightings = {"uniform": wts}
        if cell.method in WEIGHTED:
            weightings["likeliness"] = likeliness_weights(loglik)
        e = noise @ c  # sampled final-state noise of every sequence
        for weighting, omega in weightings.items():
            u_hat = lqg.sample_argmin(noise, omega, **kw)
            row = {
                "problem": cell.problem,
                "a": cell.a,
                "H": cell.H,
                "method": cell.method,
                "weighting": weighting,
                "N": cell.N,
                "M": cell.M,
                "P": int(noise.shape[0]),
                "replicate": rep,
                "regret": lqg.regret(u_hat, **kw),
                "shift": float(np.dot(omega, e) / omega.sum()),
            }
            row.update({f"u_hat_{k}": float(v) for k, v in enumerate(u_hat)})
            yield row


def _task(job: tuple[list[tuple[int, RegretCell]], Mapping[str, float], int, int]) -> list:
    cells, params, seed, reps = job
    return [(i, list(cell_rows(cell, params, seed, reps))) for i, cell in cells]


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
    reps = int(cfg["replicates"])
    cost = [(1 if c.method in DETERMINISTIC else reps) * c.P * c.H for c in cells]
    # expensive cells first, dealt round-robin into tasks (never changes a number)
    ordered = sorted(enumerate(cells), key=lambda ic: -cost[ic[0]])
    n_tasks = max(1, min(len(cells), 4 * n_jobs))
    jobs = [(ordered[i::n_tasks], params, seed, reps) for i in range(n_tasks)]
    log.info(
        "decisions_lqg: %d cells x %d replicates in %d tasks on %d workers",
        len(cells),
        reps,
        len(jobs),
        n_jobs,
    )
    parts = [p for task in parallel_map(_task, jobs, n_jobs, desc="regret tasks") for p in task]
    rows = [row for _, cell_rows in sorted(parts, key=lambda p: p[0]) for row in cell_rows]
    max_H = max(int(h) for h in cfg["H_values"])
    # rows in cell order (as regret_cells lists them), then replicate, then weighting
    return pd.DataFrame(rows, columns=_columns(max_H))
