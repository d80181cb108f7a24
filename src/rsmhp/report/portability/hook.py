"""Source text of the code the portability drill runs in other processes: the recording hook
every process of the emulated run imports (``sitecustomize`` on ``PYTHONPATH``) and the probe
of a fresh process's environment (:func:`rsmhp.report.portability.emulation.probe`)."""

from __future__ import annotations

__all__ = ["HOOK", "PROBE"]

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
