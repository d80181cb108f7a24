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

Between two members a, b of the study (the equal-compute comparisons of claims FR-1..3):
:func:`paired_difference`, the mean of d = x(a) − x(b) paired per run (closed loop) or per
belief state (open loop) with its bootstrap CI; :func:`budget_check`, each budget member's
measured time against the budget and the largest member of its family that fits it;
:func:`select_run`, the run a recording shows, by a rule on the paired differences.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from rsmhp.seeding import job_rng
from rsmhp.stats import bootstrap_ci
from rsmhp.uav import methods

__all__ = [
    "BUDGET_COLUMNS",
    "FRONTIER_SUMMARY_COLUMNS",
    "RUN_SELECTIONS",
    "Paired",
    "budget_check",
    "paired_difference",
    "select_run",
    "summarize_frontier",
]

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


class Paired(NamedTuple):
    """Mean of paired differences d = x(a) − x(b) with its 95% bootstrap CI over n pairs."""

    mean: float
    low: float
    high: float
    n: int


#: the paired measures: (table, value column, pairing index, scale): closed-loop mean
#: location error per run (m) and open-loop relative regret per belief state (percent)
_MEASURES = {
    "error": ("runs", "mean_error", ["run"], 1.0),
    "regret": ("regret", "regret_rel", ["run", "step"], 100.0),
}


def paired_difference(
    table: pd.DataFrame,
    model: str,
    a: str,
    b: str,
    measure: str,
    seed: int,
    n_boot: int,
) -> Paired:
    r"""d = x(``a``) − x(``b``) on ``model``, paired over what both share: ``measure`` =
    "error" (``table`` = the runs table; x = a run's mean location error, m; pairs = runs) or
    "regret" (``table`` = the regret table; x = relative regret in percent, so d is in
    percentage points; pairs = belief states (run, step)). Mean and 95% percentile-bootstrap
    CI (stream keyed on model, a, b and the measure). Unknown model, member or measure, or
    fewer than 2 pairs: ValueError naming it."""
    if measure not in _MEASURES:
        raise ValueError(f"measure: {measure!r} (allowed: {', '.join(_MEASURES)})")
    _, col, index, scale = _MEASURES[measure]
    g = table[table["model"] == model]
    if g.empty:
        raise ValueError(f"model: {model!r} has no rows (models: {sorted(set(table['model']))})")
    for name, m in (("a", a), ("b", b)):
        if m not in set(g["method"]):
            raise ValueError(
                f"{name}: {m!r} has no {measure} rows on {model!r} "
                f"(methods: {', '.join(dict.fromkeys(g['method']))})"
            )
    wide = g.pivot_table(index=index, columns="method", values=col).dropna(subset=[a, b])
    d = scale * (wide[a] - wide[b]).to_numpy(float)
    if d.size < 2:
        raise ValueError(f"{a} − {b} on {model!r}: {d.size} pair(s) (allowed: at least 2)")
    lo, hi = _ci(d, seed, n_boot, model=model, a=a, b=b, statistic=f"paired_{measure}")
    return Paired(float(d.mean()), lo, hi, int(d.size))


BUDGET_COLUMNS = ["model", "member", "family", "plan_ms", "fits", "largest_fitting", "largest_ms"]


def budget_check(summary: pd.DataFrame, members: Sequence[str], budget_ms: float) -> pd.DataFrame:
    """Per (model, budget member): its measured median planning time per step, whether it
    fits ``budget_ms``, and the member of its family with the most compute (largest time)
    that fits on this run (empty if none): the config's choice is "the largest member within
    the budget", which these columns check. ``summary``: :func:`summarize_frontier`."""
    rows = []
    for model, s in summary.groupby("model", sort=False):
        for member in members:
            row = s[s["method"] == member]
            if row.empty:
                raise ValueError(f"budget member {member!r} has no row for model {model!r}")
            fam = row["family"].iloc[0]
            fit = s[(s["family"] == fam) & (s["plan_ms"] <= budget_ms)].sort_values("plan_ms")
            rows.append(
                {
                    "model": model,
                    "member": member,
                    "family": fam,
                    "plan_ms": float(row["plan_ms"].iloc[0]),
                    "fits": bool(row["plan_ms"].iloc[0] <= budget_ms),
                    "largest_fitting": str(fit["method"].iloc[-1]) if len(fit) else "",
                    "largest_ms": float(fit["plan_ms"].iloc[-1]) if len(fit) else float("nan"),
                }
            )
    return pd.DataFrame(rows, columns=BUDGET_COLUMNS)


#: rules of :func:`select_run` (the config's decisions.recording.select)
RUN_SELECTIONS = ("nearest_mean", "nearest_median", "largest_gain", "largest_loss")


def select_run(
    runs: pd.DataFrame,
    model: str,
    a: str,
    b: str,
    rule: str,
    path: str = "decisions.recording.select",
) -> tuple[int, float]:
    """The run of ``model`` a recording shows and its d_r = mean_error(``a``) − that of
    ``b`` (m): ``rule`` "nearest_mean" / "nearest_median": d_r nearest the mean / median of d
    over the runs; "largest_gain" / "largest_loss": the most negative / positive d_r. Ties:
    the lowest run index (deterministic; no timing column is read). ``path`` names the config
    key in the message for an unknown rule."""
    if rule not in RUN_SELECTIONS:
        raise ValueError(f"{path}: {rule!r} (allowed: {', '.join(RUN_SELECTIONS)})")
    g = runs[runs["model"] == model]
    wide = g.pivot(index="run", columns="method", values="mean_error")
    for m in (a, b):
        if m not in wide.columns:
            raise ValueError(f"{m!r} has no runs on {model!r} (methods: {', '.join(wide.columns)})")
    d = (wide[a] - wide[b]).dropna().sort_index()
    if d.empty:
        raise ValueError(f"no paired runs of {a} and {b} on {model!r}")
    if rule == "nearest_mean":
        key = (d - d.mean()).abs()
    elif rule == "nearest_median":
        key = (d - d.median()).abs()
    else:
        key = d if rule == "largest_gain" else -d
    run = int(key.index[int(np.argmin(key.to_numpy(float)))])
    return run, float(d.loc[run])
