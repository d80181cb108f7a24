r"""Across the benchmark's scenarios: how often each planning method beats NBO in closed loop.

A scenario is one set of paired closed-loop runs of several methods: a cell of the
sensitivity map (``decisions.map``: a footprint radius and a target manoeuvrability, H = 6,
the decision study's stream) or a (model variant, horizon) of the long-horizon study
(``horizon.uav``, its closed loop, the confirmatory stream). In each, run r of every method
faces the same scenario draw, so a method X is compared with NBO run by run: its
probability of improvement there is :math:`p_s = P(e_X < e_{NBO})` over the paired runs (e:
the run's mean location error, m). :func:`improvement_summary` averages :math:`p_s` over the
scenarios of each group (and of all of them) with a stratified bootstrap interval
(:func:`rsmhp.core.stats.probability_of_improvement`). The summary is descriptive, not a claim:
the scenario set, the methods and the streams were fixed by the studies it reads.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from rsmhp.core.stats import paired_wins, probability_of_improvement
from rsmhp.models.uav import methods

__all__ = [
    "PER_SCENARIO_COLUMNS",
    "RUN_COLUMNS",
    "SUMMARY_COLUMNS",
    "improvement_summary",
    "per_scenario",
    "scenario_runs",
]

#: the long per-run table every function here reads (:func:`scenario_runs`)
RUN_COLUMNS = ["group", "scenario", "method", "run", "mean_error"]
#: :func:`per_scenario`
PER_SCENARIO_COLUMNS = ["group", "scenario", "method", "runs", "p_improve", "mean_diff"]
#: :func:`improvement_summary`
SUMMARY_COLUMNS = ["group", "method", "family", "scenarios", "p_improve", "low", "high",
                   "share_above_half", "mean_diff", "worse_scenarios"]  # fmt: skip

MAP_GROUP = "map cells (H = 6)"
HORIZON_GROUP = "horizons (H = 2 to 24)"
ALL_GROUP = "all scenarios"


def _radius(v) -> str:
    return "no footprint" if pd.isna(v) else f"footprint {float(v):g} m"


def scenario_runs(map_runs: pd.DataFrame | None, closed: pd.DataFrame | None) -> pd.DataFrame:
    """The long table (:data:`RUN_COLUMNS`) of the map's runs (columns ``cell``,
    ``row_value`` (footprint radius, NaN: none), ``col_value`` (q), ``method``, ``run``,
    ``mean_error``) and the long-horizon closed loop (``model``, ``H``, ``method``, ``run``,
    ``mean_error``); either may be ``None`` or empty (a study that is not configured)."""
    parts = []
    if map_runs is not None and len(map_runs):
        m = map_runs
        label = [f"{c}: {_radius(r)}, q {float(q):g}" for c, r, q in
                 zip(m["cell"], m["row_value"], m["col_value"], strict=True)]  # fmt: skip
        parts.append(pd.DataFrame({"group": MAP_GROUP, "scenario": label,
                                   "method": m["method"], "run": m["run"],
                                   "mean_error": m["mean_error"]}))  # fmt: skip
    if closed is not None and len(closed):
        c = closed
        label = [f"{mo}, H = {int(h)}" for mo, h in zip(c["model"], c["H"], strict=True)]
        parts.append(pd.DataFrame({"group": HORIZON_GROUP, "scenario": label,
                                   "method": c["method"], "run": c["run"],
                                   "mean_error": c["mean_error"]}))  # fmt: skip
    if not parts:
        return pd.DataFrame(columns=RUN_COLUMNS)
    out = pd.concat(parts, ignore_index=True)
    dup = out.duplicated(["group", "scenario", "method", "run"])
    if dup.any():
        r = out[dup].iloc[0]
        raise ValueError(
            f"scenario runs: run {r['run']} of {r['method']!r} appears twice in {r['scenario']!r}"
        )
    return out


def _wide(runs: pd.DataFrame) -> dict[tuple[str, str], pd.DataFrame]:
    """Per (group, scenario): its runs x methods table of mean errors."""
    return {
        key: g.pivot(index="run", columns="method", values="mean_error")
        for key, g in runs.groupby(["group", "scenario"], sort=False)
    }


def _pairs(
    wide: dict[tuple[str, str], pd.DataFrame], method: str, baseline: str
) -> dict[tuple[str, str], tuple]:
    """Per (group, scenario) holding both: the paired arrays (method, baseline) over the
    runs both have, in run order."""
    out = {}
    for key, w in wide.items():
        if method not in w or baseline not in w:
            continue
        both = w[[method, baseline]].dropna()
        if len(both):
            out[key] = (both[method].to_numpy(float), both[baseline].to_numpy(float))
    return out


def _methods(runs: pd.DataFrame, baseline: str) -> list[str]:
    return [m for m in dict.fromkeys(runs["method"]) if m != baseline]


def per_scenario(runs: pd.DataFrame, baseline: str = "nbo") -> pd.DataFrame:
    """Per scenario and method (:data:`PER_SCENARIO_COLUMNS`): the paired runs, the
    probability that the method's run beats the baseline's (ties count 1/2) and the mean
    difference of the errors, method − baseline (m)."""
    rows = []
    wide = _wide(runs)
    for method in _methods(runs, baseline):
        for (group, scenario), (x, y) in _pairs(wide, method, baseline).items():
            wins = paired_wins(x, y)
            rows.append({"group": group, "scenario": scenario, "method": method,
                         "runs": len(x), "p_improve": float(np.mean(wins)),
                         "mean_diff": float(np.mean(x - y))})  # fmt: skip
    return pd.DataFrame(rows, columns=PER_SCENARIO_COLUMNS)


def improvement_summary(
    runs: pd.DataFrame, baseline: str = "nbo", n_boot: int = 2000, seed: int = 0
) -> pd.DataFrame:
    """Per group (each group of scenarios, then all of them) and method
    (:data:`SUMMARY_COLUMNS`): the average over the scenarios that ran both of the
    probability that the method beats the baseline run by run, its 95% stratified-bootstrap
    interval and the share of scenarios whose own probability is above 1/2; beside it, in
    metres, the mean over those scenarios of the scenario's mean paired difference (method −
    baseline, m; scenarios of different models weigh equally, whatever their error's scale)
    and how many scenarios have a mean difference above 0 (the method is worse there on
    average, whatever its probability of winning a run). The row of all scenarios is there
    only for a method that ran in more than one group."""
    rows = []
    groups: Sequence[str] = [*dict.fromkeys(runs["group"]), ALL_GROUP]
    wide = _wide(runs)
    for method in _methods(runs, baseline):
        pairs = _pairs(wide, method, baseline)
        in_groups = {g for g, _ in pairs}
        for group in groups:
            if group == ALL_GROUP and len(in_groups) < 2:
                continue
            sel = [v for (g, _), v in pairs.items() if group in (g, ALL_GROUP)]
            if not sel:
                continue
            imp = probability_of_improvement(sel, n_boot=n_boot, seed=seed)
            diffs = [float(np.mean(x - y)) for x, y in sel]
            rows.append({"group": group, "method": method,
                         "family": methods.from_name(method).family,
                         "scenarios": imp.scenarios, "p_improve": imp.p, "low": imp.low,
                         "high": imp.high,
                         "share_above_half": imp.share_above_half,
                         "mean_diff": float(np.mean(diffs)),
                         "worse_scenarios": int(sum(d > 0 for d in diffs))})  # fmt: skip
    return pd.DataFrame(rows, columns=SUMMARY_COLUMNS)
