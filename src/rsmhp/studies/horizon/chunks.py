"""The long-horizon jobs split in jobs of runs (config ``split.horizon_uav``,
``split.horizon_uav_closed``, ``split.horizon_optimiser``).

A (model, H) unit of rules ``horizon_uav``, ``horizon_uav_closed`` and ``horizon_optimiser``
runs as :func:`unit_jobs` jobs: the configured count at the largest H of the section, fewer
at shorter horizons (:func:`rsmhp.pipeline.split.horizon_jobs`), never more than the runs. A
job takes a contiguous chunk of the runs (:func:`unit_runs`): the belief states of those
runs (``horizon_uav``, ``horizon_optimiser``) or those closed-loop runs
(``horizon_uav_closed``), computed by the unsplit functions with their ``runs`` argument;
every stream is keyed on the model, run, step, H and method, never on the chunk. The merge
rules (``*_merge``, one job per rule for every unit: :func:`units`, :func:`unit_files`,
:func:`per_unit`) put each unit's chunks back in the unsplit order (:func:`merge_horizon`,
:func:`merge_closed`, :func:`merge_optimiser`): state by state for the open-loop tables
(run-major), method-major for the closed loop.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import pandas as pd

from rsmhp.pipeline.split import horizon_jobs, merge_run_chunks, n_chunks, run_chunk
from rsmhp.studies.horizon.simulate_optimiser import split_contract
from rsmhp.studies.horizon.simulate_uav import _names, closed_contract, horizon_contracts

__all__ = [
    "layout_runs",
    "merge_closed",
    "merge_horizon",
    "merge_optimiser",
    "per_unit",
    "unit_files",
    "unit_jobs",
    "unit_runs",
    "units",
]


def unit_jobs(jobs: int, H: int, horizons: Iterable[int], n_runs: int) -> int:
    """Jobs of the (model, ``H``) unit of a section with ``horizons`` and ``n_runs`` runs when
    ``jobs`` is the configured count (at the largest H)."""
    return n_chunks(n_runs, horizon_jobs(jobs, H, horizons))


def unit_runs(n_runs: int, jobs: int, k: int) -> list[int]:
    """The runs of chunk ``k`` when runs ``0..n_runs-1`` make ``jobs`` chunks (``jobs`` as
    :func:`unit_jobs` gives it)."""
    return run_chunk(n_runs, jobs, k)


def units(
    models: Iterable[str], horizons: Sequence[int], jobs: int, n_runs: int
) -> list[tuple[str, int, int]]:
    """``(model, H, jobs of the unit)`` of every (model, H) unit of a section, models outer,
    horizons inner (the order of the unit tables' file list)."""
    hs = [int(h) for h in horizons]
    return [(str(m), h, unit_jobs(jobs, h, hs, n_runs)) for m in models for h in hs]


def layout_runs(
    layout: Sequence[tuple[str, int, int]], n_runs: int, model: str, H: int, k: int
) -> list[int]:
    """The runs of chunk ``k`` of the (``model``, ``H``) unit of ``layout`` (:func:`units`)
    when the section has ``n_runs`` runs."""
    jobs = {(m, int(h)): j for m, h, j in layout}
    if (model, int(H)) not in jobs:
        raise ValueError(f"no unit ({model!r}, H = {H}) in the layout {layout}")
    return unit_runs(n_runs, jobs[(model, int(H))], k)


def unit_files(pattern: str, layout: Sequence[tuple[str, int, int]]) -> list[str]:
    """Every chunk file of ``layout`` (:func:`units`): ``pattern`` with ``{hmodel}``, ``{H}``
    and ``{chunk}`` filled in, unit by unit, chunk by chunk."""
    return [pattern.format(hmodel=m, H=h, chunk=k) for m, h, jobs in layout for k in range(jobs)]


def per_unit(paths: Sequence[str], layout: Sequence[tuple[str, int, int]]) -> list[list[str]]:
    """``paths`` (:func:`unit_files`'s order) cut into one list per unit of ``layout``."""
    if len(paths) != sum(jobs for _, _, jobs in layout):
        raise ValueError(
            f"per_unit: {len(paths)} files for {sum(j for _, _, j in layout)} chunks of "
            f"{len(layout)} units"
        )
    out, start = [], 0
    for _, _, jobs in layout:
        out.append(list(paths[start : start + jobs]))
        start += jobs
    return out


def merge_horizon(
    approx_paths: Sequence[str],
    regret_paths: Sequence[str],
    cfg: Mapping[str, Any],
    model: str,
    H: int,
    jobs: int,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Rule ``horizon_uav_merge``: the (approx, regret) tables of (``model``, ``H``) from the
    chunks' files (chunk 0, 1, ...); ``cfg`` is ``horizon.uav``, ``jobs`` the unit's job
    count (:func:`unit_jobs`)."""
    n_runs = int(cfg["runs"])
    c_approx, c_regret = horizon_contracts(cfg, model, H)
    approx = merge_run_chunks(
        approx_paths, c_approx, n_runs, jobs, keys=("run",),
        what=f"results/horizon/uav/{model}_H{H}_approx.csv (the chunks together)",
        caller="merge_horizon",
    )  # fmt: skip
    regret = merge_run_chunks(
        regret_paths, c_regret, n_runs, jobs, keys=("run",),
        what=f"results/horizon/uav/{model}_H{H}_regret.csv (the chunks together)",
        caller="merge_horizon",
    )  # fmt: skip
    return approx, regret


def merge_closed(
    paths: Sequence[str], cfg: Mapping[str, Any], model: str, H: int, jobs: int
) -> pd.DataFrame:
    """Rule ``horizon_uav_closed_merge``: the closed-loop table of (``model``, ``H``) from the
    chunks' files; ``cfg`` is ``horizon.uav`` (its ``closed_runs`` are split)."""
    return merge_run_chunks(
        paths, closed_contract(cfg, model, H), int(cfg["closed_runs"]), jobs,
        keys=("method", "run"),
        orders={"method": [m.name for m in _names(cfg).values()]},
        what=f"results/horizon/uav/{model}_H{H}_closed.csv (the chunks together)",
        caller="merge_closed",
    )  # fmt: skip


def merge_optimiser(
    paths: Sequence[str], cfg: Mapping[str, Any], model: str, H: int, jobs: int
) -> pd.DataFrame:
    """Rule ``horizon_optimiser_merge``: the optimiser split of (``model``, ``H``) from the
    chunks' files; ``cfg`` is ``horizon.optimiser``."""
    return merge_run_chunks(
        paths, split_contract(cfg, model, H), int(cfg["runs"]), jobs, keys=("run",),
        what=f"results/horizon/optimiser/{model}_H{H}.csv (the chunks together)",
        caller="merge_optimiser",
    )  # fmt: skip
