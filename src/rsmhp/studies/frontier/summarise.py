r"""Equal-compute study: statistics of the planner frontier (tables -> numbers, no prose).

Per (model, method), from the rule ``frontier_explore``'s tables:

* compute, in two units: wall clock, ``plan_ms``, the median planning milliseconds per step
  of the interleaved timing (rule ``frontier_explore_timing``: every method at the same
  belief states, round robin, several passes), with ``plan_lo_ms`` / ``plan_hi_ms`` the
  smallest and largest per-pass median (the spread from one pass to the next) and
  ``loop_ms`` the closed loop's own planning time per step (the mean over runs of a run's
  mean, measured beside whatever else ran; the protocol's ladder counts the larger of the
  two times, as its tuning rule does); machine-independent, ``work_per_step``, the median over runs
  of the model steps per planning step (:attr:`rsmhp.models.uav.planner.PlanResult.work`), with
  the optimiser's mean iterations ``mean_nit`` and the share of plans that converged
  ``converged_rate`` (NaN without an optimiser). Without a timing table ``plan_ms`` is the
  closed loop's;
* closed loop: mean location error over runs and the paired difference method − NBO of the
  per-run mean error (m; negative: the method tracks better), with a CI over runs; the
  share of runs that lost the track;
* open loop: mean relative regret over belief states (%) and the paired difference method −
  NBO at the same states (percentage points), each with a CI over runs.

Every CI is a 95% cluster-t interval over runs (:func:`cluster_mean_ci`: the belief states of
one run share its scenario and are not independent; with 10 to 50 runs a percentile
bootstrap is too narrow, see :mod:`rsmhp.core.stats`).

Between two members a, b of the study (the equal-compute comparisons of claims FR-1..3):
:func:`paired_difference`, the mean of d = x(a) − x(b) paired per run (closed loop) or per
belief state (open loop) with its cluster-t CI; :func:`budget_check`, each budget member's
measured time against the budget and the largest member of its family that fits it;
:func:`select_run`, the run a recording shows, by a rule on the paired differences.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from rsmhp.core.seeding import job_rng
from rsmhp.core.stats import ClusterInterval, cluster_t_ci, mean_bootstrap_ci, paired_wins
from rsmhp.models.uav import methods
from rsmhp.pipeline.protocol import budget_cost

__all__ = [
    "BUDGET_COLUMNS",
    "CONFIG_SUMMARY_COLUMNS",
    "FRONTIER_SUMMARY_COLUMNS",
    "LADDER_COLUMNS",
    "RUN_SELECTIONS",
    "Paired",
    "budget_check",
    "cluster_mean_ci",
    "ladder",
    "paired_configs",
    "paired_difference",
    "prob_improvement",
    "select_run",
    "summarize_configs",
    "summarize_frontier",
    "timing_summary",
]

FRONTIER_SUMMARY_COLUMNS = [
    "model",
    "method",
    "family",
    "plan_ms",
    "plan_lo_ms",
    "plan_hi_ms",
    "loop_ms",
    "work_per_step",
    "mean_nit",
    "converged_rate",
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
    """95% percentile-bootstrap CI of the mean of ``x`` (NaNs for fewer than 2 values): the
    interval of the exploratory tables up to 76a0c01, kept beside the cluster-t one."""
    return mean_bootstrap_ci(x, job_rng(seed, "frontier_bootstrap", **key), n_boot)


def cluster_mean_ci(x: np.ndarray, clusters: np.ndarray) -> ClusterInterval | None:
    r"""The mean of ``x`` with its 95% cluster-t interval over the labels ``clusters`` (the
    runs: belief states of one run share its scenario, so they are not independent):
    :func:`rsmhp.core.stats.cluster_t_ci` of :math:`\bar x` over the G runs (leave-one-run-out
    jackknife, t with G − 1 degrees of freedom; with one value per run it is Student's t
    interval). ``None`` for fewer than 2 runs."""
    x = np.asarray(x, dtype=float)
    labels, inverse = np.unique(np.asarray(clusters), return_inverse=True)
    if labels.size < 2:
        return None
    sums = np.bincount(inverse, weights=x, minlength=labels.size)
    counts = np.bincount(inverse, minlength=labels.size).astype(float)

    def stat(idx: np.ndarray) -> float:
        return float(sums[idx].sum() / counts[idx].sum())

    return cluster_t_ci(stat, int(labels.size))


def _cluster_ci(x: np.ndarray, clusters: np.ndarray) -> tuple[float, float]:
    ci = cluster_mean_ci(x, clusters)
    return (float("nan"), float("nan")) if ci is None else (ci.low, ci.high)


def _stat(m: pd.DataFrame, col: str, how: str) -> float:
    """``m[col].median()`` or ``.mean()``; NaN for a table without the column (older runs)."""
    return float(getattr(m[col], how)()) if col in m else float("nan")


def timing_summary(timing: pd.DataFrame) -> pd.DataFrame:
    """Per (model, method) of an interleaved timing table
    (:data:`rsmhp.studies.frontier.simulate.TIMING_COLUMNS`): ``plan_ms`` the median over every
    call, ``plan_lo_ms`` / ``plan_hi_ms`` the smallest and largest median of one pass."""
    if timing.empty:
        raise ValueError("timing: no rows (the interleaved timing table is empty)")
    per_pass = timing.groupby(["model", "method", "repeat"], sort=False)["ms"].median()
    spread = per_pass.groupby(level=["model", "method"], sort=False).agg(["min", "max"])
    med = timing.groupby(["model", "method"], sort=False)["ms"].median()
    return pd.DataFrame({"plan_ms": med, "plan_lo_ms": spread["min"], "plan_hi_ms": spread["max"]})


def summarize_frontier(
    runs: pd.DataFrame,
    regret: pd.DataFrame,
    timing: pd.DataFrame | None = None,
) -> pd.DataFrame:
    """One row per (model, method) of ``runs`` (see the module docstring), in the tables'
    order. ``runs``: rows of :data:`rsmhp.studies.frontier.simulate.FRONTIER_RUN_COLUMNS`;
    ``regret``: rows of :data:`rsmhp.models.uav.scoring.REGRET_COLUMNS`; ``timing``:
    rows of :data:`rsmhp.studies.frontier.simulate.TIMING_COLUMNS` (``None``: the closed loop's
    times). A (model, method) of ``runs`` missing from ``timing`` is refused, naming it."""
    base = methods.baseline()().name
    times = timing_summary(timing) if timing is not None else None
    nan = float("nan")
    out = []
    for model, g in runs.groupby("model", sort=False):
        err = g.pivot(index="run", columns="method", values="mean_error")
        reg = regret[regret["model"] == model].pivot_table(
            index=["run", "step"], columns="method", values="regret_rel"
        )
        for method, m in g.groupby("method", sort=False):
            d_err = (err[method] - err[base]).to_numpy(float)
            e_lo, e_hi = _cluster_ci(d_err, err.index.to_numpy())
            loop_ms = float(m["plan_ms"].median())
            if times is None:
                clock = {"plan_ms": loop_ms, "plan_lo_ms": nan, "plan_hi_ms": nan}
            elif (model, method) in times.index:
                clock = {k: float(v) for k, v in times.loc[(model, method)].items()}
            else:
                raise ValueError(
                    f"timing: no interleaved timing of {method!r} on {model!r} "
                    f"(timed: {sorted(set(map(str, times.index)))})"
                )
            conv = m["converged_rate"] if "converged_rate" in m else pd.Series([nan])
            row = {
                "model": model,
                "method": method,
                "family": m["family"].iloc[0],
                **clock,
                "loop_ms": loop_ms,
                "work_per_step": _stat(m, "work_per_step", "median"),
                "mean_nit": _stat(m, "mean_nit", "mean"),
                "converged_rate": float(conv.mean()) if conv.notna().any() else nan,
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
                run_of = reg.index.get_level_values("run").to_numpy()
                r_lo, r_hi = _cluster_ci(r, run_of)
                d_lo, d_hi = _cluster_ci(d, run_of)
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
    """Mean of paired differences d = x(a) − x(b) over n pairs in ``clusters`` runs, with its
    95% cluster-t CI (``low``, ``high``; standard error ``se`` with ``df`` = clusters − 1
    degrees of freedom: :func:`cluster_mean_ci`) and, for comparison, the 95% percentile
    bootstrap CI over pairs that the exploratory tables used (``boot_low``, ``boot_high``)."""

    mean: float
    low: float
    high: float
    n: int
    se: float = float("nan")
    df: int = 0
    clusters: int = 0
    boot_low: float = float("nan")
    boot_high: float = float("nan")


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
    percentage points; pairs = belief states (run, step)). Mean, its 95% cluster-t CI over
    runs and, for comparison, the percentile-bootstrap CI over pairs (stream keyed on model,
    a, b and the measure): :class:`Paired`. Unknown model, member or measure, or fewer than 2
    runs: ValueError naming it."""
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
    runs = wide.index.get_level_values("run").to_numpy()
    ci = cluster_mean_ci(d, runs)
    if ci is None:
        raise ValueError(
            f"{a} − {b} on {model!r}: {d.size} pair(s) in {np.unique(runs).size} run(s) "
            "(allowed: at least 2 runs)"
        )
    lo, hi = _ci(d, seed, n_boot, model=model, a=a, b=b, statistic=f"paired_{measure}")
    return Paired(float(d.mean()), ci.low, ci.high, int(d.size), ci.se, ci.df, ci.df + 1, lo, hi)


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


#: rules of :func:`select_run` (the config's frontier.recording.select)
RUN_SELECTIONS = ("nearest_mean", "nearest_median", "largest_gain", "largest_loss")


def select_run(
    runs: pd.DataFrame,
    model: str,
    a: str,
    b: str,
    rule: str,
    path: str = "frontier.recording.select",
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


# ------------------------------------------------------------------------ the protocol

#: per (model, configuration) of the confirmatory run (:func:`summarize_configs`)
CONFIG_SUMMARY_COLUMNS = [
    "model",
    "config",
    "member",
    "family",
    "maxiter",
    "restarts",
    "plan_ms",
    "plan_lo_ms",
    "plan_hi_ms",
    "loop_ms",
    "work_per_step",
    "mean_nit",
    "converged_rate",
    "plan_depth",
    "max_depth",
    "root_actions",
    "frac_depth1",
    "runs",
    "mean_error",
    "error_diff",
    "error_diff_low",
    "error_diff_high",
    "lost_rate",
]


def summarize_configs(runs: pd.DataFrame, timing: pd.DataFrame) -> pd.DataFrame:
    """Per (model, configuration) of a protocol run (:data:`CONFIG_SUMMARY_COLUMNS`): compute
    in both units (interleaved wall clock: median and per-pass range; closed loop's own
    time; model steps, iterations, convergence, a tree search's depth statistics, each the
    median or mean over runs), mean location error and its paired difference with NBO over
    runs with the 95% t interval (one value per run). ``runs``:
    :data:`rsmhp.studies.frontier.simulate.CONFIG_RUN_COLUMNS`; ``timing``:
    :data:`rsmhp.studies.frontier.simulate.CONFIG_TIMING_COLUMNS`."""
    base = methods.baseline()().name
    times = timing_summary(timing.rename(columns={"config": "method"}))
    out = []
    for model, g in runs.groupby("model", sort=False):
        err = g.pivot(index="run", columns="config", values="mean_error")
        if base not in err.columns:
            raise ValueError(f"runs: no {base!r} rows on {model!r} (every comparison needs it)")
        for config, m in g.groupby("config", sort=False):
            if (model, config) not in times.index:
                raise ValueError(f"timing: no interleaved timing of {config!r} on {model!r}")
            d = (err[config] - err[base]).to_numpy(float)
            lo, hi = _cluster_ci(d, err.index.to_numpy())
            conv = m["converged_rate"]
            out.append(
                {
                    "model": model,
                    "config": config,
                    "member": m["member"].iloc[0],
                    "family": m["family"].iloc[0],
                    "maxiter": int(m["maxiter"].iloc[0]),
                    "restarts": int(m["restarts"].iloc[0]),
                    **{k: float(v) for k, v in times.loc[(model, config)].items()},
                    "loop_ms": float(m["plan_ms"].mean()),
                    "work_per_step": float(m["work_per_step"].median()),
                    "mean_nit": float(m["mean_nit"].mean()),
                    "converged_rate": float(conv.mean()) if conv.notna().any() else float("nan"),
                    **{k: float(m[k].mean()) for k in _DEPTH},
                    "runs": len(m),
                    "mean_error": float(m["mean_error"].mean()),
                    "error_diff": float(d.mean()),
                    "error_diff_low": lo,
                    "error_diff_high": hi,
                    "lost_rate": float(m["lost"].astype(bool).mean()),
                }
            )
    return pd.DataFrame(out, columns=CONFIG_SUMMARY_COLUMNS)


_DEPTH = ("plan_depth", "max_depth", "root_actions", "frac_depth1")


def paired_configs(runs: pd.DataFrame, model: str, a: str, b: str) -> Paired:
    """d = mean location error of configuration ``a`` − that of ``b`` on ``model``, paired
    over runs: mean, 95% t interval (:func:`cluster_mean_ci` with one value per run), its
    standard error and degrees of freedom (no bootstrap: ``boot_*`` are NaN)."""
    g = runs[runs["model"] == model]
    wide = g.pivot(index="run", columns="config", values="mean_error")
    for name, c in (("a", a), ("b", b)):
        if c not in wide.columns:
            raise ValueError(f"{name}: {c!r} has no runs on {model!r}")
    d = (wide[a] - wide[b]).dropna().to_numpy(float)
    ci = cluster_mean_ci(d, np.arange(d.size))
    if ci is None:
        raise ValueError(f"{a} − {b} on {model!r}: {d.size} paired run(s) (allowed: at least 2)")
    return Paired(float(d.mean()), ci.low, ci.high, int(d.size), ci.se, ci.df, ci.df + 1)


def prob_improvement(a: np.ndarray, b: np.ndarray) -> tuple[float, float, float]:
    r"""Probability of improvement of a over b (lower is better) over paired runs, as rliable
    defines it: :math:`P = \frac1n \sum_r [1(a_r < b_r) + \tfrac12 1(a_r = b_r)]`, with the
    95% t interval of that mean over runs, clipped to [0, 1]. Fewer than 2 runs: NaN CI."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.shape != b.shape or a.ndim != 1 or a.size == 0:
        raise ValueError(f"a and b must be 1-D of one length >= 1, got {a.shape} and {b.shape}")
    s = paired_wins(a, b)
    p = float(s.mean())
    if s.size < 2:
        return p, float("nan"), float("nan")
    ci = cluster_mean_ci(s, np.arange(s.size))
    return p, max(0.0, ci.low), min(1.0, ci.high)


#: per (model, budget, family) of the confirmatory run (:func:`ladder`)
LADDER_COLUMNS = [
    "model",
    "budget_ms",
    "family",
    "config",
    "plan_ms",
    "loop_ms",
    "cost_ms",
    "work_per_step",
    "within_budget",
    "mean_error",
    "diff_mc",
    "diff_mc_low",
    "diff_mc_high",
    "p_improve",
    "p_improve_low",
    "p_improve_high",
    "diff_nbo",
    "diff_nbo_low",
    "diff_nbo_high",
]


def ladder(
    runs: pd.DataFrame,
    summary: pd.DataFrame,
    chosen: Mapping[str, Mapping[str, Mapping[str, Any]]],
    budgets_ms: Sequence[float],
    reference: str = "rsmhp",
) -> pd.DataFrame:
    """Per model, budget and family (:data:`LADDER_COLUMNS`): the tuned configuration
    (``chosen[model][budget text][family]``, a :class:`rsmhp.pipeline.protocol.Configuration`), its
    interleaved time, closed-loop time, the cost the budget counts (``cost_ms``:
    :func:`rsmhp.pipeline.protocol.budget_cost` of this run's two times, as the tuning rule counts
    them) and work per step, ``within_budget`` (cost within the budget), its mean error,
    the paired difference with the ``reference`` family's member at the same budget (t CI
    over runs) with the probability of improvement over it (:func:`prob_improvement`), and
    the paired difference with NBO (from ``summary``, :func:`summarize_configs`)."""
    s = summary.set_index(["model", "config"])
    out = []
    for model, per in chosen.items():
        g = runs[runs["model"] == model]
        wide = g.pivot(index="run", columns="config", values="mean_error")
        for b in budgets_ms:
            fams = per.get(f"{float(b):g}", {})
            ref = fams.get(reference)
            for family, c in fams.items():
                row = s.loc[(model, c.name)]
                cost = float(budget_cost(row["plan_ms"], row["loop_ms"]))
                rec = {
                    "model": model,
                    "budget_ms": float(b),
                    "family": family,
                    "config": c.name,
                    "plan_ms": float(row["plan_ms"]),
                    "loop_ms": float(row["loop_ms"]),
                    "cost_ms": cost,
                    "work_per_step": float(row["work_per_step"]),
                    "within_budget": cost <= float(b),
                    "mean_error": float(row["mean_error"]),
                    "diff_nbo": float(row["error_diff"]),
                    "diff_nbo_low": float(row["error_diff_low"]),
                    "diff_nbo_high": float(row["error_diff_high"]),
                }
                nan = float("nan")
                if ref is not None and ref.name != c.name:
                    d = paired_configs(runs, model, c.name, ref.name)
                    p = prob_improvement(wide[c.name].to_numpy(), wide[ref.name].to_numpy())
                    rec.update(diff_mc=d.mean, diff_mc_low=d.low, diff_mc_high=d.high)
                    rec.update(p_improve=p[0], p_improve_low=p[1], p_improve_high=p[2])
                elif ref is not None:  # the reference itself
                    rec.update(diff_mc=0.0, diff_mc_low=0.0, diff_mc_high=0.0)
                    rec.update(p_improve=0.5, p_improve_low=nan, p_improve_high=nan)
                else:
                    rec.update(diff_mc=nan, diff_mc_low=nan, diff_mc_high=nan)
                    rec.update(p_improve=nan, p_improve_low=nan, p_improve_high=nan)
                out.append(rec)
    return pd.DataFrame(out, columns=LADDER_COLUMNS)
