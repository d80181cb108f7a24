"""The confirmatory run split in jobs of runs (rsmhp.studies.frontier.chunks), on a short model.

Oracle: the unsplit computation. The chunks' files, merged as rule frontier_confirm_merge
merges them, give the bytes the unsplit table gives: through one run store (every column, the
planning time included: both read the one stored measurement) and without a store (every
column but the planning time, which is a measurement of the job that simulated the run).
"""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

from rsmhp.pipeline.io import IntermediateFileError, write_csv
from rsmhp.pipeline.protocol import Configuration, stream_seed
from rsmhp.pipeline.runstore import RunStore
from rsmhp.studies.frontier.chunks import confirm_chunks, confirm_runs, merge_confirm
from rsmhp.studies.frontier.simulate import run_configurations

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
MODELS = [{"name": "paper"}, {"name": "footprint150", "sensor": {"footprint_radius": 150.0}}]
# NBO first, a restart configuration, a tree search: not in alphabetical order
CONFIGS = [
    Configuration("nbo"),
    Configuration("rsmhp_nt8", 5, 1),
    Configuration("dpw_s10"),
    Configuration("antithetic_nt8"),
]
RUNS = 5
SEED = stream_seed(11, "confirm")


def _uav() -> dict:
    cfg = copy.deepcopy(CONFIG["uav"])
    cfg["scenario"]["steps"] = 5
    cfg["planner"].update(horizon=3, maxiter=5, maxfun=10)
    return cfg


def _run(runs, store=None):
    return run_configurations(_uav(), MODELS, "footprint150", CONFIGS, runs, SEED, 50.0, store)


def _merged(tmp_path: Path, jobs: int, store=None, name: str = "x") -> bytes:
    paths = []
    for k in confirm_chunks(RUNS, jobs):
        paths.append(str(tmp_path / f"{name}{jobs}_{k}.csv"))
        write_csv(_run(confirm_runs(RUNS, jobs, k), store), paths[-1])
    write_csv(merge_confirm(paths, CONFIGS, RUNS, jobs, "footprint150"), tmp_path / "m.csv")
    return (tmp_path / "m.csv").read_bytes()


def test_merged_chunks_are_the_unsplit_table_byte_for_byte(tmp_path):
    store = RunStore(tmp_path / "store")
    write_csv(_run(range(RUNS), store), tmp_path / "unsplit.csv")
    unsplit = (tmp_path / "unsplit.csv").read_bytes()
    assert store.stats.computed == len(CONFIGS) * RUNS
    for jobs in (2, 3, RUNS, 9):  # 9 jobs: one per run
        assert _merged(tmp_path, jobs, store) == unsplit, jobs
    assert store.stats.computed == len(CONFIGS) * RUNS  # every chunk read the stored runs


def test_without_a_store_every_column_but_the_planning_time_is_the_same(tmp_path):
    import pandas as pd

    unsplit = _run(range(RUNS))
    paths = []
    for k in confirm_chunks(RUNS, 2):
        paths.append(str(tmp_path / f"{k}.csv"))
        write_csv(_run(confirm_runs(RUNS, 2, k)), paths[-1])
    merged = merge_confirm(paths, CONFIGS, RUNS, 2, "footprint150")
    write_csv(merged.drop(columns="plan_ms"), tmp_path / "a.csv")
    write_csv(unsplit.drop(columns="plan_ms"), tmp_path / "b.csv")
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()
    assert list(merged.columns) == list(unsplit.columns)
    pd.testing.assert_series_equal(merged["run"], unsplit["run"])


def test_a_missing_or_foreign_chunk_is_refused(tmp_path):
    paths = [str(tmp_path / f"{k}.csv") for k in range(2)]
    for k, p in enumerate(paths):
        write_csv(_run(confirm_runs(RUNS, 2, k)), p)
    with pytest.raises(ValueError, match="1 chunk files for 5 runs in 2 jobs"):
        merge_confirm(paths[:1], CONFIGS, RUNS, 2, "footprint150")
    write_csv(_run(confirm_runs(RUNS, 2, 0)), paths[1])  # chunk 0's runs in chunk 1's file
    with pytest.raises(IntermediateFileError, match=r"1\.csv.*rerun rule frontier_confirm"):
        merge_confirm(paths, CONFIGS, RUNS, 2, "footprint150")
