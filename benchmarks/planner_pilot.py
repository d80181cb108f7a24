"""Pilot of the equal-compute comparison (issue 21): open-loop regret and planning seconds per
step of every planner family at several sizes, on the decision study's belief states.

    .venv/bin/python benchmarks/planner_pilot.py [--runs 4] [--models paper footprint150]

For each model variant of ``uav_models`` named, the belief states of the first
``--runs`` NBO closed-loop runs at ``decisions.uav.steps`` (the decision study's states and
streams), every method below plans once and is scored exactly as ``decisions_uav`` scores
(:func:`rsmhp.models.uav.scoring.score_state`: regret against the multi-start reference
on an independent evaluation set). Planning time per step is measured separately, in this
process on one thread: the median over the states of the wall time of one ``plan`` call
(after one warm-up call per method). Prints per model and method: mean relative regret (%) with
its standard error over states, its paired difference from NBO's at the same states
(percentage points, with the standard error of the paired differences) and the median
planning milliseconds per step. A pilot, not
the study: it informs the sizes and budgets of the study's config (not a test; numbers move
with the machine).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd
import yaml
from threadpoolctl import threadpool_limits

from rsmhp.core.seeding import job_rng
from rsmhp.models.uav import methods
from rsmhp.models.uav.planner import Belief
from rsmhp.models.uav.scoring import belief_states, merge_variant, score_state
from rsmhp.models.uav.simulation import UAVSetup

ROOT = Path(__file__).resolve().parents[1]
BLOCK = {
    "nbo": True,
    "rsmhp_nt": [16, 64, 256],
    "rqmc_nt": [16, 64, 256],
    "antithetic_nt": [16, 64, 256],
    "sigma": True,
    "dpw": [{"sims": 100}, {"sims": 300}, {"sims": 1000}],
}


def plan_ms(planners, setup, states, seed) -> dict[str, float]:
    """Median wall milliseconds of one plan call per method over ``states``."""
    out = {}
    for name, m in planners.items():
        planner = m.planner(setup)
        times = []
        for k, st in enumerate(states):
            belief = Belief(st.uav, st.x_hat, st.P_hat)
            rng = job_rng(seed, "pilot", state=k, method=name) if m.uses_rng else None
            if k == 0:
                planner.plan(belief, st.warm, rng)  # warm-up (compilation, caches)
            t0 = time.perf_counter()
            planner.plan(belief, st.warm, rng)
            times.append(time.perf_counter() - t0)
        out[name] = 1e3 * float(np.median(times))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=4, help="NBO runs whose belief states are used")
    ap.add_argument("--models", nargs="+", default=["paper", "footprint150"])
    args = ap.parse_args()
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    dec = cfg["decisions"]["uav"]
    variants = {v["name"]: v for v in dec["models"]}
    unknown = sorted(set(args.models) - set(variants))
    if unknown or args.runs < 1:
        ap.error(f"--models from {sorted(variants)} (got {unknown}), --runs >= 1")
    planners = methods.from_config(BLOCK, "pilot")
    seed = cfg["seed"]
    rows = []
    with threadpool_limits(limits=1):
        for model in args.models:
            setup = UAVSetup.from_config(merge_variant(cfg["uav"], variants[model]))
            states = belief_states(setup, model, seed, range(args.runs), dec["steps"])
            ms = plan_ms(planners, setup, states, seed)
            for st in states:
                for r in score_state(st, setup, planners, dec, seed):
                    rows.append({**r, "plan_ms": ms[r["method"]]})
    df = pd.DataFrame(rows)
    # paired with NBO at the same state: regret_rel(method) - regret_rel(NBO)
    base = df[df["method"] == "nbo"].set_index(["model", "run", "step"])["regret_rel"]
    df["vs_nbo"] = (
        df["regret_rel"]
        - base.reindex(pd.MultiIndex.from_frame(df[["model", "run", "step"]])).to_numpy()
    )
    g = df.groupby(["model", "method"], sort=False)
    n = g.size()
    out = pd.DataFrame(
        {
            "regret_rel_pct": 100 * g["regret_rel"].mean(),
            "se_pct": 100 * g["regret_rel"].std(ddof=1) / np.sqrt(n),
            "minus_nbo_pp": 100 * g["vs_nbo"].mean(),
            "paired_se_pp": 100 * g["vs_nbo"].std(ddof=1) / np.sqrt(n),
            "plan_ms": g["plan_ms"].first(),
            "states": n,
        }
    )
    with pd.option_context(
        "display.width", 160, "display.max_rows", 200, "display.max_columns", 20
    ):
        print(out.round(4))


if __name__ == "__main__":
    main()
