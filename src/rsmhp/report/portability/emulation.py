"""The emulated machine of the portability drill: its environment (:func:`emulation_env`), the
copy of the workflow it runs (:func:`copy_workflow`), the recording hook
(:func:`install_hook`, :func:`read_records`) and what the emulation measurably changed
(:func:`probe`, :func:`numba_cache_targets`, :func:`summarise_emulation`).

Three environment variables change the code paths a different x86-64 machine would take:
``NUMBA_CPU_NAME=generic`` (numba's baseline x86-64 target, in a cache directory of its own),
``OPENBLAS_CORETYPE`` (OpenBLAS kernels of another core) and ``NPY_DISABLE_CPU_FEATURES``
(numpy's runtime-dispatched SIMD loops off); see :mod:`rsmhp.report.portability`.
:func:`cpu_target_env` sets the same variables for another named CPU model (an AVX2 machine
without AVX-512: ``znver3``, ``Haswell``, :func:`numpy_avx512_targets`), for
``benchmarks/cpu_targets.py`` and ``tests/models/uav/test_cpu_targets.py``.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from collections.abc import Collection, Mapping, Sequence
from pathlib import Path
from typing import Any

from rsmhp.report.portability.hook import HOOK, PROBE

__all__ = [
    "AVX2_CORETYPE",
    "AVX2_CPU",
    "COMPONENTS",
    "DEFAULT_CORETYPE",
    "RECORDS_ENV",
    "blas_cores",
    "copy_workflow",
    "cpu_target_env",
    "emulation_env",
    "install_hook",
    "numba_cache_targets",
    "numpy_avx512_targets",
    "probe",
    "provenance_blas",
    "read_records",
    "summarise_emulation",
]

#: OpenBLAS core type of the emulated machine: SSE4.2 without AVX (numpy's own baseline)
DEFAULT_CORETYPE = "Nehalem"

#: what can be emulated: numba's target CPU, OpenBLAS's core type, numpy's SIMD dispatch
COMPONENTS = ("numba", "openblas", "numpy")

#: environment variable naming the directory the hook writes its records to
RECORDS_ENV = "RSMHP_DRILL_RECORDS"

#: an AVX2 machine without AVX-512: LLVM's CPU model (Zen 3) and OpenBLAS's core type
AVX2_CPU = "znver3"
AVX2_CORETYPE = "Haswell"


def probe(env: Mapping[str, str] | None = None, python: str = sys.executable) -> dict[str, Any]:
    """What a fresh Python process in ``env`` (default: this one's) reports: OpenBLAS core
    types (threadpoolctl), numpy's dispatchable and active SIMD extensions, the host CPU
    (LLVM) and the CPU and features numba generates code for."""
    res = subprocess.run(
        [python, "-c", PROBE],
        env=dict(os.environ if env is None else env),
        capture_output=True,
        text=True,
        timeout=300,
    )
    if res.returncode != 0:
        raise RuntimeError(f"the environment probe failed:\n{res.stderr[-2000:]}")
    return json.loads(res.stdout.strip().splitlines()[-1])


def emulation_env(
    base: Mapping[str, str],
    drill_dir: str | os.PathLike,
    coretype: str | None = DEFAULT_CORETYPE,
    numpy_disable: Sequence[str] = (),
    numba: bool = True,
) -> dict[str, str]:
    """``base`` with the emulated machine's variables: numba's generic target (unless not
    ``numba``) and in any case a numba cache directory of its own
    (``<drill_dir>/numba-cache``), the OpenBLAS core type ``coretype`` (None: the host's),
    numpy's SIMD extensions ``numpy_disable`` switched off, and the recording hook
    (``<drill_dir>/hook``) first on ``PYTHONPATH``, writing to ``<drill_dir>/records``."""
    drill_dir = Path(drill_dir).resolve()
    env = dict(base)
    env.pop("NUMBA_CPU_FEATURES", None)  # generic implies no features (numba's default)
    env.pop("NUMBA_CPU_NAME", None)
    if numba:
        env["NUMBA_CPU_NAME"] = "generic"
    env["NUMBA_CACHE_DIR"] = str(drill_dir / "numba-cache")
    env.pop("OPENBLAS_CORETYPE", None)
    if coretype:
        env["OPENBLAS_CORETYPE"] = coretype
    if numpy_disable:
        env["NPY_DISABLE_CPU_FEATURES"] = " ".join(numpy_disable)
    else:
        env.pop("NPY_DISABLE_CPU_FEATURES", None)
    env["PYTHONPATH"] = os.pathsep.join(
        filter(None, [str(drill_dir / "hook"), base.get("PYTHONPATH")])
    )
    env[RECORDS_ENV] = str(drill_dir / "records")
    return env


def numpy_avx512_targets() -> list[str]:
    """The runtime-dispatch targets of this numpy that need AVX-512 (``X86_V4``, the
    ``AVX512_*`` groups; numpy 1.x: ``AVX512F``, ``AVX512_SKX``, ...), in numpy's order: the
    names ``NPY_DISABLE_CPU_FEATURES`` takes to leave numpy on its AVX2 loops. Taken from numpy
    itself, as it rejects names that are not dispatch targets of its build."""
    try:
        from numpy._core._multiarray_umath import __cpu_dispatch__
    except ImportError:  # numpy < 2
        from numpy.core._multiarray_umath import __cpu_dispatch__
    return [f for f in __cpu_dispatch__ if f == "X86_V4" or f.startswith("AVX512")]


def cpu_target_env(
    base: Mapping[str, str],
    cpu: str = AVX2_CPU,
    coretype: str | None = AVX2_CORETYPE,
    numpy_disable: Sequence[str] = (),
) -> dict[str, str]:
    """``base`` with numba generating code for the LLVM CPU model ``cpu`` with that model's
    own features (``NUMBA_CPU_NAME=cpu``, ``NUMBA_CPU_FEATURES`` empty: numba would otherwise
    add the host's features, AVX-512 included, to any CPU name), the OpenBLAS core type
    ``coretype`` (None: the host's) and numpy's SIMD targets ``numpy_disable`` switched off
    (e.g. :func:`numpy_avx512_targets`). numba's cache directory is left as it is: its index
    keys entries on the CPU name and features, so they sit beside the host's."""
    env = dict(base)
    env["NUMBA_CPU_NAME"] = cpu
    env["NUMBA_CPU_FEATURES"] = ""
    env.pop("OPENBLAS_CORETYPE", None)
    if coretype:
        env["OPENBLAS_CORETYPE"] = coretype
    env.pop("NPY_DISABLE_CPU_FEATURES", None)
    if numpy_disable:
        env["NPY_DISABLE_CPU_FEATURES"] = " ".join(numpy_disable)
    return env


def copy_workflow(root: str | os.PathLike, dest: str | os.PathLike) -> Path:
    """Copy the workflow of checkout ``root`` (Snakefile, ``workflow/``, ``config/``,
    ``src/``, and the data files the workflow reads at parse time: ``paper/exploratory/``,
    ``paper/superseded/``
    and ``tests/config/``, where the test config's tuned file and preregistration live;
    caches and build files aside) to ``dest`` (replaced); the copy's Snakefile."""
    root, dest = Path(root), Path(dest)
    if dest.exists():
        shutil.rmtree(dest)
    dest.mkdir(parents=True)
    shutil.copy2(root / "Snakefile", dest / "Snakefile")
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "*.egg-info", "*.nbi", "*.nbc")
    subs = ("workflow", "config", "src", "paper/exploratory", "paper/superseded", "tests/config")
    for sub in subs:
        if (root / sub).is_dir():
            shutil.copytree(root / sub, dest / sub, ignore=ignore)
    return dest / "Snakefile"


def install_hook(drill_dir: str | os.PathLike) -> Path:
    """Write the recording hook (``<drill_dir>/hook/sitecustomize.py``); its path."""
    hook = Path(drill_dir) / "hook" / "sitecustomize.py"
    hook.parent.mkdir(parents=True, exist_ok=True)
    hook.write_text(HOOK, encoding="utf-8")
    return hook


def read_records(records: str | os.PathLike) -> list[dict[str, Any]]:
    """The hook's records (one per process that loaded numpy), by process id."""
    out = []
    for path in sorted(Path(records).glob("*.json")):
        try:
            out.append(json.loads(path.read_text(encoding="utf-8")))
        except (OSError, ValueError):
            continue
    return sorted(out, key=lambda r: r.get("pid", 0))


def numba_cache_targets(cache_dir: str | os.PathLike) -> dict[str, list[str]]:
    """{index file: sorted CPU names its kernels were built for} of a numba cache directory
    (the index key holds numba's ``magic_tuple``: triple, CPU name, features)."""
    import pickle

    out: dict[str, list[str]] = {}
    for path in sorted(Path(cache_dir).rglob("*.nbi")):
        try:
            with open(path, "rb") as fh:
                pickle.load(fh)  # numba version
                _, overloads = pickle.loads(fh.read())
            out[path.name] = sorted({str(key[1][1]) for key in overloads})
        except Exception:  # an unreadable index is shown as such
            out[path.name] = ["unreadable"]
    return out


def provenance_blas(results: Path) -> str | None:
    """The ``blas`` line of ``<results>/provenance.json``; None if there is none."""
    try:
        return json.loads((results / "provenance.json").read_text(encoding="utf-8")).get("blas")
    except (OSError, ValueError):
        return None


def blas_cores(blas: str | None) -> list[str]:
    """Core types in a provenance ``blas`` line (``openblas 0.3.30 SkylakeX; ...``)."""
    if not blas:
        return []
    return sorted({part.split()[-1] for part in blas.split(";") if len(part.split()) >= 3})


def _rule_of(record: Mapping[str, Any]) -> str:
    """The rule a recorded process ran (Snakemake runs ``.snakemake/scripts/tmpXXXX.<rule>.py``;
    a joblib worker has its parent's name), else its program name."""
    arg0 = str(record.get("argv0", "?"))
    m = re.fullmatch(r"tmp[^.]*[.](\w+)[.]py", arg0)
    return m.group(1) if m else arg0


def _kernels(records: Sequence[Mapping[str, Any]]) -> tuple[dict[str, dict[str, Any]], set[str]]:
    """({kernel: its target CPUs, times compiled, times loaded} summed over the ``records``,
    the rules whose processes used a compiled kernel)."""
    kernels: dict[str, dict[str, Any]] = {}
    rules: set[str] = set()
    for rec in records:
        for name, k in rec.get("numba", {}).get("kernels", {}).items():
            agg = kernels.setdefault(name, {"targets": set(), "compiled": 0, "loaded": 0})
            agg["targets"].update(cpu for cpu, _ in k["targets"])
            agg["compiled"] += k["compiled"]
            agg["loaded"] += k["loaded"]
            rules.add(_rule_of(rec))
    return kernels, rules


def _openblas_problems(
    native: Mapping[str, Any],
    emulated: Mapping[str, Any],
    run_blas: list[str],
    emulated_blas: str | None,
) -> list[str]:
    """The host's OpenBLAS core type in the emulated probe, a process or the provenance."""
    problems = []
    host = set(native["openblas"])
    if host & set(emulated["openblas"]):
        problems.append(
            f"OpenBLAS core type {emulated['openblas']} is the host's {native['openblas']} "
            "(OPENBLAS_CORETYPE unknown to this OpenBLAS, or not a DYNAMIC_ARCH build)"
        )
    if host & set(run_blas + blas_cores(emulated_blas)):
        problems.append("a process of the emulated run used the host's OpenBLAS core type")
    return problems


def _numba_problems(
    kernels: Mapping[str, Mapping[str, Any]], run_cpus: list[str], cached_cpus: list[str]
) -> list[str]:
    """No kernel used, a kernel built for another CPU than ``generic`` (in the run or the
    cache), or none compiled in the run."""
    problems = []
    if not kernels:
        problems.append("no compiled rsmhp kernel was used in the emulated run")
    if run_cpus and run_cpus != ["generic"]:
        problems.append(f"kernels of the emulated run were built for {run_cpus}")
    if kernels and not sum(k["compiled"] for k in kernels.values()):
        problems.append("no kernel was compiled in the emulated run (all from a cache)")
    if cached_cpus and cached_cpus != ["generic"]:
        problems.append(f"the emulated numba cache holds kernels for {cached_cpus}")
    return problems


def _inside(
    records: Sequence[Mapping[str, Any]],
    kernels: Mapping[str, Mapping[str, Any]],
    rules: set[str],
) -> dict[str, Any]:
    """What the hook's ``records`` say about the emulated run, summed over its processes."""
    return {
        "processes recorded": len(records),
        "processes with compiled kernels": sum(
            bool(r.get("numba", {}).get("kernels")) for r in records
        ),
        "rules with compiled kernels": sorted(rules),
        "numba target CPUs": sorted({cpu for k in kernels.values() for cpu in k["targets"]}),
        "numba features": sorted(
            {
                feat or "(none)"
                for rec in records
                for k in rec.get("numba", {}).get("kernels", {}).values()
                for _, feat in k["targets"]
            }
        ),
        "openblas core types": sorted({c for rec in records for c in rec.get("openblas", [])}),
        "numpy SIMD extensions": sorted({f for rec in records for f in rec.get("numpy_simd", [])}),
        "kernels": {
            name: {
                "targets": sorted(k["targets"]),
                "compiled": k["compiled"],
                "loaded": k["loaded"],
            }
            for name, k in sorted(kernels.items())
        },
    }


def summarise_emulation(
    native: Mapping[str, Any],
    emulated: Mapping[str, Any],
    records: Sequence[Mapping[str, Any]],
    cache_targets: Mapping[str, Sequence[str]],
    native_blas: str | None,
    emulated_blas: str | None,
    components: Collection[str] = COMPONENTS,
) -> dict[str, Any]:
    """What the emulation changed, measured: the ``native`` and ``emulated`` probes
    (:func:`probe`), the hook's ``records`` from inside the emulated run, the emulated numba
    cache (:func:`numba_cache_targets`) and the ``blas`` line of both runs' provenance.
    ``effective`` is false, with the ``problems``, when an emulated ``component`` did not
    take effect: no record (hook not loaded); OpenBLAS on the host's core type in the probe,
    a process or the provenance; a kernel built for another CPU than ``generic``, none used
    or none compiled in the run (all from a cache); numpy SIMD extensions still active."""
    kernels, rules = _kernels(records)
    inside = _inside(records, kernels, rules)
    run_simd = inside["numpy SIMD extensions"]
    cached_cpus = sorted({cpu for cpus in cache_targets.values() for cpu in cpus})
    problems = []
    if not records:
        problems.append("no process of the emulated run left a record (hook not loaded)")
    if "openblas" in components:
        run_blas = inside["openblas core types"]
        problems += _openblas_problems(native, emulated, run_blas, emulated_blas)
    if "numba" in components:
        problems += _numba_problems(kernels, inside["numba target CPUs"], cached_cpus)
    if "numpy" in components and (run_simd or emulated.get("numpy_simd")):
        problems.append(f"numpy SIMD extensions still active: {run_simd or emulated['numpy_simd']}")
    return {
        "components": [c for c in COMPONENTS if c in components],
        "native": dict(native),
        "emulated": dict(emulated),
        "native run blas (provenance.json)": native_blas,
        "emulated run blas (provenance.json)": emulated_blas,
        "inside the emulated run": inside,
        "emulated numba cache": dict(cache_targets),
        "effective": not problems,
        "problems": problems,
    }
