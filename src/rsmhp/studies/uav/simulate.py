"""UAV Monte-Carlo study (paper Sec. III-B, Figs. 4-5): one chunk of runs for one method.

Every run seeds itself from its run index (:mod:`rsmhp.models.uav.simulation`), so chunking and the
worker count never change a number. Outputs: one summary row per run (:data:`RUN_COLUMNS`)
and one row per (run, step) (:data:`STEP_COLUMNS`). ``plan_seconds`` is wall time and the
only non-deterministic column (with a run store, the wall time of the job that computed the
run: :mod:`rsmhp.models.uav.runs`).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from typing import Any

import pandas as pd

from rsmhp.models.uav import methods
from rsmhp.models.uav.methods import Method
from rsmhp.models.uav.runs import simulate_runs
from rsmhp.models.uav.simulation import MODEL_KEYS, STEP_VALUES, UAVSetup
from rsmhp.pipeline.contracts import Contract
from rsmhp.pipeline.parallel import chunked
from rsmhp.pipeline.runstore import RunStore

__all__ = [
    "NONDETERMINISTIC_COLUMNS",
    "RUN_COLUMNS",
    "STEP_COLUMNS",
    "UAV_MODEL_KEYS",
    "chunk_contracts",
    "chunk_runs",
    "run_chunk",
    "runs_contract",
]

log = logging.getLogger(__name__)

RUN_COLUMNS = [
    "method",
    "family",
    "N_T",
    "N",
    "M",
    "run",
    "seed",
    "mean_error",
    "rmse",
    "final_error",
    "mean_trace",
    "mean_nit",
    "plan_seconds",
]
STEP_COLUMNS = ["method", "N_T", "run", "step", *STEP_VALUES, "nit", "kernel_calls"]
#: config keys of the ``uav`` section a simulation depends on (besides its method and the seed;
#: :data:`rsmhp.models.uav.simulation.MODEL_KEYS`)
UAV_MODEL_KEYS = MODEL_KEYS
#: wall-time columns: excluded from every determinism check
NONDETERMINISTIC_COLUMNS = ("plan_seconds",)


def chunk_runs(n_runs: int, n_chunks: int, chunk: int) -> list[int]:
    """Run indices of chunk ``chunk`` (0-based) when ``n_runs`` runs are split in ``n_chunks``."""
    parts = chunked(list(range(n_runs)), n_chunks)
    if not 0 <= chunk < len(parts):
        raise ValueError(f"chunk {chunk} out of range: {n_runs} runs make {len(parts)} chunks")
    return parts[chunk]


_RUN_INTEGERS = ("N_T", "N", "M", "run", "seed")
_STEP_INTEGERS = ("N_T", "run", "step", "nit", "kernel_calls")


def runs_contract(methods: Sequence[str], n_runs: int, seed: int) -> Contract:
    """What ``results/uav/runs.csv`` must hold: one row per (method, run) for runs
    ``0..n_runs-1`` of every method, simulated with ``seed``, finite errors."""
    keys = [(m, r) for m in methods for r in range(int(n_runs))]
    return Contract(
        rule="uav_collect",
        columns=RUN_COLUMNS,
        text=("method", "family"),
        integer=_RUN_INTEGERS,
        keys=("method", "run"),
        expected=pd.DataFrame(keys, columns=["method", "run"]),
        values={"seed": int(seed)},
    )


def chunk_contracts(
    method: Method | Mapping[str, Any], runs: Sequence[int], steps: int, seed: int
) -> tuple[Contract, Contract]:
    """What one chunk's runs CSV and steps Parquet (rule ``uav_simulate``) must hold: the
    runs ``runs`` of ``method`` (a registered method or its spec), each with steps
    ``1..steps``."""
    if not isinstance(method, Method):
        method = methods.from_spec(method)
    runs = [int(r) for r in runs]
    fixed = {"method": method.name, "N_T": method.n_traj}
    run_c = Contract(
        rule="uav_simulate",
        columns=RUN_COLUMNS,
        text=("method", "family"),
        integer=_RUN_INTEGERS,
        keys=("run",),
        expected=pd.DataFrame({"run": runs}),
        values={**fixed, "family": method.family, "seed": int(seed)},
    )
    step_keys = [(r, k) for r in runs for k in range(1, int(steps) + 1)]
    step_c = Contract(
        rule="uav_simulate",
        columns=STEP_COLUMNS,
        text=("method",),
        integer=_STEP_INTEGERS,
        keys=("run", "step"),
        expected=pd.DataFrame(step_keys, columns=["run", "step"]),
        values=fixed,
    )
    return run_c, step_c


def run_chunk(
    uav: Mapping[str, Any],
    method: Method | Mapping[str, Any],
    runs: Sequence[int],
    seed: int,
    n_jobs: int = 1,
    store: RunStore | None = None,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Simulate ``runs`` with ``method`` (a registered :class:`rsmhp.models.uav.methods.Method` or
    its :meth:`~rsmhp.models.uav.methods.Method.spec`): (runs, steps) tables. ``uav`` needs the
    model sections only (not ``methods``). With a ``store``, runs it holds are read, not
    simulated (:mod:`rsmhp.models.uav.runs`; ``plan_seconds`` is then the computing run's)."""
    if not isinstance(method, Method):
        method = methods.from_spec(method)
    setup = UAVSetup.from_config(uav)
    jobs = [(setup, method, seed, int(r)) for r in runs]
    log.info("uav %s: %d runs on %d workers", method.name, len(jobs), n_jobs)
    out = simulate_runs(jobs, store, n_jobs, desc=f"uav {method.name} runs")
    for (_, _, _, run), (_, steps) in zip(jobs, out, strict=True):
        for row in steps:
            row.update(method=method.name, N_T=method.n_traj, run=run)
    runs_df = pd.DataFrame([s for s, _ in out], columns=RUN_COLUMNS)
    steps_df = pd.DataFrame([r for _, rows in out for r in rows], columns=STEP_COLUMNS)
    return runs_df, steps_df
