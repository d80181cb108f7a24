"""The split rules in the workflow (config ``split``, rsmhp.pipeline.split), on the tiny config.

Oracles: the job layout computed here from the config (rsmhp.studies.*.chunks) against the
dry run's job counts; the session's tiny run (every split rule in two jobs per unit) against
a rerun of the same workflow with every rule unsplit (``split`` all 1): the merged tables are
the same bytes, code stamp included, but for measured times (the horizon regret's
``plan_ms``, the ablation's ``cpu_seconds``; the closed-loop tables' planning times are read
from the one run store, so they are the same too).
"""

from __future__ import annotations

import re
import shutil

import pandas as pd
import pytest
import yaml

from rsmhp.pipeline.config import merge
from rsmhp.pipeline.split import SPLIT_RULES
from rsmhp.studies.decisions.chunks import chunk_jobs
from rsmhp.studies.estimators.chunks import ablation_chunks
from rsmhp.studies.frontier.chunks import confirm_chunks
from rsmhp.studies.horizon.chunks import units
from tests.pipeline.test_workflow import ROOT, TINY, snakemake

UNSPLIT = "split={" + ", ".join(f"{r}: 1" for r in SPLIT_RULES) + "}"
#: merged tables with no measured column: the same bytes, split or not
SAME = [
    "results/decisions/uav_regret.csv",
    "results/frontier/confirm/fp150.csv",
    "results/horizon/uav/paper_H2_approx.csv",
    "results/horizon/uav/paper_H4_approx.csv",
    "results/horizon/uav/paper_H2_closed.csv",
    "results/horizon/uav/paper_H4_closed.csv",
    "results/horizon/optimiser/paper_H2.csv",
    "results/horizon/optimiser/paper_H4.csv",
]
#: merged tables with a measured column: every other column the same
MEASURED = {
    "results/estimators/ablation.csv": "cpu_seconds",
    "results/horizon/uav/paper_H4_regret.csv": "plan_ms",
}


def _config() -> dict:
    return merge(yaml.safe_load((ROOT / "config/config.yaml").read_text()),
                 yaml.safe_load(TINY.read_text()))  # fmt: skip


def _jobs(out: str) -> dict[str, int]:
    stats = out.split("Job stats:", 1)[1].split("\ntotal", 1)[0]
    return {r: int(n) for r, n in re.findall(r"^(\w+)\s+(\d+)$", stats, flags=re.M)}


def test_dry_run_has_the_configured_jobs(tiny_dry_run):
    """The session's dry run of the tiny config (no job runs: the fast tier)."""
    cfg = _config()
    split, hz, hzo = cfg["split"], cfg["horizon"]["uav"], cfg["horizon"]["optimiser"]
    out = tiny_dry_run
    jobs = _jobs(out)
    est = cfg["estimators"]
    want = {
        "estimators_ablation": len(ablation_chunks(est, cfg["lqg"]["model"], 2)),
        "decisions_uav": len(
            chunk_jobs(
                {**cfg["decisions"]["uav"], "models": cfg["uav_models"]}, split["decisions_uav"]
            )
        ),
        "frontier_confirm": len(confirm_chunks(3, split["frontier_confirm"])),  # 3 runs, fp150
        "horizon_uav": sum(
            j for *_, j in units(hz["models"], hz["H"], split["horizon_uav"], hz["runs"])
        ),
        "horizon_uav_closed": sum(
            j
            for *_, j in units(
                hz["models"], hz["H"], split["horizon_uav_closed"], hz["closed_runs"]
            )
        ),
        "horizon_optimiser": sum(
            j
            for *_, j in units(
                hzo.get("models") or hz["models"], hzo["H"], split["horizon_optimiser"], hzo["runs"]
            )
        ),
    }
    assert {r: jobs[r] for r in SPLIT_RULES} == want
    assert want["horizon_uav"] == 3  # H = 4 in two jobs, H = 2 in one
    # one merge per rule (per model for the confirmatory run)
    assert {jobs[f"{r}_merge"] for r in SPLIT_RULES} == {1}
    assert "results/horizon/uav/chunks/paper_H4/1_closed.csv" in out


@pytest.mark.workflow
def test_unsplit_rerun_writes_the_same_tables(run_j2, tmp_path):
    run = tmp_path / "run"
    shutil.copytree(run_j2, run, symlinks=True)
    res = snakemake(run, "-j2", "--config", UNSPLIT, "--", *SAME, *MEASURED)
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-3000:]
    ran = _jobs(out)
    # every rule with more than one job in a unit ran again, unsplit, and so did every merge
    assert set(SPLIT_RULES) <= set(ran) and {f"{r}_merge" for r in SPLIT_RULES} <= set(ran)
    for rel in SAME:
        assert (run / rel).read_bytes() == (run_j2 / rel).read_bytes(), rel
    for rel, measured in MEASURED.items():
        a, b = pd.read_csv(run / rel), pd.read_csv(run_j2 / rel)
        assert list(a.columns) == list(b.columns)
        assert a.drop(columns=measured).to_csv(index=False) == b.drop(columns=measured).to_csv(
            index=False
        ), rel
    # the store held every closed-loop run: the unsplit jobs simulated none
    for log in ("frontier_confirm/fp150_0.log", "horizon_uav_closed/paper_H4_0.log"):
        text = (run / "results/logs" / log).read_text()
        assert re.search(r"run store: 0 computed, [1-9]\d* reused", text), (log, text[-2000:])
