"""Registry of UAV planning methods: one module per family, each a :class:`Method` subclass
registered with :func:`register` (see :mod:`rsmhp.models.uav.methods.base` for the contract).

Every module of this package is imported when the package is, so a new family is one new
module here (plus its config entry); a family defined elsewhere (e.g. in a test) registers by
decorating its class with :func:`register`. The pipeline reaches methods only through this
registry:

* :func:`from_config` builds the members of a ``methods`` config block, in table order;
* :func:`from_name` / :func:`from_spec` rebuild a member from its name or its rule params;
* :func:`schema` is the JSON Schema of a ``methods`` block (each family's fragment);
* :func:`config_problems` collects the families' cross-field checks;
* :func:`families` lists the registered families in order; :func:`baseline` is the family
  every comparison is made against.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import pandas as pd

from rsmhp.models.uav.methods.base import COLUMNS, Hypotheses, Method

__all__ = [
    "COLUMNS",
    "Hypotheses",
    "Method",
    "baseline",
    "config_problems",
    "families",
    "from_config",
    "from_name",
    "from_spec",
    "register",
    "schema",
    "sort_names",
    "unregister",
]

_FAMILIES: dict[str, type[Method]] = {}


def register(cls: type[Method]) -> type[Method]:
    """Class decorator: add the family ``cls`` to the registry. Refuses a family or config
    key that is already registered (by another class) and a second baseline."""
    if not (isinstance(cls, type) and issubclass(cls, Method)):
        raise TypeError(f"register expects a Method subclass, got {cls!r}")
    for other in _FAMILIES.values():
        if other is cls or (other.__qualname__ == cls.__qualname__ and other.family == cls.family):
            continue
        if other.family == cls.family or other.config_key == cls.config_key:
            raise ValueError(
                f"method family {cls.family!r} (config key {cls.config_key!r}) clashes with "
                f"the registered {other.__name__} ({other.family!r}, {other.config_key!r})"
            )
        if cls.baseline and other.baseline:
            raise ValueError(f"{cls.__name__}: {other.__name__} is already the baseline family")
    _FAMILIES[cls.family] = cls
    return cls


def unregister(family: str) -> None:
    """Remove a family (for tests that register a toy method)."""
    _FAMILIES.pop(family, None)


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


def _import_families() -> None:
    for info in pkgutil.iter_modules(__path__):
        if info.name != "base":
            importlib.import_module(f"{__name__}.{info.name}")


_import_families()


# ------------------------------------------------- names of runs' methods


def baseline_name() -> str:
    """Name of the baseline family's member (``"nbo"``), the B of every "vs" comparison."""
    return baseline()().name


def is_family(names: pd.Series, family: type[Method]) -> pd.Series:
    """Boolean mask (same index as ``names``, a column of method names): which belong to
    ``family``."""
    return names.map(lambda m: from_name(str(m)).family == family.family).astype(bool)
