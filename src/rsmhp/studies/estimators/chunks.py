"""The estimator ablation split in jobs of grid cells (config ``split.estimators_ablation``).

The grid's cells (:func:`rsmhp.models.lqg.ablation.grid_points`), largest first
(:func:`rsmhp.models.lqg.ablation.by_weight`), are dealt round robin into the jobs
(:func:`chunk_points`), so the jobs take about equal work. Rule ``estimators_ablation`` runs
one job's cells (:func:`run_ablation_chunk`; every replicate's stream is keyed on the cell
and the replicate, never on the job) and rule ``estimators_ablation_merge`` puts the jobs'
rows back in table order (:func:`merge_ablation`): ``results/estimators/ablation.csv`` as the
unsplit job wrote it (``cpu_seconds`` aside, a measured time).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import pandas as pd

from rsmhp.models.lqg.ablation import (
    GridPoint,
    ablation_contract,
    build_problem,
    by_weight,
    grid_points,
    n_trajectories,
    run_points,
    sort_ablation,
)
from rsmhp.pipeline.split import merge_checked, n_chunks, restrict

__all__ = ["ablation_chunks", "chunk_points", "merge_ablation", "run_ablation_chunk"]

#: the columns that identify a grid cell in the ablation table
CELL_KEYS = ["problem", "scheme", "N", "M", "n_trajectories"]


def _specs(cfg: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    return {s["name"]: {k: v for k, v in s.items() if k != "name"} for s in cfg["problems"]}


def _grid(cfg: Mapping[str, Any], lqg_model: Mapping[str, Any]):
    problems = {n: build_problem(s, lqg_model) for n, s in _specs(cfg).items()}
    return problems, grid_points(cfg, problems)


def ablation_chunks(cfg: Mapping[str, Any], lqg_model: Mapping[str, Any], jobs: int) -> list[int]:
    """The job indices of the ``estimators`` section ``cfg`` split in ``jobs`` jobs."""
    _, points = _grid(cfg, lqg_model)
    return list(range(n_chunks(len(points), jobs)))


def chunk_points(
    cfg: Mapping[str, Any], lqg_model: Mapping[str, Any], jobs: int, k: int
) -> list[GridPoint]:
    """The cells of job ``k``: every ``n``-th cell from the ``k``-th of the cells ordered by
    weight, ``n`` = the number of jobs (:func:`ablation_chunks`)."""
    problems, points = _grid(cfg, lqg_model)
    n = n_chunks(len(points), jobs)
    if not 0 <= int(k) < n:
        raise ValueError(f"chunk {k} out of range: {len(points)} cells in {jobs} jobs make {n}")
    return by_weight(points, problems)[int(k) :: n]


def run_ablation_chunk(
    cfg: Mapping[str, Any],
    lqg_model: Mapping[str, Any],
    seed: int,
    jobs: int,
    k: int,
    n_jobs: int = 1,
) -> pd.DataFrame:
    """The ablation rows of job ``k``'s cells (every replicate), in table order, on ``n_jobs``
    workers: the rows :func:`rsmhp.models.lqg.ablation.run_ablation` computes for them."""
    specs = _specs(cfg)
    points = chunk_points(cfg, lqg_model, jobs, k)
    df = run_points(
        points,
        specs,
        lqg_model,
        seed,
        int(cfg["replicates"]),
        n_jobs,
        label=f"estimators job {k}",
    )
    return sort_ablation(df, list(specs))


def _cells(cfg: Mapping[str, Any], lqg_model: Mapping[str, Any], jobs: int, k: int) -> pd.DataFrame:
    problems, _ = _grid(cfg, lqg_model)
    rows = [
        (p.problem, p.scheme, p.N, p.M, n_trajectories(p, problems[p.problem]))
        for p in chunk_points(cfg, lqg_model, jobs, k)
    ]
    return pd.DataFrame(rows, columns=CELL_KEYS)


def merge_ablation(
    paths: Sequence[str], cfg: Mapping[str, Any], lqg_model: Mapping[str, Any], jobs: int
) -> pd.DataFrame:
    """``results/estimators/ablation.csv`` from the jobs' files ``paths`` (job 0, 1, ...),
    each checked against the rows of its cells."""
    n = len(ablation_chunks(cfg, lqg_model, jobs))
    if len(paths) != n:
        raise ValueError(f"merge_ablation: {len(paths)} files for {jobs} jobs (expected {n})")
    whole = ablation_contract(cfg, lqg_model)
    return merge_checked(
        [str(p) for p in paths],
        [restrict(whole, _cells(cfg, lqg_model, jobs, k)) for k in range(n)],
        whole,
        keys=("problem", "scheme", "weighting", "N", "M", "n_trajectories", "replicate"),
        orders={"problem": list(_specs(cfg))},
        what="results/estimators/ablation.csv (the jobs together)",
    )
