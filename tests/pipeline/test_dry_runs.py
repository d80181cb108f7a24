"""Dry runs of the whole workflow (``snakemake -n``): Snakemake parses the workflow and plans
every job, none runs. Not marked ``workflow`` (the line is drawn at executing jobs: see
tests/conftest.py), so they are in the fast tier. The tiny config's dry run through the SLURM
profile is the session fixture ``tiny_dry_run``, which tests/pipeline/test_split_workflow.py
and tests/studies/horizon/test_optimiser_split_workflow.py read as well."""

from __future__ import annotations

import subprocess
import sys

import pytest
import yaml

from tests.pipeline.test_workflow import ROOT


def test_slurm_profile_plans_every_rule(tiny_dry_run, tmp_path):
    """workflow/profiles/slurm dry-runs the whole workflow with the SLURM executor plugin
    (installed by the dev extra: then ``tiny_dry_run`` is the profile's) and applies its
    per-rule resources."""
    pytest.importorskip("snakemake_executor_plugin_slurm")
    out = tiny_dry_run
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
