"""Benchmark (not a test): the planner's compiled kernels on this CPU and on an emulated AVX2
CPU without AVX-512, side by side, in one run.

Two CPU targets:

* ``native``: the environment as it is (numba compiles for LLVM's host CPU with the host's
  features; OpenBLAS and numpy pick their kernels for this machine);
* ``avx2``: :func:`rsmhp.report.portability.emulation.cpu_target_env`: numba compiles for
  ``--target-cpu`` (default ``znver3``, e.g. ``haswell``) with that CPU model's own features
  (``NUMBA_CPU_NAME``, and ``NUMBA_CPU_FEATURES`` empty: a CPU name alone keeps the host's
  AVX-512 features), OpenBLAS runs its ``--coretype`` kernels (default ``Haswell``) and numpy's
  AVX-512 dispatch targets are off (``NPY_DISABLE_CPU_FEATURES``, the names this numpy knows,
  :func:`rsmhp.report.portability.emulation.numpy_avx512_targets`).

Every measurement runs in a fresh subprocess with BLAS pinned to one thread, alternating
between the targets item by item (which target goes first alternates too) so that machine
load affects both alike. Each subprocess first warms up: the first calls compile the kernels
for its target, or load them from numba's cache, whose index keys entries on the CPU name and
features (native and emulated code sit side by side); the ``warm-up`` rows give those seconds
(with ``--cold``, an empty temporary cache, the first worker of each target compiles: the
per-target compile time). Each worker checks that its target took effect (numba's CPU and
features of every kernel it ran, OpenBLAS core type, numpy SIMD).

    .venv/bin/python benchmarks/cpu_targets.py [--target-cpu znver3] [--repeats 7] [--cold]
        [--json out.json]

A few minutes at most (about 20 s with both targets in the cache; a cold cache compiles the
kernels once per target, about a minute each).

Items:

* ``kernel``: ns per trajectory-step (one predict + update of one hypothesis for one control
  sequence) of :func:`rsmhp.models.uav.fused.evaluate`, value and value + gradient, H = 6,
  200 sequences per call, best of ``--repeats``; N_T = 250 (hypotheses vectorised) and
  N_T = 16 (below ``fused.SOA_MIN_HYPOTHESES``: one hypothesis at a time);
* ``minimise``: one :func:`rsmhp.models.uav.fused.minimise` call (a planning step of the
  compiled L-BFGS, ``uav.planner``'s maxiter / maxfun), N_T = 256, H = 6, best of
  ``--repeats``;
* ``loop``: one closed-loop run (:func:`rsmhp.models.uav.simulation.simulate_run`) of NBO and
  RS-MHP N_T = 256 on ``config/config.yaml``'s model, seconds per run and ms per planning step
  (the run's planner time / steps), median of runs 1..``--runs`` (after an untimed run 1).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TARGETS = ("native", "avx2")

WORKER = r"""
import json, sys, time
import numpy as np
import yaml
from threadpoolctl import threadpool_info, threadpool_limits
import rsmhp
from rsmhp.models.uav import fused
from rsmhp.models.uav.simulation import UAVSetup

root, item, arg, runs = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[5]
repeats = int(sys.argv[4])
cfg = yaml.safe_load(open(f"{root}/config/config.yaml"))
setup = UAVSetup.from_config(cfg["uav"])
H = 6
rng = np.random.default_rng(0)
state = np.array([0.0, 0.0, 20.0, 0.5])
P0 = np.diag([900.0, 900.0, 25.0, 25.0])


def frozen_of(n_t):
    txy = rng.uniform(-400, 400, (n_t, H, 2))
    return fused.Frozen(state, setup.uav, P0, txy, setup.target.dt, setup.target.Q, setup.sensor)


def best(fn):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


out = {}
with threadpool_limits(limits=1):
    if item == "kernel":
        T, C = int(arg), 200
        frozen = frozen_of(T)
        x = rng.uniform(-1, 1, (C, 2 * H))
        t0 = time.perf_counter()
        for grad in (False, True):
            fused.evaluate(x, frozen, want_grad=grad)
        warm = time.perf_counter() - t0
        for grad in (False, True):
            t = best(lambda: fused.evaluate(x, frozen, want_grad=grad))
            out["value+grad" if grad else "value"] = t / (C * T * H) * 1e9
    elif item == "minimise":
        frozen = frozen_of(int(arg))
        x0 = rng.uniform(-0.5, 0.5, 2 * H)
        p = setup.planner
        t0 = time.perf_counter()
        res = fused.minimise(x0, frozen, p.maxiter, p.maxfun)
        warm = time.perf_counter() - t0
        out["call"] = best(lambda: fused.minimise(x0, frozen, p.maxiter, p.maxfun))
        out["nit"], out["nfev"] = res[3], res[4]
    else:  # a closed-loop run of method `arg`
        from rsmhp.models.uav import methods
        from rsmhp.models.uav.simulation import simulate_run

        spec = methods.from_config({"nbo": True, "rsmhp_nt": [256]})[arg]
        r_list = [int(r) for r in runs.split(",")]
        t0 = time.perf_counter()
        simulate_run(setup, spec, cfg["seed"], r_list[0])  # warm-up, not timed
        warm = time.perf_counter() - t0
        res = []
        for r in r_list:
            t0 = time.perf_counter()
            summary, rows = simulate_run(setup, spec, cfg["seed"], r)
            res.append((time.perf_counter() - t0, summary["plan_seconds"] / len(rows)))
        out["run"] = sorted(r[0] for r in res)[len(res) // 2]
        out["step"] = sorted(r[1] for r in res)[len(res) // 2]

from numba.core import config
from numba.core.dispatcher import Dispatcher
from numba.core.registry import cpu_target

targets, compiled, loaded = set(), 0, 0
for name, mod in list(sys.modules.items()):
    if not name.startswith("rsmhp") or mod is None:
        continue
    for obj in list(vars(mod).values()):
        if isinstance(obj, Dispatcher) and obj.overloads:
            for res in obj.overloads.values():
                _, cpu, features = res.library.codegen.magic_tuple()
                targets.add((str(cpu), str(features)))
            compiled += int(sum(obj.stats.cache_misses.values()))
            loaded += int(sum(obj.stats.cache_hits.values()))
try:
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__
except ImportError:
    from numpy.core._multiarray_umath import __cpu_dispatch__, __cpu_features__
facts = {
    "numba_cpu_name": config.CPU_NAME,
    "codegen": list(map(str, cpu_target.target_context.codegen().magic_tuple()[1:])),
    "kernel_targets": sorted(map(list, targets)),
    "compiled": compiled,
    "loaded": loaded,
    "openblas": sorted({str(i.get("architecture")) for i in threadpool_info()
                        if i.get("user_api") == "blas"}),
    "numpy_simd": [f for f in __cpu_dispatch__ if __cpu_features__.get(f)],
}
print(json.dumps({"module": rsmhp.__file__, "warmup": warm, "out": out, "facts": facts}))
"""


def _envs(cpu: str, coretype: str, cache_dir: str | None) -> dict[str, dict[str, str]]:
    """The subprocess environment of each target (BLAS and OpenMP pinned to one thread; numba's
    cache in ``cache_dir`` if given)."""
    from rsmhp.report.portability.emulation import cpu_target_env, numpy_avx512_targets

    base = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    if cache_dir:
        base["NUMBA_CACHE_DIR"] = cache_dir
    base["OPENBLAS_NUM_THREADS"] = base["OMP_NUM_THREADS"] = base["MKL_NUM_THREADS"] = "1"
    for var in ("NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES", "OPENBLAS_CORETYPE"):
        base.pop(var, None)
    base.pop("NPY_DISABLE_CPU_FEATURES", None)
    return {"native": base, "avx2": cpu_target_env(base, cpu, coretype, numpy_avx512_targets())}


def _check(target: str, facts: dict, cpu: str, coretype: str, host: str) -> None:
    """Exit when the target did not take effect in the worker."""
    problems = []
    kernel_cpus = sorted({c for c, _ in facts["kernel_targets"]})
    if target == "avx2":
        if facts["kernel_targets"] != [[cpu, ""]]:
            problems.append(f"kernels built for {facts['kernel_targets']}, not [{cpu!r}, '']")
        if facts["openblas"] != [coretype]:
            problems.append(f"OpenBLAS core types {facts['openblas']}, not [{coretype!r}]")
        simd = [f for f in facts["numpy_simd"] if f == "X86_V4" or f.startswith("AVX512")]
        if simd:
            problems.append(f"numpy AVX-512 dispatch still active: {simd}")
    elif kernel_cpus != [host]:
        problems.append(f"native kernels built for {kernel_cpus}, not the host's {host!r}")
    if problems:
        raise SystemExit(f"{target}: the target did not take effect: {'; '.join(problems)}")


def _run(env: dict[str, str], *args: str) -> dict:
    res = subprocess.run(
        [sys.executable, "-c", WORKER, str(ROOT), *args], env=env, capture_output=True, text=True
    )
    if res.returncode != 0:
        raise SystemExit(f"worker failed for {args}:\n{res.stderr[-3000:]}")
    data = json.loads(res.stdout.strip().splitlines()[-1])
    if not data["module"].startswith(str(ROOT / "src")):
        raise SystemExit(f"imported rsmhp from {data['module']}, not from {ROOT / 'src'}")
    return data


def _machine(host: str, avx512: bool) -> str:
    import llvmlite
    import numba
    import numpy as np

    model = platform.processor() or "?"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return (
        f"CPU {model!r}, {os.cpu_count()} CPUs; LLVM host CPU {host} "
        f"(avx512f {'yes' if avx512 else 'no'}); numba {numba.__version__}, "
        f"llvmlite {llvmlite.__version__}, numpy {np.__version__}, "
        f"Python {platform.python_version()}"
    )


def _describe(facts: dict) -> str:
    """numba's target, OpenBLAS core types and numpy's SIMD dispatch of a worker."""
    cpu, features = facts["codegen"]
    if not features:
        numba = f"{cpu} with the CPU model's own features"
    else:
        on = "+avx512f" in features.split(",")
        numba = f"{cpu} with the host's features (avx512f {'on' if on else 'off'})"
    simd = " ".join(facts["numpy_simd"]) or "(none)"
    return f"numba {numba}; OpenBLAS {', '.join(facts['openblas'])}; numpy dispatch {simd}"


def _rows(label: str, item: str, arg: str, data: dict[str, dict]) -> list[dict]:
    """The table rows of one item measured on both targets."""
    out = {t: d["out"] for t, d in data.items()}
    rows = []

    def row(name: str, unit: str, key: str, scale: float, fmt: str, note: str = "") -> None:
        vals = {t: o[key] * scale for t, o in out.items()}
        rows.append({"item": name, "unit": unit, **vals, "fmt": fmt, "note": note})

    if item == "kernel":
        for k in ("value", "value+grad"):
            row(f"{label} {k}", "ns/t-s", k, 1.0, ".2f")
    elif item == "minimise":
        its = ", ".join(f"{t} {o['nit']}/{o['nfev']}" for t, o in out.items())
        row(f"{label} per call", "ms", "call", 1e3, ".3f", f"iterations/evaluations: {its}")
    else:
        row(f"{label}", "s", "run", 1.0, ".4f")
        row(f"{label}: planning step", "ms", "step", 1e3, ".3f")
    rows.append(
        {
            "item": f"  warm-up ({item} {arg})",
            "unit": "s",
            **{t: d["warmup"] for t, d in data.items()},
            "fmt": ".2f",
            "note": ", ".join(
                f"{t}: {data[t]['facts']['compiled']} compiled, {data[t]['facts']['loaded']} loaded"
                for t in TARGETS
            ),
        }
    )
    for r in rows:
        r["ratio"] = r["avx2"] / r["native"] if r["native"] else float("nan")
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--target-cpu", default="znver3", help="LLVM CPU model of the avx2 target")
    ap.add_argument("--coretype", default="Haswell", help="OpenBLAS core type of the avx2 target")
    ap.add_argument("--repeats", type=int, default=7, help="timed calls per kernel item (best)")
    ap.add_argument("--runs", type=int, default=3, help="timed closed-loop runs (median)")
    ap.add_argument("--items", nargs="*", default=["kernel", "minimise", "loop"])
    ap.add_argument(
        "--cold", action="store_true", help="an empty numba cache: warm-up = compile time"
    )
    ap.add_argument("--json", type=Path, help="also write the numbers here")
    args = ap.parse_args()
    sys.path.insert(0, str(ROOT / "src"))
    with tempfile.TemporaryDirectory(prefix="rsmhp-cpu-targets-") as tmp:
        _measure(args, tmp if args.cold else None)


def _measure(args: argparse.Namespace, cache_dir: str | None) -> None:
    import llvmlite.binding as ll

    host = ll.get_host_cpu_name()
    avx512 = bool(ll.get_host_cpu_features().get("avx512f"))
    envs = _envs(args.target_cpu, args.coretype, cache_dir)
    env_vars = ("NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES", "OPENBLAS_CORETYPE")
    env_vars += ("NPY_DISABLE_CPU_FEATURES",)
    avx2_env = {k: envs["avx2"].get(k) for k in env_vars}
    machine = _machine(host, avx512)
    print(machine)
    print("avx2 target: " + " ".join(f"{k}={v!r}" for k, v in avx2_env.items()))
    print(f"numba cache: {cache_dir or 'the default (warm if used before)'}", flush=True)

    runs = ",".join(str(r) for r in range(1, args.runs + 1))
    jobs: list[tuple[str, str, str]] = []  # (label, item, argument)
    if "kernel" in args.items:
        jobs += [("kernel N_T=250", "kernel", "250"), ("kernel N_T=16", "kernel", "16")]
    if "minimise" in args.items:
        jobs.append(("minimise N_T=256", "minimise", "256"))
    if "loop" in args.items:
        jobs += [("NBO run", "loop", "nbo"), ("RS-MHP N_T=256 run", "loop", "rsmhp_nt256")]

    head = f"{'item [unit]':38s} {'native':>9s} {'avx2':>9s} {'avx2/native':>11s}"
    print(f"\n{head}\n{'-' * len(head)}", flush=True)
    rows: list[dict] = []
    facts: dict[str, dict] = {}
    t_start = time.perf_counter()
    for i, (label, item, arg) in enumerate(jobs):
        data = {}
        for target in TARGETS if i % 2 == 0 else TARGETS[::-1]:  # who goes first alternates
            d = _run(envs[target], item, arg, str(args.repeats), runs)
            _check(target, d["facts"], args.target_cpu, args.coretype, host)
            data[target] = d
            facts.setdefault(target, d["facts"])
        for r in _rows(label, item, arg, data):
            f = r["fmt"]
            name = f"{r['item']} [{r['unit']}]"
            print(
                f"{name:38s} {r['native']:>9{f}} {r['avx2']:>9{f}} {r['ratio']:>10.2f}x"
                + (f"  {r['note']}" if r["note"] else ""),
                flush=True,
            )
            rows.append(r)
    print(f"\n(measured in {time.perf_counter() - t_start:.0f} s)")
    for target, f in facts.items():
        print(f"{target}: {_describe(f)}")
    if args.json:
        doc = {
            "machine": machine,
            "host_cpu": host,
            "host_avx512f": avx512,
            "target_cpu": args.target_cpu,
            "coretype": args.coretype,
            "cold_cache": bool(cache_dir),
            "avx2_env": avx2_env,
            "rows": [{k: v for k, v in r.items() if k != "fmt"} for r in rows],
            "facts": facts,
        }
        args.json.write_text(json.dumps(doc, indent=2) + "\n")
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
