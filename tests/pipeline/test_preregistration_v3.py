"""The third preregistration (config/preregistration_v3.yaml): it holds what version 3
requires, its stream is a placeholder the workflow refuses to run, its stated powers are
what its own inputs give (and a file whose powers do not is refused), and its sds from
published intervals are those intervals' sds."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from rsmhp.pipeline.power_design import entry_power, power_problems, sd_from_ci
from rsmhp.pipeline.protocol import (
    DRY_RUN_STREAM,
    PLACEHOLDER_STREAM,
    Preregistration,
    file_sha256,
    tuned_configurations,
)

ROOT = Path(__file__).resolve().parents[2]
V3 = ROOT / "config" / "preregistration_v3.yaml"
TUNED = ROOT / "config" / "tuned_v3.yaml"


def _doc() -> dict:
    return yaml.safe_load(V3.read_text(encoding="utf-8"))


def _write(tmp_path: Path, doc: dict) -> Path:
    p = tmp_path / "pre.yaml"
    p.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return p


def test_the_committed_design_waits_for_its_stream():
    doc = _doc()
    assert doc["version"] == 3 and doc["stream"] == PLACEHOLDER_STREAM
    assert doc["tuned"]["sha256"] == file_sha256(TUNED)
    with pytest.raises(ValueError, match="stream is still '<named by the run issue>'"):
        Preregistration.load(V3, TUNED)
    pre = Preregistration.load(V3, TUNED, DRY_RUN_STREAM)
    assert pre.doc["stream"] == DRY_RUN_STREAM
    for model in doc["models"]:  # every FR claim's families have members at the headline
        per = tuned_configurations(yaml.safe_load(TUNED.read_text()), model)
        head = per[f"{float(doc['headline_budget_ms']):g}"]
        for spec in doc["claims"].values():
            assert spec["family"] in head and spec["against"] in head
    with pytest.raises(ValueError, match="dry_run_stream: 'confirm3'"):
        Preregistration.load(V3, TUNED, "confirm3")


def test_every_stated_power_is_what_its_inputs_give():
    doc = _doc()
    assert power_problems(doc["power"]) == []
    # every claim of Holm's family and every FR setup has a power entry
    for cid in (
        "FR-1",
        "FR-2",
        "FR-3",
        "HZ-1",
        "HZ-2",
        "UAV-1",
        "UAV-2",
        "UAV-3",
        "DEC-6",
        "DEC-7",
    ):
        assert doc["power"][cid], cid
    for model in doc["models"]:
        for cid in doc["claims"]:
            e = doc["power"][cid][model]
            assert (
                e["units"] == doc["runs"][model] and e["margin"] == doc["claims"][cid]["margin_m"]
            )
    # an sd taken from a published interval is that interval's sd
    for setups in doc["power"].values():
        for e in setups.values():
            src = e["sd_from"]
            if "claim" in src:
                assert e["sd"] == pytest.approx(
                    sd_from_ci(src["low"], src["high"], src["n"]), rel=1e-3
                )
    # the design's run counts are those the power block uses
    assert doc["paper_claims"]["uav_runs"] == doc["power"]["UAV-2"]["paper"]["units"]
    assert (
        10 * doc["paper_claims"]["decisions_runs"] == doc["power"]["DEC-7"]["footprint150"]["units"]
    )
    # the run's config overlay runs exactly that design
    overlay = yaml.safe_load((ROOT / "config" / "confirm_v3.yaml").read_text(encoding="utf-8"))
    assert overlay["frontier"]["confirm"]["preregistration"] == "config/preregistration_v3.yaml"
    assert overlay["uav"]["runs"] == doc["paper_claims"]["uav_runs"]
    assert overlay["decisions"]["uav"]["runs"] == doc["paper_claims"]["decisions_runs"]
    assert overlay["horizon"]["uav"]["runs"] == doc["horizon"]["uav"]["runs"]
    assert doc["power"]["HZ-1"]["paper"]["units"] == doc["horizon"]["uav"]["runs"]


def test_a_power_its_inputs_do_not_give_is_refused(tmp_path):
    doc = _doc()
    doc["power"]["FR-2"]["footprint150"]["power"] = 0.99  # the second preregistration's slip
    with pytest.raises(ValueError, match=r"power\.FR-2\.footprint150: power 0\.99 is stated"):
        Preregistration.load(_write(tmp_path, doc), TUNED, DRY_RUN_STREAM)
    doc = _doc()
    del doc["budget_tolerance"]
    with pytest.raises(ValueError, match="missing budget_tolerance"):
        Preregistration.load(_write(tmp_path, doc), TUNED, DRY_RUN_STREAM)
    e = dict(doc["power"]["UAV-2"]["paper"])
    assert entry_power(e) == pytest.approx(e["power"], abs=0.006)


def _snakemake(tmp_path: Path, *args: str) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-m", "snakemake", "-d", str(tmp_path), "--configfile",
           str(ROOT / "config" / "confirm_v3.yaml"), *args]  # fmt: skip
    return subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=600)


@pytest.mark.workflow
def test_a_dry_run_lists_the_jobs_and_a_real_run_is_refused(tmp_path):
    dry = _snakemake(tmp_path, "-n", "--config", "dry_run_stream=dry-run")
    assert dry.returncode == 0, dry.stderr[-2000:]
    out = dry.stdout + dry.stderr
    assert "frontier_confirm " in out and "horizon_uav " in out
    real = _snakemake(tmp_path, "-j1", "--config", "dry_run_stream=dry-run")
    assert real.returncode != 0
    said = real.stdout + real.stderr
    assert "allowed with snakemake -n only" in said
    for key in ("horizon.stream", "uav.stream", "decisions.stream"):  # every study's stream
        assert key in said, key
    plain = _snakemake(tmp_path, "-n")  # no stand-in: the placeholder refuses
    assert plain.returncode != 0 and "stream is still" in plain.stdout + plain.stderr
    assert not (tmp_path / "results").exists()


def test_the_fr_sds_are_those_of_the_committed_tuning_runs():
    """The FR claims' sds come from the tuning runs (paper/tuning_v3/runs_<model>.csv): the
    sd of the paired difference of the two tuned members the entry names."""
    import pandas as pd

    doc = _doc()
    for cid in doc["claims"]:
        for model, e in doc["power"][cid].items():
            src = e["sd_from"]
            assert src["stream"] == "tune"
            runs = pd.read_csv(ROOT / "paper" / "tuning_v3" / f"runs_{model}.csv")
            w = runs.pivot(index="run", columns="config", values="mean_error")
            assert len(w) == src["runs"]
            sd = float((w[src["a"]] - w[src["b"]]).std(ddof=1))
            assert sd == pytest.approx(e["sd"], abs=6e-4), (cid, model)
