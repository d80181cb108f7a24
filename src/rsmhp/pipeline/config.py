"""Configuration checks with messages that name the field and its allowed range.

:func:`check_config` validates a config mapping against ``workflow/schemas/config.schema.yaml``
(JSON Schema draft 2020-12) and then checks the constraints a schema cannot express
(``M <= N``, ``P.start <= P.stop``...): those of the shared sections here, those of a study's
section in the study's own package (``rsmhp.studies.<study>.checks.config_problems``, found by
:func:`studies`; the helpers they share are the public functions below). A key that moved
(:data:`MOVED`) is refused first, with where it went. It reports *every* problem at once, each as
``<dotted.path>: <value> <what is wrong> (allowed: <range>)``, and raises
:class:`ConfigError` before any job starts. The Snakefile calls it, then snakemake's own
``validate`` (which also fills defaults).
"""

from __future__ import annotations

import copy
import importlib
import importlib.util
import math
import os
import pkgutil
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml
from jsonschema import Draft202012Validator, validators
from jsonschema.exceptions import ValidationError

from rsmhp.models.uav import methods as uav_methods
from rsmhp.pipeline.config_layout import ADDED, MOVED, hash_view

__all__ = [
    "ADDED",
    "CONFIG_PATH",
    "MOVED",
    "SCHEMA_PATH",
    "ConfigError",
    "baseline_problems",
    "check_config",
    "hash_view",
    "late_steps",
    "load_config_file",
    "load_schema",
    "member_names",
    "merge",
    "model_names",
    "run_steps",
    "studies",
    "study_checks",
    "typed_overrides",
]

ROOT = Path(__file__).resolve().parents[3]
SCHEMA_PATH = ROOT / "workflow" / "schemas" / "config.schema.yaml"
CONFIG_PATH = ROOT / "config" / "config.yaml"


#: PyYAML's safe loader, libyaml's (C) where PyYAML has it, for the schema (our own file): read
#: about ten times faster (it took 0.6 s of every parse of the workflow). A user's config file
#: keeps the pure-Python loader, which refuses what libyaml lets through (a tab after a colon)
SAFE_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class ConfigError(ValueError):
    """The configuration is invalid; the message lists every offending field."""


def load_schema(path: str | os.PathLike | None = None) -> dict[str, Any]:
    """The config schema with every registered UAV method family's fragment inserted into
    ``$defs/uav_methods`` (:func:`rsmhp.models.uav.methods.schema`): the file itself names no
    family, so a new method needs no schema edit."""
    with open(path or SCHEMA_PATH, encoding="utf-8") as fh:
        schema = yaml.load(fh, Loader=SAFE_LOADER)
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
        data = yaml.safe_load(text)  # not libyaml's: it accepts a tab after a colon
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


def _moved(config: Mapping[str, Any]) -> list[str]:
    problems = []
    for path, where in MOVED.items():
        node: Any = config
        for key in path:
            node = node.get(key) if isinstance(node, Mapping) else None
        if node is not None:
            problems.append(
                f"{'.'.join(path)}: this key moved to {where} in version 5; move its value "
                "there (allowed: no such key)"
            )
    return problems


def studies() -> list[str]:
    """The study packages of :mod:`rsmhp.studies` that have a ``checks`` module (each the
    config checks and memory estimates of its config section), in name order."""
    import rsmhp.studies

    return [
        info.name
        for info in pkgutil.iter_modules(rsmhp.studies.__path__)
        if info.ispkg and importlib.util.find_spec(f"rsmhp.studies.{info.name}.checks") is not None
    ]


def study_checks(name: str) -> Any:
    """The ``checks`` module of study ``name`` (:func:`studies`)."""
    return importlib.import_module(f"rsmhp.studies.{name}.checks")


def _cross_field(config: Mapping[str, Any]) -> list[str]:
    """Constraints between fields that JSON Schema cannot express: the shared sections'
    here, then every study's (its ``checks.config_problems``, as the method registry asks
    every family)."""
    names = [m.get("name") for m in config.get("uav_models", []) or [] if isinstance(m, Mapping)]
    dup = sorted({n for n in names if names.count(n) > 1})
    problems = []
    if dup:
        problems.append(f"uav_models: duplicate name(s) {dup} (allowed: unique names)")
    for name in studies():
        problems += study_checks(name).config_problems(config)
    return problems


# ------------------------------------------------------------------ helpers of the studies' checks


def run_steps(config: Mapping[str, Any]) -> int:
    """The steps of a UAV closed-loop run (``uav.scenario.steps``, default 60)."""
    return ((config.get("uav", {}) or {}).get("scenario", {}) or {}).get("steps", 60)


def late_steps(path: str, steps: Any, n_steps: int) -> list[str]:
    """The problem of belief-state steps at ``path`` that are not before a run's last step."""
    late = [s for s in steps or [] if isinstance(s, int) and s >= n_steps]
    if not late:
        return []
    return [
        f"{path}: {late} not before the run's last step (allowed: 0 <= step < "
        f"uav.scenario.steps = {n_steps})"
    ]


def model_names(config: Mapping[str, Any]) -> list[Any]:
    """The names of the UAV model variants (``uav_models``) the studies may name."""
    return [m.get("name") for m in config.get("uav_models", []) or [] if isinstance(m, Mapping)]


def member_names(methods: Any) -> dict[str, Any]:
    """name -> Method of a methods block ({} where the block is invalid: reported elsewhere)."""
    if not isinstance(methods, Mapping):
        return {}
    try:
        return dict(uav_methods.from_config(methods))
    except (ValueError, TypeError, KeyError):
        return {}


def baseline_problems(path: str, methods: Mapping[str, Any], why: str) -> list[str]:
    """The problem of a methods block at ``path`` without the baseline family (NBO), which
    is ``why`` (e.g. "the baseline of the regret")."""
    base = uav_methods.baseline()
    if methods.get(base.config_key, base.default):
        return []
    return [
        f"{path}.{base.config_key}: {str(methods.get(base.config_key)).lower()} (allowed: true; "
        f"{base.family_label} is {why})"
    ]


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
    moved = _moved(config)
    if moved:
        raise ConfigError("invalid configuration (nothing was run):\n  - " + "\n  - ".join(moved))
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
