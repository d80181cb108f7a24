"""Benchmark (not a test): the planner's cost kernels side by side, in one run, one thread.

One planning step's workload: N_T target hypotheses x H steps for one control sequence,
R evaluated from the geometry inside every kernel. Three implementations:

* ``fused``: the compiled kernel (:mod:`rsmhp.models.uav.fused`), value, or value + exact gradient
  (adjoint) in one pass;
* ``numpy``: the vectorised numpy kernel (:mod:`rsmhp.models.uav.kernel`), the test oracle; before
the
  fused kernel the planner got its gradient from it as a batch of 2H + 1 = 13 candidates
  (base point and forward differences);
* ``filterpy``: a per-trajectory loop of filterpy predict / update calls.

Prints (a) ns per trajectory-step (one predict + update of one hypothesis for one sequence)
for the value and for value + gradient; (b) value + gradient as a multiple of one fused value
evaluation and the speed-up over the 13-candidate numpy forward-difference batch; (d) the
fused kernel's first-call time in a fresh process, compiling (empty cache) and loading from
the cache. All ratios are measured in this run, on this machine.

    .venv/bin/python benchmarks/uav_kernel.py [--nt 250] [--horizon 6] [--repeats 200]
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from threadpoolctl import threadpool_limits

from rsmhp.models.uav import fused, kinematics, sensor
from rsmhp.models.uav.kernel import objective
from rsmhp.models.uav.kinematics import UAVParams
from rsmhp.models.uav.sensor import SensorModel
from rsmhp.models.uav.target import TargetModel
from rsmhp.models.uav.tracker import Tracker

FIRST_CALL = """
import time
t0 = time.perf_counter()
from rsmhp.models.uav import fused
t1 = time.perf_counter()
fused.warm_up()
t2 = time.perf_counter()
print(t1 - t0, t2 - t1)
"""


def _best(fn, repeats: int) -> float:
    """Median seconds per call over ``repeats`` calls (after one warm-up call)."""
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def _first_call(cache_dir: str) -> tuple[float, float]:
    env = {**os.environ, "NUMBA_CACHE_DIR": cache_dir}
    out = subprocess.run(
        [sys.executable, "-c", FIRST_CALL], env=env, capture_output=True, text=True, check=True
    )
    t_import, t_first = (float(v) for v in out.stdout.split())
    return t_import, t_first


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nt", type=int, default=250)
    ap.add_argument("--horizon", type=int, default=6)
    ap.add_argument("--repeats", type=int, default=200)
    args = ap.parse_args()
    H, T = args.horizon, args.nt
    rng = np.random.default_rng(0)
    uav = UAVParams(1.0, 9.81, 3.0, math.pi / 4, 10.0, 35.0, 100.0)
    model, sens = TargetModel(1.0, 1.0), SensorModel(0.05, 0.10, 100.0)
    P0 = np.diag([2500.0, 2500.0, 25.0, 25.0])
    state = np.array([0.0, 0.0, 20.0, 0.3])
    x = rng.uniform(-0.9, 0.9, 2 * H)
    tgt_xy = rng.uniform(-600, 600, (T, H, 2))
    scale = np.tile(uav.control_scale, H)
    n = T * H  # trajectory-steps of one sequence

    frozen = fused.Frozen(state, uav, P0, tgt_xy, model.dt, model.Q, sens)
    x1 = x[None]

    def numpy_value(xs: np.ndarray) -> np.ndarray:
        states = kinematics.rollout(state, (xs * scale).reshape(len(xs), H, 2), uav)
        return objective(P0, states[..., :2], tgt_xy, model.dt, model.Q, sens)

    fd_batch = np.vstack([x1, x1 + np.diag(np.full(2 * H, 1e-4))])  # 13 candidates for H = 6

    def filterpy_value(xs: np.ndarray) -> np.ndarray:
        states = kinematics.rollout(state, (xs * scale).reshape(len(xs), H, 2), uav)
        out = np.zeros(len(xs))
        for c in range(len(xs)):
            for i in range(T):
                trk = Tracker(np.zeros(4), P0, model)
                for j in range(H):
                    trk.predict()
                    R = sensor.measurement_cov(states[c, j, :2], tgt_xy[i, j], sens)
                    trk.update(np.zeros(2), R)
                    out[c] += np.trace(trk.kf.P)
        return out / T

    with threadpool_limits(limits=1):
        fused.warm_up()
        t_fv = _best(lambda: fused.evaluate(x1, frozen, want_grad=False), args.repeats)
        t_fg = _best(lambda: fused.evaluate(x1, frozen, want_grad=True), args.repeats)
        t_nv = _best(lambda: numpy_value(x1), max(args.repeats // 4, 5))
        t_nfd = _best(lambda: numpy_value(fd_batch), max(args.repeats // 10, 5))
        t_pv = _best(lambda: filterpy_value(x1), 2)
        t_pfd = t_pv * len(fd_batch)  # the loop is linear in the candidates (not re-timed)
        v_fused = fused.evaluate(x1, frozen, want_grad=False)[0][0]
        v_numpy = numpy_value(x1)[0]
        v_filterpy = filterpy_value(x1)[0]
    with tempfile.TemporaryDirectory() as cache:
        imp_cold, t_compile = _first_call(cache)
        imp_warm, t_load = _first_call(cache)

    per = lambda t: t / n * 1e9  # noqa: E731
    print(
        f"workload: one control sequence, N_T={T} hypotheses x H={H} steps = {n} trajectory-steps"
    )
    print(f"one thread; medians of repeated calls; {sys.platform}, {os.cpu_count()} CPUs")
    print("(a) ns per trajectory-step")
    print(f"    {'':10s} {'value':>10s} {'value+gradient':>16s}  (gradient by)")
    print(f"    {'fused':10s} {per(t_fv):10.1f} {per(t_fg):16.1f}  (adjoint, exact)")
    print(f"    {'numpy':10s} {per(t_nv):10.1f} {per(t_nfd):16.1f}  (13-candidate fwd differences)")
    print(f"    {'filterpy':10s} {per(t_pv):10.1f} {per(t_pfd):16.1f}  (13 x the value loop)")
    print(f"    value ratio numpy/fused {t_nv / t_fv:.1f}x, filterpy/fused {t_pv / t_fv:.0f}x")
    print(f"    (the 13-candidate batch is {per(t_nfd) / 13:.1f} ns per candidate trajectory-step)")
    print("(b) value + gradient")
    print(f"    fused value+gradient = {t_fg / t_fv:.2f} x one fused value evaluation")
    print(
        f"    13-candidate numpy forward-difference batch / fused value+gradient = "
        f"{t_nfd / t_fg:.1f}x  ({t_nfd * 1e6:.0f} us vs {t_fg * 1e6:.0f} us)"
    )
    print("(d) first call of the fused kernels in a fresh process (import numba+rsmhp, then call)")
    print(f"    empty cache (compile): import {imp_cold:.2f} s + first call {t_compile:.2f} s")
    print(f"    warm cache (load)    : import {imp_warm:.2f} s + first call {t_load:.2f} s")
    rel = max(abs(v_numpy - v_fused) / v_numpy, abs(v_filterpy - v_fused) / v_filterpy)
    print(
        f"check: value fused {v_fused:.6f}, numpy {v_numpy:.6f}, filterpy {v_filterpy:.6f}; "
        f"max relative difference {rel:.1e}"
    )


if __name__ == "__main__":
    main()
