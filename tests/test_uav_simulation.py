"""Closed-loop UAV runs: determinism, paired design, chunking, recordings, analysis rules."""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from rerun.chunk import RrdReader

from rsmhp.analysis import uav as analysis
from rsmhp.experiments.uav import NONDETERMINISTIC_COLUMNS, RUN_COLUMNS, run_chunk
from rsmhp.uav import simulation
from rsmhp.uav.recording import record_uav_run
from rsmhp.uav.simulation import UAVSetup, draw_scenario, method_specs, simulate_run

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_UAV = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["uav"]


@pytest.fixture(scope="module")
def short_cfg() -> dict:
    cfg = copy.deepcopy(DEFAULT_UAV)
    cfg["scenario"]["steps"] = 8
    cfg["planner"].update(horizon=4, maxiter=5, maxfun=10)
    cfg["methods"] = {"nbo": True, "rsmhp_nt": [10], "tree": [{"N": 3, "M": 10}]}
    return cfg


def _det(summary: dict) -> dict:
    return {k: v for k, v in summary.items() if k not in NONDETERMINISTIC_COLUMNS}


def test_same_seed_same_run(short_cfg):
    setup = UAVSetup.from_config(short_cfg)
    for m in method_specs(short_cfg).values():
        a, sa = simulate_run(setup, m, 11, 2)
        b, sb = simulate_run(setup, m, 11, 2)
        assert _det(a) == _det(b) and sa == sb
    c, _ = simulate_run(setup, method_specs(short_cfg)["nbo"], 12, 2)
    assert c["mean_error"] != a["mean_error"]


def test_methods_share_scenario_truth_and_measurement_noise(short_cfg, monkeypatch):
    setup = UAVSetup.from_config(short_cfg)
    seen: dict[str, list[np.ndarray]] = {}
    real = simulation.sensor.measurement_noise
    current = {}

    def spy(uav_xy, target_xy, sensor_model, std_normal):
        seen.setdefault(current["m"], []).append(np.array(std_normal))
        return real(uav_xy, target_xy, sensor_model, std_normal)

    monkeypatch.setattr(simulation.sensor, "measurement_noise", spy)
    steps = {}
    for name, m in method_specs(short_cfg).items():
        current["m"] = name
        _, steps[name] = simulate_run(setup, m, 5, 0)
    names = list(steps)
    truth = {n: [(r["target_x"], r["target_y"]) for r in steps[n]] for n in names}
    for n in names[1:]:
        assert truth[n] == truth[names[0]]
        np.testing.assert_array_equal(np.array(seen[n]), np.array(seen[names[0]]))
    # ... while the methods do fly differently (else the comparison would be vacuous)
    uav = {n: [r["uav_x"] for r in steps[n]] for n in names}
    assert uav["nbo"] != uav["rsmhp_nt10"]


def test_scenario_ranges(short_cfg):
    setup = UAVSetup.from_config(short_cfg)
    sc = short_cfg["scenario"]
    for run in range(50):
        s = draw_scenario(setup, 3, run)
        speed = np.hypot(*s.target[2:])
        dist = np.hypot(*(s.uav[:2] - s.target[:2]))
        assert sc["target_speed_min"] <= speed <= sc["target_speed_max"]
        assert sc["uav_distance_min"] <= dist <= sc["uav_distance_max"]
        assert s.uav[2] == sc["uav_speed"]
        assert np.all(np.abs(s.target[:2]) <= sc["target_box"])


def test_chunking_and_workers_do_not_change_numbers(short_cfg):
    spec = method_specs(short_cfg)["rsmhp_nt10"]
    whole, whole_steps = run_chunk(short_cfg, spec, [0, 1, 2], seed=4, n_jobs=1)
    parts = [run_chunk(short_cfg, spec, r, seed=4, n_jobs=2) for r in ([0], [1, 2])]
    split = pd.concat([p[0] for p in parts], ignore_index=True)
    split_steps = pd.concat([p[1] for p in parts], ignore_index=True)
    cols = [c for c in RUN_COLUMNS if c not in NONDETERMINISTIC_COLUMNS]
    pd.testing.assert_frame_equal(whole[cols], split[cols])
    pd.testing.assert_frame_equal(whole_steps, split_steps)
    # the per-run metric is the mean of the per-step errors
    means = whole_steps.groupby("run")["error"].mean().to_numpy()
    np.testing.assert_allclose(whole["mean_error"].to_numpy(), means, rtol=1e-12)


def test_recording_contents_and_consistency(short_cfg, tmp_path):
    setup = UAVSetup.from_config(short_cfg)
    specs = list(method_specs(short_cfg).values())
    path = tmp_path / "run.rrd"
    rows, summaries = record_uav_run(path, setup, specs, seed=5, run=1, max_hypotheses=4)
    reader = RrdReader(path)
    assert len(reader.recordings()) == 1 and len(reader.blueprints()) == 1
    counts: dict[str, int] = {}
    for chunk in reader.store().stream():
        counts[chunk.entity_path] = counts.get(chunk.entity_path, 0) + chunk.num_rows
    K = short_cfg["scenario"]["steps"]
    for m in specs:
        for ent in ("uav_path", "uav", "plan", "hypotheses", "target", "estimate", "ellipse"):
            assert counts[f"/{m.name}/map/{ent}"] == K
        assert counts[f"/error/{m.name}"] == K + 1  # + static series style
        assert counts[f"/trace/{m.name}"] == K + 1
    for entity, n in rows.items():
        assert counts["/" + entity] == n
    # the recorded runs are the study's runs
    for m, s in zip(specs, summaries, strict=True):
        ref, _ = simulate_run(setup, m, 5, 1)
        assert _det(s) == _det(ref)


def _runs(diff: np.ndarray) -> pd.DataFrame:
    n = diff.size
    base = np.linspace(10, 20, n)
    rows = []
    for name, fam, nt, err in (
        ("nbo", "nbo", 1, base),
        ("rsmhp_nt50", "rsmhp", 50, base + diff),
        ("rsmhp_nt250", "rsmhp", 250, base + 2 * diff),
    ):
        rows += [
            {"method": name, "family": fam, "N_T": nt, "N": 0, "M": 0, "run": r, "seed": 0,
             "mean_error": e, "rmse": e, "final_error": e, "mean_trace": 1.0, "mean_nit": 1.0,
             "plan_seconds": 0.1}
            for r, e in enumerate(err)
        ]  # fmt: skip
    return pd.DataFrame(rows, columns=RUN_COLUMNS)


@pytest.mark.parametrize(
    ("shift", "verdict"),
    [(-0.5, "supported"), (0.5, "not supported"), (0.0, "inconclusive")],
)
def test_verdict_rules(shift, verdict):
    rng = np.random.default_rng(0)
    # differences shift + N(0, 0.3^2)-like spread (exactly centred), 200 runs: the bootstrap
    # CI half-width is about 1.96 * 0.3 / sqrt(200) = 0.04, far from |shift| = 0.5
    noise = rng.standard_normal(200)
    noise = 0.3 * (noise - noise.mean()) / noise.std()
    runs = _runs(shift + noise)
    summary = analysis.summarize_methods(runs, seed=1, n_boot=2000)
    paired = analysis.paired_differences(runs, seed=1, n_boot=2000)
    claims = {c.id: c.verdict for c in analysis.uav_claims(summary, paired)}
    assert claims == {"UAV-1": verdict, "UAV-2": verdict}
    row = paired[(paired["method"] == "rsmhp_nt250") & (paired["baseline"] == "nbo")].iloc[0]
    assert row["ci_low"] <= row["mean_diff"] <= row["ci_high"]
    assert row["mean_diff"] == pytest.approx(2 * shift, abs=1e-12)
    pd.testing.assert_frame_equal(paired, analysis.paired_differences(runs, seed=1, n_boot=2000))
