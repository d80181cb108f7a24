"""The compiled closed loop (rsmhp.models.uav.loop) against the Python loop, its oracle: every
step row of every built-in family bit for bit (float hex of every column), on the paper's
model, both footprint detection models, with restarts, several runs; and which loop a run takes."""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import pytest
import yaml

from rsmhp.models.uav import loop
from rsmhp.models.uav import methods as registry
from rsmhp.models.uav.methods.nbo import NBO
from rsmhp.models.uav.simulation import UAVSetup, simulate_run
from rsmhp.testing import check_method

ROOT = Path(__file__).resolve().parents[3]
DEFAULT_UAV = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["uav"]

#: one member of every built-in family with a compiled loop (small sizes: the same code paths)
COMPILED = ["nbo", "rsmhp_nt16", "rsmhp_nt2h", "rqmc_nt16", "antithetic_nt16", "sigma",
            "tree_n4_m20"]  # fmt: skip


def _setup(**sensor) -> UAVSetup:
    cfg = copy.deepcopy(DEFAULT_UAV)
    restarts = sensor.pop("restarts", 0)
    cfg["sensor"].update(sensor)
    cfg["planner"]["restarts"] = restarts
    return UAVSetup.from_config(cfg)


SETUPS = {
    "paper": {},
    "footprint150_hard": {"footprint_radius": 150.0},
    "footprint150_logistic": {"footprint_radius": 150.0, "detection": "logistic"},
    "paper_restarts2": {"restarts": 2},
}


def _hex_rows(rows: list[dict]) -> list[dict]:
    return [{k: (v.hex() if isinstance(v, float) else (type(v).__name__, v)) for k, v in r.items()}
            for r in rows]  # fmt: skip


def _untimed(summary: dict) -> dict:
    out = {k: v for k, v in summary.items() if k != "plan_seconds"}
    out["diagnostics"] = {k: v.hex() for k, v in out["diagnostics"].items()}
    return {k: (v.hex() if isinstance(v, float) else v) for k, v in out.items()}


@pytest.mark.parametrize("setup_name", list(SETUPS))
@pytest.mark.parametrize("name", COMPILED)
def test_compiled_rows_are_the_python_loops_bit_for_bit(name: str, setup_name: str) -> None:
    setup = _setup(**SETUPS[setup_name])
    method = registry.from_name(name)
    assert loop.path(method, setup)[0] == "compiled"
    for run in (0, 3, 8):
        py_sum, py_rows = simulate_run(setup, method, 2024, run, path="python")
        c_sum, c_rows = simulate_run(setup, method, 2024, run, path="compiled")
        assert len(c_rows) == setup.steps == 60
        assert _hex_rows(c_rows) == _hex_rows(py_rows)
        assert _untimed(c_sum) == _untimed(py_sum)
        # the default path is the compiled one
        auto = simulate_run(setup, method, 2024, run)
        assert _hex_rows(auto[1]) == _hex_rows(py_rows)
        assert math.isfinite(c_sum["plan_seconds"]) and c_sum["plan_seconds"] > 0


def test_restart_diagnostics_and_counters_follow_the_winning_start() -> None:
    """With restarts the step's iterations and work are those of every start, the kernel
    calls the count when the winner finished, and the summary reports which start won."""
    setup = _setup(restarts=3)
    method = registry.from_name("rsmhp_nt16")
    summary, rows = simulate_run(setup, method, 5, 1, path="compiled")
    assert set(summary["diagnostics"]) == {"status", "restart"}
    assert 0.0 <= summary["diagnostics"]["restart"] <= 3.0
    plain, _ = simulate_run(_setup(), method, 5, 1, path="compiled")
    assert set(plain["diagnostics"]) == {"status"}
    # the kernel calls counted up to the winning start: at least the warm start's
    assert all(r["kernel_calls"] >= 1 for r in rows)
    assert summary["work_per_step"] > plain["work_per_step"]


def test_tree_search_and_plugins_keep_the_python_loop() -> None:
    setup = _setup()
    tree = registry.from_name("dpw_s30")
    which, why = loop.path(tree, setup)
    assert which == "python" and "declares no compiled closed loop" in why
    with pytest.raises(ValueError, match="no compiled closed loop for dpw_s30"):
        simulate_run(setup, tree, 1, 0, path="compiled")


def test_a_subclass_does_not_inherit_the_compiled_loop() -> None:
    """A family that subclasses NBO but draws otherwise must not take NBO's nominal kernel."""

    @dataclass(frozen=True)
    class Shifted(NBO):
        family: ClassVar[str] = "shifted_nbo_test"

    assert loop.path(Shifted(), _setup()) == (
        "python",
        "family 'shifted_nbo_test' declares no compiled closed loop",
    )


def test_recordings_scipy_and_bad_path_take_the_python_loop_or_fail_clearly() -> None:
    setup = _setup()
    nbo = registry.from_name("nbo")
    assert loop.path(nbo, setup, observer=True)[0] == "python"
    cfg = copy.deepcopy(DEFAULT_UAV)
    cfg["planner"]["optimiser"] = "scipy"
    scipy_setup = UAVSetup.from_config(cfg)
    which, why = loop.path(nbo, scipy_setup)
    assert which == "python" and "scipy" in why
    with pytest.raises(ValueError, match="path must be 'auto', 'python' or 'compiled'"):
        simulate_run(setup, nbo, 1, 0, path="fast")
    seen: list[int] = []
    _, rows = simulate_run(setup, nbo, 1, 0, observer=lambda info: seen.append(info.step))
    assert seen == list(range(1, 61))
    assert _hex_rows(rows) == _hex_rows(simulate_run(setup, nbo, 1, 0)[1])


def test_plan_seconds_is_a_share_of_the_run() -> None:
    import time

    setup = _setup()
    method = registry.from_name("rsmhp_nt16")
    t0 = time.perf_counter()
    summary, _ = simulate_run(setup, method, 3, 0, path="compiled")
    wall = time.perf_counter() - t0
    assert 0 < summary["plan_seconds"] <= wall


def test_check_method_reports_the_loop() -> None:
    report = check_method(type(registry.from_name("nbo")))
    assert report.loop == {"nbo": ("compiled", loop.KINDS["nominal"])}
    assert "closed loop" in report.checks


def test_a_generator_error_propagates_and_no_generator_is_left_registered() -> None:
    from rsmhp.models.uav import fused
    from rsmhp.models.uav.methods.monte_carlo import MonteCarlo

    @dataclass(frozen=True)
    class Broken(MonteCarlo):
        family: ClassVar[str] = "broken_test"
        closed_loop: ClassVar[str] = "drawn"

        def hypotheses(self, belief, setup, rng):
            if belief.P_hat[0, 0] < 2000.0:  # a later step: the first plans went through
                raise RuntimeError("hypotheses failed at a late step")
            return super().hypotheses(belief, setup, rng)

    setup = _setup()
    with pytest.raises(RuntimeError, match="hypotheses failed at a late step"):
        simulate_run(setup, Broken(4), 1, 0, path="compiled")
    assert fused.CONTEXTS == {}
    simulate_run(setup, registry.from_name("rsmhp_nt16"), 1, 0)
    assert fused.CONTEXTS == {}
