"""rsmhp.models.uav.runs: closed-loop runs through the run store.

Oracles: the tables the studies make without a store (and simulate_run itself); the number of
simulate_run calls, counted by a wrapper; the key compared with itself after one change at a
time (setup field, method, seed, run, code of the closed loop in a copy of the source tree,
environment)."""

from __future__ import annotations

import copy
import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from rsmhp.models.uav import methods, runs
from rsmhp.models.uav.methods.nbo import NBO
from rsmhp.models.uav.runs import (
    NAMESPACE,
    closed_loop_code,
    closed_loop_key,
    environment,
    simulate_run_stored,
    simulate_runs,
)
from rsmhp.models.uav.scoring import run_map_cell
from rsmhp.models.uav.simulation import UAVSetup, simulate_run
from rsmhp.pipeline.protocol import Configuration
from rsmhp.pipeline.runstore import RunStore, canonical_json, key_digest
from rsmhp.studies.frontier.simulate import run_configurations
from rsmhp.studies.horizon.simulate_uav import horizon_setup, run_horizon_closed
from rsmhp.studies.uav.simulate import NONDETERMINISTIC_COLUMNS, run_chunk

ROOT = Path(__file__).resolve().parents[3]
UAV = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["uav"]
MODELS = [{"name": "paper"}, {"name": "footprint150", "sensor": {"footprint_radius": 150.0}}]
#: timing columns: the computing run's measurement, the one field a stored run does not repeat
TIMING = ("plan_seconds", "plan_ms")


def _uav() -> dict:
    cfg = copy.deepcopy(UAV)
    cfg["scenario"]["steps"] = 5
    cfg["planner"].update(horizon=3, maxiter=6, maxfun=12)
    return cfg


def _setup() -> UAVSetup:
    return UAVSetup.from_config(_uav())


@pytest.fixture
def counted(monkeypatch) -> list[tuple[str, int, int]]:
    """The (method, seed, run) of every simulate_run call the store makes."""
    calls: list[tuple[str, int, int]] = []

    def wrapper(setup, method, seed, run, observer=None):
        calls.append((method.name, seed, run))
        return simulate_run(setup, method, seed, run, observer)

    monkeypatch.setattr(runs, "simulate_run", wrapper)
    return calls


def _same_table(a: pd.DataFrame, b: pd.DataFrame) -> None:
    """Every column but the timing ones identical (values and dtypes)."""
    keep = [c for c in a.columns if c not in TIMING]
    pd.testing.assert_frame_equal(a[keep], b[keep], check_exact=True)
    assert list(a.columns) == list(b.columns)


# ---------------------------------------------------------------------- tables


def test_the_uav_study_tables_are_the_same_with_and_without_the_store(tmp_path, counted):
    spec = methods.from_name("rsmhp_nt10").spec()
    plain_runs, plain_steps = run_chunk(_uav(), spec, [0, 1, 2], seed=4)
    assert len(counted) == 3
    store = RunStore(tmp_path)
    first = run_chunk(_uav(), spec, [0, 1, 2], seed=4, store=store)
    again = run_chunk(_uav(), spec, [0, 1, 2], seed=4, store=store)
    assert len(counted) == 6  # the store computed each run once; the second call read them
    assert (store.stats.computed, store.stats.reused, store.stats.waited) == (3, 3, 0)
    for got_runs, got_steps in (first, again):
        _same_table(plain_runs, got_runs)
        pd.testing.assert_frame_equal(plain_steps, got_steps, check_exact=True)
    # the one measurement: the second call reports the first call's planning time
    pd.testing.assert_series_equal(first[0]["plan_seconds"], again[0]["plan_seconds"])
    assert NONDETERMINISTIC_COLUMNS == ("plan_seconds",)


def test_a_run_one_study_stored_is_read_by_another(tmp_path, counted):
    """The horizon study at the base horizon and the UAV study ask for the same runs (same
    setup, method, seed, run): the second study simulates none of them, and its table is the
    one it makes without a store."""
    store = RunStore(tmp_path)
    cfg = {"closed_runs": 2, "methods": {"nbo": True, "rsmhp_nt": [10]}}
    H = _uav()["planner"]["horizon"]
    for name in ("nbo", "rsmhp_nt10"):
        run_chunk(_uav(), methods.from_name(name).spec(), [0, 1], seed=9, store=store)
    assert len(counted) == 4
    stored = run_horizon_closed(_uav(), MODELS, cfg, "paper", H, 9, store)
    assert len(counted) == 4 and store.stats.reused == 4
    plain = run_horizon_closed(_uav(), MODELS, cfg, "paper", H, 9)
    _same_table(plain, stored)
    # another horizon is another setup: simulated, not read
    run_horizon_closed(_uav(), MODELS, cfg, "paper", H + 1, 9, store)
    assert len(counted) == 4 + 2 * 4


def test_the_map_and_the_protocol_tables_are_the_same_with_and_without_the_store(tmp_path):
    cfg = {
        "rows": {"key": "sensor.footprint_radius", "values": [150.0]},
        "cols": {"key": "target.q", "values": [1.0]},
        "runs": 2,
        "methods": {"nbo": True, "rsmhp_nt": [10], "tree": []},
        "regret_runs": 1,
        "regret_steps": [0],
        "track_loss_error": 50.0,
    }
    scoring = {"n_eval": 100, "polish": 1, "random_starts": 1, "eval_maxiter": 5, "n_random": 10}
    store = RunStore(tmp_path)
    plain = run_map_cell(_uav(), cfg, scoring, "r0c0", 5)
    for _ in range(2):
        got = run_map_cell(_uav(), cfg, scoring, "r0c0", 5, store=store)
        _same_table(plain[0], got[0])
        pd.testing.assert_frame_equal(plain[1], got[1], check_exact=True)
    configs = [Configuration("nbo"), Configuration("rsmhp_nt10", maxiter=3, restarts=1)]
    args = (_uav(), MODELS, "footprint150", configs, [0, 1], 5, 50.0)
    _same_table(run_configurations(*args), run_configurations(*args, store=store))
    # the map cell r0c0 is footprint150 at q = 1, NBO at the default budget is the protocol's
    # Configuration("nbo"): its 2 runs were read; the other configuration's 2 simulated
    assert (store.stats.computed, store.stats.reused) == (4 + 2, 4 + 2)
    _same_table(run_configurations(*args), run_configurations(*args, store=store))
    assert (store.stats.computed, store.stats.reused) == (4 + 2, 4 + 2 + 4)


def test_simulate_run_stored_returns_what_simulate_run_returns(tmp_path):
    setup, nbo = _setup(), methods.from_name("nbo")
    want_summary, want_steps = simulate_run(setup, nbo, 3, 1)
    store = RunStore(tmp_path)
    for _ in range(2):
        summary, steps = simulate_run_stored(setup, nbo, 3, 1, store)
        assert list(summary) == list(want_summary) and steps == want_steps
        assert {k: v for k, v in summary.items() if k not in TIMING} == {
            k: v for k, v in want_summary.items() if k not in TIMING
        }
    assert store.path(NAMESPACE, closed_loop_key(setup, nbo, 3, 1)).is_file()


def test_a_family_outside_the_registry_is_simulated_not_stored(tmp_path, counted):
    @dataclasses.dataclass(frozen=True)
    class Mine(NBO):
        pass

    store = RunStore(tmp_path)
    for _ in range(2):
        simulate_runs([(_setup(), Mine(), 3, 0)], store)
    assert len(counted) == 2 and store.stats.computed == 0
    assert not list(Path(tmp_path).rglob("*.run"))
    with pytest.raises(ValueError, match=r"outside rsmhp\.models\.uav\.methods"):
        closed_loop_key(_setup(), Mine(), 3, 0)


# ---------------------------------------------------------------------- the key


def _digest(setup=None, method="rsmhp_nt10", seed=3, run=1) -> str:
    setup = _setup() if setup is None else setup
    return key_digest(closed_loop_key(setup, methods.from_name(method), seed, run))


def test_the_key_changes_with_every_part_of_the_setup_method_seed_and_run():
    base, s = _digest(), _setup()
    p0 = s.P0.copy()
    p0[0, 0] = np.nextafter(p0[0, 0], np.inf)  # one ulp
    changed = {
        "horizon": dataclasses.replace(s, planner=dataclasses.replace(s.planner, horizon=4)),
        "maxiter": dataclasses.replace(s, planner=dataclasses.replace(s.planner, maxiter=7)),
        "restarts": dataclasses.replace(s, planner=dataclasses.replace(s.planner, restarts=1)),
        "start": dataclasses.replace(s, planner=dataclasses.replace(s.planner, start="pursuit")),
        "footprint": dataclasses.replace(
            s, sensor=dataclasses.replace(s.sensor, footprint_radius=150.0)
        ),
        "q": dataclasses.replace(s, target=dataclasses.replace(s.target, q=2.0)),
        "accel": dataclasses.replace(s, uav=dataclasses.replace(s.uav, accel_max=2.0)),
        "P0": dataclasses.replace(s, P0=p0),
        "steps": dataclasses.replace(s, steps=6),
        "scenario": dataclasses.replace(s, scenario={**s.scenario, "uav_speed": 21.0}),
    }
    digests = {name: _digest(setup) for name, setup in changed.items()}
    digests |= {
        "method": _digest(method="rsmhp_nt11"),
        "family": _digest(method="antithetic_nt10"),
        "seed": _digest(seed=4),
        "run": _digest(run=2),
    }
    assert base not in digests.values(), [k for k, v in digests.items() if v == base]
    assert len(set(digests.values())) == len(digests)
    assert _digest() == base  # and it is a function of them: equal parts, equal key


def test_a_warm_start_key_is_the_key_before_the_start_existed():
    """The planner's ``start`` is left out of the key when it is "warm": the canonical text is
    the setup's with every field but that one (the key of every stored run before the field
    existed), class tags and field order included; a pursuit start is in the key."""
    s = _setup()
    key = closed_loop_key(s, methods.from_name("nbo"), 3, 1)
    text = canonical_json(key)
    full = canonical_json({**key, "setup": s})  # the setup with every field
    assert full.count(',"start":"warm"') == 1 and '"start"' not in text  # sorted: the last
    assert text == full.replace(',"start":"warm"', "")
    assert '"__dataclass__":"rsmhp.models.uav.planner.PlannerParams"' in text
    pursuit = dataclasses.replace(s, planner=dataclasses.replace(s.planner, start="pursuit"))
    key_p = closed_loop_key(pursuit, methods.from_name("nbo"), 3, 1)
    assert canonical_json(key_p) == canonical_json({**key_p, "setup": pursuit})
    assert '"start":"pursuit"' in canonical_json(key_p)


def test_the_key_changes_with_the_environment(monkeypatch):
    base = _digest()
    monkeypatch.setenv("OPENBLAS_CORETYPE", "Nehalem")
    environment.cache_clear()
    try:
        assert environment()["env"]["OPENBLAS_CORETYPE"] == "Nehalem"
        assert _digest() != base
    finally:
        monkeypatch.undo()
        environment.cache_clear()
    assert _digest() == base


def test_the_key_changes_with_the_code_digest(monkeypatch):
    base = _digest()
    monkeypatch.setattr(runs, "closed_loop_code", lambda family, src=None: "000000000000")
    assert _digest() != base


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, (path, old)
    path.write_text(text.replace(old, new, 1))


def test_an_edit_of_the_closed_loop_changes_every_familys_code_and_a_family_only_its_own(
    tmp_path,
):
    """A copy of the source tree, edited one module at a time: the model changes the digest
    of every family; one family's module changes that family's and no other's; a study's
    module (not run by the closed loop) changes none."""
    src = tmp_path / "src"
    shutil.copytree(ROOT / "src" / "rsmhp", src / "rsmhp",
                    ignore=shutil.ignore_patterns("__pycache__", "*.nb[ic]"))  # fmt: skip
    fams = ("nbo", "monte_carlo", "rqmc")

    def codes() -> dict[str, str]:
        return {f: closed_loop_code(f, src) for f in fams}

    before = codes()
    assert before == {f: closed_loop_code(f) for f in fams}  # the copy is the same code
    assert len(set(before.values())) == 3
    _edit(src / "rsmhp/studies/uav/simulate.py", "def chunk_runs(", "def chunk_runs_(")
    runs._code.cache_clear()
    assert codes() == before
    _edit(src / "rsmhp/models/uav/methods/nbo.py", "from __future__", "X = 1\nfrom __future__")
    runs._code.cache_clear()
    after_nbo = codes()
    assert after_nbo["nbo"] != before["nbo"]
    assert {f: after_nbo[f] for f in fams[1:]} == {f: before[f] for f in fams[1:]}
    _edit(src / "rsmhp/models/uav/kinematics.py", "from __future__", "Y = 2\nfrom __future__")
    runs._code.cache_clear()
    after_model = codes()
    assert all(after_model[f] != after_nbo[f] for f in fams)
    runs._code.cache_clear()


def test_the_same_run_of_two_studies_has_one_key():
    """Built from the config two ways (the UAV study's setup, the horizon study's at the base
    horizon), the paper model's run is one key."""
    H = _uav()["planner"]["horizon"]
    a = closed_loop_key(_setup(), methods.from_name("nbo"), 3, 0)
    b = closed_loop_key(horizon_setup(_uav(), MODELS[0], H), methods.from_name("nbo"), 3, 0)
    assert key_digest(a) == key_digest(b)
    assert set(a) == {"kind", "setup", "method", "seed", "run", "code", "environment"}


# ---------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (lambda: closed_loop_key({"uav": 1}, methods.from_name("nbo"), 1, 0), TypeError, "setup"),
        (lambda: closed_loop_key(_setup(), {"family": "nbo"}, 1, 0), TypeError, "method"),
        (lambda: closed_loop_key(_setup(), methods.from_name("nbo"), -1, 0), ValueError, "seed"),
        (lambda: closed_loop_key(_setup(), methods.from_name("nbo"), 1, 1.5), ValueError, "run"),
        (lambda: simulate_runs([(_setup(), methods.from_name("nbo"), 1, 0)], "store"), TypeError,
         "store must be a RunStore or None, got str"),
        (lambda: simulate_runs([(_setup(), methods.from_name("nbo"), 1)], None), ValueError,
         "jobs[0] must be (setup, method, seed, run)"),
        (lambda: closed_loop_code("no such"), ValueError, "family: a module name"),
    ],
)  # fmt: skip
def test_bad_input_is_named(call, error, message):
    with pytest.raises(error) as err:
        call()
    assert message in str(err.value)
