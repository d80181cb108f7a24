"""Config validation: the default config passes; bad values name the field and range."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

from rsmhp.config import ConfigError, check_config

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


def test_default_and_test_configs_are_valid():
    check_config(DEFAULT)
    tiny = yaml.safe_load((ROOT / "tests" / "config" / "tiny.yaml").read_text())
    check_config(_deep_merge(DEFAULT, tiny))


def _deep_merge(base: dict, over: dict) -> dict:
    """``over`` merged into a copy of ``base`` recursively (as snakemake merges configfiles)."""
    out = copy.deepcopy(base)
    for k, v in over.items():
        out[k] = _deep_merge(out[k], v) if isinstance(v, dict) and k in out else v
    return out


def _with(path: str, value):
    cfg = copy.deepcopy(DEFAULT)
    *parents, leaf = path.split(".")
    node = cfg
    for p in parents:
        node = node[p]
    node[leaf] = value
    return cfg


@pytest.mark.parametrize(
    ("path", "value", "expected"),
    [
        ("lqg.model.sigma", -1.0, r"lqg\.model\.sigma: -1\.0 .*allowed: number in \(0, 1000\]"),
        ("lqg.model.a", 1.5, r"lqg\.model\.a: 1\.5 .*allowed: number in \(0, 1\)"),
        ("lqg.model.a", 0, r"lqg\.model\.a: 0 .*allowed: number in \(0, 1\)"),
        ("lqg.recording.M", 9, r"lqg\.recording\.M: 9 is greater than lqg\.recording\.N = 4"),
        ("lqg.convergence.replicates", 1, r"lqg\.convergence\.replicates: 1 .*\[3, 100000\]"),
        ("lqg.convergence.P", {"start": 500, "stop": 100, "step": 1}, r"P\.start: 500"),
        ("lqg.nbo_error.H_values", [1, 0], r"lqg\.nbo_error\.H_values\[1\]: 0"),
        ("seed", "abc", r"seed: 'abc' is invalid"),
        ("lqg.bogus", 1, r"lqg\.bogus: unknown key"),
        ("typo_top", 1, r"typo_top: unknown key"),
        ("estimators.budgets", [16, 48], r"estimators\.budgets: 48 is not a power of 2"),
        ("estimators.recording", {"N": 2, "M": 3, "u": [0.1]}, r"estimators\.recording\.M: 3"),
        ("estimators.max_leaves", 2, r"estimators\.max_leaves: 2 .*\[4, 1000000\]"),
        ("estimators.schemes", ["mc", "magic"], r"estimators\.schemes\[1\]: 'magic'"),
        (
            "estimators.problems",
            [{"name": "p", "kind": "ncv_2d", "u": [[0.1, 0.2]], "dt": 1.0}],
            r"estimators\.problems\[0\] \(p\): kind ncv_2d needs \['q', ",
        ),
        (
            "estimators.problems",
            [{"name": "p", "kind": "scalar_lqg", "u": [0.1]}] * 2,
            r"duplicate name\(s\) \['p'\]",
        ),
    ],
)
def test_bad_values_are_named(path, value, expected):
    with pytest.raises(ConfigError, match=expected):
        check_config(_with(path, value))


def test_all_problems_reported_at_once():
    cfg = _with("lqg.model.sigma", -1.0)
    cfg["lqg"]["model"]["a"] = 2.0
    with pytest.raises(ConfigError) as exc:
        check_config(cfg)
    assert "lqg.model.sigma" in str(exc.value) and "lqg.model.a" in str(exc.value)


@pytest.mark.parametrize(
    ("path", "value", "expected"),
    [
        ("uav.aircraft.speed_min", 40.0, r"uav\.aircraft\.speed_min: 40\.0 is not < uav\.aircraft"),
        ("uav.scenario.uav_speed", 50.0, r"uav\.scenario\.uav_speed: 50\.0 is outside"),
        ("uav.scenario.uav_distance_min", 900.0, r"uav\.scenario\.uav_distance_min: 900\.0"),
        ("uav.methods.tree", [{"N": 1, "M": 5}], r"uav\.methods\.tree\[0\]\.M: 5 is greater"),
        ("uav.planner.horizon", 0, r"uav\.planner\.horizon: 0 .*allowed: integer in \[1, 50\]"),
        ("uav.aircraft.bank_max_deg", 90, r"uav\.aircraft\.bank_max_deg: 90 .*\(0, 90\)"),
        ("uav.methods.rsmhp_nt", [50, 50], r"uav\.methods\.rsmhp_nt"),
    ],
)
def test_bad_uav_values_are_named(path, value, expected):
    with pytest.raises(ConfigError, match=expected):
        check_config(_with(path, value))
