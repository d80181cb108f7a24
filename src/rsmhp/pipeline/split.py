"""Jobs split into chunks and merged again (config key ``split``, docs/workflow.md).

The longest simulations run as several jobs: one per chunk of closed-loop runs, of the runs
whose belief states a job works at, or of the cells of a grid. Each chunk job computes
exactly the rows the unsplit job computed for its runs or cells (every random stream is keyed
on the run, state or cell, never on the chunk), and a cheap merge rule reads the chunks,
checks each against its part of the table's contract, puts the rows back in the unsplit
job's order and writes the same table: byte for byte, apart from the code stamp
(:mod:`rsmhp.pipeline.io`) and measured times (a planning time, a CPU time), which differ
between any two runs anyway.

:data:`SPLIT_RULES` are the rules of the config's ``split`` section (jobs per unit of work:
per model, per (model, H), or the whole grid); :func:`chunk` and :func:`n_chunks` cut a
unit's items into contiguous near-equal chunks (:func:`rsmhp.pipeline.parallel.chunked`);
:func:`horizon_jobs` scales a long-horizon rule's count down at shorter horizons;
:func:`restrict` and :func:`merge_ordered` are the merge's pieces.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Mapping, Sequence
from typing import Any, TypeVar

import pandas as pd

from rsmhp.core import guards
from rsmhp.pipeline.contracts import Contract, check_table, read_checked
from rsmhp.pipeline.parallel import chunked

__all__ = [
    "SPLIT_RULES",
    "chunk",
    "horizon_jobs",
    "merge_checked",
    "merge_ordered",
    "merge_run_chunks",
    "n_chunks",
    "restrict",
    "run_chunk",
]

T = TypeVar("T")

#: rule -> what one of its units is (the ``split`` key of the config names the rule)
SPLIT_RULES = {
    "estimators_ablation": "the grid of the estimator study (jobs of cells)",
    "decisions_uav": "a model variant of decisions.uav (jobs of runs)",
    "frontier_confirm": "a model of the confirmatory run (jobs of closed-loop runs)",
    "horizon_uav": "a (model, H) of horizon.uav at the largest H (jobs of runs)",
    "horizon_uav_closed": "a (model, H) of horizon.uav at the largest H (jobs of closed-loop runs)",
    "horizon_optimiser": "a (model, H) of horizon.optimiser at the largest H (jobs of runs)",
}


def n_chunks(n_items: int, jobs: int) -> int:
    """Chunks ``n_items`` items make when split in ``jobs`` jobs: ``min(jobs, n_items)``, at
    least 1 (no job is empty)."""
    n_items = guards.integer("n_items", n_items, minimum=0)
    jobs = guards.positive_int("jobs", jobs)
    return max(1, min(int(jobs), int(n_items)))


def chunk(items: Sequence[T], jobs: int, k: int) -> list[T]:
    """Chunk ``k`` (0-based) of ``items`` split in ``jobs`` contiguous, near-equal chunks.
    Refuses a ``k`` outside ``0..n_chunks(len(items), jobs) - 1``."""
    parts = chunked(list(items), guards.positive_int("jobs", jobs))
    k = guards.integer("chunk", k, minimum=0)
    if not items or k >= len(parts):
        raise ValueError(
            f"chunk {k} out of range: {len(items)} items in {jobs} jobs make {len(parts)} "
            f"chunks (allowed: 0..{len(parts) - 1})"
        )
    return parts[k]


def horizon_jobs(jobs: int, H: int, horizons: Iterable[int]) -> int:
    """Jobs of a (model, H) unit when ``jobs`` is the count at the largest of ``horizons``:
    ``ceil(jobs H / max(horizons))`` (the work of a long-horizon job grows with H, so the
    short horizons stay one job each)."""
    jobs = guards.positive_int("jobs", jobs)
    H = guards.positive_int("H", H)
    largest = max((int(h) for h in horizons), default=0)
    if largest < H:
        raise ValueError(f"H = {H} is not among the horizons {list(horizons)}")
    return max(1, math.ceil(int(jobs) * H / largest))


def restrict(contract: Contract, rows: pd.DataFrame | Mapping[str, Sequence[Any]]) -> Contract:
    """``contract`` for a chunk: its expected key rows restricted to those that match one of
    ``rows`` on ``rows``' columns (a frame, or a mapping column -> allowed values, e.g.
    ``{"run": [3, 4]}``)."""
    if contract.expected is None:
        raise ValueError(f"restrict: the contract of rule {contract.rule} lists no key rows")
    exp = contract.expected
    if isinstance(rows, Mapping):
        mask = pd.Series(True, index=exp.index)
        for col, values in rows.items():
            mask &= exp[col].isin(list(values))
        keep = exp[mask]
    else:
        cols = list(rows.columns)
        keep = exp.merge(rows[cols].drop_duplicates(), on=cols, how="inner")
    return dataclasses.replace(contract, expected=keep.reset_index(drop=True))


def merge_ordered(
    frames: Sequence[pd.DataFrame],
    keys: Sequence[str],
    orders: Mapping[str, Sequence[Any]] | None = None,
) -> pd.DataFrame:
    """The rows of ``frames`` (the chunks, each in the unsplit job's order) in the unsplit
    job's order: sorted by ``keys``, a column of ``orders`` by the position of its value in
    the given sequence (e.g. the configured method order), the others by value; rows equal
    on every key keep their order within their chunk (the chunks hold disjoint key sets)."""
    if not frames:
        raise ValueError("merge_ordered: no chunks")
    orders = dict(orders or {})
    parts = [f.assign(_chunk=i, _row=range(len(f))) for i, f in enumerate(frames)]
    df = pd.concat(parts, ignore_index=True)
    sort = []
    for key in keys:
        if key in orders:
            rank = {v: i for i, v in enumerate(orders[key])}
            unknown = sorted(set(df[key]) - set(rank), key=str)
            if unknown:
                raise ValueError(f"merge_ordered: {key} values {unknown} not in {list(rank)}")
            df[f"_rank_{key}"] = df[key].map(rank)
            sort.append(f"_rank_{key}")
        else:
            sort.append(key)
    df = df.sort_values([*sort, "_chunk", "_row"], kind="stable")
    drop = ["_chunk", "_row", *(c for c in sort if c.startswith("_rank_"))]
    return df.drop(columns=drop).reset_index(drop=True)


def merge_checked(
    paths: Sequence[str],
    contracts: Sequence[Contract],
    whole: Contract,
    keys: Sequence[str],
    orders: Mapping[str, Sequence[Any]] | None = None,
    what: str = "the chunks together",
) -> pd.DataFrame:
    """Read every chunk file of ``paths`` checked against its contract of ``contracts``
    (:func:`rsmhp.pipeline.contracts.read_checked`), merge them (:func:`merge_ordered`) and
    check the result against ``whole``, the unsplit table's contract."""
    if len(paths) != len(contracts):
        raise ValueError(f"merge_checked: {len(paths)} files but {len(contracts)} contracts")
    frames = [read_checked(p, c) for p, c in zip(paths, contracts, strict=True)]
    return check_table(merge_ordered(frames, keys, orders), what, whole)


def run_chunk(n_runs: int, jobs: int, k: int) -> list[int]:
    """The run indices of chunk ``k`` of runs ``0..n_runs-1`` split in ``jobs`` jobs."""
    return chunk(range(int(n_runs)), jobs, k)


def merge_run_chunks(
    paths: Sequence[str],
    whole: Contract,
    n_runs: int,
    jobs: int,
    keys: Sequence[str],
    orders: Mapping[str, Sequence[Any]] | None = None,
    what: str = "the chunks together",
    caller: str = "merge_run_chunks",
) -> pd.DataFrame:
    """A table split into chunks of runs (:func:`run_chunk`) from its chunk files ``paths``
    (chunk 0, 1, ...): their number checked against :func:`n_chunks` (the message names
    ``caller``), each checked against the rows its runs must hold (``whole`` restricted to
    them), then :func:`merge_checked`."""
    expected = n_chunks(n_runs, jobs)
    if len(paths) != expected:
        raise ValueError(
            f"{caller}: {len(paths)} chunk files for {n_runs} runs in {jobs} jobs "
            f"(expected {expected})"
        )
    parts = [restrict(whole, {"run": run_chunk(n_runs, jobs, k)}) for k in range(len(paths))]
    return merge_checked([str(p) for p in paths], parts, whole, keys, orders, what)
