"""The published reference of the confirmatory run and the paired comparison of a new planner
with it (rsmhp.studies.frontier.reference, rsmhp.studies.frontier.compare)."""

from __future__ import annotations

import json
import re

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from scipy import stats

from rsmhp.studies.frontier.compare import compare_figure, compare_markdown, paired_comparison
from rsmhp.studies.frontier.reference import (
    REFERENCE_COLUMNS,
    check_reference,
    ladder_rows,
    load_reference,
    method_sources,
    scenario_fingerprint,
    write_reference,
)

LADDER = ladder_rows({"paper": {"1": {"rsmhp": "rsmhp_nt64", "sigma": "sigma"}}})


def _runs(config, errors, model="paper", ms=0.5):
    n = len(errors)
    return pd.DataFrame({
        "model": model, "config": config, "member": config.split("/")[0], "family": "x",
        "maxiter": 30, "restarts": 0, "run": np.arange(n), "mean_error": errors,
        "final_error": errors, "lost": False, "plan_ms": ms, "work_per_step": 1.0,
    })  # fmt: skip


def _reference(rng, n=40):
    base = rng.normal(10, 2, n)  # the scenario's difficulty, shared by every method (paired)
    return base, pd.concat(
        [
            _runs("nbo", base + 1.0, ms=0.05),
            _runs("rsmhp_nt64", base + rng.normal(0, 0.05, n)),
            _runs("sigma", base + 0.6 + rng.normal(0, 0.05, n)),
        ],
        ignore_index=True,
    )


def test_paired_differences_their_t_intervals_and_verdicts():
    rng = np.random.default_rng(3)
    base, ref = _reference(rng)
    new = _runs("lhs_nt64", base + rng.normal(0, 0.05, 40), ms=0.7)
    t = paired_comparison(new, ref, LADDER, margin_m=0.25)
    assert list(t["config"]) == ["nbo", "rsmhp_nt64", "sigma"]
    d = new["mean_error"].to_numpy() - ref[ref.config == "sigma"]["mean_error"].to_numpy()
    half = stats.t.ppf(0.975, 39) * d.std(ddof=1) / np.sqrt(40)
    row = t[t.config == "sigma"].iloc[0]
    assert row["mean_diff"] == pytest.approx(d.mean()) and row["runs"] == 40
    assert row["high"] - row["mean_diff"] == pytest.approx(half)
    # 1 m better than NBO, within ±0.25 m of its own family, 0.6 m better than sigma points
    assert list(t["verdict"]) == ["better", "equivalent", "better"]
    worse = paired_comparison(_runs("lhs_nt64", base + 2.0), ref, LADDER, margin_m=0.25)
    assert set(worse["verdict"]) == {"worse"}
    noisy = _runs("lhs_nt64", base + rng.normal(0, 5, 40))
    assert "inconclusive" in set(paired_comparison(noisy, ref, LADDER, 0.25)["verdict"])
    assert np.isnan(t.iloc[0]["budget_ms"]) and t.iloc[1]["budget_ms"] == 1.0


def test_unpaired_runs_are_refused():
    rng = np.random.default_rng(4)
    base, ref = _reference(rng)
    new = _runs("lhs_nt64", base[:30])
    with pytest.raises(ValueError, match="do not pair"):
        paired_comparison(new, ref, LADDER, 0.25)
    with pytest.raises(ValueError, match="no runs of 'missing'"):
        paired_comparison(_runs("lhs", base), ref, [{**LADDER[0], "config": "missing"}], 0.25)


def test_reference_round_trip_and_tampering(tmp_path):
    rng = np.random.default_rng(5)
    _, ref = _reference(rng)
    fp = scenario_fingerprint("abc123", {"runs": {"paper": 40}, "stream": "confirm2"})
    pq, _ = write_reference(ref, {"scenario": fp, "ladder": LADDER}, tmp_path)
    runs, meta = load_reference(tmp_path)
    assert list(runs.columns) == REFERENCE_COLUMNS and len(runs) == len(ref)
    assert meta["scenario"] == fp and meta["rows"] == len(ref)
    df = pd.read_parquet(pq)
    df.loc[0, "mean_error"] += 1.0  # an edited reference is refused
    df.to_parquet(pq, index=False)
    with pytest.raises(ValueError, match="changed after publishing"):
        load_reference(tmp_path)
    with pytest.raises(ValueError, match="does not exist"):
        load_reference(tmp_path / "nowhere")
    with pytest.raises(ValueError, match="missing column"):
        write_reference(ref.drop(columns="plan_ms"), {}, tmp_path / "x")


def test_a_fingerprint_that_differs_is_named():
    ref = {
        "scenario": scenario_fingerprint("abc", {"runs": {"paper": 80}, "seed": 1, "uav": {"H": 6}})
    }
    same = scenario_fingerprint("abc", {"runs": {"paper": 80}, "seed": 1, "uav": {"H": 6}})
    assert check_reference(ref, same, ["paper"]) == []
    other = scenario_fingerprint("xyz", {"runs": {"paper": 80}, "seed": 2, "uav": {"H": 8, "v": 1}})
    problems = check_reference(ref, other, ["paper", "footprint150"])
    assert problems[0].startswith("scenario code: digest abc in the reference, xyz here")
    assert "config seed (reference 1, this workflow 2)" in problems
    assert "config uav.H (reference 6, this workflow 8)" in problems
    assert "config uav.v (only in this workflow: 1)" in problems
    assert any(p.startswith("model 'footprint150': not in the reference") for p in problems)


def test_report_figure_and_sources(tmp_path):
    rng = np.random.default_rng(6)
    base, ref = _reference(rng)
    t = paired_comparison(_runs("lhs_nt64", base), ref, LADDER, 0.25)
    meta = {"commit": "abc", "preregistration": {"sha256": "f" * 64},
            "scenario": {"config": {"stream": "confirm2"}}}  # fmt: skip
    text = compare_markdown(t, meta, 0.25, {"lhs_nt64": "pkg lhs 0123"})
    assert "## lhs_nt64 on 'paper' (40 paired runs" in text and "`lhs_nt64` (pkg lhs 0123)" in text
    assert re.search(r"\| –\s+\| nbo: nbo\s+\|", text) and "stream `confirm2`" in text
    fig = compare_figure(t, ref, LADDER)
    assert len(fig.axes) == 1
    plt.close(fig)
    src = method_sources(["rsmhp_nt64"])["rsmhp_nt64"]
    assert src.startswith("rsmhp rsmhp ") and len(src.split()[-1]) == 16
    json.dumps(src)
