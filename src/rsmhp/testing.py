r"""Conformance check of a UAV planning-method family: :func:`check_method` (the analogue of
scikit-learn's ``check_estimator``), the first thing to run on a new family.

``check_method(cls)`` takes a registered :class:`rsmhp.models.uav.methods.Method` subclass
and checks the contract of :mod:`rsmhp.models.uav.methods.base` on a few configured members,
on a small setup (horizon :data:`HORIZON`, a short optimiser budget: seconds). It raises
``AssertionError`` at the first failure, with a message naming the family, the member where
there is one, and the failed property (the ``[...]`` tag below); it returns a
:class:`CheckReport` otherwise.

Members: those given (``members``), else ``cls.from_config(value)`` for the given ``value``,
else for the family's optional ``example`` class attribute (a small config value), else for
a small value derived from the family's ``schema`` (the two smallest of 4, 8, 16, 2, 1, ...
that the schema and :meth:`~rsmhp.models.uav.methods.Method.from_config` accept; ``True`` for a
flag; required object fields only), else for ``default``.

Properties
----------
Class (``[class attributes]``, ``[schema]``, ``[default]``, ``[colour_key]``, ``[registry]``):
``family``, ``config_key``, ``family_label`` non-empty strings without spaces (the label may
have them); ``schema`` a valid JSON Schema (``check_schema``); ``default`` valid against it,
and, for a family of an installed plugin (:func:`rsmhp.models.uav.methods.plugins`), building no
member (a plugin changes no run it is not configured in); ``colour_key`` a key of
:data:`rsmhp.report.palette.METHOD_COLOURS` or a hex colour ``#rrggbb`` (a family the palette
does not know); ``order`` an int; ``baseline``, ``uses_rng``, ``estimates_cost`` bools; the
class registered, and exactly one baseline family. ``config_key`` and ``colour_key`` default to
the family's id where the family does not set them (``Method.derived_attributes`` lists
which), so a new family whose id the palette does not know fails ``[colour_key]`` until it
sets a colour.

Members (``[config]``, ``[names]``, ``[round trip]``, ``[spec]``, ``[columns]``,
``[job_key]``, ``[presentation]``, ``[registry config]``, ``[config schema]``): the config
value is valid against the schema, has no cross-field problem and builds them through the
family, and through the registry (among the other families' defaults), counted by
``methods.count``; the config schema's ``methods`` blocks (``$defs/uav_methods`` of
:func:`rsmhp.pipeline.config.load_schema`: ``uav.methods``, ``decisions.uav.methods``, ...)
accept ``{config_key: value}``; names non-empty, of ``[A-Za-z0-9_.-]`` (rule wildcards and
file names), unique, claimed by no other registered family, and the family's ``parse`` gives
``None`` for other names (it must not raise: :func:`~rsmhp.models.uav.methods.from_name` asks
every family in turn); ``cls.parse(m.name) == m``, ``from_name(m.name) == m`` and
``from_spec(m.spec()) == m`` (and hashable);
``columns()`` exactly ``N_T``, ``N``, ``M``, integers :math:`\ge 0`; ``job_key()`` a
JSON-serialisable mapping with ``job_key()["method"] == m.name``, none of the closed loop's
own keys (``run``, ``step``, ``experiment``), distinct across members and usable by
:func:`rsmhp.core.seeding.job_rng`; ``spec()`` JSON-serialisable with the family;
``label()`` a non-empty string, ``shade_size()`` ``None`` or a positive int, the palette
colours the member (:func:`rsmhp.report.palette.method_colour` by name equals
:func:`~rsmhp.report.palette.member_colour`).

Hypotheses, for a family with ``estimates_cost`` (``[hypotheses]``, ``[weights]``,
``[determinism]``, ``[stream independence]``): drawn from the member's closed-loop stream
``job_rng(seed, "uav_plan", run=0, step=1, **m.job_key())``, a
:class:`~rsmhp.models.uav.methods.Hypotheses` with states (T, H, 4), T >= 1, finite; weights
(T,) finite, :math:`\ge 0`, :math:`|\sum_i \omega_i - 1| \le 10^{-12}`; ``noise`` ``None``
or (T, H + 1, 4) finite and reproducing the states (:math:`x_0 = \hat x + n_0`,
:math:`x_j = F x_{j-1} + n_j`); the belief is not modified. Determinism: the same seed gives
identical arrays, also from an equal fresh member; with ``uses_rng`` another seed gives other
hypotheses, without it ``rng=None`` gives the same ones. Independence: the draws depend only
on the member's own stream: not on numpy's or Python's global random state, nor on draws made
in between by the other members (no state carried from call to call).

Planning step (``[planner]``, ``[plan]``, ``[time per step]``, ``[planner protocol]``,
``[plan determinism]``, ``[plan independence]``): ``m.planner(setup)`` is a
:class:`rsmhp.models.uav.planner.Planner`; ``plan(belief, zeros (H, 2), rng)`` (``rng=None``
without ``uses_rng``, as the closed loop calls it) returns a
:class:`~rsmhp.models.uav.planner.PlanResult` with controls (H, 2) finite and within
:math:`\pm` ``uav.control_scale``; ``uav_path`` (H, 4) the kinematic rollout of those
controls; a finite ``cost``; ``cost_warm`` a float; ``nit``, ``n_kernel_calls`` ints
:math:`\ge 0`; ``diagnostics`` a mapping of names to floats; ``converged`` ``None`` or a
bool; ``hypotheses`` ``None`` or valid hypotheses of horizon H. Time per step: the step's wall
time (what the closed loop sums into ``plan_seconds``; :attr:`CheckReport.plan_seconds`) is
positive and finite, and the step reports its compute: ``work`` (machine-independent, in model
steps; the closed loop's ``work_per_step``, the frontier study's budget axis) an int
:math:`> 0` that fits an int64, and at least one cost evaluation (T H model steps) when the
plan has T hypotheses (:attr:`CheckReport.plan_work`). The planner protocol: a family with a
cost estimate (``estimates_cost``, the default) returns the hypotheses it planned over, those
of :meth:`~rsmhp.models.uav.methods.Method.hypotheses` for the same stream (the decision study
scores its own cost of other plans with them); a family without (``estimates_cost`` False, a
tree search planning over simulated beliefs) overrides
:meth:`~rsmhp.models.uav.methods.Method.planner` (the default plans over hypotheses), returns
``hypotheses=None`` and its :meth:`~rsmhp.models.uav.methods.Method.hypotheses` raises
``NotImplementedError`` (no study asks it for any); with ``uses_rng`` the plan depends on the
stream (another seed gives another result), without it planning with a stream (the decision
study passes one to every member) gives the same result as with ``None``. Determinism and
independence: the same planner planning again with the same seed (and other global random
state) gives the identical result; so does a fresh planner of an equal fresh member
(``from_spec``) after the other members and the baseline have planned; the belief and warm
start are not modified.

Closed loop (``[closed loop]``): ``closed_loop`` is one of
:data:`rsmhp.models.uav.loop.KINDS`; :attr:`CheckReport.loop` says which loop each member's
runs take and why (:func:`rsmhp.models.uav.loop.path`); a member on the compiled loop gives
the Python loop's step rows bit for bit (float hex) and its summary (all but the timing) on
two short runs.
"""

from __future__ import annotations

import json
import math
import random
import re
import time
from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import jsonschema
import numpy as np

from rsmhp.core.seeding import job_rng
from rsmhp.models.uav import loop
from rsmhp.models.uav import methods as registry
from rsmhp.models.uav.kinematics import UAVParams, rollout
from rsmhp.models.uav.methods import COLUMNS, Hypotheses, Method
from rsmhp.models.uav.planner import Belief, Planner, PlannerParams, PlanResult
from rsmhp.models.uav.sensor import SensorModel
from rsmhp.models.uav.simulation import UAVSetup, simulate_run
from rsmhp.models.uav.target import TargetModel
from rsmhp.report import palette

__all__ = ["HORIZON", "CheckReport", "check_method", "example_belief", "example_setup"]

#: planning horizon of :func:`example_setup`
HORIZON = 4
#: root seed of the streams the check draws from
SEED = 20240601
#: tolerance of :math:`|\sum_i \omega_i - 1|`
WEIGHT_TOL = 1e-12
#: keys the closed loop adds to a member's job key (``job_rng(seed, "uav_plan", run=r,
#: step=k, **job_key)``)
_RESERVED_KEYS = ("run", "step", "experiment")
_NAME = re.compile(r"[A-Za-z0-9_.\-]+")
_TOKEN = re.compile(r"[A-Za-z0-9_]+")
_HEX = re.compile(r"#[0-9a-fA-F]{6}")


@dataclass(frozen=True)
class CheckReport:
    """What :func:`check_method` checked: the family, its members' names, the properties (in
    the order checked), the wall time (s) of each member's planning step and its reported
    compute (``PlanResult.work``, model steps)."""

    family: str
    members: tuple[str, ...]
    checks: tuple[str, ...]
    plan_seconds: dict[str, float] = field(default_factory=dict)
    plan_work: dict[str, int] = field(default_factory=dict)
    #: the closed loop each member's runs take on the check's setup: ``(path, reason)`` with
    #: path ``"compiled"`` or ``"python"`` (:func:`rsmhp.models.uav.loop.path`)
    loop: dict[str, tuple[str, str]] = field(default_factory=dict)


def example_setup(horizon: int = HORIZON) -> UAVSetup:
    """A small UAV setup: the paper's aircraft, target and sensor (``config/config.yaml``),
    horizon ``horizon``, an optimiser budget of 10 iterations and 20 evaluations."""
    return UAVSetup(
        uav=UAVParams(
            dt=1.0,
            g=9.81,
            accel_max=3.0,
            bank_max=math.radians(45.0),
            speed_min=10.0,
            speed_max=35.0,
            altitude=100.0,
        ),
        target=TargetModel(dt=1.0, q=1.0),
        sensor=SensorModel(0.05, 0.10, 100.0),
        planner=PlannerParams(horizon=horizon, maxiter=10, maxfun=20),
        P0=np.diag([50.0**2, 50.0**2, 5.0**2, 5.0**2]),
        steps=5,
        scenario={
            "target_box": 200.0,
            "target_speed_min": 5.0,
            "target_speed_max": 12.0,
            "uav_distance_min": 300.0,
            "uav_distance_max": 600.0,
            "uav_speed": 20.0,
        },
    )


def example_belief() -> Belief:
    """A belief 300 m from the UAV with a correlated (non-diagonal) covariance."""
    P_hat = np.array(
        [
            [900.0, 120.0, 30.0, -4.0],
            [120.0, 400.0, 5.0, 9.0],
            [30.0, 5.0, 16.0, 1.0],
            [-4.0, 9.0, 1.0, 9.0],
        ]
    )
    return Belief(np.array([0.0, 0.0, 20.0, 0.0]), np.array([300.0, -50.0, 6.0, 2.0]), P_hat)


# ------------------------------------------------------------------------- the checker


class _Checker:
    """Names every failure after the family (and member) and the property checked."""

    def __init__(self, cls: type) -> None:
        self.cls = cls
        family = getattr(cls, "family", "?")
        self.where = f"{getattr(cls, '__name__', cls)!r} (family {family!r})"
        self.done: list[str] = []

    def fail(self, prop: str, detail: str, member: Method | None = None) -> None:
        where = self.where
        if member is not None:
            where += f", member {_safe_name(member)!r}"
        raise AssertionError(f"check_method {where}: [{prop}] {detail}")

    def that(self, ok: bool, prop: str, detail: str, member: Method | None = None) -> None:
        if not ok:
            self.fail(prop, detail, member)

    @contextmanager
    def step(self, prop: str, member: Method | None = None) -> Iterator[None]:
        """Run a block; an exception other than an ``AssertionError`` of the check is a
        failure of ``prop``."""
        try:
            yield
        except AssertionError as e:
            if str(e).startswith("check_method "):
                raise
            self.fail(prop, f"{type(e).__name__}: {e}", member)
        except Exception as e:
            self.fail(prop, f"raised {type(e).__name__}: {e}", member)
        if prop not in self.done:
            self.done.append(prop)


def _safe_name(m: Any) -> str:
    try:
        return str(m.name)
    except Exception:
        return repr(m)


def check_method(
    cls: type[Method],
    members: Iterable[Method] | None = None,
    *,
    value: Any = None,
    setup: UAVSetup | None = None,
    belief: Belief | None = None,
) -> CheckReport:
    """Check the family ``cls`` and its members against the method contract (module
    docstring); ``AssertionError`` naming the family, the member and the property at the
    first failure. ``members``: configured members of ``cls`` to check; otherwise built from
    the config ``value`` (or the family's example, see the module docstring). ``setup`` and
    ``belief`` default to :func:`example_setup` and :func:`example_belief`."""
    c = _Checker(cls)
    with c.step("class attributes"):
        c.that(
            isinstance(cls, type) and issubclass(cls, Method),
            "class attributes",
            f"expected a subclass of rsmhp.models.uav.methods.Method, got {cls!r}",
        )
    _check_class(c, cls)
    setup = example_setup() if setup is None else setup
    belief = example_belief() if belief is None else belief
    built, value = _members(c, cls, members, value, setup)
    _check_members(c, cls, built)
    if value is not None:
        _check_registry_config(c, cls, built, value)
    seconds: dict[str, float] = {}
    work: dict[str, int] = {}
    for m in built:
        if cls.estimates_cost:
            _check_hypotheses(c, m, built, setup, belief)
        seconds[m.name], work[m.name] = _check_plan(c, m, built, setup, belief)
    loops = {m.name: _check_loop(c, m, setup) for m in built}
    names = tuple(m.name for m in built)
    return CheckReport(cls.family, names, tuple(c.done), seconds, work, loops)


def _check_loop(c: _Checker, m: Method, setup: UAVSetup) -> tuple[str, str]:
    """Which closed loop the member's runs take; a compiled one must give the Python loop's
    rows bit for bit (two short runs, every column, the summary but its timing)."""
    with c.step("closed loop", m):
        c.that(
            vars(type(m)).get("closed_loop", "python") in loop.KINDS,
            "closed loop",
            f"closed_loop must be one of {sorted(loop.KINDS)}, got {type(m).closed_loop!r}",
            m,
        )
        which = loop.path(m, setup)
        if which[0] == "compiled":
            for run in (0, 1):
                a = simulate_run(setup, m, 11, run, path="python")
                b = simulate_run(setup, m, 11, run, path="compiled")
                for ra, rb in zip(a[1], b[1], strict=True):
                    c.that(
                        ra.keys() == rb.keys() and all(_same(v, rb[k]) for k, v in ra.items()),
                        "closed loop",
                        f"run {run} step {ra['step']}: the compiled loop's row {rb} differs "
                        f"from the Python loop's {ra}",
                        m,
                    )
                sa = {k: v for k, v in a[0].items() if k != "plan_seconds"}
                sb = {k: v for k, v in b[0].items() if k != "plan_seconds"}
                c.that(
                    sa == sb,
                    "closed loop",
                    f"run {run}: summaries differ: {sb} against the Python loop's {sa}",
                    m,
                )
    return which


def _same(a: Any, b: Any) -> bool:
    """Equal, floats bit for bit (their hex forms)."""
    if isinstance(a, float) and isinstance(b, float):
        return a.hex() == b.hex()
    return type(a) is type(b) and a == b


# ------------------------------------------------------------------------------ class


def _check_class(c: _Checker, cls: type[Method]) -> None:
    with c.step("class attributes"):
        for attr in ("family", "config_key"):
            v = getattr(cls, attr, None)
            c.that(
                isinstance(v, str) and _TOKEN.fullmatch(v) is not None,
                "class attributes",
                f"{attr} must be a non-empty string of [A-Za-z0-9_], got {v!r}",
            )
        label = getattr(cls, "family_label", None)
        c.that(
            isinstance(label, str) and label.strip() != "",
            "class attributes",
            f"family_label must be a non-empty string, got {label!r}",
        )
        order = getattr(cls, "order", None)
        c.that(
            isinstance(order, int) and not isinstance(order, bool),
            "class attributes",
            f"order must be an int, got {order!r}",
        )
        for attr in ("baseline", "uses_rng", "estimates_cost"):
            v = getattr(cls, attr, None)
            c.that(isinstance(v, bool), "class attributes", f"{attr} must be a bool, got {v!r}")
        pattern = getattr(cls, "name_pattern", None)
        if pattern is not None:
            c.that(
                isinstance(pattern, str),
                "class attributes",
                f"name_pattern must be a str, got {pattern!r}",
            )
            re.compile(pattern)
        for attr in ("schema", "default"):
            c.that(hasattr(cls, attr), "class attributes", f"{attr} is missing")
    with c.step("schema"):
        schema = cls.schema
        c.that(
            isinstance(schema, Mapping),
            "schema",
            f"must be a mapping (a JSON Schema), got {type(schema).__name__}",
        )
        try:
            _validator(schema).check_schema(schema)
        except jsonschema.SchemaError as e:
            c.fail("schema", f"not a valid JSON Schema: {e.message}")
        json.dumps(schema)
    with c.step("default"):
        errors = list(_validator(cls.schema)(cls.schema).iter_errors(cls.default))
        c.that(
            not errors,
            "default",
            f"{cls.default!r} is not valid against the schema: "
            + "; ".join(e.message for e in errors),
        )
        plugin = next((p for p in registry.plugins() if p.cls is cls), None)
        if plugin is not None:
            n = len(cls.from_config(cls.default, f"methods.{cls.config_key}"))
            c.that(
                n == 0,
                "default",
                f"a plugin family (distribution {plugin.distribution!r}) must configure no "
                f"member by default (installing it must change no existing run), but "
                f"{cls.default!r} builds {n}",
            )
    with c.step("colour_key"):
        key = getattr(cls, "colour_key", None)
        c.that(
            isinstance(key, str) and (key in palette.METHOD_COLOURS or _HEX.fullmatch(key)),
            "colour_key",
            f"{key!r} is neither a key of rsmhp.report.palette.METHOD_COLOURS "
            f"(allowed: {sorted(palette.METHOD_COLOURS)}) nor a hex colour '#rrggbb'"
            + (
                "; it defaults to the family id: set colour_key to a hex colour"
                if "colour_key" in getattr(cls, "derived_attributes", ())
                else ""
            ),
        )
    with c.step("registry"):
        fams = registry.families()
        c.that(
            cls in fams,
            "registry",
            "the class is not registered (decorate it with rsmhp.models.uav.methods.register)",
        )
        base = [f.family for f in fams if f.baseline]
        c.that(
            len(base) == 1,
            "registry",
            f"exactly one registered family must be the baseline, found {base}",
        )


def _validator(schema: Mapping[str, Any]) -> type:
    return jsonschema.validators.validator_for(schema, default=jsonschema.Draft202012Validator)


# ---------------------------------------------------------------------------- members


def _members(
    c: _Checker, cls: type[Method], members: Iterable[Method] | None, value: Any, setup: UAVSetup
) -> tuple[list[Method], Any]:
    """The members to check and the config value that built them (``None``: given)."""
    uav = {"planner": {"horizon": setup.planner.horizon}}
    path = f"methods.{cls.config_key}"
    if members is not None:
        built = list(members)
        with c.step("config"):
            for m in built:
                c.that(
                    isinstance(m, cls),
                    "config",
                    f"members must be instances of {cls.__name__}, got {m!r}",
                )
    else:
        if value is None:
            value = _example_value(cls, uav)
            c.that(
                value is not None,
                "config",
                "no member to check: the family has no `example`, no small schema-valid "
                "value builds members and its default builds none (pass members= or value=)",
            )
        with c.step("config"):
            errors = list(_validator(cls.schema)(cls.schema).iter_errors(value))
            c.that(
                not errors,
                "config",
                f"{value!r} is not valid against the schema: "
                + "; ".join(e.message for e in errors),
            )
            problems = cls.config_problems(value, path, uav)
            c.that(
                isinstance(problems, list) and not problems,
                "config",
                f"config_problems of {value!r}: {problems!r}",
            )
            built = list(cls.from_config(value, path))
            for m in built:
                c.that(
                    isinstance(m, cls),
                    "config",
                    f"from_config must build {cls.__name__} members, got {m!r}",
                )
    c.that(bool(built), "config", "no member to check")
    return built, value


def _check_registry_config(c: _Checker, cls: type[Method], built: list[Method], value: Any) -> None:
    """The registry builds the family's members of ``value`` among the others' defaults
    (unique names, table order) and counts them."""
    path = f"methods.{cls.config_key}"
    with c.step("registry config"):
        via = registry.from_config({cls.config_key: value}, "methods")
        mine = [m for m in via.values() if type(m) is cls]
        c.that(
            sorted(mine, key=_safe_name) == sorted(built, key=_safe_name),
            "registry config",
            f"the registry's from_config builds {mine!r}, the family's {built!r}",
        )
        n = registry.count({cls.config_key: value}) - registry.count({})
        n_default = len(cls.from_config(cls.default, path))
        c.that(
            n + n_default == len(built),
            "registry config",
            f"methods.count counts {n + n_default} members of {value!r}, "
            f"from_config builds {len(built)}",
        )
    with c.step("config schema"):
        schema = _methods_block_schema()
        block = schema["$defs"]["uav_methods"]
        c.that(
            cls.config_key in block.get("properties", {}),
            "config schema",
            f"the config schema's methods blocks ($defs/uav_methods) have no key "
            f"{cls.config_key!r} (rsmhp.pipeline.config.load_schema inserts "
            "rsmhp.models.uav.methods.schema())",
        )
        errors = list(_validator(schema)(schema).iter_errors({cls.config_key: value}))
        c.that(
            not errors,
            "config schema",
            f"the config schema's methods blocks refuse {{{cls.config_key!r}: {value!r}}}: "
            + "; ".join(e.message for e in errors),
        )


def _methods_block_schema() -> dict[str, Any]:
    """A schema of one ``methods`` block of the config (``uav.methods`` and the others): the
    config schema's ``$defs/uav_methods`` with the registry's families, as
    :func:`rsmhp.pipeline.config.load_schema` builds it (outside a checkout, without the
    schema file: the registry's part alone)."""
    from rsmhp.pipeline import config

    if config.SCHEMA_PATH.is_file():
        defs = config.load_schema()["$defs"]
    else:
        defs = config.with_methods({"$defs": {"uav_methods": {"type": "object"}}})["$defs"]
    return {"$ref": "#/$defs/uav_methods", "$defs": defs}


def _example_value(cls: type[Method], uav: Mapping[str, Any]) -> Any:
    """The config value of the members checked by default (module docstring), or ``None``."""
    candidates: list[Any] = []
    if hasattr(cls, "example"):
        candidates.append(cls.example)
    try:
        candidates += _schema_examples(cls.schema)
    except Exception:  # an unusual schema: fall back to the default
        pass
    candidates.append(cls.default)
    for value in candidates:
        try:
            if not _validator(cls.schema)(cls.schema).is_valid(value):
                continue
            if cls.config_problems(value, "x", uav):
                continue
            if cls.from_config(value, "x"):
                return value
        except Exception:
            continue
    return None


#: the small numbers tried first for an integer or number of a schema
_SMALL = (4, 8, 16, 2, 1, 32, 64, 3, 5, 6)


def _schema_examples(schema: Mapping[str, Any]) -> list[Any]:
    """Small values for ``schema``, preferred first (not all of them valid)."""
    if "enum" in schema:
        return list(schema["enum"])
    if "const" in schema:
        return [schema["const"]]
    kind = schema.get("type")
    ok = _validator(schema)(schema).is_valid
    if kind == "boolean":
        return [True]
    if kind in ("integer", "number"):
        return [v for v in _SMALL if ok(v)][:3]
    if kind == "array":
        items = [v for v in _schema_examples(schema.get("items", {})) if ok([v])]
        return [items[:2], items[:1]] if items else []
    if kind == "object":
        props = schema.get("properties", {})
        required = list(schema.get("required", []))
        options = {k: _schema_examples(props.get(k, {})) for k in required}
        if any(not v for v in options.values()):
            return []
        first = {k: v[0] for k, v in options.items()}
        out = [first]
        for k, v in options.items():  # a second object: the first field that can differ
            if len(v) > 1:
                out.append({**first, k: v[1]})
                break
        return out
    return []


def _check_members(c: _Checker, cls: type[Method], built: list[Method]) -> None:
    names: list[str] = []
    for m in built:
        with c.step("names", m):
            name = m.name
            c.that(
                isinstance(name, str) and _NAME.fullmatch(name) is not None,
                "names",
                f"name must be a non-empty string of [A-Za-z0-9_.-], got {name!r}",
                m,
            )
            names.append(name)
            for other in registry.families():
                if other is cls:
                    continue
                claimed = other.parse(name)
                c.that(
                    claimed is None,
                    "names",
                    f"the name is also a name of family {other.family!r} ({claimed!r})",
                    m,
                )
    dup = sorted({n for n in names if names.count(n) > 1})
    c.that(not dup, "names", f"names {dup} are not unique across the members")
    with c.step("names"):
        foreign = ("", "x", "nbo", "rsmhp_nt4", "tree_n8_m100", "dpw_s8", "lhs_nt4")
        for n in (*foreign, *(f"{name}_x" for name in names), *(f"x{name}" for name in names)):
            if n in names:
                continue
            try:
                got = cls.parse(n)
            except Exception as e:
                c.fail("names", f"parse({n!r}) raised {type(e).__name__}: {e} (must be None)")
            c.that(
                got is None or _safe_name(got) == n,
                "names",
                f"parse({n!r}) must be None (not a name of the family), got {got!r}",
            )
    keys: dict[str, str] = {}
    for m in built:
        with c.step("round trip", m):
            c.that(hash(m) == hash(m), "round trip", "not hashable", m)
            own = cls.parse(m.name)
            c.that(own == m, "round trip", f"{cls.__name__}.parse(name) gives {own!r}", m)
            back = registry.from_name(m.name)
            c.that(back == m, "round trip", f"from_name(name) gives {back!r}, not {m!r}", m)
            spec = m.spec()
            c.that(isinstance(spec, Mapping), "spec", f"spec() must be a dict, got {spec!r}", m)
            again = registry.from_spec(spec)
            c.that(again == m, "round trip", f"from_spec(spec()) gives {again!r}", m)
        with c.step("spec", m):
            c.that(
                spec.get("family") == cls.family,
                "spec",
                f"spec()['family'] must be {cls.family!r}, got {spec.get('family')!r}",
                m,
            )
            json.dumps(spec)
        with c.step("columns", m):
            cols = m.columns()
            c.that(
                isinstance(cols, Mapping) and set(cols) == set(COLUMNS),
                "columns",
                f"columns() must have exactly the keys {list(COLUMNS)}, got {cols!r}",
                m,
            )
            for k, v in cols.items():
                c.that(
                    isinstance(v, int | np.integer) and not isinstance(v, bool) and v >= 0,
                    "columns",
                    f"columns()[{k!r}] must be an int >= 0, got {v!r}",
                    m,
                )
        with c.step("job_key", m):
            key = m.job_key()
            c.that(isinstance(key, Mapping), "job_key", f"must be a dict, got {key!r}", m)
            text = json.dumps(key, sort_keys=True)
            c.that(
                key.get("method") == m.name,
                "job_key",
                f"job_key()['method'] must be the name {m.name!r}, got {key.get('method')!r}",
                m,
            )
            bad = [k for k in _RESERVED_KEYS if k in key]
            c.that(not bad, "job_key", f"holds the closed loop's own key(s) {bad}", m)
            c.that(
                text not in keys,
                "job_key",
                f"the same job key as member {keys.get(text)!r}: they would draw the same streams",
                m,
            )
            keys[text] = m.name
            job_rng(SEED, "uav_plan", run=0, step=1, **key)
        with c.step("presentation", m):
            label = m.label()
            c.that(
                isinstance(label, str) and label.strip() != "",
                "presentation",
                f"label() must be a non-empty string, got {label!r}",
                m,
            )
            size = m.shade_size()
            c.that(
                size is None
                or (isinstance(size, int | np.integer) and not isinstance(size, bool) and size > 0),
                "presentation",
                f"shade_size() must be None or an int > 0, got {size!r}",
                m,
            )
            colour = palette.member_colour(m)
            c.that(
                palette.method_colour(m.name) == colour,
                "presentation",
                f"method_colour(name) is {palette.method_colour(m.name)!r}, the member's "
                f"colour {colour!r}",
                m,
            )
            sorted([m, *built], key=lambda x: x.sort_key())


# ------------------------------------------------------------------------- hypotheses


def _stream(m: Method, seed: int = SEED) -> np.random.Generator:
    """The member's stream of the first planning step of run 0 (as the closed loop builds
    it)."""
    return job_rng(seed, "uav_plan", run=0, step=1, **m.job_key())


def _copy(belief: Belief) -> Belief:
    return Belief(
        *(np.array(a, dtype=float, copy=True) for a in (belief.uav, belief.x_hat, belief.P_hat))
    )


def _same_belief(a: Belief, b: Belief) -> bool:
    return all(
        np.array_equal(x, y) for x, y in ((a.uav, b.uav), (a.x_hat, b.x_hat), (a.P_hat, b.P_hat))
    )


def _same_hypotheses(a: Hypotheses, b: Hypotheses) -> bool:
    if (a.noise is None) != (b.noise is None):
        return False
    same = np.array_equal(a.states, b.states) and np.array_equal(a.weights, b.weights)
    return same and (a.noise is None or np.array_equal(a.noise, b.noise))


@contextmanager
def _global_random_state(seed: int) -> Iterator[None]:
    """numpy's and Python's global random generators seeded with ``seed``, restored after."""
    np_state, py_state = np.random.get_state(), random.getstate()  # noqa: NPY002
    np.random.seed(seed)  # noqa: NPY002
    random.seed(seed)
    try:
        yield
    finally:
        np.random.set_state(np_state)  # noqa: NPY002
        random.setstate(py_state)


def _validate_hypotheses(
    c: _Checker, m: Method, hyp: Any, belief: Belief, setup: UAVSetup, prop: str
) -> None:
    H = setup.planner.horizon
    c.that(
        isinstance(hyp, Hypotheses),
        prop,
        f"must be rsmhp.models.uav.methods.Hypotheses, got {type(hyp).__name__}",
        m,
    )
    s = np.asarray(hyp.states)
    c.that(
        s.ndim == 3 and s.shape[0] >= 1 and s.shape[1:] == (H, 4),
        prop,
        f"states must have shape (T, H, 4) = (T, {H}, 4) with T >= 1, got {s.shape}",
        m,
    )
    c.that(bool(np.isfinite(s).all()), prop, "states are not all finite", m)
    w = np.asarray(hyp.weights)
    T = s.shape[0]
    c.that(w.shape == (T,), "weights", f"weights must have shape ({T},), got {w.shape}", m)
    c.that(bool(np.isfinite(w).all()), "weights", "weights are not all finite", m)
    c.that(bool((w >= 0).all()), "weights", f"weights must be >= 0, min {w.min()!r}", m)
    total = float(w.sum())
    c.that(
        abs(total - 1.0) <= WEIGHT_TOL,
        "weights",
        f"weights sum to one: sum is {total!r} (|sum - 1| = {abs(total - 1.0):.3g} > "
        f"{WEIGHT_TOL:g})",
        m,
    )
    if hyp.noise is None:
        return
    n = np.asarray(hyp.noise)
    c.that(
        n.shape == (T, H + 1, 4),
        prop,
        f"noise must be None or of shape (T, H + 1, 4) = ({T}, {H + 1}, 4), got {n.shape}",
        m,
    )
    c.that(bool(np.isfinite(n).all()), prop, "noise is not all finite", m)
    F = setup.target.F
    x = np.asarray(belief.x_hat, dtype=float) + n[:, 0]
    scale = max(1.0, float(np.abs(s).max()))
    for j in range(H):
        x = x @ F.T + n[:, j + 1]
        err = float(np.abs(x - s[:, j]).max())
        c.that(
            err <= 1e-9 * scale,
            prop,
            f"noise does not reproduce the states (x_0 = x_hat + noise[:, 0], x_j = F x_(j-1) "
            f"+ noise[:, j]): max error {err:.3g} at step {j + 1}",
            m,
        )


def _check_hypotheses(
    c: _Checker, m: Method, built: list[Method], setup: UAVSetup, belief: Belief
) -> None:
    uses = m.uses_rng
    with c.step("hypotheses", m):
        before = _copy(belief)
        hyp = m.hypotheses(belief, setup, _stream(m))
        c.that(_same_belief(belief, before), "hypotheses", "hypotheses() modified the belief", m)
        _validate_hypotheses(c, m, hyp, belief, setup, "hypotheses")
    with c.step("determinism", m):
        again = m.hypotheses(belief, setup, _stream(m))
        c.that(
            _same_hypotheses(hyp, again),
            "determinism",
            "the same stream seed gives different hypotheses",
            m,
        )
        fresh = registry.from_spec(m.spec())
        c.that(
            _same_hypotheses(hyp, fresh.hypotheses(belief, setup, _stream(m))),
            "determinism",
            "an equal fresh member (from_spec) draws other hypotheses from the same stream",
            m,
        )
        if uses:
            other = m.hypotheses(belief, setup, _stream(m, SEED + 1))
            c.that(
                not _same_hypotheses(hyp, other),
                "determinism",
                "uses_rng is True but another stream seed gives identical hypotheses",
                m,
            )
        else:
            none = m.hypotheses(belief, setup, None)
            c.that(
                _same_hypotheses(hyp, none),
                "determinism",
                "uses_rng is False but hypotheses(rng=None) differ from those with a stream",
                m,
            )
    with c.step("stream independence", m):
        with _global_random_state(1):
            a = m.hypotheses(belief, setup, _stream(m) if uses else None)
        with _global_random_state(2):
            b = m.hypotheses(belief, setup, _stream(m) if uses else None)
        c.that(
            _same_hypotheses(a, b) and _same_hypotheses(a, hyp),
            "stream independence",
            "the hypotheses depend on numpy's or Python's global random state, not only on "
            "the member's stream",
            m,
        )
        # the other members draw in between (and a call with another seed): nothing carries over
        others = [o for o in built if o != m]
        baseline = registry.baseline()()
        for o in [*others, baseline]:
            if o.estimates_cost:
                o.hypotheses(belief, setup, _stream(o) if o.uses_rng else None)
        m.hypotheses(belief, setup, _stream(m, SEED + 2))
        c.that(
            _same_hypotheses(m.hypotheses(belief, setup, _stream(m)), hyp),
            "stream independence",
            "the hypotheses changed after other members' draws (state carried between calls)",
            m,
        )


# ---------------------------------------------------------------------------- planning


def _plan(m: Method, setup: UAVSetup, belief: Belief, seed: int = SEED, planner: Any = None):
    """One planning step of ``m`` as the closed loop makes it (its stream, or ``None``)."""
    planner = m.planner(setup) if planner is None else planner
    H = setup.planner.horizon
    return planner.plan(belief, np.zeros((H, 2)), _stream(m, seed) if m.uses_rng else None)


#: the fields of a PlanResult compared by the determinism checks
_PLAN_FIELDS = ("controls", "cost", "cost_warm", "nit", "n_kernel_calls", "work", "uav_path")


def _plan_diffs(a: PlanResult, b: PlanResult) -> list[str]:
    """The fields in which two plans differ (NaN equals NaN)."""
    out = []
    for f in _PLAN_FIELDS:
        x, y = np.asarray(getattr(a, f)), np.asarray(getattr(b, f))
        if not (x.shape == y.shape and np.array_equal(x, y, equal_nan=x.dtype.kind == "f")):
            out.append(f)
    da, db = dict(a.diagnostics), dict(b.diagnostics)
    if set(da) != set(db) or any(
        not np.array_equal(da[k], db[k], equal_nan=isinstance(da[k], float | np.floating))
        for k in da
    ):
        out.append("diagnostics")
    ha, hb = a.hypotheses, b.hypotheses
    if (ha is None) != (hb is None) or (ha is not None and not _same_hypotheses(ha, hb)):
        out.append("hypotheses")
    return out


def _check_plan(
    c: _Checker, m: Method, built: list[Method], setup: UAVSetup, belief: Belief
) -> tuple[float, int]:
    H = setup.planner.horizon
    uses = m.uses_rng
    with c.step("planner", m):
        c.that(
            m.estimates_cost or type(m).planner is not Method.planner,
            "planner protocol",
            "a family without a cost estimate (estimates_cost False) must override "
            "Method.planner (the default plans over hypotheses())",
            m,
        )
        planner = m.planner(setup)
        c.that(
            isinstance(planner, Planner),
            "planner",
            f"planner(setup) must have plan(belief, warm_start, rng), got {type(planner).__name__}",
            m,
        )
    with c.step("plan", m):
        warm = np.zeros((H, 2))
        before = _copy(belief)
        with _global_random_state(1):
            t0 = time.perf_counter()
            res = planner.plan(belief, warm, _stream(m) if uses else None)
            seconds = time.perf_counter() - t0
        c.that(_same_belief(belief, before), "plan", "plan() modified the belief", m)
        c.that(bool((warm == 0).all()), "plan", "plan() modified the warm start", m)
        _validate_plan(c, m, res, setup, belief)
        if type(m).planner is Method.planner and m.estimates_cost:
            own = m.hypotheses(belief, setup, _stream(m) if uses else None)
            c.that(
                res.hypotheses is not None and _same_hypotheses(res.hypotheses, own),
                "plan",
                "the default planner did not plan over the member's hypotheses of its stream",
                m,
            )
    with c.step("time per step", m):
        c.that(
            math.isfinite(seconds) and seconds > 0,
            "time per step",
            f"the planning step's wall time must be positive and finite, got {seconds!r} s",
            m,
        )
        work = res.work
        c.that(
            0 < work < 2**63,
            "time per step",
            f"work (the step's compute in model steps, the closed loop's work_per_step) must be "
            f"reported: an int in [1, 2**63), got {work!r}",
            m,
        )
        if res.hypotheses is not None:
            T = int(np.shape(res.hypotheses.states)[0])
            c.that(
                work >= T * H,
                "time per step",
                f"work {work} is less than one cost evaluation of its {T} hypotheses over "
                f"{H} steps ({T * H} model steps)",
                m,
            )
    with c.step("planner protocol", m):
        _check_protocol(c, m, res, setup, belief)
    with c.step("plan determinism", m):
        with _global_random_state(2):
            again = planner.plan(belief, np.zeros((H, 2)), _stream(m) if uses else None)
        diffs = _plan_diffs(res, again)
        c.that(
            not diffs,
            "plan determinism",
            f"planning again with the same stream (and other global random state) changed {diffs}",
            m,
        )
    with c.step("plan independence", m):
        # a fresh planner of an equal fresh member, after the others (and the baseline) planned
        with _global_random_state(3):
            fresh = registry.from_spec(m.spec())
            fresh_planner = fresh.planner(setup)
            for o in [*(o for o in built if o != m), registry.baseline()()]:
                _plan(o, setup, belief)
            diffs = _plan_diffs(res, _plan(fresh, setup, belief, planner=fresh_planner))
        c.that(
            not diffs,
            "plan independence",
            f"a fresh planner of an equal member, planning with the same stream after the other "
            f"members planned, changed {diffs} (state shared between planners or members)",
            m,
        )
    return seconds, int(work)


def _check_protocol(c: _Checker, m: Method, res: PlanResult, setup: UAVSetup, belief: Belief):
    """The planner protocol of the module docstring: hypotheses or none, and the stream."""
    prop = "planner protocol"
    if m.estimates_cost:
        c.that(
            res.hypotheses is not None,
            prop,
            "a family with a cost estimate (estimates_cost True) must return the hypotheses it "
            "planned over (PlanResult.hypotheses; the decision study scores its own cost of "
            "other plans with them), got None",
            m,
        )
        own = m.hypotheses(belief, setup, _stream(m) if m.uses_rng else None)
        c.that(
            _same_hypotheses(res.hypotheses, own),
            prop,
            "the plan's hypotheses are not the member's hypotheses() of the same stream (the "
            "studies take either for the member's cost estimate)",
            m,
        )
    else:
        c.that(
            res.hypotheses is None,
            prop,
            "a family without a cost estimate (estimates_cost False) must plan with "
            "hypotheses=None (the decision study would take them for its cost of any plan), "
            f"got {type(res.hypotheses).__name__}",
            m,
        )
        try:
            m.hypotheses(belief, setup, _stream(m))
        except NotImplementedError:
            pass
        else:
            c.fail(
                prop,
                "a family without a cost estimate (estimates_cost False) has no hypotheses: "
                "hypotheses() must raise NotImplementedError (set estimates_cost True if the "
                "hypotheses are its cost estimate)",
                m,
            )
    if m.uses_rng:
        other = _plan(m, setup, belief, SEED + 1)
        c.that(
            bool(_plan_diffs(res, other)),
            prop,
            "uses_rng is True but planning with another stream seed gives the identical plan "
            "(set uses_rng False for a deterministic method)",
            m,
        )
    else:
        H = setup.planner.horizon
        streamed = m.planner(setup).plan(belief, np.zeros((H, 2)), _stream(m))
        diffs = _plan_diffs(res, streamed)
        c.that(
            not diffs,
            prop,
            f"uses_rng is False but planning with a stream instead of None changed {diffs} "
            "(the decision study passes every member a stream)",
            m,
        )


def _validate_plan(c: _Checker, m: Method, res: Any, setup: UAVSetup, belief: Belief) -> None:
    H = setup.planner.horizon
    prop = "plan"
    c.that(
        isinstance(res, PlanResult),
        prop,
        f"plan() must return a PlanResult, got {type(res).__name__}",
        m,
    )
    u = np.asarray(res.controls)
    c.that(u.shape == (H, 2), prop, f"controls must have shape ({H}, 2), got {u.shape}", m)
    c.that(bool(np.isfinite(u).all()), prop, "controls are not all finite", m)
    scale = np.asarray(setup.uav.control_scale, dtype=float)
    excess = float((np.abs(u) - scale * (1 + 1e-12)).max())
    c.that(
        excess <= 0,
        prop,
        f"controls leave the bounds ±{scale.tolist()} (by {excess:.3g})",
        m,
    )
    path = np.asarray(res.uav_path)
    c.that(path.shape == (H, 4), prop, f"uav_path must have shape ({H}, 4), got {path.shape}", m)
    ref = rollout(np.asarray(belief.uav, dtype=float), u, setup.uav)
    c.that(
        np.allclose(path, ref, rtol=1e-9, atol=1e-6),
        prop,
        f"uav_path is not the rollout of the controls (max error {np.abs(path - ref).max():.3g})",
        m,
    )
    c.that(
        isinstance(res.cost, float | np.floating) and math.isfinite(res.cost),
        prop,
        f"cost must be a finite float, got {res.cost!r}",
        m,
    )
    c.that(
        isinstance(res.cost_warm, float | np.floating),
        prop,
        f"cost_warm must be a float (NaN if unknown), got {res.cost_warm!r}",
        m,
    )
    for f in ("nit", "n_kernel_calls", "work"):
        v = getattr(res, f)
        c.that(
            isinstance(v, int | np.integer) and not isinstance(v, bool) and v >= 0,
            prop,
            f"{f} must be an int >= 0, got {v!r}",
            m,
        )
    c.that(
        res.converged is None or isinstance(res.converged, bool | np.bool_),
        prop,
        f"converged must be None or a bool, got {res.converged!r}",
        m,
    )
    d = res.diagnostics
    c.that(isinstance(d, Mapping), prop, f"diagnostics must be a dict, got {d!r}", m)
    for k, v in d.items():
        c.that(
            isinstance(k, str) and isinstance(v, float | int | np.floating | np.integer),
            prop,
            f"diagnostics must map names to floats, got {k!r}: {v!r}",
            m,
        )
    if res.hypotheses is not None:
        _validate_hypotheses(c, m, res.hypotheses, belief, setup, prop)
