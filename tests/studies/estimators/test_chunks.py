"""The estimator ablation split in jobs of cells (rsmhp.studies.estimators.chunks).

Oracle: the unsplit computation (rsmhp.models.lqg.ablation.run_ablation). The jobs' files,
merged as rule estimators_ablation_merge merges them, give the bytes of the unsplit table
but for ``cpu_seconds`` (a measured time); the jobs hold every cell once, largest first, and
take about equal shares of the weight.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from rsmhp.models.lqg.ablation import build_problem, grid_points, point_weight, run_ablation
from rsmhp.pipeline.io import IntermediateFileError, write_csv
from rsmhp.studies.estimators.chunks import (
    ablation_chunks,
    chunk_points,
    merge_ablation,
    run_ablation_chunk,
)
from tests.studies.estimators.test_estimator_study import MODEL, NCV

# the ncv problem first: the merged order is the config's, not the alphabet's
CFG = {
    "replicates": 12,
    "problems": [NCV, {"name": "lqg_paper", "kind": "scalar_lqg", "u": [0.55, 0.17]}],
    "schemes": [
        "mc",
        "antithetic",
        "sobol",
        "cubature",
        "gauss_hermite",
        "tree",
        "tree_pernode",
        "pruned",
        "nbo",
    ],
    "budgets": [16, 64],
    "tree_N": [2, 3, 4],
    "max_leaves": 64,
    "pruning": {"N": [4, 8], "M": [1, 2]},
}


def _bytes(df, path: Path) -> bytes:
    write_csv(df.drop(columns="cpu_seconds"), path)
    return path.read_bytes()


def test_jobs_hold_every_cell_once_largest_first():
    problems = {s["name"]: build_problem(s, MODEL) for s in CFG["problems"]}
    every = grid_points(CFG, problems)
    for jobs in (1, 3, 4, len(every) + 5):
        parts = [chunk_points(CFG, MODEL, jobs, k) for k in ablation_chunks(CFG, MODEL, jobs)]
        assert len(parts) == min(jobs, len(every))
        assert sorted(map(repr, (p for part in parts for p in part))) == sorted(map(repr, every))
        weights = [sum(point_weight(p, problems[p.problem]) for p in part) for part in parts]
        assert weights == sorted(weights, reverse=True)  # job 0 takes the largest cell ...
        assert all(len(a) - len(b) in (0, 1) for a, b in itertools.pairwise(parts))
    with pytest.raises(ValueError, match="chunk 4 out of range"):
        chunk_points(CFG, MODEL, 4, 4)


@pytest.mark.parametrize("jobs", [2, 3])
def test_merged_jobs_are_the_unsplit_table_byte_for_byte(tmp_path, jobs):
    whole = run_ablation(CFG, MODEL, seed=11, n_jobs=1)
    paths = []
    for k in ablation_chunks(CFG, MODEL, jobs):
        paths.append(str(tmp_path / f"{k}.csv"))
        write_csv(run_ablation_chunk(CFG, MODEL, 11, jobs, k), paths[-1])
    merged = merge_ablation(paths, CFG, MODEL, jobs)
    assert list(merged.columns) == list(whole.columns)
    assert _bytes(merged, tmp_path / "a.csv") == _bytes(whole, tmp_path / "b.csv")
    assert list(dict.fromkeys(merged["problem"])) == ["ncv2", "lqg_paper"]
    # a job's file with another job's cells is refused, naming the file and the rule
    write_csv(run_ablation_chunk(CFG, MODEL, 11, jobs, 0), paths[1])
    with pytest.raises(IntermediateFileError, match=r"1\.csv.*rerun rule estimators_ablation"):
        merge_ablation(paths, CFG, MODEL, jobs)
