r"""Equal-compute study: statistics of the planner frontier (tables -> numbers, no prose).

Per (model, method), from the rule ``decisions_frontier``'s tables:

* compute: ``plan_ms``, the median over runs of the planning milliseconds per step;
* closed loop: mean location error over runs and the paired difference method − NBO of the
  per-run mean error (m; negative: the method tracks better), with a percentile-bootstrap
  CI over runs; the share of runs that lost the track;
* open loop: mean relative regret over belief states (%) and the paired difference method −
  NBO at the same states (percentage points), each with a bootstrap CI over states.

Bootstrap streams are keyed on (model, method, statistic), so a row never depends on the
other rows.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from rsmhp.seeding import job_rng
from rsmhp.stats import bootstrap_ci
from rsmhp.uav import methods

__all__ = ["FRONTIER_SUMMARY_COLUMNS", "summarize_frontier"]

FRONTIER_SUMMARY_COLUMNS = [
    "model",
    "method",
    "family",
    "plan_ms",
    "runs",
    "mean_error",
    "error_diff",
    "error_diff_low",
    "error_diff_high",
    "lost_rate",
    "states",
    "regret_pct",
    "regret_pct_low",
    "regret_pct_high",
    "regret_diff_pp",
    "regret_diff_pp_low",
    "regret_diff_pp_high",
]


def _ci(x: np.ndarray, seed: int, n_boot: int, **key: Any) -> tuple[float, float]:
    """95% percentile-bootstrap CI of the mean of ``x`` (NaNs for fewer than 2 values)."""
    x = np.asarray(x, dtype=float)
    if x.size < 2:
        return float("nan"), float("nan")
    return bootstrap_ci(x, job_rng(seed, "frontier_bootstrap", **key), n_boot, 0.95)


def summarize_frontier(
    runs: pd.DataFrame, regret: pd.DataFrame, seed: int, n_boot: int
) -> pd.DataFrame:
    """One row per (model, method) of ``runs`` (see the module docstring), in the tables'
    order. ``runs``: rows of :data:`rsmhp.experiments.frontier.FRONTIER_RUN_COLUMNS`;
    ``regret``: rows of :data:`rsmhp.experiments.decisions_uav.REGRET_COLUMNS`."""
    base = methods.baseline()().name
    out = []
    for model, g in runs.groupby("model", sort=False):
        err = g.pivot(index="run", columns="method", values="mean_error")
        reg = regret[regret["model"] == model].pivot_table(
            index=["run", "step"], columns="method", values="regret_rel"
        )
        for method, m in g.groupby("method", sort=False):
            key = {"model": model, "method": method}
            d_err = (err[method] - err[base]).to_numpy(float)
            e_lo, e_hi = _ci(d_err, seed, n_boot, **key, statistic="error_diff")
            row = {
                "model": model,
                "method": method,
                "family": m["family"].iloc[0],
                "plan_ms": float(m["plan_ms"].median()),
                "runs": len(m),
                "mean_error": float(m["mean_error"].mean()),
                "error_diff": float(d_err.mean()),
                "error_diff_low": e_lo,
                "error_diff_high": e_hi,
                "lost_rate": float(m["lost"].astype(bool).mean()),
                "states": 0,
            }
            if method in reg.columns and len(reg):
                r = 100 * reg[method].to_numpy(float)
                d = r - 100 * reg[base].to_numpy(float)
                r_lo, r_hi = _ci(r, seed, n_boot, **key, statistic="regret")
                d_lo, d_hi = _ci(d, seed, n_boot, **key, statistic="regret_diff")
                row.update(
                    states=int(r.size),
                    regret_pct=float(r.mean()),
                    regret_pct_low=r_lo,
                    regret_pct_high=r_hi,
                    regret_diff_pp=float(d.mean()),
                    regret_diff_pp_low=d_lo,
                    regret_diff_pp_high=d_hi,
                )
            out.append(row)
    return pd.DataFrame(out, columns=FRONTIER_SUMMARY_COLUMNS)
