"""Benchmark (not a test): this checkout against another one, side by side, in one run.

Every measurement runs in a fresh subprocess with that checkout's ``src`` on the path and BLAS
pinned to one thread, alternating between the checkouts item by item so that machine load
affects both alike; each subprocess warms up (imports, compiled-kernel cache) before timing.

    .venv/bin/python benchmarks/speed.py --baseline /tmp/rsmhp-d90d881 [--parts kernel loop rules]

(``git worktree add /tmp/rsmhp-d90d881 d90d881`` gives the reference checkout of issue 20.)

Parts:

* ``kernel``: ns per trajectory-step (one predict + update of one hypothesis for one control
  sequence) of the planner's compiled cost, value and value + gradient, N_T = 250, H = 6,
  200 sequences per call (best of 7 repeats);
* ``loop``: per default method of ``config/config.yaml``, seconds per closed-loop run (wall
  time of ``simulate_run``, median of runs 1..3) and per planning step (the run's planner
  time / steps);
* ``rules``: wall time of the two slowest simulation rules' work with the full config:
  ``decisions_lqg`` and one UAV decision-map cell (1 thread each, as the rules declare).

The full replication's wall time is measured with ``make replicate`` (``time``), see the
README; it is not repeated here because one run of the reference takes 15 minutes.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

COMMON = r"""
import json, sys, time
import numpy as np
import yaml
from snakemake.utils import validate
from threadpoolctl import threadpool_limits
import rsmhp
root = sys.argv[1]
cfg = yaml.safe_load(open(f"{root}/config/config.yaml"))
validate(cfg, f"{root}/workflow/schemas/config.schema.yaml")
"""

KERNEL = (
    COMMON
    + r"""
from rsmhp.models.uav import fused
from rsmhp.models.uav.simulation import UAVSetup
setup = UAVSetup.from_config(cfg["uav"])
T, H, C = 250, 6, 200
rng = np.random.default_rng(0)
state = np.array([0.0, 0.0, 20.0, 0.5])
txy = rng.uniform(-400, 400, (T, H, 2))
P0 = np.diag([900.0, 900.0, 25.0, 25.0])
frozen = fused.Frozen(state, setup.uav, P0, txy, setup.target.dt, setup.target.Q, setup.sensor)
x = rng.uniform(-1, 1, (C, 2 * H))
out = {}
with threadpool_limits(limits=1):
    for grad in (False, True):
        fused.evaluate(x, frozen, want_grad=grad)
        best = np.inf
        for _ in range(7):
            t0 = time.perf_counter()
            fused.evaluate(x, frozen, want_grad=grad)
            best = min(best, time.perf_counter() - t0)
        out["value+grad" if grad else "value"] = best / (C * T * H) * 1e9
print(json.dumps({"module": rsmhp.__file__, "out": out}))
"""
)

LOOP = (
    COMMON
    + r"""
from rsmhp.models.uav.simulation import UAVSetup, simulate_run
try:  # the method registry; older checkouts had method_specs
    from rsmhp.models.uav import methods as _methods
    spec = _methods.from_config(cfg["uav"]["methods"])[sys.argv[2]]
except ImportError:
    from rsmhp.models.uav.simulation import method_specs
    spec = method_specs(cfg["uav"])[sys.argv[2]]
setup = UAVSetup.from_config(cfg["uav"])
runs = [int(r) for r in sys.argv[3].split(",")]
res = []
with threadpool_limits(limits=1):
    simulate_run(setup, spec, cfg["seed"], runs[0])  # warm-up, not timed
    for r in runs:
        t0 = time.perf_counter()
        summary, rows = simulate_run(setup, spec, cfg["seed"], r)
        res.append((time.perf_counter() - t0, summary["plan_seconds"] / len(rows)))
print(json.dumps({"module": rsmhp.__file__, "out": res}))
"""
)

RULES = (
    COMMON
    + r"""
part = sys.argv[2]
if part == "decisions_lqg":
    from rsmhp.models.lqg.regret import run_lqg_regret
    small = dict(cfg["decisions"]["lqg"], replicates=2)
    run_lqg_regret(small, cfg["lqg"]["model"], cfg["seed"], n_jobs=1)  # warm-up
    t0 = time.perf_counter()
    run_lqg_regret(cfg["decisions"]["lqg"], cfg["lqg"]["model"], cfg["seed"], n_jobs=1)
    out = time.perf_counter() - t0
else:
    from rsmhp.models.uav.scoring import run_map_cell
    from rsmhp.studies.uav.simulate import UAV_MODEL_KEYS
    dec = cfg["decisions"]
    keys = ("rows", "cols", "runs", "methods", "regret_runs", "regret_steps", "track_loss_error")
    mcfg = {k: dec["map"][k] for k in keys if k in dec["map"]}
    skeys = ("n_eval", "polish", "random_starts", "eval_maxiter", "n_random")
    scoring = {k: dec["uav"][k] for k in skeys}
    uav = {k: cfg["uav"][k] for k in UAV_MODEL_KEYS}
    warm = dict(mcfg, runs=1, regret_runs=1, regret_steps=[0])
    run_map_cell(uav, warm, scoring, part, cfg["seed"], 1)  # warm-up
    t0 = time.perf_counter()
    run_map_cell(uav, mcfg, scoring, part, cfg["seed"], 1)
    out = time.perf_counter() - t0
print(json.dumps({"module": rsmhp.__file__, "out": out}))
"""
)


def _run(root: Path, code: str, *args: str) -> object:
    env = {**os.environ, "PYTHONPATH": str(root / "src"), "OPENBLAS_NUM_THREADS": "1"}
    env["OMP_NUM_THREADS"] = env["MKL_NUM_THREADS"] = "1"
    res = subprocess.run(
        [sys.executable, "-c", code, str(root), *args], env=env, capture_output=True, text=True
    )
    if res.returncode != 0:
        raise SystemExit(f"worker failed for {root} {args}:\n{res.stderr[-3000:]}")
    data = json.loads(res.stdout.strip().splitlines()[-1])
    if not data["module"].startswith(str(root / "src")):
        raise SystemExit(f"{root}: imported rsmhp from {data['module']}, not from its src/")
    return data["out"]


def _pair(baseline: Path | None, code: str, *args: str) -> tuple[object, object | None]:
    ours = _run(ROOT, code, *args)
    base = _run(baseline.resolve(), code, *args) if baseline else None
    return ours, base


def _line(label: str, ours: float, base: float | None, unit: str, fmt: str = "{:.4g}") -> str:
    s = f"{label:28s} {fmt.format(ours):>12s} {unit:8s}"
    if base is not None:
        s += f" {fmt.format(base):>12s} {unit:8s} {base / ours:7.1f}x"
    return s


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", type=Path, help="root of the checkout to compare with")
    ap.add_argument("--parts", nargs="*", default=["kernel", "loop", "rules"])
    ap.add_argument("--runs", type=int, default=3, help="timed closed-loop runs per method")
    ap.add_argument("--methods", nargs="*", help="default: every method of the default config")
    ap.add_argument("--cell", default="r1c1", help="the decision-map cell of the rules part")
    ap.add_argument(
        "--rules", nargs="*", default=["decisions_lqg", "cell"], help="rules part: which rules"
    )
    args = ap.parse_args()
    sys.path.insert(0, str(ROOT / "src"))
    import yaml

    from rsmhp.models.uav import methods as registry

    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    head = f"{'':28s} {'this':>12s} {'':8s}"
    if args.baseline:
        head += f" {'baseline':>12s} {'':8s} {'ratio':>8s}"
    print(f"{os.cpu_count()} CPUs; baseline: {args.baseline}\n{head}", flush=True)
    if "kernel" in args.parts:
        ours, base = _pair(args.baseline, KERNEL)
        for k in ("value", "value+grad"):
            print(_line(f"kernel {k}", ours[k], base and base[k], "ns/t-s", "{:.2f}"), flush=True)
    if "loop" in args.parts:
        runs = ",".join(str(r) for r in range(1, args.runs + 1))
        methods = args.methods or list(registry.from_config(cfg["uav"]["methods"]))
        for m in methods:
            ours, base = _pair(args.baseline, LOOP, m, runs)
            med = lambda res, i: sorted(r[i] for r in res)[len(res) // 2]  # noqa: E731
            print(_line(f"{m} run", med(ours, 0), base and med(base, 0), "s"), flush=True)
            print(
                _line(f"{m} planning step", med(ours, 1) * 1e3, base and med(base, 1) * 1e3, "ms"),
                flush=True,
            )
    if "rules" in args.parts:
        parts = [p for p in ("decisions_lqg", "cell") if p in args.rules]
        for part in (args.cell if p == "cell" else p for p in parts):
            ours, base = _pair(args.baseline, RULES, part)
            label = "decisions_lqg (1 worker)" if part == "decisions_lqg" else f"map cell {part}"
            print(_line(label, ours, base, "s", "{:.1f}"), flush=True)


if __name__ == "__main__":
    main()
