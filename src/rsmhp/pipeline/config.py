"""Configuration checks with messages that name the field and its allowed range.

:func:`check_config` validates a config mapping against ``workflow/schemas/config.schema.yaml``
(JSON Schema draft 2020-12) and then checks the constraints a schema cannot express
(``M <= N``, ``P.start <= P.stop``...). It reports *every* problem at once, each as
``<dotted.path>: <value> <what is wrong> (allowed: <range>)``, and raises
:class:`ConfigError` before any job starts. The Snakefile calls it, then snakemake's own
``validate`` (which also fills defaults).
"""

from __future__ import annotations

import copy
import math
import os
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml
from jsonschema import Draft202012Validator, validators
from jsonschema.exceptions import ValidationError

from rsmhp.models.uav import methods as uav_methods
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.models.uav.methods.pruned_tree import PrunedTree

__all__ = [
    "CONFIG_PATH",
    "SCHEMA_PATH",
    "ConfigError",
    "check_config",
    "load_config_file",
    "load_schema",
    "merge",
    "typed_overrides",
]

ROOT = Path(__file__).resolve().parents[3]
SCHEMA_PATH = ROOT / "workflow" / "schemas" / "config.schema.yaml"
CONFIG_PATH = ROOT / "config" / "config.yaml"


class ConfigError(ValueError):
    """The configuration is invalid; the message lists every offending field."""


def load_schema(path: str | os.PathLike | None = None) -> dict[str, Any]:
    """The config schema with every registered UAV method family's fragment inserted into
    ``$defs/uav_methods`` (:func:`rsmhp.models.uav.methods.schema`): the file itself names no
    family, so a new method needs no schema edit."""
    with open(path or SCHEMA_PATH, encoding="utf-8") as fh:
        schema = yaml.safe_load(fh)
    return with_methods(schema)


def with_methods(schema: Mapping[str, Any]) -> dict[str, Any]:
    """``schema`` (a copy) with ``$defs/uav_methods`` from the method registry."""
    from rsmhp.models.uav import methods

    out = copy.deepcopy(dict(schema))
    defs = out.get("$defs", {})
    if "uav_methods" in defs:
        defs["uav_methods"] = {**defs["uav_methods"], **methods.schema()}
    return out


def load_config_file(path: str | os.PathLike) -> dict[str, Any]:
    """Parse one YAML config file; :class:`ConfigError` names the file, line and column of a
    syntax error, and refuses an empty file or one whose top level is not a mapping."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ConfigError(f"{path}: cannot be read ({exc.strerror})") from exc
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"{path}:{mark.line + 1}:{mark.column + 1}" if mark else str(path)
        what = " ".join(
            str(p) for p in (getattr(exc, "context", None), getattr(exc, "problem", None)) if p
        )
        raise ConfigError(
            f"{where}: not valid YAML ({what or exc}); check the indentation and the brackets "
            "on that line and the one before"
        ) from exc
    if data is None:
        raise ConfigError(
            f"{path}: the file is empty (allowed: a YAML mapping of config keys, e.g. "
            "'seed: 7'; see config/config.yaml)"
        )
    if not isinstance(data, dict):
        raise ConfigError(
            f"{path}: the top level is a {type(data).__name__}, not a mapping of config keys "
            "(allowed: e.g. 'seed: 7' on its own line)"
        )
    return data


def merge(base: Mapping[str, Any], overlay: Mapping[str, Any]) -> dict[str, Any]:
    """Snakemake's overlay rule (``snakemake.utils.update_config``) on copies: mappings merge
    key by key, anything else (lists included) replaces the base value."""
    from snakemake.utils import update_config  # the rule itself, on copies

    out = copy.deepcopy(dict(base))
    update_config(out, copy.deepcopy(dict(overlay)))
    return out


def typed_overrides(overrides: Mapping[str, Any]) -> dict[str, Any]:
    """Give nested ``--config`` values their YAML types.

    Snakemake parses ``--config key=value`` with int, float, bool and then YAML's
    *BaseLoader*, which keeps every nested scalar a string: ``--config 'lqg={model: {a:
    0.3}}'`` arrives as ``{"model": {"a": "0.3"}}``. Below the top level this re-reads each
    string with ``yaml.safe_load`` (``"0.3"`` -> 0.3, ``"null"`` -> None, ``"[1, 2]"`` -> a
    list); top-level values, already typed by Snakemake, are kept.
    """

    def retype(value: Any) -> Any:
        if isinstance(value, Mapping):
            return {k: retype(v) for k, v in value.items()}
        if isinstance(value, list):
            return [retype(v) for v in value]
        if isinstance(value, str):
            try:
                return yaml.safe_load(value)
            except yaml.YAMLError:
                return value
        return value

    return {k: retype(v) if isinstance(v, Mapping | list) else v for k, v in overrides.items()}


def _dotted(path) -> str:
    return (
        ".".join(str(p) if not isinstance(p, int) else f"[{p}]" for p in path).replace(".[", "[")
        or "<root>"
    )


def _allowed(schema: Mapping[str, Any]) -> str:
    """Human-readable allowed range/type of a schema node."""
    lo = schema.get("minimum", schema.get("exclusiveMinimum"))
    hi = schema.get("maximum", schema.get("exclusiveMaximum"))
    if lo is not None or hi is not None:
        left = "(" if "exclusiveMinimum" in schema or lo is None else "["
        right = ")" if "exclusiveMaximum" in schema or hi is None else "]"
        lo_txt = "-inf" if lo is None else lo
        hi_txt = "inf" if hi is None else hi
        return f"{schema.get('type', 'number')} in {left}{lo_txt}, {hi_txt}{right}"
    if "enum" in schema:
        return "one of " + ", ".join(map(repr, schema["enum"]))
    if schema.get("type") == "object" and "properties" in schema:
        return "keys " + ", ".join(schema["properties"])
    if "type" in schema:
        return str(schema["type"])
    return "see workflow/schemas/config.schema.yaml"


def _message(err: ValidationError) -> str:
    path = _dotted(err.absolute_path)
    if err.validator == "additionalProperties":
        extra = sorted(set(err.instance) - set(err.schema.get("properties", {})))
        prefix = f"{path}." if err.absolute_path else ""
        return (
            f"{', '.join(prefix + e for e in extra)}: unknown key (allowed at {path}: "
            f"{', '.join(err.schema.get('properties', {}))})"
        )
    if err.validator == "required":
        return f"{path}: {err.message}"
    if err.validator in ("minItems", "maxItems"):
        return f"{path}: {err.message}"
    return f"{path}: {err.instance!r} is invalid ({err.message}; allowed: {_allowed(err.schema)})"


def _cross_field(config: Mapping[str, Any]) -> list[str]:
    """Constraints between fields that JSON Schema cannot express."""
    problems = []
    lqg = config.get("lqg", {}) or {}
    grid = (lqg.get("convergence", {}) or {}).get("P", {}) or {}
    if {"start", "stop"} <= grid.keys() and grid["start"] > grid["stop"]:
        problems.append(
            f"lqg.convergence.P.start: {grid['start']} is greater than lqg.convergence.P.stop "
            f"= {grid['stop']} (allowed: start <= stop)"
        )
    est = config.get("estimators", {}) or {}
    problems.extend(_estimator_problems(est.get("problems", []) or []))
    for n in est.get("budgets", []) or []:
        if isinstance(n, int) and n & (n - 1):
            problems.append(
                f"estimators.budgets: {n} is not a power of 2 (allowed: 2, 4, 8, ... for Sobol')"
            )
    pr = est.get("pruning", {}) or {}
    if pr.get("N") and pr.get("M") and min(pr["M"]) > max(pr["N"]):
        problems.append(
            f"estimators.pruning.M: every M ({min(pr['M'])} and up) is greater than every N "
            f"(at most {max(pr['N'])}) (allowed: M <= N for at least one pair)"
        )
    for section in ("lqg", "estimators"):
        rec = (config.get(section, {}) or {}).get("recording", {}) or {}
        if {"N", "M"} <= rec.keys() and rec["M"] > rec["N"]:
            problems.append(
                f"{section}.recording.M: {rec['M']} is greater than {section}.recording.N = "
                f"{rec['N']} (allowed: 1 <= M <= N; the paper prunes to M <= N trajectories)"
            )
    for key in ("x0", "r", "target", "sigma", "a"):
        val = (lqg.get("model", {}) or {}).get(key)
        if isinstance(val, float) and not math.isfinite(val):
            problems.append(f"lqg.model.{key}: {val} is not finite")
    problems += _horizon_lqg_problems((config.get("horizon", {}) or {}).get("lqg", {}) or {})
    # horizon.optimiser: steps inside a run, models, methods, budgets (imported here: no rule
    # imports this module, so its code digests stay as they are)
    from rsmhp.studies.horizon.simulate_optimiser import config_problems as _optimiser_problems

    problems += _optimiser_problems(config)
    problems += _nothing_to_run(config)
    problems += _uav_cross_field(config.get("uav", {}) or {})
    problems += _decisions_cross_field(config)
    return problems


def _nothing_to_run(config: Mapping[str, Any]) -> list[str]:
    """Configs that validate field by field but leave an analysis without its inputs (they
    used to fail after the simulations)."""
    problems = []
    grid = ((config.get("lqg", {}) or {}).get("convergence", {}) or {}).get("P", {}) or {}
    if {"start", "stop", "step"} <= grid.keys() and grid["step"] > 0:
        n_p = len(range(int(grid["start"]), int(grid["stop"]) + 1, int(grid["step"])))
        if n_p < 3:
            problems.append(
                f"lqg.convergence.P: {{start: {grid['start']}, stop: {grid['stop']}, step: "
                f"{grid['step']}}} gives {n_p} value(s) (allowed: at least 3, for the error "
                "slope in P)"
            )
    est = config.get("estimators", {}) or {}
    schemes = est.get("schemes") or []
    if schemes and "mc" not in schemes:
        problems.append(
            f"estimators.schemes: {schemes} has no mc (allowed: any list containing mc, the "
            "reference every estimator is compared with)"
        )
    tree_n, max_leaves = est.get("tree_N") or [], est.get("max_leaves")
    horizons = [
        len(spec["u"]) for spec in est.get("problems") or [] if isinstance(spec.get("u"), list)
    ]
    if {"tree", "tree_pernode"} & set(schemes) and tree_n and max_leaves and horizons:
        if not any(n**h <= max_leaves for n in tree_n for h in horizons):
            problems.append(
                f"estimators.tree_N: no N in {tree_n} gives a tree with N^H <= "
                f"estimators.max_leaves = {max_leaves} for any problem (H in "
                f"{sorted(set(horizons))}) (allowed: at least one such N, or drop tree and "
                "tree_pernode from estimators.schemes)"
            )
    methods = (config.get("uav", {}) or {}).get("methods")
    if isinstance(methods, Mapping):
        n = uav_methods.count(methods)
        if n < 2:
            problems.append(
                f"uav.methods: {n} method(s) (allowed: at least 2, e.g. nbo and one rsmhp_nt, "
                "so that there is a comparison)"
            )
    return problems


def _decisions_cross_field(config: Mapping[str, Any]) -> list[str]:
    """Belief-state steps inside a run, map axes with values their key allows, a method to
    compare, unique model names, frontier models that are decision-study models."""
    problems: list[str] = []
    dec = config.get("decisions", {}) or {}
    n_steps = ((config.get("uav", {}) or {}).get("scenario", {}) or {}).get("steps", 60)
    fr = config.get("frontier", {}) or {}
    for path, steps in (
        ("decisions.uav.steps", (dec.get("uav", {}) or {}).get("steps", [])),
        ("decisions.map.regret_steps", (dec.get("map", {}) or {}).get("regret_steps", [])),
        ("frontier.regret_steps", fr.get("regret_steps", [])),
        ("frontier.timing.steps", (fr.get("timing", {}) or {}).get("steps", [])),
        (
            "frontier.tuning.timing.steps",
            ((fr.get("tuning", {}) or {}).get("timing", {}) or {}).get("steps", [0, 7, 20]),
        ),
        (
            "frontier.confirm.timing.steps",
            ((fr.get("confirm", {}) or {}).get("timing", {}) or {}).get("steps", [0, 7, 20]),
        ),
    ):
        late = [s for s in steps or [] if isinstance(s, int) and s >= n_steps]
        if late:
            problems.append(
                f"{path}: {late} not before the run's last step (allowed: 0 <= step < "
                f"uav.scenario.steps = {n_steps})"
            )
    rr = fr.get("regret_runs", 10)
    if fr.get("exploratory") and isinstance(rr, int) and rr < 2:
        problems.append(
            f"frontier.regret_runs: {rr} (allowed: at least 2 with "
            "frontier.exploratory: true: its open-loop CIs are over runs)"
        )
    names = [m.get("name") for m in (dec.get("uav", {}) or {}).get("models", []) or []]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        problems.append(f"decisions.uav.models: duplicate name(s) {dup} (allowed: unique names)")
    base = uav_methods.baseline()
    for section, block in (
        ("decisions.uav", dec.get("uav")),
        ("decisions.map", dec.get("map")),
        ("frontier", fr),
    ):
        methods = (block or {}).get("methods")
        if isinstance(methods, Mapping) and methods:
            n = uav_methods.count(methods)
            if not methods.get(base.config_key, base.default):
                problems.append(
                    f"{section}.methods.{base.config_key}: "
                    f"{str(methods.get(base.config_key)).lower()} (allowed: true; "
                    f"{base.family_label} is "
                    "the baseline every comparison of the decision study is made against)"
                )
            if n < 2 and section == "decisions.map":
                problems.append(
                    "decisions.map.methods: fewer than 2 methods (allowed: NBO and at least "
                    "one RS-MHP N_T or tree, to compare)"
                )
            if n < 1:
                problems.append(f"{section}.methods: no method (allowed: at least 1)")
            problems += uav_methods.config_problems(
                methods, f"{section}.methods", config.get("uav", {}) or {}
            )
    unknown = [m for m in fr.get("models", []) or [] if names and m not in names]
    if unknown:
        problems.append(
            f"frontier.models: {unknown} not model(s) of decisions.uav.models "
            f"(allowed: {', '.join(map(str, names))})"
        )
    fr_models = [m for m in fr.get("models", []) or [] if isinstance(m, str)]
    rec = (fr.get("recording", {}) or {}).get("model")
    if rec is not None and fr_models and rec not in fr_models:
        problems.append(
            f"frontier.recording.model: {rec!r} is not a model of frontier.models "
            f"(allowed: {', '.join(fr_models)}; the recording replays one of its runs)"
        )
    problems += _budget_problems(dec, fr, bool(fr_models))
    problems += _horizon_problems(config, names, n_steps)
    mp = dec.get("map", {}) or {}
    claim_method = (dec.get("claims", {}) or {}).get("map_method") or ""
    map_methods = mp.get("methods")
    if claim_method and isinstance(map_methods, Mapping):
        try:
            run = [n for n, m in uav_methods.from_config(map_methods).items() if not m.baseline]
        except (ValueError, TypeError):
            run = []  # reported above by the families' own checks
        if run and claim_method not in run:
            problems.append(
                f"decisions.claims.map_method: {claim_method!r} is not a method of "
                f"decisions.map.methods (allowed: {', '.join(run)}, or '' for the first "
                "RS-MHP member)"
            )
    keys = []
    for axis in ("rows", "cols"):
        ax = mp.get(axis) or {}
        key = ax.get("key")
        keys.append(key)
        for v in ax.get("values", []) or []:
            if v is None and key != "sensor.footprint_radius":
                problems.append(
                    f"decisions.map.{axis}.values: null is only allowed for "
                    f"sensor.footprint_radius (unlimited), not for {key}"
                )
            elif v is not None and not (isinstance(v, int | float) and 0 < v <= 100000):
                problems.append(
                    f"decisions.map.{axis}.values: {v!r} is invalid for {key} "
                    "(allowed: number in (0, 100000])"
                )
    if keys[0] is not None and keys[0] == keys[1]:
        problems.append(
            f"decisions.map.cols.key: {keys[1]} is also the rows' key (allowed: two different keys)"
        )
    return problems


def _horizon_problems(config: Mapping[str, Any], names: list, n_steps: int) -> list[str]:
    """``horizon.uav``: models of the decision study, belief-state steps inside a run, NBO
    among the methods, and claim members that the study runs (HZ-2: a pruned tree and a
    Monte-Carlo member)."""
    hz = (config.get("horizon", {}) or {}).get("uav", {}) or {}
    path = "horizon.uav"
    problems: list[str] = []
    models = [m for m in hz.get("models", []) or [] if isinstance(m, str)]
    unknown = [m for m in models if names and m not in names]
    if unknown:
        problems.append(
            f"{path}.models: {unknown} not model(s) of decisions.uav.models "
            f"(allowed: {', '.join(map(str, names))})"
        )
    late = [s for s in hz.get("steps", []) or [] if isinstance(s, int) and s >= n_steps]
    if late:
        problems.append(
            f"{path}.steps: {late} not before the run's last step (allowed: 0 <= step < "
            f"uav.scenario.steps = {n_steps})"
        )
    methods = hz.get("methods")
    base = uav_methods.baseline()
    if isinstance(methods, Mapping) and methods:
        if not methods.get(base.config_key, base.default):
            problems.append(
                f"{path}.methods.{base.config_key}: {str(methods.get(base.config_key)).lower()} "
                f"(allowed: true; {base.family_label} is the baseline of the regret)"
            )
        problems += uav_methods.config_problems(
            methods, f"{path}.methods", config.get("uav", {}) or {}
        )
    run = _member_names(methods)
    claims = hz.get("claims", {}) or {}
    closed = claims.get("closed_model") or ""
    if closed and closed not in models:
        problems.append(
            f"{path}.claims.closed_model: {closed!r} is not a model of {path}.models "
            f"(allowed: {', '.join(models) or 'none configured'}, or '')"
        )
    rec = hz.get("recording", {}) or {}
    if rec.get("model"):
        if rec["model"] not in models:
            problems.append(
                f"{path}.recording.model: {rec['model']!r} is not a model of {path}.models "
                f"(allowed: {', '.join(models) or 'none configured'}, or '')"
            )
        hs = [h for h in hz.get("H", []) or [] if isinstance(h, int)]
        if "H" in rec and rec["H"] not in hs:
            problems.append(
                f"{path}.recording.H: {rec['H']} is not a horizon of {path}.H (allowed: "
                f"{', '.join(map(str, hs))})"
            )
        if not (claims.get("monte_carlo") or ""):
            problems.append(
                f"{path}.recording.model: {rec['model']!r} needs {path}.claims.monte_carlo "
                "(the run is chosen from its paired differences with NBO), got ''"
            )
    for key, family in (("tree", PrunedTree), ("monte_carlo", MonteCarlo)):
        name = claims.get(key) or ""
        ok = [n for n, m in run.items() if isinstance(m, family)]
        if name and run and name not in ok:
            problems.append(
                f"{path}.claims.{key}: {name!r} is not a {family.__name__} member of "
                f"{path}.methods (allowed: {', '.join(ok) or 'none configured'}, or '')"
            )
    return problems


def _horizon_lqg_problems(hz: Mapping[str, Any]) -> list[str]:
    """``horizon.lqg``: Sobol' sizes are powers of 2, and HZ-4's pruned tree is a cell of
    the estimator grid that is pruned at some configured horizon."""
    path = "horizon.lqg"
    est = hz.get("estimators", {}) or {}
    ns = [n for n in est.get("n", []) or [] if isinstance(n, int)]
    problems = [
        f"{path}.estimators.n: {n} is not a power of 2 (allowed: 2, 4, 8, ... for Sobol')"
        for n in ns
        if n & (n - 1)
    ]
    tree = (hz.get("claims", {}) or {}).get("pruned", {}) or {}
    if not tree:
        return problems
    N, M = tree.get("N"), tree.get("M")
    n_list = [N_ for N_ in est.get("pruned_N", []) or [] if isinstance(N_, int)]
    if N not in n_list:
        problems.append(
            f"{path}.claims.pruned.N: {N!r} is not in {path}.estimators.pruned_N (allowed: "
            f"{', '.join(map(str, n_list)) or 'none configured'})"
        )
    if M not in ns:
        problems.append(
            f"{path}.claims.pruned.M: {M!r} is not in {path}.estimators.n (allowed: "
            f"{', '.join(map(str, ns)) or 'none configured'})"
        )
    hs = sorted(h for h in hz.get("sim_H", []) or [] if isinstance(h, int))
    if isinstance(N, int) and isinstance(M, int) and hs:
        pruned = [h for h in hs if N**h > M]
        if len(pruned) < 2:
            problems.append(
                f"{path}.claims.pruned: N = {N}, M = {M} is pruned (N^H > M) at "
                f"{len(pruned)} of {path}.sim_H = {hs} (allowed: at least 2 such horizons, "
                "HZ-4 compares the first with the last)"
            )
    return problems


def _member_names(methods: Any) -> dict[str, Any]:
    """name -> Method of a methods block ({} where the block is invalid: reported elsewhere)."""
    if not isinstance(methods, Mapping):
        return {}
    try:
        return dict(uav_methods.from_config(methods))
    except (ValueError, TypeError, KeyError):
        return {}


def _budget_problems(
    dec: Mapping[str, Any], fr: Mapping[str, Any], frontier_runs: bool
) -> list[str]:
    """``frontier.budget.members``: methods of the frontier, one per non-baseline
    family and one for each such family of the frontier, all run by the map;
    ``frontier.claims.sigma_reference``: a Monte-Carlo member of the frontier."""
    if not frontier_runs:
        return []
    problems: list[str] = []
    path = "frontier.budget.members"
    members = list(((fr.get("budget", {}) or {}).get("members", [])) or [])
    run = _member_names(fr.get("methods"))
    if not run:
        return problems
    unknown = [m for m in members if m not in run]
    if unknown:
        problems.append(
            f"{path}: {unknown} not method(s) of frontier.methods "
            f"(allowed: {', '.join(n for n, m in run.items() if not m.baseline)})"
        )
    fams: dict[str, list[str]] = {}
    for name in members:
        if name in run:
            fams.setdefault(run[name].family, []).append(name)
    base = [n for n in members if n in run and run[n].baseline]
    if base:
        problems.append(f"{path}: {base} is the baseline (allowed: one member per other family)")
    twice = {f: n for f, n in fams.items() if len(n) > 1}
    if twice:
        problems.append(f"{path}: several members of one family {twice} (allowed: one each)")
    missing = sorted({m.family for m in run.values() if not m.baseline} - set(fams))
    if missing:
        problems.append(
            f"{path}: no member of the frontier's famil(ies) {missing} (allowed: one member "
            "of every family frontier.methods runs)"
        )
    map_run = _member_names((dec.get("map", {}) or {}).get("methods"))
    absent = [m for m in members if m in run and map_run and m not in map_run]
    if absent:
        problems.append(
            f"decisions.map.methods: lacks the budget member(s) {absent} of {path} (allowed: "
            "a map that runs every budget member, so that it shows each family at the budget)"
        )
    ref = (fr.get("claims", {}) or {}).get("sigma_reference")
    mc = [n for n, m in run.items() if isinstance(m, MonteCarlo)]
    if ref is not None and mc and ref not in mc:
        problems.append(
            f"frontier.claims.sigma_reference: {ref!r} is not a Monte-Carlo member "
            f"of frontier.methods (allowed: {', '.join(mc)})"
        )
    return problems


def _uav_cross_field(uav: Mapping[str, Any]) -> list[str]:
    """UAV bounds (lo <= hi), initial speed inside the speed range, tree able to keep M."""
    problems = []
    for section, lo, hi, strict in (
        ("aircraft", "speed_min", "speed_max", True),
        ("scenario", "target_speed_min", "target_speed_max", False),
        ("scenario", "uav_distance_min", "uav_distance_max", False),
    ):
        node = uav.get(section, {}) or {}
        if {lo, hi} <= node.keys() and (node[lo] >= node[hi] if strict else node[lo] > node[hi]):
            rel = "<" if strict else "<="
            problems.append(
                f"uav.{section}.{lo}: {node[lo]} is not {rel} uav.{section}.{hi} = {node[hi]} "
                f"(allowed: {lo} {rel} {hi})"
            )
    ac, sc = uav.get("aircraft", {}) or {}, uav.get("scenario", {}) or {}
    if {"speed_min", "speed_max"} <= ac.keys() and "uav_speed" in sc:
        if not ac["speed_min"] <= sc["uav_speed"] <= ac["speed_max"]:
            problems.append(
                f"uav.scenario.uav_speed: {sc['uav_speed']} is outside the aircraft's speed range "
                f"(allowed: {ac['speed_min']} <= uav_speed <= {ac['speed_max']})"
            )
    problems += uav_methods.config_problems(uav.get("methods"), "uav.methods", uav)
    return problems


NCV_KEYS = ("dt", "q", "w_pos", "w_vel", "r_u", "f_pos", "f_vel", "target", "x0")


def _estimator_problems(problems: list[Mapping[str, Any]]) -> list[str]:
    """Unique names and per-kind requirements of ``estimators.problems`` entries."""
    out = []
    names = [spec.get("name") for spec in problems]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        out.append(f"estimators.problems: duplicate name(s) {dupes} (allowed: unique names)")
    for i, spec in enumerate(problems):
        path = f"estimators.problems[{i}] ({spec.get('name')})"
        u = spec.get("u", [])
        if spec.get("kind") == "scalar_lqg":
            if any(isinstance(v, list) for v in u):
                out.append(f"{path}.u: {u} must be a list of numbers for kind scalar_lqg")
            for key in ("x0", "target"):
                if isinstance(spec.get(key), list):
                    out.append(f"{path}.{key}: must be a number for kind scalar_lqg")
            extra = sorted(set(spec) & (set(NCV_KEYS) - {"x0", "target"}))
            if extra:
                out.append(f"{path}: {extra} only apply to kind ncv_2d")
        elif spec.get("kind") == "ncv_2d":
            missing = [k for k in NCV_KEYS if k not in spec]
            if missing:
                out.append(f"{path}: kind ncv_2d needs {missing}")
            for key in ("target", "x0"):
                val = spec.get(key)
                if key in spec and (not isinstance(val, list) or len(val) != 4):
                    out.append(
                        f"{path}.{key}: {val!r} must be a list of 4 numbers (px, py, vx, vy)"
                    )
            if not all(isinstance(v, list) for v in u):
                out.append(f"{path}.u: {u} must be a list of [ax, ay] pairs for kind ncv_2d")
            extra = sorted(set(spec) & {"a", "sigma", "r"})
            if extra:
                out.append(f"{path}: {extra} only apply to kind scalar_lqg")
    return out


def _strict_integer(checker, instance) -> bool:
    """JSON Schema's "integer" without whole-number floats: ``seed: 7.0`` or ``chunks: 2.0``
    are refused (they would otherwise reach names and seeds as floats)."""
    return isinstance(instance, int) and not isinstance(instance, bool)


def _finite_number(checker, instance) -> bool:
    """JSON Schema's "number" without NaN and infinity (YAML's ``.nan``, ``.inf``)."""
    return (
        isinstance(instance, int | float)
        and not isinstance(instance, bool)
        and math.isfinite(instance)
    )


_Validator = validators.extend(
    Draft202012Validator,
    type_checker=Draft202012Validator.TYPE_CHECKER.redefine_many(
        {"integer": _strict_integer, "number": _finite_number}
    ),
)


def _non_finite(node: Any, path: tuple = ()) -> list[str]:
    """Every NaN or infinite float anywhere in the config (also where the schema allows any
    value), as a message naming its key."""
    if isinstance(node, float) and not math.isfinite(node):
        return [f"{_dotted(path)}: {node!r} is not a finite number (allowed: finite numbers)"]
    if isinstance(node, Mapping):
        return [m for k, v in node.items() for m in _non_finite(v, (*path, k))]
    if isinstance(node, list | tuple):
        return [m for i, v in enumerate(node) for m in _non_finite(v, (*path, i))]
    return []


def check_config(
    config: Mapping[str, Any], schema: Mapping[str, Any] | str | os.PathLike | None = None
) -> None:
    """Raise :class:`ConfigError` listing every problem of ``config``; return None if valid.

    ``schema`` is the schema mapping or its path (default: the repository's schema file).
    """
    schema = load_schema(schema) if not isinstance(schema, Mapping) else with_methods(schema)
    validator = _Validator(schema)
    errors = sorted(
        validator.iter_errors(dict(config)), key=lambda e: list(map(str, e.absolute_path))
    )
    problems = _non_finite(config)
    flagged = {p.split(":")[0] for p in problems}
    problems += [m for m in map(_message, errors) if m.split(":")[0] not in flagged]
    if not problems:
        problems = _cross_field(config)
    if problems:
        raise ConfigError(
            "invalid configuration (nothing was run):\n  - " + "\n  - ".join(problems)
        )


def main(argv: list[str] | None = None) -> int:
    """``python -m rsmhp.pipeline.config [FILE ...]``: check config files as the workflow would use
    them (``config/config.yaml`` overlaid by each FILE in order, then every check of
    :func:`check_config`); print every problem with its file and line or key. Exit status 0
    if valid, 1 if not."""
    files = [Path(a) for a in (sys.argv[1:] if argv is None else argv)]
    try:
        config = load_config_file(CONFIG_PATH)
        for f in files:
            config = merge(config, load_config_file(f))
        check_config(config)
    except ConfigError as exc:
        print(exc, file=sys.stderr)
        return 1
    print(f"valid: {', '.join(map(str, [CONFIG_PATH, *files]))}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
