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
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import textwrap
from collections.abc import Collection, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

__all__ = [
    "COMPONENTS",
    "DEFAULT_CORETYPE",
    "compare_claims",
    "compare_frames",
    "compare_results",
    "emulation_env",
    "expected_class",
    "is_timing_column",
    "main",
    "probe",
    "read_records",
    "render",
    "summarise_emulation",
]

#: OpenBLAS core type of the emulated machine: SSE4.2 without AVX (numpy's own baseline)
DEFAULT_CORETYPE = "Nehalem"

#: what can be emulated: numba's target CPU, OpenBLAS's core type, numpy's SIMD dispatch
COMPONENTS = ("numba", "openblas", "numpy")

#: the checkout whose Snakefile the drill runs (the package's own, like rsmhp.report.provenance)
ROOT = Path(__file__).resolve().parents[3]

#: subdirectory of the emulated working directory holding the drill's own files
DRILL_DIR = ".drill"

#: environment variable naming the directory the hook writes its records to
RECORDS_ENV = "RSMHP_DRILL_RECORDS"

#: the code stamp column of every table (rsmhp.pipeline.io.CODE_COLUMN; not imported, so this module
#: stays outside the code digest of every rule)
CODE_COLUMN = "code"

#: read_csv arguments that parse every float exactly (pandas 3's default parser does;
#: before it, the round-trip parser)
_CSV_EXACT = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}

_TIMING = re.compile(r"(.*_)?(seconds|ms)(_.*)?|cpu_.*")

#: tables of the statistically reproducible studies (README: UAV closed loop, UAV decisions)
_STATISTICAL = ("uav/", "decisions/uav_", "decisions/map/")

# The hook every process of the emulated run imports (sitecustomize on PYTHONPATH). It only
# registers an exit handler; at exit it writes one JSON record of what the process used.
HOOK = '''\
"""Written by rsmhp.report.portability (the portability drill): at exit, record what this process
ran on (numba's target CPU per compiled rsmhp kernel, OpenBLAS core type, numpy SIMD)."""
import atexit
import os
import sys


def _rsmhp_drill_record():
    out = os.environ.get("RSMHP_DRILL_RECORDS")
    if not out or "numpy" not in sys.modules:
        return
    import json

    import re

    arg0 = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else "?"
    rule = re.fullmatch(r"tmp[^.]*[.](\\w+)[.]py", arg0)  # .snakemake/scripts/tmpXXXX.<rule>.py
    rec = {"pid": os.getpid(), "argv0": arg0, "rule": rule.group(1) if rule else None}
    try:
        from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__

        rec["numpy_simd"] = [f for f in __cpu_dispatch__ if __cpu_features__.get(f)]
    except Exception as exc:
        rec["numpy_simd_error"] = repr(exc)
    try:
        from threadpoolctl import threadpool_info

        rec["openblas"] = sorted(
            {str(i.get("architecture")) for i in threadpool_info() if i.get("user_api") == "blas"}
        )
    except Exception as exc:
        rec["openblas_error"] = repr(exc)
    if "numba" in sys.modules:
        try:
            from numba.core import config
            from numba.core.dispatcher import Dispatcher

            kernels = {}
            for name, mod in list(sys.modules.items()):
                if not name.startswith("rsmhp") or mod is None:
                    continue
                for attr, obj in list(vars(mod).items()):
                    if not isinstance(obj, Dispatcher) or not obj.overloads:
                        continue
                    targets = set()
                    for res in obj.overloads.values():
                        _, cpu, features = res.library.codegen.magic_tuple()
                        targets.add((str(cpu), str(features)))
                    stats = obj.stats
                    kernels[name + "." + attr] = {
                        "targets": sorted(list(t) for t in targets),
                        "compiled": int(sum(stats.cache_misses.values())),
                        "loaded": int(sum(stats.cache_hits.values())),
                        "cache": str(stats.cache_path),
                    }
            rec["numba"] = {
                "NUMBA_CPU_NAME": config.CPU_NAME,
                "NUMBA_CPU_FEATURES": config.CPU_FEATURES,
                "NUMBA_CACHE_DIR": config.CACHE_DIR,
                "kernels": kernels,
            }
        except Exception as exc:
            rec["numba_error"] = repr(exc)
    try:
        os.makedirs(out, exist_ok=True)
        path = os.path.join(out, "%d.json" % os.getpid())
        with open(path + ".tmp", "w", encoding="utf-8") as fh:
            json.dump(rec, fh)
        os.replace(path + ".tmp", path)
    except OSError:
        pass


atexit.register(_rsmhp_drill_record)
'''

# What a fresh process on this machine reports (native or emulated environment): the same
# facts the hook records, plus the host CPU as LLVM sees it.
PROBE = """\
import json
import numpy, scipy.linalg
from threadpoolctl import threadpool_info
out = {"openblas": sorted({str(i.get("architecture")) for i in threadpool_info()
                           if i.get("user_api") == "blas"})}
try:
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    out["numpy_dispatch"] = list(__cpu_dispatch__)
    out["numpy_simd"] = [f for f in __cpu_dispatch__ if __cpu_features__.get(f)]
except Exception:
    out["numpy_dispatch"], out["numpy_simd"] = [], []
import llvmlite.binding as ll
from numba.core import config
from numba.core.registry import cpu_target
out["host_cpu"] = ll.get_host_cpu_name()
_, cpu, features = cpu_target.target_context.codegen().magic_tuple()
out["numba_cpu"], out["numba_features"] = str(cpu), str(features)
out["numba_cache_dir"] = config.CACHE_DIR
print(json.dumps(out))
"""


# ---------------------------------------------------------------------------------------------
# the emulation


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


def _provenance_blas(results: Path) -> str | None:
    try:
        return json.loads((results / "provenance.json").read_text(encoding="utf-8")).get("blas")
    except (OSError, ValueError):
        return None


def _blas_cores(blas: str | None) -> list[str]:
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
    kernels: dict[str, dict[str, Any]] = {}
    rules: set[str] = set()
    for rec in records:
        for name, k in rec.get("numba", {}).get("kernels", {}).items():
            agg = kernels.setdefault(name, {"targets": set(), "compiled": 0, "loaded": 0})
            agg["targets"].update(cpu for cpu, _ in k["targets"])
            agg["compiled"] += k["compiled"]
            agg["loaded"] += k["loaded"]
            rules.add(_rule_of(rec))
    run_cpus = sorted({cpu for k in kernels.values() for cpu in k["targets"]})
    run_blas = sorted({c for rec in records for c in rec.get("openblas", [])})
    run_simd = sorted({f for rec in records for f in rec.get("numpy_simd", [])})
    cached_cpus = sorted({cpu for cpus in cache_targets.values() for cpu in cpus})
    problems = []
    if not records:
        problems.append("no process of the emulated run left a record (hook not loaded)")
    if "openblas" in components:
        host = set(native["openblas"])
        if host & set(emulated["openblas"]):
            problems.append(
                f"OpenBLAS core type {emulated['openblas']} is the host's {native['openblas']} "
                "(OPENBLAS_CORETYPE unknown to this OpenBLAS, or not a DYNAMIC_ARCH build)"
            )
        if host & set(run_blas + _blas_cores(emulated_blas)):
            problems.append("a process of the emulated run used the host's OpenBLAS core type")
    if "numba" in components:
        if not kernels:
            problems.append("no compiled rsmhp kernel was used in the emulated run")
        if run_cpus and run_cpus != ["generic"]:
            problems.append(f"kernels of the emulated run were built for {run_cpus}")
        if kernels and not sum(k["compiled"] for k in kernels.values()):
            problems.append("no kernel was compiled in the emulated run (all from a cache)")
        if cached_cpus and cached_cpus != ["generic"]:
            problems.append(f"the emulated numba cache holds kernels for {cached_cpus}")
    if "numpy" in components and (run_simd or emulated.get("numpy_simd")):
        problems.append(f"numpy SIMD extensions still active: {run_simd or emulated['numpy_simd']}")
    return {
        "components": [c for c in COMPONENTS if c in components],
        "native": dict(native),
        "emulated": dict(emulated),
        "native run blas (provenance.json)": native_blas,
        "emulated run blas (provenance.json)": emulated_blas,
        "inside the emulated run": {
            "processes recorded": len(records),
            "processes with compiled kernels": sum(
                bool(r.get("numba", {}).get("kernels")) for r in records
            ),
            "rules with compiled kernels": sorted(rules),
            "numba target CPUs": run_cpus,
            "numba features": sorted(
                {
                    feat or "(none)"
                    for rec in records
                    for k in rec.get("numba", {}).get("kernels", {}).values()
                    for _, feat in k["targets"]
                }
            ),
            "openblas core types": run_blas,
            "numpy SIMD extensions": run_simd,
            "kernels": {
                name: {
                    "targets": sorted(k["targets"]),
                    "compiled": k["compiled"],
                    "loaded": k["loaded"],
                }
                for name, k in sorted(kernels.items())
            },
        },
        "emulated numba cache": dict(cache_targets),
        "effective": not problems,
        "problems": problems,
    }


# ---------------------------------------------------------------------------------------------
# comparing tables


def is_timing_column(name: str) -> bool:
    """A measured time (``cpu_seconds``, ``plan_seconds``, ``plan_seconds_per_run``,
    ``seconds``, ``cpu_median``, ``plan_ms``, ...): set aside, it differs between any two
    executions."""
    return bool(_TIMING.fullmatch(str(name)))


def expected_class(table: str) -> str:
    """How the README says a table (path relative to ``results/``) reproduces: ``bitwise``
    (LQG, estimator, LQG decision study) or ``statistical`` (UAV, UAV decision study)."""
    return "statistical" if table.startswith(_STATISTICAL) else "bitwise"


def _numeric_diff(a: pd.Series, b: pd.Series) -> dict[str, Any] | None:
    """None if the columns are bitwise equal (NaN equal to NaN), else how they differ: the
    number of differing ``cells`` (``of`` all), of them ``non-finite`` (NaN or inf on one
    side only), and over the finite ones the largest absolute difference, relative
    difference ``|a - b| / max(|a|, |b|)``, absolute difference relative to the column's
    largest magnitude, and distance in units in the last place (over cells with the same
    sign on both sides, both non-zero: elsewhere it counts the floats in between, e.g.
    about 4.6e18 from 0.0 to 1e-17; None if there is none, and for integer columns)."""
    x = a.to_numpy(dtype=np.float64, na_value=np.nan)
    y = b.to_numpy(dtype=np.float64, na_value=np.nan)
    both_int = pd.api.types.is_integer_dtype(a) and pd.api.types.is_integer_dtype(b)
    if both_int:
        same = a.to_numpy() == b.to_numpy()
    else:
        same = (x.view(np.int64) == y.view(np.int64)) | (np.isnan(x) & np.isnan(y))
    if same.all():
        return None
    finite = np.isfinite(x) & np.isfinite(y)
    col_max = float(np.max(np.maximum(np.abs(x[finite]), np.abs(y[finite])), initial=0.0))
    finite &= ~same
    d = np.abs(x[finite] - y[finite])
    scale = np.maximum(np.abs(x[finite]), np.abs(y[finite]))
    rel = np.divide(d, scale, out=np.zeros_like(d), where=scale > 0)
    ulps = None
    comparable = finite & (x != 0) & (y != 0) & (np.signbit(x) == np.signbit(y))
    if comparable.any() and not both_int:
        # same sign, both non-zero: the bit patterns count the floats in between
        ulps = int(np.abs(x[comparable].view(np.int64) - y[comparable].view(np.int64)).max())
    return {
        "cells": int((~same).sum()),
        "of": len(same),
        "non-finite": int((~same & ~np.isfinite(x) | ~same & ~np.isfinite(y)).sum()),
        "max abs": float(d.max()) if d.size else math.nan,
        "max rel": float(rel.max()) if rel.size else math.nan,
        "max abs / column max": float(d.max()) / col_max if d.size and col_max > 0 else math.nan,
        "max ulps": ulps,
    }


def compare_frames(native: pd.DataFrame, emulated: pd.DataFrame) -> dict[str, Any]:
    """Compare two versions of one table, timing columns and the code stamp set aside:
    ``status`` ``identical`` (every other cell bit for bit), ``differs`` (``columns``: per
    differing column the number of cells, largest absolute and relative difference, largest
    distance in ulps; text columns: the number of cells), ``columns differ`` or ``rows
    differ``; ``set aside``: the columns left out."""
    aside = [
        c
        for c in dict.fromkeys([*native.columns, *emulated.columns])
        if c == CODE_COLUMN or is_timing_column(c)
    ]
    a, b = (
        native.drop(columns=aside, errors="ignore"),
        emulated.drop(columns=aside, errors="ignore"),
    )
    out: dict[str, Any] = {"set aside": aside, "rows": len(a), "columns": {}}
    if list(a.columns) != list(b.columns):
        out["status"] = "columns differ"
        out["detail"] = (
            f"only native: {sorted(set(a.columns) - set(b.columns))}, only emulated: "
            f"{sorted(set(b.columns) - set(a.columns))}"
            + ("" if set(a.columns) != set(b.columns) else ", order differs")
        )
        return out
    if len(a) != len(b):
        out["status"] = "rows differ"
        out["detail"] = f"{len(a)} rows native, {len(b)} emulated"
        return out
    for col in a.columns:
        sa, sb = a[col], b[col]
        numeric = all(
            pd.api.types.is_numeric_dtype(s) and not pd.api.types.is_bool_dtype(s) for s in (sa, sb)
        )
        if numeric:
            diff = _numeric_diff(sa, sb)
        else:
            ta, tb = sa.astype(object), sb.astype(object)
            same = (ta == tb).to_numpy(dtype=bool) | (ta.isna() & tb.isna()).to_numpy()
            diff = None if same.all() else {"cells": int((~same).sum()), "of": len(same)}
        if diff is not None:
            out["columns"][col] = diff
    out["status"] = "differs" if out["columns"] else "identical"
    return out


def read_table(path: str | os.PathLike) -> pd.DataFrame:
    """A CSV (floats parsed exactly: the workflow writes them with full precision) or
    Parquet table."""
    path = Path(path)
    if path.suffix == ".parquet":
        return pd.read_parquet(path)
    return pd.read_csv(path, **_CSV_EXACT)


def _tables(results: Path) -> set[str]:
    if not results.is_dir():
        return set()
    return {
        str(p.relative_to(results))
        for p in results.rglob("*")
        if p.suffix in (".csv", ".parquet")
        and p.is_file()
        and p.relative_to(results).parts[0] != "portability"
    }


def _stamps(df: pd.DataFrame) -> set[str]:
    return set(df[CODE_COLUMN].dropna().astype(str)) if CODE_COLUMN in df else set()


def compare_results(native: str | os.PathLike, emulated: str | os.PathLike) -> list[dict[str, Any]]:
    """One entry per CSV/Parquet table under either ``results`` directory (``portability/``
    aside), in path order: :func:`compare_frames` of the two versions with the table's
    ``table`` path, ``expected`` class (:func:`expected_class`) and, when the code stamps of
    the two differ (other code made them), ``code stamps``; ``status`` ``missing (native)``
    or ``missing (emulated)`` when only one run has it."""
    native, emulated = Path(native), Path(emulated)
    out = []
    for rel in sorted(_tables(native) | _tables(emulated)):
        entry: dict[str, Any] = {"table": rel, "expected": expected_class(rel)}
        if not (native / rel).is_file() or not (emulated / rel).is_file():
            side = "native" if not (native / rel).is_file() else "emulated"
            out.append({**entry, "status": f"missing ({side})", "columns": {}, "set aside": []})
            continue
        a, b = read_table(native / rel), read_table(emulated / rel)
        entry.update(compare_frames(a, b))
        if _stamps(a) != _stamps(b):
            entry["code stamps"] = {"native": sorted(_stamps(a)), "emulated": sorted(_stamps(b))}
        out.append(entry)
    return out


# ---------------------------------------------------------------------------------------------
# comparing claims


def compare_claims(
    reference: Sequence[Any], native: Sequence[Any], emulated: Sequence[Any]
) -> list[dict[str, Any]]:
    """One row per claim (reference order, then claims only in a run): the key number of
    the reference, the native and the emulated run, emulated minus native (absolute and
    relative), whether it is bitwise equal, ``make verify``'s status of each run against
    the reference (:func:`rsmhp.report.verify.compare`) and whether all three verdicts are the
    same. Claims are :class:`rsmhp.report.ledger.Claim`."""
    from rsmhp.report.verify import compare

    ver_native = compare(reference, native).set_index("id")
    ver_emul = compare(reference, emulated).set_index("id")
    by = [{c.id: c for c in claims} for claims in (reference, native, emulated)]
    ids = list(dict.fromkeys([*by[0], *by[1], *by[2]]))
    rows = []
    for cid in ids:
        ref, nat, emu = (b.get(cid) for b in by)
        some = ref or nat or emu
        value = [c.key.value if c else math.nan for c in (ref, nat, emu)]
        diff = value[2] - value[1]
        scale = max(abs(value[1]), abs(value[2]))
        rows.append(
            {
                "id": cid,
                "key number": some.key.name + (f" ({some.key.unit})" if some.key.unit else ""),
                "reproducible": some.key.reproducible,
                "reference": value[0],
                "native": value[1],
                "emulated": value[2],
                "emulated - native": diff,
                "relative": abs(diff) / scale if scale > 0 else (0.0 if diff == 0 else math.nan),
                "bitwise equal": bool(
                    nat and emu and np.float64(value[1]).tobytes() == np.float64(value[2]).tobytes()
                ),
                "emulated - reference": value[2] - value[0],
                "tolerance": float(ver_emul.loc[cid, "tolerance"])
                if cid in ver_emul.index
                else math.nan,
                "verdict (reference)": ref.verdict if ref else "-",
                "verdict (native)": nat.verdict if nat else "-",
                "verdict (emulated)": emu.verdict if emu else "-",
                "same verdict": bool(
                    ref and nat and emu and ref.verdict == nat.verdict == emu.verdict
                ),
                "verify (native)": str(ver_native.loc[cid, "status"])
                if cid in ver_native.index
                else "-",
                "verify (emulated)": str(ver_emul.loc[cid, "status"])
                if cid in ver_emul.index
                else "-",
            }
        )
    return rows


# ---------------------------------------------------------------------------------------------
# report


def _g(x: Any, digits: int = 2) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    if isinstance(x, int | np.integer):
        return str(int(x))
    return "0" if x == 0 else f"{x:.{digits}g}"


def _cell(text: Any) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _md(header: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(_cell(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def _worst(cols: Sequence[Mapping[str, Any]], key: str) -> Any:
    vals = [c[key] for c in cols if c.get(key) is not None and math.isfinite(c[key])]
    return max(vals, default=None)


def _numbers(c: Mapping[str, Any]) -> list[str]:
    return [
        _g(c.get("max abs")),
        _g(c.get("max rel")),
        _g(c.get("max abs / column max")),
        _g(c.get("max ulps")),
    ]


_NUMBER_HEADER = ["max abs", "max rel", "max abs / column max", "max ulps"]


def render(drill: Mapping[str, Any]) -> str:
    """The drill as Markdown: result line, the emulation as measured, claims, tables, and
    every differing column."""
    emu = drill["emulation"]
    inside = emu["inside the emulated run"]
    nat, comps = emu["native"], set(emu["components"])
    kernels = inside["kernels"].values()

    def emulated(component: str, text: str) -> str:
        return text if component in comps else f"{text} (not emulated)"

    cached = sorted({c for v in emu["emulated numba cache"].values() for c in v})
    n_feat = nat["numba_features"].count("+")
    emulation_rows = [
        [
            "numba target CPU (features)",
            f"{nat['numba_cpu']} ({n_feat} features on"
            + (", e.g. avx512f, fma)" if "+avx512f" in nat["numba_features"] else ")"),
            emulated(
                "numba",
                ", ".join(inside["numba target CPUs"]) or "-",
            )
            + " ("
            + (", ".join(inside["numba features"]) or "-").replace("(none)", "no features")
            + ")",
            "inside the run: the code generator of every compiled rsmhp kernel in "
            f"{inside['processes with compiled kernels']} processes "
            f"({', '.join(inside['rules with compiled kernels']) or 'none'})",
        ],
        [
            "kernels compiled / loaded",
            "the host's cache beside the source",
            f"{sum(k['compiled'] for k in kernels)} / {sum(k['loaded'] for k in kernels)} "
            f"({len(inside['kernels'])} kernels)",
            "inside the run: numba's cache statistics; the run's own cache (empty at the "
            f"start) holds kernels for {', '.join(cached) or '-'}",
        ],
        [
            "OpenBLAS core type",
            ", ".join(_blas_cores(emu["native run blas (provenance.json)"]))
            or ", ".join(nat["openblas"]),
            emulated("openblas", ", ".join(inside["openblas core types"]) or "-"),
            "threadpoolctl inside the run; provenance.json: native "
            f"`{emu['native run blas (provenance.json)']}`, emulated "
            f"`{emu['emulated run blas (provenance.json)']}`",
        ],
        [
            "numpy SIMD dispatch",
            ", ".join(nat["numpy_simd"]) or "none",
            emulated("numpy", ", ".join(inside["numpy SIMD extensions"]) or "none (baseline)"),
            "numpy's CPU features inside the run",
        ],
    ]
    claims, tables = drill["claims"], drill["tables"]
    lines = [
        f"# Portability drill: {drill['result']}",
        "",
        f"Native run `{drill['native']}`, emulated run `{drill['emulated']}`, reference "
        f"`{drill['reference']}`, config sha256 `{drill['config sha256']}`. "
        + (
            "The emulation took effect (below, as measured)."
            if emu["effective"]
            else "**The emulation did not take effect:** " + "; ".join(emu["problems"]) + "."
        ),
        "",
        "## What was emulated",
        "",
        _md(["", "native (this machine)", "emulated run", "measured"], emulation_rows),
        "",
        f"{inside['processes recorded']} processes of the emulated run left a record. "
        "Environment of the emulated run: `"
        + " ".join(f"{k}={v}" for k, v in drill["env"].items())
        + "`.",
        "",
        "## Claims",
        "",
        f"`make verify` against the reference: native **{drill['verify native']}**, emulated "
        f"**{drill['verify emulated']}**. Verdicts the same (reference, native, emulated) in "
        f"{sum(r['same verdict'] for r in claims)} of {len(claims)} claims; key number "
        f"bitwise equal (emulated vs native) in {sum(r['bitwise equal'] for r in claims)}. "
        "Tolerance: `make verify`'s, of the emulated run against the reference.",
        "",
        _md(
            [
                "id",
                "class",
                "native",
                "emulated − native",
                "relative",
                "bitwise",
                "tolerance",
                "verdict (reference / native / emulated)",
                "verify (emulated)",
            ],
            [
                [
                    r["id"],
                    r["reproducible"],
                    _g(r["native"], 6),
                    _g(r["emulated - native"]),
                    _g(r["relative"]),
                    "yes" if r["bitwise equal"] else "**no**",
                    _g(r["tolerance"]),
                    " / ".join(
                        (r["verdict (reference)"], r["verdict (native)"], r["verdict (emulated)"])
                    )
                    + ("" if r["same verdict"] else " **differs**"),
                    r["verify (emulated)"],
                ]
                for r in claims
            ],
        ),
        "",
        "## Tables",
        "",
        f"{sum(t['status'] == 'identical' for t in tables)} of {len(tables)} tables under "
        "`results/` are bitwise identical in the two runs (columns of measured times and the "
        "`code` stamp set aside). `expected`: the README's class of the study. For a table "
        "that differs: the columns that differ (cells that differ / all cells) and, worst over "
        "its numeric columns, the largest absolute difference, relative difference "
        "|a − b| / max(|a|, |b|) (large where a value is near 0), absolute difference relative "
        "to the column's largest magnitude, and distance in units in the last place (cells of "
        "the same sign, both non-zero).",
        "",
        _md(
            ["table", "expected", "status", "differing columns", *_NUMBER_HEADER],
            [
                [
                    t["table"],
                    t["expected"],
                    t["status"],
                    ", ".join(f"{k} ({v['cells']}/{v['of']})" for k, v in t["columns"].items())
                    or t.get("detail", "-"),
                    *_numbers({k: _worst(list(t["columns"].values()), k) for k in _NUMBER_HEADER}),
                ]
                for t in tables
            ],
        ),
    ]
    stamps = [t["table"] for t in tables if "code stamps" in t]
    if stamps:
        lines += [
            "",
            f"**Warning:** other code made the native and the emulated version of "
            f"{', '.join(stamps)} (their `code` stamps differ): those differences are not the "
            "emulation's alone.",
        ]
    details = [
        [t["table"], col, f"{c['cells']}/{c['of']}", *_numbers(c)]
        for t in tables
        for col, c in t["columns"].items()
    ]
    if details:
        lines += [
            "",
            "### Differing columns",
            "",
            _md(["table", "column", "cells", *_NUMBER_HEADER], details),
        ]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------------------------
# running


def _snakemake(
    workdir: Path,
    snakefile: Path,
    configfiles: Sequence[str],
    cores: int,
    targets: Sequence[str],
    env: Mapping[str, str],
    log: Path | None,
    quiet: bool,
) -> int:
    cmd = [sys.executable, "-m", "snakemake", "-s", str(snakefile), "-d", str(workdir)]
    # targets after an option: after --configfile's files they would be read as files
    cmd += [*(["--configfile", *configfiles] if configfiles else []), f"-j{cores}", *targets]
    print("$ " + " ".join(cmd), flush=True)
    fh = open(log, "a", encoding="utf-8") if log else None
    try:
        proc = subprocess.Popen(
            cmd, env=dict(env), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
        )
        assert proc.stdout is not None
        tail: list[str] = []
        for line in proc.stdout:
            if fh:
                fh.write(line)
            if not quiet:
                sys.stdout.write(line)
            tail = [*tail[-40:], line]
        code = proc.wait()
    finally:
        if fh:
            fh.close()
    if code != 0 and quiet:
        sys.stdout.write("".join(tail))
    return code


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple | set):
        return [_jsonable(v) for v in x]
    if isinstance(x, float | np.floating):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m rsmhp.report.portability``: see ``--help``. Exit status 0 when every verdict is
    the same and both runs pass verify, 1 when not, 2 when a run failed or the inputs cannot
    be compared, 3 when the emulation did not take effect."""
    from rsmhp.report.verify import load_claims

    p = argparse.ArgumentParser(
        prog="python -m rsmhp.report.portability",
        description=" ".join(__doc__.split("\n\n")[0].split()).replace("``", "`"),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=textwrap.dedent(
            """\
            examples:
              python -m rsmhp.report.portability     # full config: results/ vs paper/claims.json
              python -m rsmhp.report.portability --configfile tests/config/tiny.yaml \\
                  --native /tmp/tiny --reference /tmp/tiny/results/paper/claims.json \\
                  --output /tmp/tiny-drill/drill"""
        ),
    )
    p.add_argument("--native", default=".", help="working directory of the native run (.)")
    p.add_argument(
        "--no-native-run",
        action="store_true",
        help="only read the native results (default: complete them with snakemake first)",
    )
    p.add_argument(
        "--workdir",
        default=None,
        help="working directory of the emulated run (kept; default: a temporary directory, "
        "removed afterwards unless --keep); reused when it holds an earlier drill",
    )
    p.add_argument("--keep", action="store_true", help="keep the temporary emulated run")
    p.add_argument(
        "--reference", default="paper/claims.json", help="claims file (paper/claims.json)"
    )
    p.add_argument("--configfile", nargs="*", default=[], help="snakemake --configfile FILE(s)")
    p.add_argument("--cores", type=int, default=2, help="snakemake -j of both runs (2)")
    p.add_argument(
        "--target",
        nargs="+",
        default=["report"],
        help="snakemake targets of both runs (default: report, what make verify needs: "
        "every table and claim; `all` adds the recordings)",
    )
    p.add_argument(
        "--openblas-coretype",
        default=DEFAULT_CORETYPE,
        help=f"OPENBLAS_CORETYPE of the emulated run ({DEFAULT_CORETYPE})",
    )
    p.add_argument(
        "--emulate",
        default=",".join(COMPONENTS),
        help="what to emulate, a comma-separated subset of numba (generic target CPU), "
        "openblas (--openblas-coretype), numpy (SIMD dispatch off); default all three",
    )
    p.add_argument(
        "--output",
        default=None,
        help="report path without suffix, writes .md and .json "
        "(default <native>/results/portability/drill)",
    )
    p.add_argument(
        "--checkout",
        default=str(ROOT),
        help="the checkout whose workflow runs (default: the one rsmhp is imported from)",
    )
    p.add_argument("--quiet", action="store_true", help="do not echo snakemake's output")
    args = p.parse_args(argv)
    components = {c.strip() for c in args.emulate.split(",") if c.strip()}
    if not components or components - set(COMPONENTS):
        p.error(f"--emulate: choose from {', '.join(COMPONENTS)}, got {args.emulate!r}")

    native_dir = Path(args.native).resolve()
    configfiles = [str(Path(c).resolve()) for c in args.configfile]
    checkout = Path(args.checkout).resolve()
    output = Path(args.output) if args.output else native_dir / "results/portability/drill"
    if output.suffix in (".md", ".json"):
        output = output.with_suffix("")
    reference = Path(args.reference)
    made_by_native = reference.resolve().is_relative_to(native_dir / "results")
    if not reference.is_file() and not (made_by_native and not args.no_native_run):
        print(f"portability: reference {reference} not found", file=sys.stderr)
        return 2
    # the emulated working directory: new, or one this drill made before
    temporary = args.workdir is None
    workdir = Path(args.workdir).resolve() if args.workdir else None
    if workdir is not None:
        if workdir == native_dir or native_dir.is_relative_to(workdir):
            print("portability: the emulated run needs a directory of its own", file=sys.stderr)
            return 2
        if workdir.exists() and any(workdir.iterdir()) and not (workdir / DRILL_DIR).is_dir():
            print(f"portability: {workdir} is not empty and holds no drill", file=sys.stderr)
            return 2
    else:
        workdir = Path(tempfile.mkdtemp(prefix="rsmhp-portability-")).resolve()
    drill_dir = workdir / DRILL_DIR
    try:
        native_env = dict(os.environ)
        native_probe = probe(native_env)
        drill_dir.mkdir(parents=True, exist_ok=True)
        install_hook(drill_dir)
        snakefile = copy_workflow(checkout, drill_dir / "workflow")
        env = emulation_env(
            native_env,
            drill_dir,
            args.openblas_coretype if "openblas" in components else None,
            native_probe.get("numpy_dispatch", []) if "numpy" in components else (),
            numba="numba" in components,
        )
        emulated_probe = probe(env)
        shown_env = {
            k: env[k]
            for k in (
                "NUMBA_CPU_NAME",
                "NUMBA_CACHE_DIR",
                "OPENBLAS_CORETYPE",
                "NPY_DISABLE_CPU_FEATURES",
            )
            if k in env
        }
        print(f"portability: emulated environment {shown_env}", flush=True)
        if not args.no_native_run:
            print("portability: completing the native run", flush=True)
            code = _snakemake(
                native_dir,
                checkout / "Snakefile",
                configfiles,
                args.cores,
                args.target,
                native_env,
                None,
                args.quiet,
            )
            if code:
                print("portability: the native run failed", file=sys.stderr)
                return 2
        print(f"portability: emulated run in {workdir}", flush=True)
        log = drill_dir / "snakemake.log"
        if _snakemake(
            workdir, snakefile, configfiles, args.cores, args.target, env, log, args.quiet
        ):
            print(f"portability: the emulated run failed (log {log})", file=sys.stderr)
            return 2
        try:
            ref_claims, ref_hash = load_claims(reference)
            nat_claims, nat_hash = load_claims(native_dir / "results/paper/claims.json")
            emu_claims, emu_hash = load_claims(workdir / "results/paper/claims.json")
        except ValueError as exc:
            print(f"portability: {exc}", file=sys.stderr)
            return 2
        if len({ref_hash, nat_hash, emu_hash}) != 1:
            print(
                f"portability: config sha256 differs (reference {ref_hash}, native {nat_hash}, "
                f"emulated {emu_hash}): compare runs of the same configuration",
                file=sys.stderr,
            )
            return 2
        emulation = summarise_emulation(
            native_probe,
            emulated_probe,
            read_records(drill_dir / "records"),
            numba_cache_targets(drill_dir / "numba-cache"),
            _provenance_blas(native_dir / "results"),
            _provenance_blas(workdir / "results"),
            components,
        )
        claims = compare_claims(ref_claims, nat_claims, emu_claims)
        tables = compare_results(native_dir / "results", workdir / "results")
        verify_native = all(r["verify (native)"] == "ok" for r in claims)
        verify_emulated = all(r["verify (emulated)"] == "ok" for r in claims)
        agree = all(r["same verdict"] for r in claims)
        result = "PASS" if verify_native and verify_emulated and agree else "FAIL"
        if not emulation["effective"]:
            result = "EMULATION NOT EFFECTIVE"
        drill = {
            "result": result,
            "native": str(native_dir),
            "emulated": str(workdir)
            + (" (temporary, removed)" if temporary and not args.keep else ""),
            "reference": str(reference),
            "config sha256": ref_hash,
            "env": shown_env,
            "verify native": "PASS" if verify_native else "FAIL",
            "verify emulated": "PASS" if verify_emulated else "FAIL",
            "verdicts agree": agree,
            "emulation": emulation,
            "claims": claims,
            "tables": tables,
        }
        text = render(drill)
        md, js = Path(f"{output}.md"), Path(f"{output}.json")
        md.parent.mkdir(parents=True, exist_ok=True)
        md.write_text(text, encoding="utf-8")
        js.write_text(json.dumps(_jsonable(drill), indent=1) + "\n", encoding="utf-8")
        print(text)
        print(f"portability: wrote {md} and {js}")
        if not emulation["effective"]:
            return 3
        return 0 if result == "PASS" else 1
    finally:
        if temporary and not args.keep:
            shutil.rmtree(workdir, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
