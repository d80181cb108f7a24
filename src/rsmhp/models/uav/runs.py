r"""UAV closed-loop runs through the run store (:mod:`rsmhp.pipeline.runstore`): a run that
several rules need is simulated once and read by the others, and a rule that reruns after an
edit outside the closed loop reads its runs. In the full config the UAV study and the map cell
of the paper's model share 100 runs; the horizon and equal-compute studies draw from their own
seed streams (:mod:`rsmhp.pipeline.protocol`), so none of their runs is another rule's.

The key of a run
----------------
:func:`rsmhp.models.uav.simulation.simulate_run` draws every random number from streams keyed
on (seed, run, the method's ``job_key``), so a run is a function of

* the **setup**: every field of the :class:`~rsmhp.models.uav.simulation.UAVSetup`, its nested
  frozen dataclasses (aircraft, target, sensor, planner with horizon and optimiser budget) and
  arrays (``P0``: dtype, shape and every bit) and the scenario ranges; the planner's
  ``start`` only when it is not the default ``"warm"`` (:func:`_key_setup`: a run from the
  warm start has the key it had before the field existed);
* the **method**: its family, class and :meth:`~rsmhp.models.uav.methods.Method.spec`;
* the **seed** and the **run** index;
* the **code**: :func:`closed_loop_code`, the digest (:mod:`rsmhp.pipeline.code_digest`) of
  ``rsmhp.models.uav.simulation`` and everything it can import, with the method registry
  restricted to the run's family module (:func:`~rsmhp.pipeline.code_digest.method_only`): an
  edit of the model, the planner, the tracker or the family invalidates the family's entries;
  an edit of another family's module invalidates none of them;
* the **environment** that changes floating-point results (:func:`environment`): Python,
  numpy, scipy and numba versions, the CPU the compiled kernels are generated for, and the
  variables of the portability drill (``NUMBA_CPU_NAME``, ``NUMBA_CPU_FEATURES``,
  ``OPENBLAS_CORETYPE``, ``NPY_DISABLE_CPU_FEATURES``), so an emulated or upgraded run never
  reads another's entries.

:func:`closed_loop_key` is that mapping. Every field of a stored run is a deterministic
function of it, except the **timing**: ``plan_seconds`` (the planner's wall time) is the one
measurement of the process that computed the run, and a rule that reads the entry reports
that measurement (its ``plan_ms`` likewise). Equal-compute claims do not rest on it (the
protocol's times come from the interleaved timing rules).

Families defined outside ``rsmhp.models.uav.methods`` (a plugin package, a test) are never
stored: their code is not under the digest. Runs with an ``observer`` (recordings) are not
stored either; they call :func:`~rsmhp.models.uav.simulation.simulate_run` themselves.

Shared by the studies ``rsmhp.studies.frontier``, ``rsmhp.studies.horizon`` and
``rsmhp.studies.uav`` (so it lives below them).
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import os
import platform
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from rsmhp.core import guards
from rsmhp.models.uav.methods import Method
from rsmhp.models.uav.simulation import UAVSetup, simulate_run
from rsmhp.pipeline.code_digest import METHOD_REGISTRY, method_only, module_digest
from rsmhp.pipeline.parallel import parallel_map
from rsmhp.pipeline.runstore import RunStore

__all__ = [
    "CLOSED_LOOP",
    "NAMESPACE",
    "Job",
    "closed_loop_code",
    "closed_loop_key",
    "environment",
    "family_module",
    "simulate_run_stored",
    "simulate_runs",
]

log = logging.getLogger(__name__)

#: the store's namespace of closed-loop runs
NAMESPACE = "uav_closed_loop"
#: the module whose code (and what it can import) a closed-loop run executes
CLOSED_LOOP = "rsmhp.models.uav.simulation"
#: environment variables that change the closed loop's floating point (portability drill)
_ENV_VARS = (
    "NUMBA_CPU_NAME",
    "NUMBA_CPU_FEATURES",
    "OPENBLAS_CORETYPE",
    "NPY_DISABLE_CPU_FEATURES",
)

#: one run: (setup, method, seed, run index)
Job = tuple[UAVSetup, Method, int, int]


def family_module(method: Method) -> str | None:
    """The module name of ``method``'s family under the registry (``"monte_carlo"``), or None
    for a family defined elsewhere (a plugin, a test): such runs are not stored."""
    guards.instance_of("method", method, Method)
    module = type(method).__module__
    package, _, name = module.rpartition(".")
    return name if package == METHOD_REGISTRY else None


@functools.cache
def _code(family: str, src: str | None) -> str:
    return module_digest([CLOSED_LOOP], src, method_only([family])).digest


def closed_loop_code(family: str, src: str | os.PathLike[str] | None = None) -> str:
    """The digest of the closed loop's code for family module ``family`` (``"nbo"``): the
    code :data:`CLOSED_LOOP` can import, the registry restricted to that family
    (:func:`rsmhp.pipeline.code_digest.module_digest`). ``src`` is the directory holding
    ``rsmhp`` (default: the imported package's). Computed once per process and ``src``."""
    if not isinstance(family, str) or not family.isidentifier():
        raise ValueError(f"family: a module name of {METHOD_REGISTRY} (e.g. 'nbo'), got {family!r}")
    return _code(family, None if src is None else str(Path(src).resolve()))


@functools.cache
def environment() -> dict[str, Any]:
    """What besides the code and the key changes a run's floating point: the Python, numpy,
    scipy and numba versions, the machine, the CPU the compiled kernels are generated for
    (numba's target) and the emulation variables of the portability drill."""
    import llvmlite.binding as llvm
    import numba
    import scipy

    return {
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "numba": numba.__version__,
        "machine": platform.machine(),
        "cpu": numba.config.CPU_NAME or llvm.get_host_cpu_name(),
        "env": {v: os.environ.get(v) for v in _ENV_VARS},
    }


def _tagged(value: Any, fields: dict[str, Any]) -> dict[str, Any]:
    """The dataclass ``value`` as the store's canonical form writes one
    (:func:`rsmhp.pipeline.runstore.canonical_json`: its class and its fields), with
    ``fields`` in place of its own."""
    cls = type(value)
    return {"__dataclass__": f"{cls.__module__}.{cls.__qualname__}", "fields": fields}


def _key_setup(setup: UAVSetup) -> Any:
    """The setup as the key holds it: ``setup`` itself, except that a planner with the
    default ``start`` (``"warm"``) is written without that field, so the key's canonical
    text is the one it had before ``PlannerParams.start`` existed; any other start is a
    field of the key like the rest."""
    planner = setup.planner
    if planner.start != "warm":
        return setup
    own = {f.name: getattr(setup, f.name) for f in dataclasses.fields(setup)}
    own["planner"] = _tagged(
        planner,
        {f.name: getattr(planner, f.name) for f in dataclasses.fields(planner)
         if f.name != "start"},
    )  # fmt: skip
    return _tagged(setup, own)


def closed_loop_key(setup: UAVSetup, method: Method, seed: int, run: int) -> dict[str, Any]:
    """The store key of run ``run`` of ``method`` on ``setup`` with root seed ``seed`` (see
    the module docstring); a family outside the registry is refused (it cannot be stored)."""
    guards.instance_of("setup", setup, UAVSetup)
    family = family_module(method)
    if family is None:
        raise ValueError(
            f"closed_loop_key: method {method.name!r} comes from {type(method).__module__}, "
            f"outside {METHOD_REGISTRY}: its code is not covered by the digest, so its runs "
            "are not stored"
        )
    cls = type(method)
    return {
        "kind": NAMESPACE,
        "setup": _key_setup(setup),
        "method": {
            "family": method.family,
            "class": f"{cls.__module__}.{cls.__qualname__}",
            "spec": method.spec(),
        },
        "seed": guards.nonneg_int("seed", seed),
        "run": guards.nonneg_int("run", run),
        "code": closed_loop_code(family),
        "environment": environment(),
    }


def _simulate(job: Job) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    setup, method, seed, run = job
    return simulate_run(setup, method, seed, run)


def simulate_runs(
    jobs: Sequence[Job], store: RunStore | None, n_jobs: int = 1, *, desc: str = "runs"
) -> list[tuple[dict[str, Any], list[dict[str, Any]]]]:
    """``[simulate_run(*job) for job in jobs]``, in order: the runs ``store`` holds are read,
    the others simulated on ``n_jobs`` processes (:func:`rsmhp.pipeline.parallel.parallel_map`)
    and stored. ``store=None``, or a family outside the registry, simulates without a store.
    Every field but ``plan_seconds`` equals what :func:`simulate_run` returns."""
    jobs = [tuple(j) for j in jobs]
    for i, job in enumerate(jobs):
        if len(job) != 4:
            raise ValueError(f"jobs[{i}] must be (setup, method, seed, run), got {len(job)} items")
    if store is None:
        return parallel_map(_simulate, jobs, n_jobs, desc=desc)
    if not isinstance(store, RunStore):
        raise TypeError(f"store must be a RunStore or None, got {type(store).__name__}")
    stored = [i for i, (_, m, _, _) in enumerate(jobs) if family_module(m) is not None]
    out: list[Any] = [None] * len(jobs)
    loose = sorted(set(range(len(jobs))) - set(stored))
    if loose:
        log.info("run store: %d runs of families outside %s are simulated, not stored",
                 len(loose), METHOD_REGISTRY)  # fmt: skip
        values = parallel_map(_simulate, [jobs[i] for i in loose], n_jobs, desc=desc)
        for i, value in zip(loose, values, strict=True):
            out[i] = value
    keys = [closed_loop_key(*jobs[i]) for i in stored]

    def compute(positions: list[int]) -> list[Any]:
        return parallel_map(_simulate, [jobs[stored[p]] for p in positions], n_jobs, desc=desc)

    for i, value in zip(stored, store.get_many(NAMESPACE, keys, compute), strict=True):
        out[i] = value
    return out


def simulate_run_stored(
    setup: UAVSetup, method: Method, seed: int, run: int, store: RunStore | None
) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """One run as :func:`simulate_run` returns it, through ``store`` (see
    :func:`simulate_runs`)."""
    return simulate_runs([(setup, method, seed, run)], store)[0]
