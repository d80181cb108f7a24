"""How long the default replication would take with the third preregistration's design in
place of the published one, from a finished run's own job times (issue 43).

    .venv/bin/python benchmarks/confirm_v3_estimate.py [--results results]
        [--preregistration config/preregistration_v3.yaml] [--tuned config/tuned_v3.yaml]
        [--candidates paper/tuning_v3/candidates.csv] [--avx2 1.06] [--setup 90]
        [--job-seconds paper/tuning_v3/replication_job_seconds.csv] [--write-job-seconds FILE]

Every job's wall time is the ``s`` column of its ``results/benchmarks/`` file. What the design
changes is scaled: the UAV study's simulations by the ratio of closed-loop runs, the decision
study's open-loop jobs by the ratio of belief states (runs), the long-horizon study's
open-loop jobs by the ratio of runs; the confirmatory closed loop is replaced by the third
design's (per model: runs x every configuration's (60 steps x its mean closed-loop ms per
step on the tuning stream + the tuning run's 5.3 ms of other work per run), the tuning jobs'
own per-run overhead) and its timing job scaled by the number of configurations. Set-up (venv,
kernels) is added as measured by the fresh-clone runs (about 90 s). ``--avx2`` scales the job
time to a CPU without AVX-512 (1.06: the emulated run of issue 35, docs/performance.md). The
wall time on two cores is at least half the job time (no idle core), so the estimate prints
that bound: a lower bound of the wall time, not a forecast. Nothing is run.
``--job-seconds`` reads the per-rule sums from a CSV (rule, seconds) instead of
``results/benchmarks/`` (the committed one is the replication the third preregistration's
estimate used); ``--write-job-seconds`` writes that CSV from ``results/``.
"""

from __future__ import annotations

import argparse
import csv
from collections import defaultdict
from pathlib import Path

import pandas as pd
import yaml

from rsmhp.pipeline.protocol import DRY_RUN_STREAM, Preregistration

STEPS = 60  # closed-loop steps of a run (uav.scenario.steps)
RUN_OVERHEAD_S = 0.0053  # per closed-loop run beyond planning (the third tuning's jobs)


def job_seconds(results: Path) -> dict[str, float]:
    """Rule -> the sum of its jobs' wall seconds."""
    out: dict[str, float] = defaultdict(float)
    for f in (results / "benchmarks").rglob("*.tsv"):
        rule = f.parent.name if f.parent.name != "benchmarks" else f.stem
        with f.open() as fh:
            rows = list(csv.DictReader(fh, delimiter="\t"))
        out[rule] += float(rows[0]["s"]) if rows else 0.0
    return dict(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", default="results")
    ap.add_argument("--preregistration", default="config/preregistration_v3.yaml")
    ap.add_argument("--tuned", default="config/tuned_v3.yaml")
    ap.add_argument("--candidates", default="paper/tuning_v3/candidates.csv")
    ap.add_argument("--config", default="config/config.yaml")
    ap.add_argument("--avx2", type=float, default=1.06)
    ap.add_argument("--setup", type=float, default=90.0)
    ap.add_argument("--job-seconds", default=None)
    ap.add_argument("--write-job-seconds", default=None)
    a = ap.parse_args()
    if a.job_seconds:
        table = pd.read_csv(a.job_seconds)
        jobs = dict(zip(table["rule"], table["seconds"].astype(float), strict=True))
    else:
        jobs = job_seconds(Path(a.results))
    if a.write_job_seconds:
        pd.DataFrame(sorted(jobs.items()), columns=["rule", "seconds"]).to_csv(
            a.write_job_seconds, index=False, float_format="%.2f"
        )
    cfg = yaml.safe_load(Path(a.config).read_text())
    pre = Preregistration.load(a.preregistration, a.tuned, DRY_RUN_STREAM)
    tuned = yaml.safe_load(Path(a.tuned).read_text())
    cand = pd.read_csv(a.candidates).set_index(["model", "config"])
    doc = pre.doc
    confirm3, n_configs = 0.0, 0
    for m in doc["models"]:
        configs = pre.configurations(tuned, m)
        n_configs += len(configs)
        per_run = sum(STEPS * cand.loc[(m, c.name), "closed_loop_ms"] / 1e3 + RUN_OVERHEAD_S
                      for c in configs)  # fmt: skip
        confirm3 += pre.runs(m) * per_run
    old_configs = 0
    old = Preregistration.load(cfg["frontier"]["confirm"]["preregistration"],
                               cfg["frontier"]["confirm"]["tuned"])  # fmt: skip
    old_tuned = yaml.safe_load(Path(cfg["frontier"]["confirm"]["tuned"]).read_text())
    old_configs = sum(len(old.configurations(old_tuned, m)) for m in old.doc["models"])
    scale = {
        "uav_simulate": doc["paper_claims"]["uav_runs"] / cfg["uav"]["runs"],
        "decisions_uav": doc["paper_claims"]["decisions_runs"] / cfg["decisions"]["uav"]["runs"],
        "horizon_uav": doc["horizon"]["uav"]["runs"] / cfg["horizon"]["uav"]["runs"],
        "frontier_confirm_timing": n_configs / old_configs,
    }
    rows = []
    for rule, s in sorted(jobs.items()):
        if rule.startswith("frontier_tune"):
            continue  # not part of the replication
        new = confirm3 if rule == "frontier_confirm" else s * scale.get(rule, 1.0)
        rows.append((rule, s, new))
    now = sum(r[1] for r in rows)
    then = sum(r[2] for r in rows)
    print(f"{'rule':32s} {'this run (s)':>12s} {'third design (s)':>16s}")
    for rule, s, new in rows:
        if abs(new - s) > 0.05 or s > 60:
            print(f"{rule:32s} {s:12.1f} {new:16.1f}")
    print(f"{'total job time':32s} {now:12.1f} {then:16.1f}")
    for name, total in (("this run", now), ("third design", then)):
        wall = a.setup + a.avx2 * total / 2
        print(f"{name}: at least {wall / 60:.1f} min on 2 cores without AVX-512 "
              f"({a.setup:.0f} s set-up + {a.avx2:g} x {total:.0f} s / 2)")  # fmt: skip


if __name__ == "__main__":
    main()
