"""Provenance of a run: code, config, software and machine, as the report rule records it."""

from __future__ import annotations

import subprocess

from rsmhp.report.provenance import provenance


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


def test_code_provenance_lists_each_rules_recorded_digest_and_its_modules(tmp_path):
    """Per rule: the digests its tables record (with the files), the digest its code gives
    now and the modules behind it; results/paper (the published copy) is not read."""
    import pandas as pd

    from rsmhp.pipeline.code_digest import describe
    from rsmhp.pipeline.io import stamping, write_csv, write_parquet
    from rsmhp.report.provenance import code_provenance

    src = tmp_path / "src" / "rsmhp"
    src.mkdir(parents=True)
    (src / "__init__.py").write_text("")
    (src / "model.py").write_text("def f():\n    return 1\n")
    scripts = tmp_path / "workflow" / "scripts"
    scripts.mkdir(parents=True)
    (scripts / "simulate.py").write_text("from rsmhp.model import f\n")
    now = describe(scripts / "simulate.py", tmp_path / "src")
    results = tmp_path / "results"
    df = pd.DataFrame({"x": [1.0]})
    with stamping(f"simulate:{now.digest}"):
        write_csv(df, results / "sim" / "a.csv")
        write_parquet(df, results / "sim" / "a.parquet")
    with stamping("summarise:0123456789ab"):  # no scripts/summarise.py: no current digest
        write_csv(df, results / "summary.csv")
        write_csv(df, results / "paper" / "copy.csv")
    code = code_provenance(results, scripts, extra={"report": ("fedcba987654", ["p.json"])})
    assert code["rules"]["simulate"] == {
        "recorded": {now.digest: [str(results / "sim/a.csv"), str(results / "sim/a.parquet")]},
        "current": now.digest,
        "modules": ["rsmhp", "rsmhp.model", "simulate.py"],
    }
    assert code["rules"]["summarise"] == {
        "recorded": {"0123456789ab": [str(results / "summary.csv")]}
    }
    assert code["rules"]["report"] == {"recorded": {"fedcba987654": ["p.json"]}}
    assert code["modules"] == {m: d[:12] for m, d in now.modules.items()}
