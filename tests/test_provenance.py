"""Provenance of a run: code, config, software and machine, as the report rule records it."""

from __future__ import annotations

import subprocess

from rsmhp.provenance import provenance


def test_provenance_names_commit_config_versions_blas_and_cpu(tmp_path):
    prov = provenance({"threads": 2, "seed": 7})
    head = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True).stdout
    assert prov["commit"] == head.strip()
    assert prov["uncommitted changes (outside paper/)"] in ("yes", "no")
    assert len(prov["config sha256"]) == 16
    assert prov["threads"].startswith("2 (of ")
    for key in ("python", "numpy", "scipy", "numba", "snakemake", "blas", "cpu", "cpu flags"):
        assert prov[key] and prov[key] != "not installed", key
    # the hash identifies the config, whatever its key order
    assert provenance({"seed": 7, "threads": 2})["config sha256"] == prov["config sha256"]
    assert provenance({"seed": 8, "threads": 2})["config sha256"] != prov["config sha256"]


def test_provenance_outside_a_git_checkout(tmp_path):
    prov = provenance({"threads": 1}, root=tmp_path)
    assert prov["commit"] == "unknown (not a git checkout)"
    assert prov["uncommitted changes (outside paper/)"] == "unknown"
