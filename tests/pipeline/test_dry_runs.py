"""Dry runs of the whole workflow (``snakemake -n``): Snakemake parses the workflow and plans
every job, none runs. Not marked ``workflow`` (the line is drawn at executing jobs: see
tests/conftest.py), so they are in the fast tier; the tiny config's own dry run is the session
fixture ``tiny_dry_run`` (tests/pipeline/test_split_workflow.py and
tests/studies/horizon/test_optimiser_split_workflow.py read it)."""

from __future__ import annotations

import subprocess
import sys

import pytest
import yaml

from tests.pipeline.test_workflow import ROOT, snakemake


def test_slurm_profile_plans_every_rule(tmp_path):
    """workflow/profiles/slurm dry-runs the whole workflow with the SLURM executor plugin
    (installed by the dev extra) and applies its per-rule resources."""
    pytest.importorskip("snakemake_executor_plugin_slurm")
    res = snakemake(tmp_path, "-n", "--profile", str(ROOT / "workflow/profiles/slurm"))
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-3000:]
    listing = subprocess.run(
        [sys.executable, "-m", "snakemake", "-s", str(ROOT / "Snakefile"), "--list-rules"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        check=True,
    ).stdout
    every = {line.split()[0] for line in listing.splitlines() if line.strip()}
    planned = {
        line.split()[1].rstrip(":")
        for line in out.splitlines()
        if line.startswith(("rule ", "localrule "))
    }
    # the default target plans every rule except the six study-level target rules and verify
    targets = {"lqg", "estimators", "uav", "decisions", "frontier", "horizon", "verify"}
    # ... and the protocol's tuning (its own target, `make tune`) and the exploratory target
    targets |= {"tune", "frontier_tune", "frontier_tune_timing", "frontier_tune_select"}
    targets |= {"frontier_exploratory"}
    # ... and the comparison of new planners with the reference (make compare)
    targets |= {"compare", "frontier_compare", "frontier_compare_run"}
    assert planned == every - targets
    profile = yaml.safe_load((ROOT / "workflow/profiles/slurm/config.yaml").read_text())
    assert profile["executor"] == "slurm"
    block = out.split("rule estimators_ablation:", 1)[1].split("\n\n", 1)[0]
    assert "mem_mb=8000" in block and "runtime=60" in block
