"""The long-horizon jobs split in jobs of runs (rsmhp.studies.horizon.chunks), on a short model.

Oracle: the unsplit computation of each rule. The chunks' files, merged as the *_merge rules
merge them, give the bytes of the unsplit tables: the optimiser split and the
cost-approximation table entirely; the regret table but for its measured planning time; the
closed loop entirely through one run store (both read the one stored measurement of the
planning time). Also: the job count of a (model, H) unit by hand and the layout helpers.
"""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.runstore import RunStore
from rsmhp.studies.horizon.chunks import (
    layout_runs,
    merge_closed,
    merge_horizon,
    merge_optimiser,
    per_unit,
    unit_files,
    unit_jobs,
    unit_runs,
    units,
)
from rsmhp.studies.horizon.simulate_optimiser import run_optimiser_split
from rsmhp.studies.horizon.simulate_uav import run_horizon, run_horizon_closed

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
MODELS = [{"name": "paper"}, {"name": "footprint150", "sensor": {"footprint_radius": 150.0}}]
SCORING = {"n_eval": 100, "polish": 1, "random_starts": 1, "eval_maxiter": 5, "n_random": 10}
HZ = {
    "runs": 3,
    "closed_runs": 3,
    "steps": [0, 2],
    "plans": 3,
    "n_ref": 200,
    "replicates": 2,
    "methods": {
        "nbo": True,
        "rsmhp_nt": [8],
        "sigma": True,
        "tree": [{"N": 2, "M": 4}],
        "dpw": [{"sims": 10}],
    },
}
HZO = {
    "runs": 3,
    "steps": [0, 2],
    "methods": {"nbo": True, "rsmhp_nt": [8], "dpw": [{"sims": 10}]},
    "budgets": [{"maxiter": 3, "restarts": 0}, {"maxiter": 6, "restarts": 1}],
    "polish_starts": 1,
    "polish_maxiter": 10,
}
H = 3


def _uav() -> dict:
    cfg = copy.deepcopy(CONFIG["uav"])
    cfg["scenario"]["steps"] = 4
    cfg["planner"].update(horizon=2, maxiter=4, maxfun=8)
    return cfg


def _bytes(df, path: Path) -> bytes:
    write_csv(df, path)
    return path.read_bytes()


def _chunk_files(tmp_path: Path, name: str, frames) -> list[str]:
    paths = []
    for k, df in enumerate(frames):
        paths.append(str(tmp_path / f"{name}_{k}.csv"))
        write_csv(df, paths[-1])
    return paths


def test_unit_jobs_and_layout():
    assert [unit_jobs(2, h, [2, 4, 6, 8, 12, 16, 24], 10) for h in (2, 12, 16, 24)] == [1, 1, 2, 2]
    assert [unit_jobs(4, h, [6, 12, 24], 10) for h in (6, 12, 24)] == [1, 2, 4]
    assert unit_jobs(8, 24, [24], 3) == 3  # never more jobs than runs
    assert [unit_runs(10, 4, k) for k in range(4)] == [[0, 1], [2, 3, 4], [5, 6, 7], [8, 9]]
    layout = units(["paper", "fp"], [6, 12], 2, 10)
    assert layout == [("paper", 6, 1), ("paper", 12, 2), ("fp", 6, 1), ("fp", 12, 2)]
    files = unit_files("{hmodel}_H{H}/{chunk}.csv", layout)
    assert files == [
        "paper_H6/0.csv",
        "paper_H12/0.csv",
        "paper_H12/1.csv",
        "fp_H6/0.csv",
        "fp_H12/0.csv",
        "fp_H12/1.csv",
    ]
    assert per_unit(files, layout)[1] == ["paper_H12/0.csv", "paper_H12/1.csv"]
    assert layout_runs(layout, 10, "fp", 12, 1) == [5, 6, 7, 8, 9]
    assert layout_runs(layout, 10, "fp", 6, 0) == list(range(10))
    with pytest.raises(ValueError, match=r"no unit \('fp', H = 24\)"):
        layout_runs(layout, 10, "fp", 24, 0)
    with pytest.raises(ValueError, match="5 files for 6 chunks of 4 units"):
        per_unit(files[:5], layout)


@pytest.mark.parametrize("jobs", [2, 3])
def test_horizon_uav_chunks_merge_to_the_unsplit_tables(tmp_path, jobs):
    approx, regret = run_horizon(_uav(), MODELS, HZ, SCORING, "footprint150", H, 5)
    parts = [
        run_horizon(_uav(), MODELS, HZ, SCORING, "footprint150", H, 5, runs=unit_runs(3, jobs, k))
        for k in range(jobs)
    ]
    a_paths = _chunk_files(tmp_path, "approx", [a for a, _ in parts])
    r_paths = _chunk_files(tmp_path, "regret", [r for _, r in parts])
    m_approx, m_regret = merge_horizon(a_paths, r_paths, HZ, "footprint150", H, jobs)
    assert _bytes(m_approx, tmp_path / "a.csv") == _bytes(approx, tmp_path / "b.csv")
    # the regret rows but their planning time (a measurement of the job that planned)
    assert list(m_regret.columns) == list(regret.columns)
    assert _bytes(m_regret.drop(columns="plan_ms"), tmp_path / "c.csv") == _bytes(
        regret.drop(columns="plan_ms"), tmp_path / "d.csv"
    )


def test_closed_loop_chunks_merge_to_the_unsplit_table_through_the_store(tmp_path):
    store = RunStore(tmp_path / "store")
    closed = run_horizon_closed(_uav(), MODELS, HZ, "paper", H, 9, store)
    parts = [
        run_horizon_closed(_uav(), MODELS, HZ, "paper", H, 9, store, runs=unit_runs(3, 2, k))
        for k in range(2)
    ]
    assert store.stats.computed == len(closed)  # the chunks read the stored runs
    merged = merge_closed(_chunk_files(tmp_path, "c", parts), HZ, "paper", H, 2)
    assert _bytes(merged, tmp_path / "a.csv") == _bytes(closed, tmp_path / "b.csv")
    assert list(dict.fromkeys(merged["method"])) == list(dict.fromkeys(closed["method"]))


def test_optimiser_chunks_merge_to_the_unsplit_table(tmp_path):
    model = MODELS[1]
    whole = run_optimiser_split(_uav(), model, H, HZO, SCORING, 5)
    parts = [
        run_optimiser_split(_uav(), model, H, HZO, SCORING, 5, runs=unit_runs(3, 3, k))
        for k in range(3)
    ]
    merged = merge_optimiser(_chunk_files(tmp_path, "o", parts), HZO, "footprint150", H, 3)
    assert _bytes(merged, tmp_path / "a.csv") == _bytes(whole, tmp_path / "b.csv")
