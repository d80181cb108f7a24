"""Argument guards for the library's public entry points.

Every guard checks one argument (or one pair) and either returns it or raises an exception
whose message names the argument, the value given and what is allowed, e.g.
``H must be an integer >= 1, got 2.5``. Wrong *types* (a string, a bool where a count is
expected, an object that is not a model) raise :class:`TypeError`; wrong *values* (out of
range, non-finite, badly shaped, not positive definite) raise :class:`ValueError`.

Conventions
-----------
* Integers: Python ``int`` and numpy integer types are returned as they are (the same
  object, so nothing downstream changes); whole-number floats (``3.0``) are accepted and
  returned as ``int`` (``3``), as :mod:`rsmhp.core.seeding` identifies ``3.0`` with ``3``;
  fractional or non-finite floats raise :class:`ValueError`; ``bool`` raises
  :class:`TypeError` (``True`` is not a count).
* Real numbers: ``int``, ``float`` and numpy scalars (not ``bool``); NaN is always refused,
  infinity unless ``finite=False``. The value is returned unchanged.
* Arrays: converted with ``np.asarray(x, dtype=float)`` (the conversion every entry point
  already makes), then checked for shape and finiteness.
* Covariances: symmetric up to rounding (``|P - P^T| <= 1e-8 max|P|``) and positive definite
  (Cholesky succeeds) or, with ``semi=True``, positive semidefinite (smallest eigenvalue of
  the symmetrised matrix ``>= -1e-10`` times the largest magnitude). A definiteness failure
  raises :class:`NotPositiveDefiniteError`, a :class:`numpy.linalg.LinAlgError` and hence a
  :class:`ValueError`.

The guards are meant for entry points and constructors (once per call of a public function,
once per planning step at most), never for compiled kernels or per-trajectory loops.
"""

from __future__ import annotations

import math
from collections.abc import Collection
from typing import Any

import numpy as np

__all__ = [
    "NotPositiveDefiniteError",
    "finite_array",
    "float_array",
    "generator",
    "instance_of",
    "int_array",
    "integer",
    "nonneg_int",
    "one_of",
    "ordered",
    "positive_int",
    "probability",
    "real",
    "show",
    "spd_matrix",
]

SYMMETRY_RTOL = 1e-8
"""Largest asymmetry ``|P - P^T|`` accepted, relative to ``max |P|``."""
PSD_RTOL = 1e-10
"""Largest negative eigenvalue accepted with ``semi=True``, relative to the largest one."""


class NotPositiveDefiniteError(np.linalg.LinAlgError):
    """A covariance that must be positive (semi)definite is not (a ``ValueError``)."""


def show(value: Any) -> str:
    """A short text of ``value`` for messages (numpy scalars as plain numbers)."""
    if isinstance(value, np.ndarray):
        if value.ndim == 0:
            return show(value[()])
        if value.size <= 8:
            return f"array {np.array2string(value, separator=', ')}"
        return f"an array of shape {value.shape}"
    if isinstance(value, np.generic):
        value = value.item()
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _type_name(value: Any) -> str:
    return type(value).__name__


def _int_range(minimum: int | None, maximum: int | None) -> str:
    if minimum is not None and maximum is not None:
        return f"in [{minimum}, {maximum}]"
    if minimum is not None:
        return f">= {minimum}"
    if maximum is not None:
        return f"<= {maximum}"
    return ""


def integer(
    name: str, value: Any, *, minimum: int | None = None, maximum: int | None = None
) -> int:
    """``value`` as an integer in ``[minimum, maximum]`` (either bound optional).

    ``int`` and numpy integers are returned unchanged; whole-number floats as ``int``.
    Raises :class:`TypeError` for ``bool`` and non-numbers, :class:`ValueError` for
    fractional or non-finite floats and for values out of range.
    """
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, int | np.integer) and not isinstance(value, bool | np.bool_):
        out = value
    elif isinstance(value, float | np.floating):
        if not (math.isfinite(value) and float(value).is_integer()):
            raise ValueError(f"{name} must be {_int_allowed(minimum, maximum)}, got {show(value)}")
        out = int(value)
    else:
        what = "bool" if isinstance(value, bool | np.bool_) else _type_name(value)
        raise TypeError(
            f"{name} must be {_int_allowed(minimum, maximum)}, got {what} {show(value)}"
        )
    if (minimum is not None and out < minimum) or (maximum is not None and out > maximum):
        raise ValueError(f"{name} must be {_int_range(minimum, maximum)}, got {show(value)}")
    return out


def _int_allowed(minimum: int | None, maximum: int | None) -> str:
    return f"an integer {_int_range(minimum, maximum)}".rstrip()


def positive_int(name: str, value: Any) -> int:
    """A count or horizon: an integer ``>= 1`` (see :func:`integer`)."""
    return integer(name, value, minimum=1)


def nonneg_int(name: str, value: Any) -> int:
    """An index or seed: an integer ``>= 0`` (see :func:`integer`)."""
    return integer(name, value, minimum=0)


def _real_range(
    lo: float | None, hi: float | None, lo_open: bool, hi_open: bool
) -> tuple[str, str]:
    """(verb, requirement): ("lie", "in the open interval (0, 1)"), ("be", ">= 0"), ..."""
    if lo is not None and hi is not None:
        kind = {
            (True, True): "open",
            (False, False): "closed",
            (True, False): "half-open",
            (False, True): "half-open",
        }[lo_open, hi_open]
        left, right = "(" if lo_open else "[", ")" if hi_open else "]"
        return "lie", f"in the {kind} interval {left}{lo:g}, {hi:g}{right}"
    if lo is not None:
        return "be", f"{'>' if lo_open else '>='} {lo:g}"
    if hi is not None:
        return "be", f"{'<' if hi_open else '<='} {hi:g}"
    return "be", ""


def real(
    name: str,
    value: Any,
    *,
    lo: float | None = None,
    hi: float | None = None,
    lo_open: bool = False,
    hi_open: bool = False,
    finite: bool = True,
) -> Any:
    """A real number (not ``bool``), not NaN, finite unless ``finite=False``, within the
    bounds (``lo < value`` if ``lo_open`` else ``lo <= value``; likewise ``hi``).

    Returned unchanged (a numpy scalar stays a numpy scalar).
    """
    if (
        type(value) is float
        and value == value
        and (  # fast path: a plain finite float in range
            (lo is None or (value > lo if lo_open else value >= lo))
            and (hi is None or (value < hi if hi_open else value <= hi))
            and (not finite or abs(value) != math.inf)
        )
    ):
        return value
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, bool | np.bool_) or not isinstance(
        value, int | float | np.integer | np.floating
    ):
        _, req = _real_range(lo, hi, lo_open, hi_open)
        what = f"a real number {req}".rstrip()
        raise TypeError(f"{name} must be {what}, got {_type_name(value)} {show(value)}")
    if math.isnan(value) or (finite and math.isinf(value)):
        if not finite:
            raise ValueError(f"{name} must not be NaN, got {show(value)}")
        verb, req = _real_range(lo, hi, lo_open, hi_open)
        tail = "" if not req else (f" and {req}" if verb == "be" else f" and lie {req}")
        raise ValueError(f"{name} must be finite{tail}, got {show(value)}")
    bad = (
        (lo is not None and (value <= lo if lo_open else value < lo))
        or (hi is not None and (value >= hi if hi_open else value > hi))
    )  # fmt: skip
    if bad:
        verb, req = _real_range(lo, hi, lo_open, hi_open)
        raise ValueError(f"{name} must {verb} {req}, got {show(value)}")
    return value


def probability(name: str, value: Any) -> Any:
    """A probability: a real number in ``[0, 1]``."""
    return real(name, value, lo=0.0, hi=1.0)


def _shape_text(shape: tuple[int | str | None, ...]) -> str:
    dims = ["?" if d is None else str(d) for d in shape]
    return "(" + ", ".join(dims) + ("," if len(dims) == 1 else "") + ")"


def float_array(name: str, x: Any) -> np.ndarray:
    """``np.asarray(x, dtype=float)``; :class:`TypeError` naming ``name`` if ``x`` does not
    convert (strings, objects, ragged lists). No value check (see :func:`finite_array`)."""
    try:
        return np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(
            f"{name} must be an array of real numbers, got {_type_name(x)} {show(x)}"
        ) from None


def finite_array(
    name: str,
    x: Any,
    *,
    shape: tuple[int | str | None, ...] | None = None,
    ndim: int | Collection[int] | None = None,
    nonempty: bool = False,
) -> np.ndarray:
    """``np.asarray(x, dtype=float)``, checked: finite entries, ``shape`` (ints are exact,
    strings and ``None`` are any length, e.g. ``("n", 4)``), ``ndim`` (one value or several)
    and, with ``nonempty``, every dimension >= 1."""
    a = float_array(name, x)
    if shape is not None:
        ok = a.ndim == len(shape) and all(
            not isinstance(d, int) or a.shape[i] == d for i, d in enumerate(shape)
        )
        if not ok or (nonempty and 0 in a.shape):
            extra = " with every dimension >= 1" if nonempty else ""
            raise ValueError(f"{name} must have shape {_shape_text(shape)}{extra}, got {a.shape}")
    else:
        if ndim is not None:
            allowed = (ndim,) if isinstance(ndim, int) else tuple(ndim)
            if a.ndim not in allowed:
                want = " or ".join(str(n) for n in allowed)
                raise ValueError(f"{name} must have {want} dimension(s), got shape {a.shape}")
        if nonempty and (a.size == 0):
            raise ValueError(f"{name} must not be empty, got shape {a.shape}")
    if not np.isfinite(a).all():
        bad = np.argwhere(~np.isfinite(a))
        n_bad = len(bad)
        first = tuple(int(i) for i in bad[0]) if a.ndim else ()
        val = a[first] if a.ndim else a[()]
        where = f" at index {first if len(first) != 1 else first[0]}" if a.ndim else ""
        raise ValueError(
            f"{name} must be finite, got {val}{where} ({n_bad} non-finite entr"
            f"{'y' if n_bad == 1 else 'ies'})"
        )
    return a


def spd_matrix(name: str, P: Any, *, semi: bool = False, size: int | None = None) -> np.ndarray:
    """A covariance: a finite square (``size`` x ``size`` if given) matrix, symmetric up to
    rounding, positive definite (or semidefinite with ``semi``). Returns the array
    (``np.asarray(P, dtype=float)``, not symmetrised)."""
    dim: int | str = size if size is not None else "d"
    a = finite_array(name, P, shape=(dim, dim))
    if a.shape[0] != a.shape[1] or a.shape[0] == 0:
        raise ValueError(f"{name} must be a non-empty square matrix, got shape {a.shape}")
    scale = float(np.abs(a).max())
    asym = float(np.abs(a - a.T).max())
    if asym > SYMMETRY_RTOL * scale:
        raise ValueError(
            f"{name} must be symmetric, got max |{name} - {name}^T| = {asym:.3g} "
            f"(max |{name}| = {scale:.3g})"
        )
    sym = 0.5 * (a + a.T)
    try:
        np.linalg.cholesky(sym)
        return a  # positive definite (hence also semidefinite)
    except np.linalg.LinAlgError:
        pass
    eig = np.linalg.eigvalsh(sym)
    if semi and eig[0] >= -PSD_RTOL * float(np.abs(eig).max()):
        return a
    kind = "positive semidefinite" if semi else "positive definite"
    raise NotPositiveDefiniteError(
        f"{name} must be symmetric {kind}, got smallest eigenvalue {eig[0]:.6g}"
    )


def ordered(name_lo: str, lo: Any, name_hi: str, hi: Any, *, strict: bool = True) -> None:
    """Bounds in order: ``lo < hi`` (``lo <= hi`` if not ``strict``)."""
    if (lo >= hi) if strict else (lo > hi):
        op = "<" if strict else "<="
        raise ValueError(
            f"{name_lo} must be {op} {name_hi}, got {name_lo} = {show(lo)}, {name_hi} = {show(hi)}"
        )


def one_of(name: str, value: Any, allowed: Collection[Any]) -> Any:
    """``value`` if it is one of ``allowed``."""
    try:
        ok = value in allowed
    except TypeError:  # unhashable
        ok = False
    if not ok:
        raise ValueError(f"{name} must be one of {tuple(allowed)}, got {show(value)}")
    return value


def instance_of(name: str, value: Any, cls: type | tuple[type, ...]) -> Any:
    """``value`` if it is an instance of ``cls`` (else :class:`TypeError`)."""
    if not isinstance(value, cls):
        names = " or ".join(c.__name__ for c in (cls if isinstance(cls, tuple) else (cls,)))
        raise TypeError(f"{name} must be a {names}, got {_type_name(value)} {show(value)}")
    return value


def generator(name: str, rng: Any) -> np.random.Generator:
    """A :class:`numpy.random.Generator` (the streams of :mod:`rsmhp.core.seeding`)."""
    return instance_of(name, rng, np.random.Generator)


def int_array(name: str, values: Any, *, minimum: int = 1) -> Any:
    """A scalar or array of integers ``>= minimum`` (integer dtype, or floats that are all
    whole numbers); returned unchanged."""
    a = np.asarray(values)
    if a.dtype.kind == "b" or a.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be integer(s) >= {minimum}, got {a.dtype} {show(values)}")
    if a.dtype.kind == "f" and not (np.isfinite(a).all() and (a == np.round(a)).all()):
        raise ValueError(f"{name} must be integer(s) >= {minimum}, got {show(values)}")
    if a.size and a.min() < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {show(values)}")
    if a.size == 0:
        raise ValueError(f"{name} must not be empty, got {show(values)}")
    return values
