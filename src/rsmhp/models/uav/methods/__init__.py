"""Registry of UAV planning methods: one module per family, each a :class:`Method` subclass
registered with :func:`register` (see :mod:`rsmhp.models.uav.methods.base` for the contract).

Every module of this package is imported when the package is, so a new family is one new
module here (plus its config entry); a family defined elsewhere (e.g. in a test) registers by
decorating its class with :func:`register`. An installed package adds families through the
entry-point group :data:`PLUGIN_GROUP` (``rsmhp.methods``): each entry point names a module
that registers its families with :func:`register`, or a :class:`Method` subclass to register;
all are loaded after the built-in families (:func:`plugins` lists them). A plugin family must
default to no member, so installing a plugin changes no existing run; a family or config key
that is taken is refused naming both packages, and a plugin that fails to load raises
:class:`PluginError` naming its entry point and distribution. The pipeline reaches methods only
through this registry:

* :func:`from_config` builds the members of a ``methods`` config block, in table order;
* :func:`from_name` / :func:`from_spec` rebuild a member from its name or its rule params;
* :func:`schema` is the JSON Schema of a ``methods`` block (each family's fragment);
* :func:`config_problems` collects the families' cross-field checks;
* :func:`families` lists the registered families in order; :func:`baseline` is the family
  every comparison is made against.

:func:`register` checks the class first: every attribute of the contract present (written,
or derived from ``family``: :meth:`Method.derivations`), of the right type, and no abstract
method left; a ``TypeError`` names the class and the attribute otherwise.
"""

from __future__ import annotations

import importlib
import importlib.metadata
import pkgutil
import re
import types
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import pandas as pd

from rsmhp.models.uav.methods.base import (
    COLUMNS,
    Hypotheses,
    Method,
    NTrajMethod,
    OnOffMethod,
)

__all__ = [
    "COLUMNS",
    "PLUGIN_GROUP",
    "Hypotheses",
    "Method",
    "NTrajMethod",
    "OnOffMethod",
    "Plugin",
    "PluginError",
    "baseline",
    "config_problems",
    "families",
    "from_config",
    "from_name",
    "from_spec",
    "load_plugins",
    "plugins",
    "register",
    "schema",
    "sort_names",
    "unregister",
]

_FAMILIES: dict[str, type[Method]] = {}

#: the entry-point group of method plugins
PLUGIN_GROUP = "rsmhp.methods"


@dataclass(frozen=True)
class Plugin:
    """A family registered by an installed plugin: the class, the distribution that installed
    it (name and version) and its entry point (``name = value``)."""

    family: str
    config_key: str
    cls: type[Method]
    distribution: str
    version: str | None
    entry_point: str


class PluginError(ImportError):
    """A method plugin failed to load (the message names its entry point and distribution)."""


class _Clash(ValueError):
    """A family or config key that is already registered."""


_PLUGINS: dict[str, Plugin] = {}
#: the plugins' entry points (a plugin module may be imported before its entry point is
#: loaded: its classes are attributed by module) and the one being loaded
_ENTRY_POINTS: list[Any] = []
_LOADING: list[Any] = []


def _plugin_entry_point(cls: type, loading: bool = True) -> Any:
    """The entry point that brings ``cls``: the one being loaded (``loading``), else the one
    naming its module; ``None`` for a family of no plugin."""
    if loading and _LOADING:
        return _LOADING[-1]
    mod = cls.__module__
    named = (e for e in _ENTRY_POINTS if mod == e.module or mod.startswith(e.module + "."))
    return next(named, None)


def _distribution(ep: Any) -> tuple[str, str | None]:
    """Name and version of the distribution of the entry point ``ep``."""
    dist = getattr(ep, "dist", None)
    if dist is None:
        return f"(unknown distribution of module {ep.module!r})", None
    return str(dist.name), getattr(dist, "version", None)


def _origin(cls: type, new: bool = False) -> str:
    """Who defined ``cls`` (``new``: the class being registered), for messages: a plugin's
    distribution and entry point, else the top-level package of its module (``package
    'rsmhp'``)."""
    p = _PLUGINS.get(cls.family)
    if p is not None and p.cls is cls:
        return f"distribution {p.distribution!r} (entry point {p.entry_point!r})"
    ep = _plugin_entry_point(cls, loading=new)
    if ep is not None:
        return f"distribution {_distribution(ep)[0]!r} (entry point '{ep.name} = {ep.value}')"
    return f"package {cls.__module__.partition('.')[0]!r}"


#: the class attributes every family has, written or derived, and what to write if one is
#: missing (the contract: :mod:`rsmhp.models.uav.methods.base`)
_REQUIRED = {
    "family": "the family's identifier, e.g. 'rsmhp'",
    "config_key": "derived from family unless written",
    "schema": "the JSON Schema of the config value; an OnOffMethod writes description instead",
    "default": "the config value when a methods block omits the key",
    "family_label": "the family's human-readable name",
    "colour_key": "derived from family unless written",
    "order": "the family's position in tables and figures, an int",
    "n_traj": "N_T, the tables' column: a field, a property or a constant",
}
_IDENTIFIER = re.compile(r"[A-Za-z0-9_]+")


def _check_class(cls: type[Method]) -> None:
    """``TypeError`` naming the class and the attribute if the family class lacks an
    attribute of the contract, has one of the wrong type, or leaves an abstract method."""
    where = f"method family class {cls.__qualname__} (module {cls.__module__})"
    required = dict(_REQUIRED)
    if getattr(cls.parse, "__func__", None) is Method.parse.__func__:
        required["name_pattern"] = "the regular expression of the members' names, or own parse"
    field_names = {f.name for f in fields(cls)} if hasattr(cls, "__dataclass_fields__") else set()
    missing = [a for a in required if not hasattr(cls, a) and a not in field_names]
    if missing:
        listed = "; ".join(f"{a!r} ({required[a]})" for a in missing)
        raise TypeError(
            f"{where}: class attribute{'s' if len(missing) > 1 else ''} missing: {listed}"
        )
    if cls.__abstractmethods__:
        raise TypeError(
            f"{where}: abstract method(s) {sorted(cls.__abstractmethods__)} not implemented"
        )

    def wrong(attr: str, expected: str) -> TypeError:
        return TypeError(
            f"{where}: class attribute {attr!r} must be {expected}, got {getattr(cls, attr)!r}"
        )

    for attr in ("family", "config_key"):
        v = getattr(cls, attr)
        if not (isinstance(v, str) and _IDENTIFIER.fullmatch(v)):
            raise wrong(attr, "a non-empty string of [A-Za-z0-9_]")
    checks = {
        "schema": (isinstance(cls.schema, Mapping), "a mapping (a JSON Schema)"),
        "family_label": (
            isinstance(cls.family_label, str) and cls.family_label.strip() != "",
            "a non-empty string",
        ),
        "colour_key": (
            isinstance(cls.colour_key, str),
            "a string (a key of the report's colours or '#rrggbb')",
        ),
        "order": (isinstance(cls.order, int) and not isinstance(cls.order, bool), "an int"),
        **{
            a: (isinstance(getattr(cls, a), bool), "a bool")
            for a in ("baseline", "uses_rng", "estimates_cost")
        },
    }
    for attr, (ok, expected) in checks.items():
        if not ok:
            raise wrong(attr, expected)
    pattern = getattr(cls, "name_pattern", None)
    if pattern is not None:
        if not isinstance(pattern, str):
            raise wrong("name_pattern", "a string (a regular expression)")
        try:
            re.compile(pattern)
        except re.error as e:
            raise TypeError(f"{where}: class attribute 'name_pattern' {pattern!r}: {e}") from e


def register(cls: type[Method]) -> type[Method]:
    """Class decorator: add the family ``cls`` to the registry. Refuses a class that misses
    or mistypes an attribute of the contract (``TypeError`` naming the class and the
    attribute), a family or config key that is already registered (by another class, naming
    the packages of both), a second baseline, and a plugin family whose ``default``
    configures members."""
    if not (isinstance(cls, type) and issubclass(cls, Method)):
        raise TypeError(f"register expects a Method subclass, got {cls!r}")
    _check_class(cls)
    for other in _FAMILIES.values():
        # the same class again (its module imported or run again) replaces itself
        same = (other.__module__, other.__qualname__) == (cls.__module__, cls.__qualname__)
        if other is cls or (same and other.family == cls.family):
            continue
        if other.family == cls.family or other.config_key == cls.config_key:
            raise _Clash(
                f"method family {cls.family!r} (config key {cls.config_key!r}, {cls.__name__}) "
                f"of {_origin(cls, new=True)} clashes with the registered {other.__name__} "
                f"({other.family!r}, {other.config_key!r}) of {_origin(other)}"
            )
        if cls.baseline and other.baseline:
            raise ValueError(f"{cls.__name__}: {other.__name__} is already the baseline family")
    ep = _plugin_entry_point(cls)
    if ep is not None:
        if cls.default:
            raise ValueError(
                f"method family {cls.family!r} of {_origin(cls, new=True)}: a plugin "
                f"family's default must configure no member ([] or false), got "
                f"{cls.default!r}: installing a plugin must change no existing run"
            )
        dist, version = _distribution(ep)
        point = f"{ep.name} = {ep.value}"
        _PLUGINS[cls.family] = Plugin(cls.family, cls.config_key, cls, dist, version, point)
    _FAMILIES[cls.family] = cls
    return cls


def unregister(family: str) -> None:
    """Remove a family (for tests that register a toy method)."""
    _FAMILIES.pop(family, None)
    _PLUGINS.pop(family, None)


def plugins() -> list[Plugin]:
    """The families registered by installed plugins, in table order, with their distribution."""
    return [_PLUGINS[c.family] for c in families() if c.family in _PLUGINS]


def families() -> list[type[Method]]:
    """Registered families, in table order (``order``, then family name)."""
    return sorted(_FAMILIES.values(), key=lambda c: (c.order, c.family))


def baseline() -> type[Method]:
    """The family every comparison is made against."""
    found = [c for c in families() if c.baseline]
    if len(found) != 1:
        raise RuntimeError(f"exactly one baseline family must be registered, found {found}")
    return found[0]


def schema() -> dict[str, Any]:
    """JSON Schema of a ``methods`` config block: one optional key per family."""
    return {
        "type": "object",
        "additionalProperties": False,
        "properties": {c.config_key: c.schema for c in families()},
    }


def from_config(methods: Mapping[str, Any], path: str = "methods") -> dict[str, Method]:
    """The members of a ``methods`` block keyed by name, in table order; a family whose key is
    absent takes its ``default``. Unknown keys raise ``ValueError`` naming them."""
    if not isinstance(methods, Mapping):
        raise TypeError(f"{path} must be a mapping, got {type(methods).__name__}")
    keys = {c.config_key for c in families()}
    unknown = sorted(set(methods) - keys)
    if unknown:
        raise ValueError(f"{path}: unknown method key(s) {unknown} (allowed: {sorted(keys)})")
    out: list[Method] = []
    for cls in families():
        value = methods.get(cls.config_key, cls.default)
        out += cls.from_config(value, f"{path}.{cls.config_key}")
    names = [m.name for m in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ValueError(f"{path}: method name(s) {dup} appear twice (allowed: unique methods)")
    return {m.name: m for m in sorted(out, key=lambda m: m.sort_key())}


def config_problems(methods: Any, path: str, uav: Mapping[str, Any]) -> list[str]:
    """Every family's cross-field problems for a ``methods`` block (see
    :meth:`Method.config_problems`); nothing for a value that is not a mapping (the schema
    reports it)."""
    if not isinstance(methods, Mapping):
        return []
    return [
        p
        for c in families()
        if c.config_key in methods
        for p in c.config_problems(methods[c.config_key], f"{path}.{c.config_key}", uav)
    ]


def count(methods: Mapping[str, Any]) -> int:
    """How many methods a (schema-valid) ``methods`` block configures, without building
    them (config checks); a family's missing key counts its default."""
    n = 0
    for c in families():
        value = methods.get(c.config_key, c.default)
        n += (1 if value else 0) if isinstance(value, bool) else len(value or [])
    return n


def from_name(name: str) -> Method:
    """The member called ``name``; ``ValueError`` naming the families if none parses it."""
    for cls in families():
        m = cls.parse(str(name))
        if m is not None:
            return m
    raise ValueError(
        f"method {name!r} belongs to no registered family "
        f"(allowed: names of {', '.join(c.family for c in families())})"
    )


def from_spec(spec: Mapping[str, Any]) -> Method:
    """The member described by ``spec`` (:meth:`Method.spec`, e.g. a rule's params)."""
    spec = dict(spec)
    family = spec.pop("family", None)
    if family not in _FAMILIES:
        raise ValueError(f"method spec: unknown family {family!r} (allowed: {sorted(_FAMILIES)})")
    return _FAMILIES[family](**spec)


def sort_names(names: Iterable[str]) -> list[str]:
    """Method names in table order."""
    return sorted(names, key=lambda n: from_name(n).sort_key())


def load_plugins(entry_points: Iterable[Any] | None = None) -> list[Plugin]:
    """Load method plugins: ``entry_points`` (default: the installed entry points of
    :data:`PLUGIN_GROUP`, by distribution and name); returns :func:`plugins`. A plugin that
    fails to load raises :class:`PluginError` (a clash: ``ValueError``) and registers nothing."""
    if entry_points is None:
        found = importlib.metadata.entry_points(group=PLUGIN_GROUP)
        entry_points = sorted(found, key=lambda e: (_distribution(e)[0], e.name))
    entry_points = list(entry_points)
    _ENTRY_POINTS.extend(e for e in entry_points if e not in _ENTRY_POINTS)
    for ep in entry_points:
        _load_plugin(ep)
    return plugins()


def _load_plugin(ep: Any) -> None:
    dist, version = _distribution(ep)
    point = f"{ep.name} = {ep.value}"
    saved = dict(_FAMILIES), dict(_PLUGINS)
    _LOADING.append(ep)
    try:
        obj = ep.load()
        if isinstance(obj, type) and issubclass(obj, Method):
            if obj not in _FAMILIES.values():
                register(obj)
        elif not isinstance(obj, types.ModuleType):
            raise TypeError(f"it names {obj!r}, neither a module nor a Method subclass")
        # a module imported before the registry (it imports the registry) registers its
        # families when its import resumes
        initialising = getattr(getattr(obj, "__spec__", None), "_initializing", False)
        if not initialising and not any(p.entry_point == point for p in _PLUGINS.values()):
            raise TypeError("it registers no method family (decorate the class with @register)")
    except Exception as e:
        for registry, before in zip((_FAMILIES, _PLUGINS), saved, strict=True):
            registry.clear()
            registry.update(before)
        if isinstance(e, _Clash):
            raise
        raise PluginError(
            f"method plugin entry point {point!r} (group {PLUGIN_GROUP!r}) of distribution "
            f"{dist!r}{' ' + version if version else ''} failed to load: "
            f"{type(e).__name__}: {e} (fix the plugin, or uninstall it: pip uninstall {dist})"
        ) from e
    finally:
        _LOADING.pop()


def _import_families() -> None:
    for info in pkgutil.iter_modules(__path__):
        if info.name != "base":
            importlib.import_module(f"{__name__}.{info.name}")
    load_plugins()


_import_families()


# ------------------------------------------------- names of runs' methods


def baseline_name() -> str:
    """Name of the baseline family's member (``"nbo"``), the B of every "vs" comparison."""
    return baseline()().name


def is_family(names: pd.Series, family: type[Method]) -> pd.Series:
    """Boolean mask (same index as ``names``, a column of method names): which belong to
    ``family``."""
    return names.map(lambda m: from_name(str(m)).family == family.family).astype(bool)
