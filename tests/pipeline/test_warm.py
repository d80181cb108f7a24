"""The compile-once step (:mod:`rsmhp.pipeline.warm`): every kernel module is covered, a warm
machine loads instead of compiling, and bad input is refused."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest

from rsmhp.pipeline import warm

SRC = Path(__file__).resolve().parents[2] / "src"


def _kernel_modules() -> set[str]:
    """Modules of the package that define a cached numba kernel (``@njit(cache=True ...)``)."""
    found = set()
    for path in (SRC / "rsmhp").rglob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "njit":
                if any(k.arg == "cache" for k in node.keywords):
                    found.add(".".join(path.relative_to(SRC).with_suffix("").parts))
    return found


def test_every_kernel_module_is_warmed():
    covered = {m.partition(":")[0] for task in warm.TASKS for m in task if ":" not in m}
    assert set(warm.LINKED.values()) <= covered
    missing = _kernel_modules() - covered - set(warm.LINKED)
    assert not missing, f"kernel modules without a place in warm.TASKS: {sorted(missing)}"
    entries = [m for task in warm.TASKS for m in task]
    assert len(set(entries)) == len(entries), "an entry is in two tasks"


@pytest.mark.compile
def test_warm_reports_every_module_and_a_warm_process_compiles_nothing():
    wall, per = warm.warm(2)
    assert [m for m, _ in per] == [m for task in warm.TASKS for m in task]
    assert wall > 0 and all(s >= 0 for _, s in per)
    # a fresh process after the warm-up: every kernel it calls is loaded, none compiled
    code = r"""
import json, importlib
from rsmhp.pipeline import warm
from numba.core.registry import CPUDispatcher
for task in warm.TASKS:
    for name in task:
        module, _, func = name.partition(":")
        getattr(importlib.import_module(module), func or "warm_up")()
# the compiled closed loop (NBO's nominal hypothesis, drawn hypotheses, the restarts) and the
# Python loop compile nothing either
import copy, yaml
from rsmhp.models.uav import methods
from rsmhp.models.uav.simulation import UAVSetup, simulate_run
cfg = yaml.safe_load(open(CONFIG))["uav"]
cfg["scenario"]["steps"], cfg["planner"]["restarts"] = 3, 1
setup = UAVSetup.from_config(cfg)
for name in ("nbo", "rsmhp_nt30", "tree_n3_m10", "sigma"):
    for path in ("compiled", "python"):
        simulate_run(setup, methods.from_name(name), 1, 0, path=path)
misses, hits = {}, 0
for task in warm.TASKS:
    for name in task:
        mod = importlib.import_module(name.partition(":")[0])
        for attr in vars(mod).values():
            if isinstance(attr, CPUDispatcher):
                hits += sum(attr.stats.cache_hits.values())
                m = sum(attr.stats.cache_misses.values())
                if m:
                    misses[f"{name}.{attr.__name__}"] = m
print(json.dumps({"misses": misses, "hits": hits}))
"""
    code = code.replace("CONFIG", repr(str(SRC.parent / "config" / "config.yaml")))
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    result = json.loads(out.strip().splitlines()[-1])
    assert result["misses"] == {}
    assert result["hits"] >= len(warm.TASKS)


@pytest.mark.parametrize("cores", [0, -1, 1.5, True, "2"])
def test_bad_cores_are_refused(cores):
    with pytest.raises(ValueError, match="cores must be an integer >= 1"):
        warm.warm(cores)


def test_cli_refuses_zero_cores(capsys):
    with pytest.raises(SystemExit):
        warm.main(["--cores", "0"])
    assert "--cores must be >= 1, got 0" in capsys.readouterr().err


def test_tasks_for_keeps_the_named_modules_entries_in_order():
    assert warm.tasks_for(None) == warm.TASKS
    assert warm.tasks_for(set()) == ()
    # a module of the second task alone: the first (the planner kernel) is dropped
    assert warm.tasks_for({"rsmhp.core.designs"}) == (("rsmhp.core.designs",),)
    picked = warm.tasks_for({"rsmhp.models.lqg.regret", "rsmhp.models.uav.target"})
    assert picked == (("rsmhp.models.uav.target", "rsmhp.models.lqg.regret"),)
    # a module whose kernels are compiled with another's (LINKED) brings that module's
    # entries, the module:function ones included
    linked, owner = next(iter(warm.LINKED.items()))
    entries = {e for task in warm.tasks_for({linked}) for e in task}
    assert entries == {e for task in warm.TASKS for e in task if e.partition(":")[0] == owner}
    # modules without kernels select nothing
    assert warm.tasks_for({"rsmhp.pipeline.io", "rsmhp"}) == ()


def test_the_scripts_of_some_rules_select_only_their_kernels():
    scripts = SRC.parent / "workflow" / "scripts"
    lqg = warm.modules_of_scripts([scripts / "lqg_convergence.py"])
    assert "rsmhp.models.lqg.oven" in lqg and "rsmhp.models.uav.fused" not in lqg
    uav = warm.tasks_for(warm.modules_of_scripts([scripts / "uav_simulate.py"]))
    assert ("rsmhp.models.uav.fused",) in uav


def test_cli_refuses_a_missing_script(capsys, tmp_path):
    with pytest.raises(SystemExit):
        warm.main(["--scripts", str(tmp_path / "nope.py")])
    assert "no such rule script" in capsys.readouterr().err


def test_cli_with_scripts_that_need_no_kernel_compiles_nothing(capsys, tmp_path):
    script = tmp_path / "plain.py"
    script.write_text("import rsmhp.pipeline.io\n")
    warm.main(["--cores", "1", "--scripts", str(script)])
    assert "no kernel to compile" in capsys.readouterr().out
