"""Benchmark (not a test): the compiled optimiser's plans against scipy's L-BFGS-B.

Belief states of closed-loop NBO runs of the default config (every step of runs 1..R) for two
sensor models: the paper's and the limited-footprint variant ``footprint150`` of the decision
study. At each state both optimisers minimise the same cost (the hypotheses of NBO, or of
RS-MHP with N_T = 50, drawn once from the state's own stream) from the same warm start, with
the config's budgets. Printed per sensor model: the number of states; the paired difference
of final costs (compiled - scipy) as a distribution (lower / equal within 1e-9 relative /
higher, the worst case relative to the cost) and its mean with a 95% percentile-bootstrap
interval, whose upper limit the issue's rule compares with 0.1% of the mean cost; and the
mean seconds per planning step of each optimiser.

    .venv/bin/python benchmarks/optimiser_quality.py [--runs 4]
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from rsmhp.core.seeding import job_rng  # noqa: E402
from rsmhp.core.stats import bootstrap_ci  # noqa: E402
from rsmhp.models.uav import methods  # noqa: E402
from rsmhp.models.uav.planner import LBFGSB, Belief, BoxQN, PlanningProblem  # noqa: E402
from rsmhp.models.uav.sensor import SensorModel  # noqa: E402
from rsmhp.models.uav.simulation import UAVSetup, simulate_run  # noqa: E402


def _states(setup: UAVSetup, seed: int, runs: int) -> list:
    nbo = methods.from_config({"nbo": True})["nbo"]
    out = []
    for r in range(1, runs + 1):
        simulate_run(
            setup,
            nbo,
            seed,
            r,
            observer=lambda i, r=r: out.append(
                (r, i.step, i.uav.copy(), i.estimate.copy(), i.covariance.copy(), i.warm_start)
            ),
        )
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=4, help="closed-loop runs per sensor model")
    args = ap.parse_args()
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    base = UAVSetup.from_config(cfg["uav"])
    models_cfg = {m["name"]: m for m in cfg["uav_models"]}
    variant = {**cfg["uav"]["sensor"], **models_cfg["footprint150"]["sensor"]}
    models = {
        "paper": base,
        "footprint150": dataclasses.replace(
            base, sensor=SensorModel.from_config({**cfg["uav"], "sensor": variant})
        ),
    }
    planners = methods.from_config({"nbo": True, "rsmhp_nt": [50]})
    for label, setup in models.items():
        diffs, costs, secs = [], [], np.zeros(2)
        for r, k, uav, x_hat, P_hat, warm in _states(setup, cfg["seed"], args.runs):
            for name, method in planners.items():
                rng = job_rng(cfg["seed"], "optimiser_quality", run=r, step=k, method=name)
                hyp = method.hypotheses(Belief(uav, x_hat, P_hat), setup, rng)
                res = []
                for i, opt in enumerate((BoxQN(), LBFGSB())):
                    prob = PlanningProblem(
                        uav, P_hat, hyp.states[..., :2], setup.uav, setup.target,
                        setup.sensor, setup.planner, weights=hyp.weights,
                    )  # fmt: skip
                    t0 = time.perf_counter()
                    res.append(opt.minimise(prob, warm))
                    secs[i] += time.perf_counter() - t0
                diffs.append(res[0].cost - res[1].cost)
                costs.append(res[1].cost)
        d, c = np.array(diffs), np.array(costs)
        rel = d / c
        lo, hi = bootstrap_ci(d, np.random.default_rng(0), 10_000, 0.95)
        n = d.size
        print(
            f"{label}: {n} planning problems ({n // len(planners)} belief states x NBO, RS-MHP 50)"
        )
        print(
            f"  compiled - scipy: lower {(rel < -1e-9).sum()}, equal within 1e-9 relative "
            f"{(np.abs(rel) <= 1e-9).sum()}, higher {(rel > 1e-9).sum()}; worst {rel.max():+.3e} "
            f"relative, best {rel.min():+.3e}"
        )
        print(
            f"  mean difference {d.mean():+.4g} m^2, 95% bootstrap CI [{lo:+.4g}, {hi:+.4g}]; "
            f"rule: upper <= 0.1% of the mean cost {1e-3 * c.mean():.4g}: "
            f"{'holds' if hi <= 1e-3 * c.mean() else 'FAILS'}"
        )
        print(
            f"  seconds per planning step: compiled {secs[0] / n:.3g}, scipy {secs[1] / n:.3g} "
            f"({secs[1] / secs[0]:.1f}x)"
        )


if __name__ == "__main__":
    main()
