"""Portability drill (``make portability``): rerun the workflow as if on another machine and
compare it with the native run and the committed reference, table by table and claim by claim.

**What is emulated.** Three environment variables change the code paths a different x86-64
machine would take, without other hardware:

* ``NUMBA_CPU_NAME=generic`` (numba's ``NUMBA_CPU_FEATURES`` then defaults to no features):
  the compiled planner kernels (:mod:`rsmhp.models.uav.fused`, :mod:`rsmhp.models.uav.target`) are
  built for baseline x86-64 (SSE2) instead of the host CPU (AVX-512, FMA, ...). Numba keys its
  on-disk cache on the target CPU, and the drill gives the emulated run a cache directory of
  its own (``NUMBA_CACHE_DIR``, empty at the start), so every kernel is compiled afresh and
  the host's cache beside the source is neither read nor written.
* ``OPENBLAS_CORETYPE`` (default ``Nehalem``, SSE4.2 without AVX): the OpenBLAS kernels of
  numpy and scipy (matrix products, Cholesky, solves) for another core than the host's
  (``SkylakeX`` on the development machine).
* ``NPY_DISABLE_CPU_FEATURES``: numpy's runtime-dispatched SIMD loops (AVX2, AVX-512: ``exp``,
  ``log``, ``tanh``, ...) are switched off, leaving numpy's baseline (SSE4.2), as on a CPU
  without them.

Every process of the emulated run imports a small ``sitecustomize`` hook (on ``PYTHONPATH``)
that records at exit, from inside the run, what that process really used: the CPU each
compiled ``rsmhp`` kernel was generated for, whether it was compiled or loaded from the cache,
the OpenBLAS core type threadpoolctl reports, and numpy's active SIMD extensions. The drill
also reads the emulated numba cache's index (the CPU every cached kernel was built for) and the
``blas`` line of both runs' ``results/provenance.json``. It fails (exit 3) when the
emulation did not take effect.

``--emulate`` chooses a subset of the three (to see which one moves which number).

**Where it runs.** The emulated run is a separate working directory (``snakemake -s
<copy>/Snakefile -d <workdir> report``; every output is written under ``<workdir>/results``),
by default a new temporary directory removed afterwards: the native ``results/`` is only read
(and, unless ``--no-native-run``, completed by an ordinary native ``snakemake report`` run
first). Target ``report`` makes every table and claim, what ``make verify`` needs
(``--target all`` adds the recordings).
The emulated run uses a copy of the checkout's workflow and ``src/`` taken when the drill
starts (``<workdir>/.drill/workflow``), so edits to the checkout during the run cannot mix
two versions of the code; the ``code`` stamps of both runs' tables show whether the native
run was made by the same code (the report warns when not).

**What is compared** (:func:`compare_results`, :func:`compare_claims`): every CSV and
Parquet table under both ``results/`` trees (measured times, i.e. columns named like
``*seconds*``, ``*_ms`` or ``cpu_*``, and the code stamp ``code`` set aside), each ``identical``
(every remaining cell bit for bit) or ``differs`` (per column: cells that differ, largest
absolute difference, largest relative difference ``|a - b| / max(|a|, |b|)`` and largest
distance in units in the last place), or missing, or of another shape; and every claim:
the key number of the reference, the native and the emulated run, the difference, both
``make verify`` comparisons with the reference (:mod:`rsmhp.report.verify`) and whether the three
verdicts are the same. The result is a Markdown report and a JSON file; the exit status is 1
when a verdict differs or a verify comparison fails.

The package: :mod:`~rsmhp.report.portability.emulation` (the emulated environment, the hook's
records and what took effect; the hook's source in :mod:`~rsmhp.report.portability.hook`),
:mod:`~rsmhp.report.portability.compare` (tables and claims),
:mod:`~rsmhp.report.portability.render` (the Markdown report) and
:mod:`~rsmhp.report.portability.cli` (the command line, ``python -m rsmhp.report.portability``).
"""

from __future__ import annotations

from rsmhp.report.portability.cli import DRILL_DIR, ROOT, main
from rsmhp.report.portability.compare import (
    CODE_COLUMN,
    compare_claims,
    compare_frames,
    compare_results,
    expected_class,
    is_timing_column,
    read_table,
)
from rsmhp.report.portability.emulation import (
    COMPONENTS,
    DEFAULT_CORETYPE,
    RECORDS_ENV,
    copy_workflow,
    emulation_env,
    install_hook,
    numba_cache_targets,
    probe,
    read_records,
    summarise_emulation,
)
from rsmhp.report.portability.hook import HOOK, PROBE

# last: the submodule ``render`` (imported above by ``cli``) must not shadow the function
from rsmhp.report.portability.render import render

__all__ = [
    "CODE_COLUMN",
    "COMPONENTS",
    "DEFAULT_CORETYPE",
    "DRILL_DIR",
    "HOOK",
    "PROBE",
    "RECORDS_ENV",
    "ROOT",
    "compare_claims",
    "compare_frames",
    "compare_results",
    "copy_workflow",
    "emulation_env",
    "expected_class",
    "install_hook",
    "is_timing_column",
    "main",
    "numba_cache_targets",
    "probe",
    "read_records",
    "read_table",
    "render",
    "summarise_emulation",
]
