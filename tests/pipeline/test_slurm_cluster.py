"""The workflow on a real single-node SLURM cluster (scripts/slurm-local.sh), through the
profile workflow/profiles/slurm, with the commands of docs/cluster.md.

Marker ``slurm``: run on the project's machines (root on Debian; CI brings the cluster up from
the distribution's packages), skipped with the reason elsewhere. Oracles: SLURM's own record
of every finished job (/var/log/slurm/jobcomp.tsv, written by slurmctld's jobcomp/script hook,
and `scontrol`), a local -j2 run of the same targets (byte-identical tables apart from
timing columns) and the profile's and rules' declared threads and memory.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
import yaml

from tests.pipeline.test_workflow import ROOT, TINY, snakemake

pytestmark = pytest.mark.slurm

SCRIPT = ROOT / "scripts" / "slurm-local.sh"
PROFILE = ROOT / "workflow" / "profiles" / "slurm"
RECORDS = Path("/var/log/slurm/jobcomp.tsv")
#: docs/cluster.md's command, with the node's CPU count as max-threads and quick status checks
RUN = [
    sys.executable, "-m", "snakemake", "-s", str(ROOT / "Snakefile"), "--configfile", str(TINY),
    "--profile", str(PROFILE), "--max-threads", str(os.cpu_count() or 1),
    "--seconds-between-status-checks", "2", "--slurm-init-seconds-before-status-checks", "2",
]  # fmt: skip


def _why_not() -> str | None:
    if os.name != "posix" or os.geteuid() != 0:
        return "needs root to bring up a local SLURM cluster (scripts/slurm-local.sh up)"
    if not Path("/etc/debian_version").exists() or shutil.which("apt-get") is None:
        return "needs a Debian machine with apt-get (SLURM from the distribution's packages)"
    if os.environ.get("RSMHP_SLURM_TEST", "1") == "0":
        return "RSMHP_SLURM_TEST=0"
    return None


@pytest.fixture(scope="module")
def cluster():
    """The local cluster, up for this module and down after it."""
    reason = _why_not()
    if reason:
        pytest.skip(reason)
    res = subprocess.run(["bash", str(SCRIPT), "up"], capture_output=True, text=True, check=False)
    if res.returncode != 0 and "not available from the configured apt sources" in res.stderr:
        pytest.skip(res.stderr.strip())
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-2000:]
    yield
    subprocess.run(["bash", str(SCRIPT), "down"], capture_output=True, text=True, check=False)


def _records(workdir: Path) -> pd.DataFrame:
    """SLURM's records of the jobs whose log lies under ``workdir``, with their rule."""
    df = pd.read_csv(RECORDS, sep="\t", dtype=str, keep_default_na=False)
    df = df[df["StdOut"].str.startswith(str(workdir))].copy()
    df["rule"] = df["Comment"].str.extract(r"^rule_(.+?)(?:_wildcards_.*)?$")[0]
    return df


def _tres(tres: str) -> dict[str, str]:
    return dict(kv.split("=", 1) for kv in tres.split(",") if "=" in kv)


def _planned(out: str) -> dict[str, int]:
    """Snakemake's job table ("Job stats"): rule -> jobs."""
    table = out.split("Job stats:", 1)[1].split("total", 1)[0]
    return {
        m.group(1): int(m.group(2)) for m in re.finditer(r"^(\w+)\s+(\d+)\s*$", table, flags=re.M)
    }


#: the targets run through SLURM, the smallest set that still shows each thing the test is for
#: (3 jobs of the tiny config; each SLURM job starts its own snakemake): lqg_convergence (8
#: threads in the profile, capped by max-threads; the job cancelled and retried),
#: horizon_lqg_estimators (2 threads and 3000 MB of the rule's own) and one horizon_uav job
#: (a job loading the compiled kernels). The first version's 25 jobs (targets `lqg horizon`)
#: and the second's 10 (the LQG summary, the long-horizon merges) checked nothing more of SLURM
TARGETS = [
    "results/lqg/convergence.csv",
    "results/horizon/lqg_estimators.csv",
    "results/horizon/uav/chunks/paper_H2/0_approx.csv",
]
#: tables compared byte for byte with the local run (no timing column: the chunk's regret
#: table has plan_ms)
SAME = [
    "results/lqg/convergence.csv",
    "results/horizon/uav/chunks/paper_H2/0_approx.csv",
]


def test_workflow_runs_through_slurm_like_locally_and_survives_scancel(cluster, tmp_path):
    """docs/cluster.md's command on three jobs of the tiny config (TARGETS):
    every job goes through SLURM (its records), the tables equal the local run's, the CPUs and
    memory of each job are the rule's and the profile's; a running job cancelled with scancel
    is retried (`retries: 1`) and the run completes."""
    proc = subprocess.Popen(
        [*RUN, *TARGETS],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    cancelled = None
    deadline = time.time() + 300
    while cancelled is None and time.time() < deadline and proc.poll() is None:
        q = subprocess.run(
            ["squeue", "-h", "-t", "RUNNING", "-o", "%i|%k"],
            capture_output=True, text=True, check=False,
        )  # fmt: skip
        for line in q.stdout.splitlines():
            jid, comment = line.split("|", 1)
            if comment.startswith("rule_lqg_convergence"):
                subprocess.run(["scancel", jid], check=True)
                cancelled = jid
                break
        time.sleep(0.5)
    out, _ = proc.communicate(timeout=900)
    assert cancelled is not None, "no lqg_convergence job was seen running\n" + out[-3000:]
    assert proc.returncode == 0, out[-4000:]
    rec = _records(tmp_path)
    conv = rec[rec["rule"] == "lqg_convergence"]
    assert list(conv["JobState"]) == ["CANCELLED", "COMPLETED"], conv
    assert conv["JobId"].iloc[0] == cancelled
    # every job Snakemake planned went through the scheduler (local rules: the targets); the
    # cancelled job was planned once and submitted twice
    planned = _planned(out)
    local = set(re.findall(r"^localrule (\w+):", out, flags=re.M))
    done = rec[rec["JobState"] == "COMPLETED"].groupby("rule").size().to_dict()
    assert {r: n for r, n in planned.items() if r not in local} == done
    assert set(rec["JobState"]) == {"COMPLETED", "CANCELLED"} and (rec["Partition"] != "").all()
    assert local <= {"all", "lqg", "estimators", "uav", "decisions", "frontier", "horizon"}
    # the results are a local run's, byte for byte: the same targets with -j2 in a directory of
    # their own (3 jobs; not the session's shared run, which this worker would wait for)
    local_run = tmp_path / "local"
    res = snakemake(local_run, "-j2", *TARGETS)
    assert res.returncode == 0, res.stderr[-3000:]
    for rel in SAME:
        assert (tmp_path / rel).read_bytes() == (local_run / rel).read_bytes(), rel
    # threads and memory that reached each job: the rule's, after the profile's set-threads
    # (capped by max-threads = the node's CPUs) and set-resources / default-resources
    profile = yaml.safe_load((PROFILE / "config.yaml").read_text())
    cpus = os.cpu_count() or 1
    for _, r in rec.iterrows():
        tres = _tres(r["TRES"])
        declared = profile["set-threads"].get(r["rule"])
        if declared is not None:
            assert int(tres["cpu"]) == min(declared, cpus), r["rule"]
        mem = profile["set-resources"].get(r["rule"], {}).get("mem_mb")
        assert tres["mem"] == f"{mem or profile['default-resources']['mem_mb']}M" or (
            mem is None and r["rule"] in RULE_MEM
        ), (r["rule"], tres)
    first = {rule: _tres(g["TRES"].iloc[-1]) for rule, g in rec.groupby("rule")}
    assert first["lqg_convergence"]["cpu"] == str(min(8, cpus))
    assert first["lqg_convergence"]["mem"] == "4000M"
    # a rule's own threads and memory (horizon_lqg_estimators: 2 threads, 3000 MB)
    assert first["horizon_lqg_estimators"]["cpu"] == str(min(2, cpus))
    assert first["horizon_lqg_estimators"]["mem"] == "3000M"


#: rules that declare their own mem_mb (not in the profile's set-resources)
RULE_MEM = {
    "horizon_lqg_estimators", "horizon_lqg_regret", "horizon_summary", "horizon_uav",
    "horizon_uav_closed", "horizon_figures", "horizon_recording", "lqg_summary",
    "lqg_figures", "lqg_recording", "lqg_linear_cost", "horizon_optimiser",
    "horizon_optimiser_summary", "horizon_optimiser_figures", "horizon_uav_merge",
    "horizon_uav_closed_merge", "horizon_optimiser_merge",
}  # fmt: skip


def test_a_job_larger_than_any_node_is_refused_before_submission(cluster, tmp_path):
    """Without max-threads the profile's 8-thread rules exceed a smaller node: the run is
    refused up front, naming the rule, its ask and the partition's offer; nothing is queued."""
    cpus = os.cpu_count() or 1
    if cpus >= 8:
        pytest.skip(f"the node has {cpus} CPUs: every rule of the profile fits")
    before = len(pd.read_csv(RECORDS, sep="\t", dtype=str)) if RECORDS.exists() else 0
    at = RUN.index("--max-threads")
    cmd = RUN[:at] + RUN[at + 2 :]
    res = subprocess.run([*cmd, "lqg"], cwd=tmp_path, capture_output=True, text=True, check=False)
    out = res.stdout + res.stderr
    assert res.returncode != 0
    assert (
        f"rule lqg_convergence: asks for 8 CPUs (threads), partition 'debug' offers at most "
        f"{cpus} per node" in out
    )
    assert "nothing was submitted" in out
    after = len(pd.read_csv(RECORDS, sep="\t", dtype=str)) if RECORDS.exists() else 0
    assert after == before
    q = subprocess.run(["squeue", "-h"], capture_output=True, text=True, check=True)
    assert q.stdout.strip() == ""
