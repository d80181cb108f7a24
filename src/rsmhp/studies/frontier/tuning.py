r"""What the tuning runs show beyond the selection (tuning stream only): every candidate's
cost and error, and what a tree search's depth buys.

:func:`candidate_table`: per model and candidate configuration, the numbers the selection rule
(:func:`rsmhp.pipeline.protocol.select`) compares: mean closed-loop location error over the
tuning runs, the planning cost per step it counts (the larger of the median interleaved time
and the closed loop's mean time per step, ms), work (model steps per step, median over runs)
and, for a tree search, the mean plan depth (steps of the plan from the tree, mean over runs of
the per-run means). :func:`depth_table`: per model, every tree search and the pursuit policy
alone (plan depth 0), each tree search's paired difference from the pursuit policy (m, mean
over the tuning runs with its 95% t interval; runs pair by seed), so a reader sees how much of
the tree search's error is the pursuit policy's and what the search adds at each depth.
Descriptive: the tuning stream chooses, it does not judge.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from rsmhp.core.stats import mean_ci
from rsmhp.pipeline.protocol import Configuration, candidate_stats

__all__ = ["CANDIDATE_COLUMNS", "DEPTH_TABLE_COLUMNS", "candidate_table", "depth_table"]

CANDIDATE_COLUMNS = [
    "model", "config", "family", "member", "maxiter", "restarts", "start", "runs",
    "mean_error", "cost_ms", "timing_ms", "closed_loop_ms", "work_per_step", "plan_depth",
]  # fmt: skip
DEPTH_TABLE_COLUMNS = [
    "model", "config", "plan_depth", "frac_depth1", "mean_error", "cost_ms", "diff_pursuit",
    "diff_low", "diff_high", "runs",
]  # fmt: skip

#: the pursuit policy's member name (the depth table's reference)
PURSUIT = "pursuit"


def candidate_table(
    quality: pd.DataFrame, timing: pd.DataFrame, configs: Sequence[Configuration]
) -> pd.DataFrame:
    """:data:`CANDIDATE_COLUMNS`, one row per (model, configuration of ``configs``) with
    closed-loop rows in ``quality`` (columns ``model``, ``config``, ``run``, ``mean_error``,
    ``plan_ms``, ``work_per_step``, ``plan_depth``) and timing rows in ``timing`` (``model``,
    ``config``, ``ms``); in model order, then the configurations' order."""
    q = candidate_stats(quality, timing).join(
        quality.groupby(["model", "config"], sort=False).agg(
            runs=("run", "nunique"), plan_depth=("plan_depth", "mean")
        )
    )
    rows = []
    for model in dict.fromkeys(quality["model"]):
        for c in configs:
            if (model, c.name) not in q.index or pd.isna(q.loc[(model, c.name), "mean_error"]):
                continue
            r = q.loc[(model, c.name)]
            rows.append({
                "model": model, "config": c.name, "family": c.family, "member": c.member,
                "maxiter": c.maxiter, "restarts": c.restarts, "start": c.start,
                "runs": int(r["runs"]), "mean_error": float(r["mean_error"]),
                "cost_ms": float(r["cost_ms"]),
                "timing_ms": float(r["timing_ms"]), "closed_loop_ms": float(r["closed_loop_ms"]),
                "work_per_step": float(r["work_per_step"]), "plan_depth": float(r["plan_depth"]),
            })  # fmt: skip
    return pd.DataFrame(rows, columns=CANDIDATE_COLUMNS)


def depth_table(quality: pd.DataFrame, candidates: pd.DataFrame) -> pd.DataFrame:
    """:data:`DEPTH_TABLE_COLUMNS`: per model, the pursuit policy alone (difference 0) and
    every tree search (family ``dpw``) of ``candidates`` (:func:`candidate_table`), in order
    of mean plan depth, with the paired difference of its runs' mean errors from the pursuit
    policy's (``quality``, runs paired by run index). A model without the pursuit policy's
    runs gets no differences (NaN)."""
    rows = []
    for model, cand in candidates.groupby("model", sort=False):
        q = quality[quality["model"] == model]
        wide = q.pivot(index="run", columns="config", values="mean_error")
        frac = q.groupby("config")["frac_depth1"].mean() if "frac_depth1" in q else None
        sel = cand[(cand["family"] == "dpw") | (cand["config"] == PURSUIT)]
        for r in sel.sort_values("plan_depth", kind="stable").itertuples(index=False):
            d = lo = hi = np.nan
            if PURSUIT in wide and r.config != PURSUIT:
                both = wide[[r.config, PURSUIT]].dropna()
                if len(both) >= 2:
                    d, lo, hi = mean_ci((both[r.config] - both[PURSUIT]).to_numpy(float))
            elif r.config == PURSUIT:
                d = lo = hi = 0.0
            rows.append({
                "model": model, "config": r.config, "plan_depth": r.plan_depth,
                "frac_depth1": float(frac.get(r.config, np.nan)) if frac is not None else np.nan,
                "mean_error": r.mean_error, "cost_ms": r.cost_ms, "diff_pursuit": d,
                "diff_low": lo, "diff_high": hi, "runs": r.runs,
            })  # fmt: skip
    return pd.DataFrame(rows, columns=DEPTH_TABLE_COLUMNS)
