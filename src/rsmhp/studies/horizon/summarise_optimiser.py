r"""Summary of the optimiser split (:mod:`rsmhp.studies.horizon.simulate_optimiser`): per model,
horizon, method and optimiser budget, the mean total, approximation and optimisation regret
with cluster-t intervals over runs, and the optimiser's counters.

With per-state values :math:`v_{r,k}` (run r, belief state k of run r) the estimate is the
mean over all states, :math:`\bar v = \sum_{r,k} v_{r,k} / \sum_r n_r`; its 95% interval is
the cluster-t interval over the G runs (:func:`rsmhp.core.stats.cluster_t_ci`: leave-one-run-out
jackknife, t with G − 1 degrees of freedom), since the states of one run share its scenario.
With one state per run it is Student's t interval of the mean. Fewer than two runs: NaN
bounds. Regrets are in percent of :math:`J_{ref}`; because the split is linear,
``regret_pct = approx_pct + optim_pct`` up to rounding, and so are the estimates (not the
bounds).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from rsmhp.core.stats import cluster_t_ci

__all__ = ["LEVEL", "SUMMARY_COLUMNS", "cluster_mean", "summarize_split"]

#: confidence level of every interval of this module
LEVEL = 0.95

_GROUP = ["model", "H", "method", "family", "maxiter", "restarts"]
_PARTS = (("regret", "regret"), ("approx", "approx_regret"), ("optim", "optim_regret"))

SUMMARY_COLUMNS = [
    *_GROUP,
    "states",
    "runs",
    *[f"{p}_{s}" for p, _ in _PARTS for s in ("pct", "lo", "hi")],
    "mean_nit",
    "converged_share",
    "mean_work",
    "polish_star_share",
]


def cluster_mean(x: np.ndarray, runs: np.ndarray) -> tuple[float, float, float]:
    """``(mean, low, high)``: the mean of ``x`` over all values and its cluster-t interval
    over the labels ``runs`` (module docstring); NaN bounds for fewer than two runs."""
    x = np.asarray(x, dtype=float)
    labels, inverse = np.unique(np.asarray(runs), return_inverse=True)
    sums = np.bincount(inverse, weights=x, minlength=labels.size)
    counts = np.bincount(inverse, minlength=labels.size).astype(float)
    mean = float(sums.sum() / counts.sum())
    if labels.size < 2:
        return mean, float("nan"), float("nan")

    def stat(idx: np.ndarray) -> float:
        return float(sums[idx].sum() / counts[idx].sum())

    ci = cluster_t_ci(stat, int(labels.size), LEVEL)
    return mean, ci.low, ci.high


def summarize_split(table: pd.DataFrame) -> pd.DataFrame:
    """One row per (model, H, method, budget) of a split table (:data:`SUMMARY_COLUMNS`), in
    the table's order: states and runs; mean regret, approximation and optimisation regret in
    percent with 95% cluster-t bounds (``*_pct``, ``*_lo``, ``*_hi``); mean iterations, share
    of converged plans, mean work (model steps) and the share of states whose x*_m came from
    the polish rather than a budget plan."""
    rows = []
    for key, g in table.groupby(_GROUP, sort=False):
        runs = g["run"].to_numpy()
        row = dict(zip(_GROUP, key, strict=True))
        row["states"] = len(g)
        row["runs"] = int(np.unique(runs).size)
        for prefix, col in _PARTS:
            mean, lo, hi = cluster_mean(100.0 * g[col].to_numpy(dtype=float), runs)
            row |= {f"{prefix}_pct": mean, f"{prefix}_lo": lo, f"{prefix}_hi": hi}
        row["mean_nit"] = float(g["nit"].mean())
        row["converged_share"] = float(g["converged"].astype(bool).mean())
        row["mean_work"] = float(g["work"].mean())
        row["polish_star_share"] = float((g["star_source"] == "polish").mean())
        rows.append(row)
    return pd.DataFrame(rows, columns=SUMMARY_COLUMNS)
