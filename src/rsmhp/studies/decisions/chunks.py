"""The UAV decision study split in jobs (config ``split.decisions_uav``).

Rule ``decisions_uav`` runs one model variant of ``uav_models`` and a contiguous
chunk of its runs (:func:`model_runs`): the belief states of those NBO runs and every method's
plan at them, scored as :func:`rsmhp.models.uav.scoring.run_uav_regret` scores them
(:func:`run_regret_chunk`; the streams are keyed on model, run, step and method, never on the
chunk). Rule ``decisions_uav_merge`` puts the chunks back in the unsplit order (model as
configured, then run; the states and methods of a run as computed) with
:func:`merge_regret`: ``results/decisions/uav_regret.csv`` as the unsplit job wrote it.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from typing import Any

import pandas as pd
from threadpoolctl import threadpool_limits

from rsmhp.models.uav import methods
from rsmhp.models.uav.scoring import (
    REGRET_COLUMNS,
    BeliefState,
    _score_task,
    belief_states,
    merge_variant,
    regret_contract,
    variant,
)
from rsmhp.models.uav.simulation import UAVSetup
from rsmhp.pipeline.parallel import parallel_map
from rsmhp.pipeline.split import chunk, merge_checked, n_chunks, restrict

__all__ = ["chunk_jobs", "merge_regret", "model_chunks", "model_runs", "run_regret_chunk"]

log = logging.getLogger(__name__)


def model_chunks(n_runs: int, jobs: int) -> list[int]:
    """The chunk indices of one model variant with ``n_runs`` runs split in ``jobs`` jobs."""
    return list(range(n_chunks(n_runs, jobs)))


def model_runs(n_runs: int, jobs: int, k: int) -> list[int]:
    """The runs of chunk ``k`` of runs ``0..n_runs-1`` split in ``jobs`` jobs."""
    return chunk(range(int(n_runs)), jobs, k)


def chunk_jobs(cfg: Mapping[str, Any], jobs: int) -> list[tuple[str, int]]:
    """Every (model, chunk) job of the ``decisions.uav`` section ``cfg``, in merge order."""
    return [
        (str(m["name"]), k) for m in cfg["models"] for k in model_chunks(int(cfg["runs"]), jobs)
    ]


def run_regret_chunk(
    uav: Mapping[str, Any],
    cfg: Mapping[str, Any],
    model: str,
    runs: Sequence[int],
    seed: int,
    n_jobs: int = 1,
) -> pd.DataFrame:
    """The rows of :func:`rsmhp.models.uav.scoring.run_uav_regret` of model variant ``model``
    at the belief states of runs ``runs``: one task per run on ``n_jobs`` workers (the rows
    never depend on it), :data:`REGRET_COLUMNS`."""
    var = variant(list(cfg["models"]), model)
    uav_cfg = merge_variant(uav, var)
    setup = UAVSetup.from_config(uav_cfg)
    with threadpool_limits(limits=1):
        states = belief_states(setup, str(var["name"]), seed, [int(r) for r in runs], cfg["steps"])
    by_run: dict[int, list[BeliefState]] = {}
    for st in states:
        by_run.setdefault(st.run, []).append(st)
    tasks = [(sts, uav_cfg, cfg["methods"], cfg, seed) for sts in by_run.values()]
    log.info(
        "decisions_uav %s runs %s: %d belief states x %d methods in %d tasks on %d workers",
        model,
        f"{min(runs)}..{max(runs)}" if len(runs) else "none",
        len(states),
        len(methods.from_config(cfg["methods"])),
        len(tasks),
        n_jobs,
    )
    rows = [r for part in parallel_map(_score_task, tasks, n_jobs, desc="states") for r in part]
    return pd.DataFrame(rows, columns=REGRET_COLUMNS)


def merge_regret(paths: Sequence[str], cfg: Mapping[str, Any], jobs: int) -> pd.DataFrame:
    """``results/decisions/uav_regret.csv`` from the chunk files ``paths`` (in the order of
    :func:`chunk_jobs`), each checked against the rows of its model and runs."""
    layout = chunk_jobs(cfg, jobs)
    if len(paths) != len(layout):
        raise ValueError(
            f"merge_regret: {len(paths)} chunk files, but {len(cfg['models'])} models of "
            f"{cfg['runs']} runs in {jobs} jobs each make {len(layout)}"
        )
    whole = regret_contract(cfg)
    n_runs = int(cfg["runs"])
    parts = [restrict(whole, {"model": [m], "run": model_runs(n_runs, jobs, k)}) for m, k in layout]
    return merge_checked(
        [str(p) for p in paths],
        parts,
        whole,
        keys=("model", "run"),
        orders={"model": [str(m["name"]) for m in cfg["models"]]},
        what="results/decisions/uav_regret.csv (the chunks together)",
    )
