"""Benchmark (not a test): seconds per closed-loop UAV run, this checkout vs an earlier one.

Runs the same closed-loop runs (default config model, seed and methods) with this checkout's
``rsmhp`` and, if ``--baseline`` is given, with the ``rsmhp`` of another checkout (e.g. the
commit before the fused kernel: ``git worktree add /tmp/rsmhp-base 71055b3``). Every
measurement runs in a fresh subprocess with BLAS pinned to one thread, alternating between
the two checkouts method by method so that machine load affects both alike; the first run of
each subprocess is a warm-up (imports, compiled-kernel cache load) and is not timed.

    .venv/bin/python benchmarks/uav_closed_loop.py [--runs 3] [--baseline /tmp/rsmhp-base]

Prints per method: median seconds per run (wall time of ``simulate_run``) for each checkout
and the ratio.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

WORKER = r"""
import json, sys, time
import numpy as np
import yaml
from snakemake.utils import validate
from threadpoolctl import threadpool_limits
import rsmhp
from rsmhp.uav.simulation import UAVSetup, simulate_run
try:  # the method registry (this version); older checkouts (--baseline) had method_specs
    from rsmhp.uav import methods as _methods
    spec_of = lambda uav, name: _methods.from_config(uav["methods"])[name]
except ImportError:
    from rsmhp.uav.simulation import method_specs
    spec_of = lambda uav, name: method_specs(uav)[name]

root, method, runs = sys.argv[1], sys.argv[2], [int(r) for r in sys.argv[3].split(",")]
cfg = yaml.safe_load(open(f"{root}/config/config.yaml"))
validate(cfg, f"{root}/workflow/schemas/config.schema.yaml")
setup = UAVSetup.from_config(cfg["uav"])
spec = spec_of(cfg["uav"], method)
out = []
with threadpool_limits(limits=1):
    simulate_run(setup, spec, cfg["seed"], runs[0])  # warm-up, not timed
    for r in runs:
        t0 = time.perf_counter()
        summary, _ = simulate_run(setup, spec, cfg["seed"], r)
        out.append((time.perf_counter() - t0, summary["mean_error"]))
print(json.dumps({"module": rsmhp.__file__, "runs": out}))
"""


def _measure(root: Path, method: str, runs: list[int]) -> list[tuple[float, float]]:
    env = {**os.environ, "PYTHONPATH": str(root / "src"), "OPENBLAS_NUM_THREADS": "1"}
    env["OMP_NUM_THREADS"] = env["MKL_NUM_THREADS"] = "1"
    res = subprocess.run(
        [sys.executable, "-c", WORKER, str(root), method, ",".join(map(str, runs))],
        env=env,
        capture_output=True,
        text=True,
    )
    if res.returncode != 0:
        raise SystemExit(f"worker failed for {root} / {method}:\n{res.stderr}")
    data = json.loads(res.stdout.strip().splitlines()[-1])
    if not data["module"].startswith(str(root / "src")):
        raise SystemExit(f"{root}: imported rsmhp from {data['module']}, not from its src/")
    return data["runs"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3, help="timed runs per method (runs 1..n)")
    ap.add_argument("--baseline", type=Path, help="root of another checkout to compare with")
    ap.add_argument("--methods", nargs="*", help="default: every method of the default config")
    args = ap.parse_args()
    sys.path.insert(0, str(ROOT / "src"))
    import yaml

    from rsmhp.uav import methods as registry

    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    methods = args.methods or list(registry.from_config(cfg["uav"]["methods"]))
    runs = list(range(1, args.runs + 1))
    print(f"closed-loop runs {runs} of the default config, one thread, {os.cpu_count()} CPUs")
    header = f"{'method':14s} {'this (s/run)':>13s}"
    if args.baseline:
        header += f" {'baseline (s/run)':>17s} {'ratio':>7s}"
    print(header)
    for method in methods:
        ours = _measure(ROOT, method, runs)
        t_ours = sorted(t for t, _ in ours)[len(ours) // 2]
        line = f"{method:14s} {t_ours:13.3f}"
        if args.baseline:
            base = _measure(args.baseline.resolve(), method, runs)
            t_base = sorted(t for t, _ in base)[len(base) // 2]
            line += f" {t_base:17.3f} {t_base / t_ours:6.1f}x"
        print(line, flush=True)


if __name__ == "__main__":
    main()
