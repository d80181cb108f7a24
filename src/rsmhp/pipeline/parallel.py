"""Within-rule parallelism: joblib over a fixed worker budget, BLAS pinned to one thread.

Snakemake gives every rule a ``threads`` budget. :func:`parallel_map` runs ``n_jobs = threads``
loky worker processes and limits every BLAS/OpenMP pool inside them to one thread
(``inner_max_num_threads=1``), so ``threads`` workers use ``threads`` cores, not
``threads x cores``. With ``n_jobs == 1`` the tasks run in-process under the same
one-thread BLAS limit.

Results come back in task order; each task must seed itself from its own job identifier
(:mod:`rsmhp.core.seeding`), which makes the output independent of the worker count.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Sequence
from typing import TypeVar

from joblib import Parallel, delayed, parallel_config
from threadpoolctl import threadpool_limits

T = TypeVar("T")
R = TypeVar("R")

__all__ = ["chunked", "parallel_map"]

log = logging.getLogger(__name__)


def chunked(items: Sequence[T], n_chunks: int) -> list[list[T]]:
    """Split ``items`` into at most ``n_chunks`` contiguous, near-equal, non-empty chunks."""
    if n_chunks < 1:
        raise ValueError(f"n_chunks must be >= 1, got {n_chunks}")
    n = len(items)
    n_chunks = min(n_chunks, n) or 1
    bounds = [round(i * n / n_chunks) for i in range(n_chunks + 1)]
    return [
        list(items[bounds[i] : bounds[i + 1]]) for i in range(n_chunks) if bounds[i + 1] > bounds[i]
    ]


def parallel_map(
    func: Callable[[T], R], tasks: Iterable[T], n_jobs: int, *, desc: str = "tasks"
) -> list[R]:
    """``[func(t) for t in tasks]`` on ``n_jobs`` processes, in order, logging progress."""
    if n_jobs < 1:
        raise ValueError(f"n_jobs (threads) must be >= 1, got {n_jobs}")
    tasks = list(tasks)
    total = len(tasks)
    if n_jobs == 1 or total <= 1:
        out = []
        with threadpool_limits(limits=1):
            for i, t in enumerate(tasks, 1):
                out.append(func(t))
                log.info("%s: %d/%d done", desc, i, total)
        return out
    out = []
    with parallel_config(backend="loky", n_jobs=n_jobs, inner_max_num_threads=1):
        gen = Parallel(return_as="generator")(delayed(func)(t) for t in tasks)
        for i, res in enumerate(gen, 1):
            out.append(res)
            log.info("%s: %d/%d done", desc, i, total)
    return out
