"""Compile every numba kernel of the project once per machine, in parallel processes.

numba compiles a kernel on its first call and keeps the machine code in its on-disk cache
(``cache=True``: beside the module, in numba's user-wide cache directory when the install is
read-only, or in ``NUMBA_CACHE_DIR``); every later process, every workflow job included,
loads it in milliseconds. A fresh clone, a CI run or a cluster node without the cache pays the
compilation once; this module pays it up front, in ``make setup`` (which ``make replicate``
and ``make test`` run first), spread over the machine's cores.

What is compiled, by whom (:data:`TASKS`; each task in its own process, largest first):

* the planner kernel (:mod:`rsmhp.models.uav.fused`: cost, gradient, the whole planning step
  and the compiled closed loop in one compiled function, with the nominal hypothesis it links
  and the closed loop's small kernels);
* the tree search with the closed-loop step it links (:mod:`rsmhp.models.uav.dpw`,
  :mod:`rsmhp.models.uav.stepper`), the hypotheses (:mod:`rsmhp.models.uav.target`), the
  LQG pruned tree (:mod:`rsmhp.models.lqg.regret`), the planner module's covariance traces
  and path (``fused.warm_up_extras``) and the scrambled Sobol' points
  (:mod:`rsmhp.core.designs`).

The planner kernel is the longest single compile (docs/performance.md, "Cold start"), so the
second process takes everything else.

Modules whose compiled code links another module's (the tree search links the closed-loop
step) share a task, so no kernel is compiled twice at once. A kernel that is already in the
cache loads in well under a second, so running this again costs little. The cache is per CPU
target: numba keys it on the LLVM CPU name and features, so ``NUMBA_CPU_NAME`` (the AVX2 and
portability emulations) compiles again, once.

A run of some targets needs only the kernels its jobs can call: ``--scripts`` names their
rule scripts, and only the entries of :data:`TASKS` whose module one of them can import
(statically, as :func:`rsmhp.pipeline.code_digest.describe` follows imports) are compiled
(:func:`tasks_for`). The portability drill of some studies does this.

    python -m rsmhp.pipeline.warm [--cores N] [--scripts workflow/scripts/<rule>.py ...]
"""

from __future__ import annotations

import argparse
import importlib
import multiprocessing
import os
import time
from collections.abc import Iterable
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

__all__ = ["LINKED", "TASKS", "main", "modules_of_scripts", "tasks_for", "warm"]

#: tasks of one process each: the modules whose ``warm_up()`` it calls, in order
#: (``module:function`` calls that function of the module instead)
TASKS: tuple[tuple[str, ...], ...] = (
    # the planner kernel alone: the longest compile (cost, gradient, planning step and the
    # closed loop in one function)
    ("rsmhp.models.uav.fused",),
    (
        "rsmhp.models.uav.dpw",
        "rsmhp.models.uav.stepper",
        "rsmhp.models.uav.target",
        # after target: both compile numba's np.partition, once per process
        "rsmhp.models.lqg.regret",
        # the planner module's small kernels (traces, path), beside the kernel's compile
        "rsmhp.models.uav.fused:warm_up_extras",
        "rsmhp.core.designs",
    ),
)

#: modules whose kernels are only ever called from another module's compiled code, and are
#: compiled (and cached) with it: module -> the module whose task compiles them
LINKED: dict[str, str] = {"rsmhp.core.boxqn": "rsmhp.models.uav.fused"}


def tasks_for(modules: Iterable[str] | None) -> tuple[tuple[str, ...], ...]:
    """The entries of :data:`TASKS` that compile kernels of ``modules`` (dotted module names,
    e.g. :func:`modules_of_scripts`): an entry counts when its module is named, or when a
    named module's kernels are compiled with it (:data:`LINKED`). Each task keeps its order;
    tasks left empty are dropped. ``None``: every task."""
    if modules is None:
        return TASKS
    wanted = set(modules)
    wanted |= {owner for linked, owner in LINKED.items() if linked in wanted}
    kept = (tuple(e for e in task if e.partition(":")[0] in wanted) for task in TASKS)
    return tuple(task for task in kept if task)


def modules_of_scripts(
    scripts: Iterable[str | os.PathLike], src: str | os.PathLike | None = None
) -> set[str]:
    """Every ``rsmhp`` module (under ``src``, by default the imported package's directory)
    that one of ``scripts`` can import, followed statically
    (:func:`rsmhp.pipeline.code_digest.describe`)."""
    from rsmhp.pipeline.code_digest import describe

    out: set[str] = set()
    for script in scripts:
        if not Path(script).is_file():
            raise FileNotFoundError(f"warm: --scripts: no such rule script {script}")
        out.update(describe(script, src).modules)
    return out


def _run(modules: tuple[str, ...]) -> list[tuple[str, float]]:
    """Call each module's ``warm_up()`` (or the function a ``module:function`` entry names) in
    this process; (entry, seconds) per entry."""
    out = []
    for name in modules:
        module, _, func = name.partition(":")
        out.append((name, float(getattr(importlib.import_module(module), func or "warm_up")())))
    return out


def warm(
    cores: int, tasks: tuple[tuple[str, ...], ...] = TASKS
) -> tuple[float, list[tuple[str, float]]]:
    """Compile (or load) the kernels of ``tasks`` (default every one; see :func:`tasks_for`)
    with ``cores`` processes (1: in this process); returns (wall seconds, (module, seconds)
    per module)."""
    if not isinstance(cores, int) or isinstance(cores, bool) or cores < 1:
        raise ValueError(f"cores must be an integer >= 1, got {cores!r}")
    t0 = time.perf_counter()
    if cores == 1 or len(tasks) <= 1:
        per = [row for task in tasks for row in _run(task)]
    else:
        ctx = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(max_workers=min(cores, len(tasks)), mp_context=ctx) as pool:
            per = [row for rows in pool.map(_run, tasks) for row in rows]
    return time.perf_counter() - t0, per


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog="python -m rsmhp.pipeline.warm",
        description="Compile every numba kernel of rsmhp into the on-disk cache, in parallel.",
    )
    parser.add_argument(
        "--cores", type=int, default=os.cpu_count() or 1, help="processes (default: all cores)"
    )
    parser.add_argument(
        "--scripts",
        nargs="+",
        default=None,
        metavar="SCRIPT",
        help="only the kernels that these rule scripts can import (default: every kernel)",
    )
    args = parser.parse_args(argv)
    if args.cores < 1:
        parser.error(f"--cores must be >= 1, got {args.cores}")
    try:
        modules = None if args.scripts is None else modules_of_scripts(args.scripts)
    except FileNotFoundError as exc:
        parser.error(str(exc))
    tasks = tasks_for(modules)
    wall, per = warm(args.cores, tasks)
    if not per:
        print("no kernel to compile: the scripts import no module with numba kernels")
        return
    detail = ", ".join(f"{name.rsplit('.', 1)[-1]} {sec:.1f} s" for name, sec in per)
    print(f"compiled kernels ready in {wall:.1f} s wall with {args.cores} cores ({detail})")


if __name__ == "__main__":
    main()
