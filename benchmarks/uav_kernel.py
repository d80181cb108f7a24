"""Benchmark (not a test): the batched covariance kernel vs a per-trajectory filterpy loop.

Same inputs for both: one planning step's workload, C = 2H + 1 candidate control sequences
(the batched forward-difference gradient) x N_T target hypotheses x H steps, R evaluated from
the geometry inside both. Prints time per trajectory-step (one predict + update of one
(candidate, hypothesis) pair) and the ratio, and checks the two agree.

    .venv/bin/python benchmarks/uav_kernel.py [--nt 250] [--horizon 6] [--repeats 50]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from threadpoolctl import threadpool_limits

from rsmhp.uav import sensor
from rsmhp.uav.kernel import covariance_traces
from rsmhp.uav.sensor import SensorModel
from rsmhp.uav.target import TargetModel
from rsmhp.uav.tracker import Tracker


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nt", type=int, default=250)
    ap.add_argument("--horizon", type=int, default=6)
    ap.add_argument("--repeats", type=int, default=50)
    args = ap.parse_args()
    H, T = args.horizon, args.nt
    C = 2 * H + 1
    rng = np.random.default_rng(0)
    model, sens = TargetModel(1.0, 1.0), SensorModel(0.05, 0.10, 100.0)
    P0 = np.diag([2500.0, 2500.0, 25.0, 25.0])
    uav_xy = rng.uniform(-600, 600, (C, H, 2))
    tgt_xy = rng.uniform(-600, 600, (T, H, 2))
    n = C * T * H
    with threadpool_limits(limits=1):
        covariance_traces(P0, uav_xy, tgt_xy, 1.0, model.Q, sens)  # warm-up
        t0 = time.perf_counter()
        for _ in range(args.repeats):
            traces = covariance_traces(P0, uav_xy, tgt_xy, 1.0, model.Q, sens)
        t_kernel = (time.perf_counter() - t0) / args.repeats
        ref = np.empty_like(traces)
        t0 = time.perf_counter()
        for c in range(C):
            for i in range(T):
                trk = Tracker(np.zeros(4), P0, model)
                for j in range(H):
                    trk.predict()
                    trk.update(
                        np.zeros(2), sensor.measurement_cov(uav_xy[c, j], tgt_xy[i, j], sens)
                    )
                    ref[c, i, j] = np.trace(trk.kf.P)
        t_loop = time.perf_counter() - t0
    rel = float(np.max(np.abs(traces - ref) / np.abs(ref)))
    print(f"workload: C={C} candidates x N_T={T} hypotheses x H={H} steps = {n} trajectory-steps")
    print(
        f"kernel : {t_kernel * 1e3:9.3f} ms per call, {t_kernel / n * 1e6:8.4f} us/trajectory-step"
    )
    print(f"filterpy: {t_loop * 1e3:9.1f} ms per call, {t_loop / n * 1e6:8.4f} us/trajectory-step")
    print(f"ratio (filterpy / kernel): {t_loop / t_kernel:.0f}x; max relative trace diff {rel:.1e}")


if __name__ == "__main__":
    main()
