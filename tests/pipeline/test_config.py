"""Config validation: the default config passes; bad values name the field and range."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

from rsmhp.pipeline.config import ConfigError, check_config

ROOT = Path(__file__).resolve().parents[2]
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


@pytest.mark.parametrize(
    ("path", "value", "expected"),
    [
        # model variants of the sensor
        ("uav.sensor.footprint_radius", 0.0, r"uav\.sensor\.footprint_radius: 0\.0 is invalid"),
        ("uav.sensor.footprint_radius", "far", r"uav\.sensor\.footprint_radius: 'far'"),
        ("uav.sensor.footprint_width", -2.0, r"uav\.sensor\.footprint_width: -2\.0"),
        ("uav.sensor.detection", "soft", r"uav\.sensor\.detection: 'soft'.*hard"),
        ("uav.sensor.noise_growth", "cubic", r"uav\.sensor\.noise_growth: 'cubic'.*quadratic"),
        ("uav.sensor.reference_distance", 0, r"uav\.sensor\.reference_distance: 0 "),
        # decisions.lqg
        ("decisions.lqg.a_values", [1.0], r"decisions\.lqg\.a_values\[0\]: 1\.0 .*\(0, 1\)"),
        ("decisions.lqg.H_values", [0], r"decisions\.lqg\.H_values\[0\]: 0 "),
        ("decisions.lqg.P", [15], r"decisions\.lqg\.P\[0\]: 15 .*multiple of 2"),
        ("decisions.lqg.tree_N", [1], r"decisions\.lqg\.tree_N\[0\]: 1 "),
        ("decisions.lqg.pruned_N", 1, r"decisions\.lqg\.pruned_N: 1 "),
        ("decisions.lqg.max_leaves", 0, r"decisions\.lqg\.max_leaves: 0 "),
        ("decisions.lqg.replicates", 1, r"decisions\.lqg\.replicates: 1 "),
        ("decisions.lqg.methods", ["greedy"], r"decisions\.lqg\.methods\[0\]: 'greedy'"),
        # decisions.uav
        # uav_models (the model variants every UAV study reads)
        ("uav_models", [{"name": "Bad Name"}], r"uav_models\[0\]\.name"),
        (
            "uav_models",
            [{"name": "x", "sensor": {"footprint_radius": -5}}],
            r"uav_models\[0\]\.sensor\.footprint_radius: -5",
        ),
        (
            "uav_models",
            [{"name": "x", "planner": {"horizon": 3}}],
            r"uav_models\[0\]\.planner: unknown key",
        ),
        ("uav_models", [{"name": "a"}, {"name": "a"}], r"uav_models: duplicate name"),
        # the key it moved from is refused with where it went
        (
            "decisions.uav.models",
            [{"name": "paper"}],
            r"decisions\.uav\.models: this key moved to uav_models",
        ),
        # scenarios
        ("scenarios.bootstrap", 10, r"scenarios\.bootstrap: 10 .*\[100, 1000000\]"),
        # decisions.uav
        ("decisions.uav.runs", 0, r"decisions\.uav\.runs: 0 "),
        ("decisions.uav.steps", [0, 60], r"decisions\.uav\.steps: \[60\] not before"),
        ("decisions.uav.n_eval", 5, r"decisions\.uav\.n_eval: 5 "),
        ("decisions.uav.polish", -1, r"decisions\.uav\.polish: -1 "),
        ("decisions.uav.random_starts", -1, r"decisions\.uav\.random_starts: -1 "),
        ("decisions.uav.eval_maxiter", 0, r"decisions\.uav\.eval_maxiter: 0 "),
        ("decisions.uav.n_random", 2, r"decisions\.uav\.n_random: 2 "),
        ("decisions.uav.methods", {"nbo": False, "rsmhp_nt": [], "tree": []}, r"no method"),
        # decisions.map
        (
            "decisions.map.rows",
            {"key": "planner.horizon", "values": [1]},
            r"decisions\.map\.rows\.key",
        ),
        (
            "decisions.map.cols",
            {"key": "target.q", "values": [None]},
            r"decisions\.map\.cols\.values: null is only allowed",
        ),
        (
            "decisions.map.cols",
            {"key": "sensor.footprint_radius", "values": [100.0]},
            r"also the rows' key",
        ),
        ("decisions.map.runs", 1, r"decisions\.map\.runs: 1 "),
        ("decisions.map.methods", {"nbo": True, "rsmhp_nt": [], "tree": []}, r"fewer than 2"),
        (
            "decisions.map.methods",
            {"nbo": False, "rsmhp_nt": [100, 250], "tree": []},
            r"decisions\.map\.methods\.nbo: false",
        ),
        (
            "decisions.uav.methods",
            {"nbo": False, "rsmhp_nt": [100], "tree": []},
            r"decisions\.uav\.methods\.nbo: false",
        ),
        ("decisions.map.regret_steps", [70], r"decisions\.map\.regret_steps: \[70\]"),
        ("decisions.map.track_loss_error", 0, r"decisions\.map\.track_loss_error: 0 "),
        ("decisions.map.bootstrap", 10, r"decisions\.map\.bootstrap: 10 "),
        ("frontier.recording.model", "nothere", r"frontier\.recording\.model: 'nothere'"),
        ("frontier.recording.select", "first", r"frontier\.recording\.select: 'first'"),
        ("frontier.budget.ms_per_step", 0, r"frontier\.budget\.ms_per_step: 0 "),
        ("frontier.claims.margin_pp", -0.1, r"frontier\.claims\.margin_pp: -0\.1 "),
        ("frontier.timing.steps", [0, 70], r"frontier\.timing\.steps: \[70\]"),
        (
            "frontier.tuning.timing.steps",
            [99],
            r"frontier\.tuning\.timing\.steps: \[99\]",
        ),
        ("frontier.tuning.budgets_ms", [0], r"tuning\.budgets_ms\[0\]: 0 "),
        ("frontier.tuning.runs", 1, r"tuning\.runs: 1 "),
        ("horizon.stream", "judge", r"horizon\.stream: 'judge'"),
    ],
)
def test_bad_decision_values_are_named(path, value, expected):
    with pytest.raises(ConfigError, match=expected):
        check_config(_with(path, value))


def _filled_default() -> dict:
    """The default config with the schema's defaults filled in (as the Snakefile sees it)."""
    from snakemake.utils import validate

    cfg = copy.deepcopy(DEFAULT)
    validate(cfg, str(ROOT / "workflow" / "schemas" / "config.schema.yaml"))
    return cfg


def _numeric_leaves(schema: dict, node, path: tuple = ()):
    """(path, kind) of every numeric field of the schema present in ``node``; kind is
    'integer' or 'number'; array elements as index 0."""
    types = schema.get("type")
    types = types if isinstance(types, list) else [types]
    if "object" in types and isinstance(node, dict):
        for key, sub in schema.get("properties", {}).items():
            if key in node:
                yield from _numeric_leaves(sub, node[key], (*path, key))
    elif "array" in types and isinstance(node, list) and node:
        yield from _numeric_leaves(schema.get("items", {}), node[0], (*path, 0))
    elif "integer" in types and not isinstance(node, bool):
        yield path, "integer"
    elif "number" in types and not isinstance(node, bool):
        yield path, "number"


def _dotted(path: tuple) -> str:
    return "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in path).lstrip(".")


SCHEMA = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
FILLED = _filled_default()


def _bad_numeric_cases():
    schema, cfg = SCHEMA, FILLED
    cases = []
    for path, kind in _numeric_leaves(schema, cfg):
        cases.append((path, float("nan")))
        cases.append((path, float("inf")))
        if kind == "integer":
            node = cfg
            for p in path:
                node = node[p]
            cases.append((path, float(node)))  # a whole-number float, e.g. 7.0
    return cases


BAD_NUMERIC = _bad_numeric_cases()


def test_the_numeric_matrix_is_large():
    assert len(BAD_NUMERIC) >= 200  # every numeric field of the schema, three ways


@pytest.mark.parametrize(
    ("path", "value"), BAD_NUMERIC, ids=[f"{_dotted(p)}={v!r}" for p, v in BAD_NUMERIC]
)
def test_nan_inf_and_float_integers_are_refused_by_name(path, value):
    cfg = copy.deepcopy(FILLED)
    node = cfg
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value
    with pytest.raises(ConfigError) as exc:
        check_config(cfg, SCHEMA)
    assert f"{_dotted(path)}: {value!r}" in str(exc.value)


@pytest.mark.parametrize(
    ("path", "value", "expected"),
    [
        ("lqg.convergence.P", {"start": 100, "stop": 200, "step": 100}, r"gives 2 value"),
        ("lqg.convergence.P", {"start": 100, "stop": 100, "step": 100}, r"gives 1 value"),
        ("estimators.schemes", ["nbo"], r"estimators\.schemes: \['nbo'\] has no mc"),
        ("estimators.tree_N", [100, 200], r"estimators\.tree_N: no N in \[100, 200\]"),
        ("uav.methods", {"nbo": False, "rsmhp_nt": [], "tree": []}, r"uav\.methods: 0 method"),
        ("uav.methods", {"nbo": True, "rsmhp_nt": [], "tree": []}, r"uav\.methods: 1 method"),
    ],
)
def test_configs_with_nothing_to_compare_are_refused(path, value, expected):
    with pytest.raises(ConfigError, match=expected):
        check_config(_with(path, value))


# ------------------------------------------------------------ config files and overrides


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("seed: 7\nlqg:\n  model: {a: 0.5\n  x: 1\n", r"bad\.yaml:4:4: not valid YAML"),
        ("seed: 7\n  lqg: 3\n", r"bad\.yaml:2:6: not valid YAML \(mapping values are not allowed"),
        ("seed: 7\nseed:\t8\n", r"bad\.yaml:2:\d+: not valid YAML"),
        ("", r"bad\.yaml: the file is empty \(allowed: a YAML mapping"),
        ("# only a comment\n", r"bad\.yaml: the file is empty"),
        ("- seed\n- 7\n", r"bad\.yaml: the top level is a list, not a mapping"),
        ("7\n", r"bad\.yaml: the top level is a int, not a mapping"),
    ],
)
def test_config_files_are_refused_with_file_and_line(tmp_path, text, message):
    from rsmhp.pipeline.config import load_config_file

    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=message):
        load_config_file(path)


def test_missing_config_file_is_named(tmp_path):
    from rsmhp.pipeline.config import load_config_file

    with pytest.raises(ConfigError, match=r"nope\.yaml: cannot be read"):
        load_config_file(tmp_path / "nope.yaml")


def test_config_cli_checks_an_overlay(tmp_path, capsys):
    from rsmhp.pipeline.config import main

    good = tmp_path / "good.yaml"
    good.write_text("lqg:\n  model: {a: 0.3}\n")
    assert main([str(good)]) == 0
    assert "valid" in capsys.readouterr().out
    bad = tmp_path / "bad.yaml"
    bad.write_text("lqg:\n  model: {a: 1.3}\nuav:\n  runs: 2.0\n")
    assert main([str(bad)]) == 1
    err = capsys.readouterr().err
    assert "lqg.model.a: 1.3" in err and "uav.runs: 2.0" in err
    broken = tmp_path / "broken.yaml"
    broken.write_text("lqg: [1, 2\n")
    assert main([str(broken)]) == 1
    assert "broken.yaml:2:1: not valid YAML" in capsys.readouterr().err


def test_nested_command_line_overrides_get_their_yaml_types():
    from rsmhp.pipeline.config import typed_overrides

    # what Snakemake hands over for --config seed=3 'lqg={model: {a: 0.3, x0: null}}'
    # 'uav={methods: {rsmhp_nt: [10, 50]}, sensor: {detection: logistic}}'
    raw = {
        "seed": 3,
        "lqg": {"model": {"a": "0.3", "x0": "null"}},
        "uav": {"methods": {"rsmhp_nt": ["10", "50"]}, "sensor": {"detection": "logistic"}},
    }
    assert typed_overrides(raw) == {
        "seed": 3,
        "lqg": {"model": {"a": 0.3, "x0": None}},
        "uav": {"methods": {"rsmhp_nt": [10, 50]}, "sensor": {"detection": "logistic"}},
    }


def test_merge_follows_snakemakes_overlay_rule():
    from rsmhp.pipeline.config import merge

    base = {"a": {"b": 1, "c": [1, 2]}, "d": 1}
    assert merge(base, {"a": {"c": [3]}}) == {"a": {"b": 1, "c": [3]}, "d": 1}
    assert base == {"a": {"b": 1, "c": [1, 2]}, "d": 1}


def test_the_exploratory_frontier_needs_two_regret_runs():
    cfg = _with("frontier.exploratory", True)
    cfg["frontier"]["regret_runs"] = 1
    with pytest.raises(ConfigError, match=r"frontier\.regret_runs: 1 \(allowed: at least 2"):
        check_config(cfg)
