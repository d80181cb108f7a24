"""Memory estimates of the simulation rules: an upper bound of the measured peak of numpy
allocations (tracemalloc), not an absurd one, and a config beyond a rule's mem_mb refused."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
import yaml

from rsmhp.models.lqg import ablation as estimators
from rsmhp.models.lqg import oven as lqg
from rsmhp.models.lqg import regret as decisions_lqg
from rsmhp.pipeline.config import CONFIG_PATH
from rsmhp.pipeline.resources import FIXED_BYTES, estimate_mb, memory_problems, working_set_bytes
from rsmhp.studies.lqg.simulate import estimate_row

MODEL = {"x0": 0.0, "a": 0.5, "r": 10.0, "target": 1.0, "sigma": 1.0}


def _peak(fn) -> int:
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@pytest.mark.parametrize(("P", "H"), [(20000, 2), (20000, 10), (5000, 40)])
def test_lqg_estimate_bounds_the_measured_peak(P, H):
    model = lqg.LQGModel(**MODEL)
    peak = _peak(lambda: estimate_row(1, "mem", model, np.full(H, 0.3), P, 0))
    bound = working_set_bytes(P, H)
    assert peak <= bound <= 3 * peak + FIXED_BYTES


@pytest.mark.parametrize("H", [2, 6])
def test_decision_cell_estimate_bounds_the_measured_peak(H):
    cell = decisions_lqg.DrawCell("mc", P=20000, H=(H,))
    model = {k: MODEL[k] for k in ("x0", "r", "target", "sigma")}
    peak = _peak(lambda: decisions_lqg.cell_rows(cell, [0.3, 0.5, 0.7], model, 1, 1))
    assert peak <= working_set_bytes(cell.P, H) <= 3 * peak + FIXED_BYTES


NCV = {
    "kind": "ncv_2d", "dt": 1.0, "q": 0.5, "w_pos": 1.0, "w_vel": 0.1, "r_u": 0.1,
    "f_pos": 2.0, "f_vel": 0.2, "target": [1.0, 0.0, 0.0, 0.0], "x0": [0.0] * 4,
    "u": [[0.1, 0.0]] * 4,
}  # fmt: skip


@pytest.mark.parametrize(
    ("spec", "point"),
    [
        ({"kind": "scalar_lqg", "u": [0.5, 0.2, 0.1]}, estimators.GridPoint("p", "mc", n=16384)),
        ({"kind": "scalar_lqg", "u": [0.5, 0.2]}, estimators.GridPoint("p", "sobol", n=16384)),
        (NCV, estimators.GridPoint("p", "mc", n=8192)),
        (NCV, estimators.GridPoint("p", "antithetic", n=8192)),
        (NCV, estimators.GridPoint("p", "tree", N=9)),
        (NCV, estimators.GridPoint("p", "pruned", N=50, M=50)),
    ],
)
def test_ablation_estimate_bounds_the_measured_peak(spec, point):
    prob = estimators.build_problem(spec, MODEL)
    leaves = estimators.n_trajectories(point, prob)
    P = point.M * point.N if point.scheme == "pruned" else leaves
    peak = _peak(lambda: list(estimators.ablation_rows(point, prob, spec, 1, 1)))
    assert peak <= working_set_bytes(P, prob.H, prob.d) <= 4 * peak + FIXED_BYTES


def test_the_issue_example_is_refused_naming_the_keys():
    cfg = yaml.safe_load(CONFIG_PATH.read_text())
    declared = {"lqg_nbo_error": 2000, "lqg_convergence": 2000, "estimators_ablation": 3000}
    assert memory_problems(cfg, declared) == []  # the full replication fits
    cfg["lqg"]["nbo_error"].update(P=10_000_000, H_values=[200])
    cfg["threads"] = 2  # the estimate is per worker (an upper bound for a one-thread rule)
    (msg,) = memory_problems(cfg, declared)
    assert msg.startswith("lqg_nbo_error: needs about ")
    assert "mem_mb = 2000" in msg and "lqg.nbo_error.P, lqg.nbo_error.H_values" in msg
    # 2 workers x 8 B x 1e7 x (200 x 7 + 8) = 2.25e11 B
    need = int(msg.split("about ")[1].split(" MB")[0])
    assert need == int(300 + 2 * (200 + (8 * 10_000_000 * (200 * 7 + 8) + 2**24) / 2**20))


def test_estimates_grow_with_the_worker_count():
    cfg = yaml.safe_load(CONFIG_PATH.read_text())
    one = estimate_mb({**cfg, "threads": 1})
    two = estimate_mb({**cfg, "threads": 2})
    assert all(two[r][0] > one[r][0] for r in one)
