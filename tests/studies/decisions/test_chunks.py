"""The UAV decision study split in jobs of runs per model variant
(rsmhp.studies.decisions.chunks), on a short model.

Oracle: the unsplit computation (rsmhp.models.uav.scoring.run_uav_regret): the jobs' files,
merged as rule decisions_uav_merge merges them, give its table byte for byte (no column of it
is measured), whatever the job and worker counts.
"""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

from rsmhp.models.uav.scoring import run_uav_regret
from rsmhp.pipeline.io import write_csv
from rsmhp.studies.decisions.chunks import chunk_jobs, merge_regret, model_runs, run_regret_chunk

ROOT = Path(__file__).resolve().parents[3]
UAV = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["uav"]
# footprint150 first: the merged order is the config's
CFG = {
    "models": [{"name": "footprint150", "sensor": {"footprint_radius": 150.0}}, {"name": "paper"}],
    "runs": 3,
    "steps": [0, 2],
    "n_eval": 100,
    "polish": 1,
    "random_starts": 1,
    "eval_maxiter": 5,
    "n_random": 10,
    "methods": {"nbo": True, "rsmhp_nt": [8], "tree": [{"N": 2, "M": 4}]},
}


def _uav() -> dict:
    cfg = copy.deepcopy(UAV)
    cfg["scenario"]["steps"] = 4
    cfg["planner"].update(horizon=2, maxiter=4, maxfun=8)
    return cfg


def test_jobs_cover_every_model_and_run():
    assert chunk_jobs(CFG, 2) == [("footprint150", 0), ("footprint150", 1), ("paper", 0),
                                  ("paper", 1)]  # fmt: skip
    assert [model_runs(3, 2, k) for k in (0, 1)] == [[0, 1], [2]]
    assert len(chunk_jobs(CFG, 7)) == 6  # at most one job per run


@pytest.mark.parametrize(("jobs", "workers"), [(2, 1), (3, 2)])
def test_merged_jobs_are_the_unsplit_table_byte_for_byte(tmp_path, jobs, workers):
    write_csv(run_uav_regret(_uav(), CFG, 5, 1), tmp_path / "unsplit.csv")
    paths = []
    for model, k in chunk_jobs(CFG, jobs):
        df = run_regret_chunk(_uav(), CFG, model, model_runs(3, jobs, k), 5, workers)
        paths.append(str(tmp_path / f"{model}_{k}.csv"))
        write_csv(df, paths[-1])
    write_csv(merge_regret(paths, CFG, jobs), tmp_path / "merged.csv")
    assert (tmp_path / "merged.csv").read_bytes() == (tmp_path / "unsplit.csv").read_bytes()
    with pytest.raises(ValueError, match="3 chunk files, but 2 models of 3 runs"):
        merge_regret(paths[:3], CFG, jobs)
