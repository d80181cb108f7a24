"""Markdown formatting shared by every study's prose and the report: numbers with a fixed
count of significant digits (:func:`fmt`, :func:`fmt_ci`), tables (:func:`markdown_table`) and
cell escaping. Pure string functions; no statistics and no claims."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pandas as pd

__all__ = ["ci_cells", "escape", "fmt", "fmt_ci", "markdown_table", "param_text", "range_text"]


def fmt(x: float | int, digits: int = 3, signed: bool = False) -> str:
    """``x`` with ``digits`` significant digits (integers in full, no exponent between 1e-4
    and 1e6); ``signed`` puts a + on positive numbers. NaN and inf raise ``ValueError``: a
    value that is absent must be explained in words, not printed as nan."""
    if isinstance(x, bool):
        raise TypeError(f"fmt expects a number, got bool {x!r}")
    xf = float(x)
    if not math.isfinite(xf):
        raise ValueError(f"cannot format {x!r}: say in words why the value is absent")
    sign = "+" if signed and xf > 0 else ""
    if float(xf).is_integer() and abs(xf) < 1e15 and (isinstance(x, int) or abs(xf) >= 10**digits):
        return f"{sign}{int(xf)}"
    if xf == 0.0:
        return "0"
    mag = math.floor(math.log10(abs(xf)))
    if -4 <= mag < 6:
        decimals = max(digits - 1 - mag, 0)
        return f"{sign}{xf:.{decimals}f}"
    return f"{sign}{xf:.{digits - 1}e}"


def fmt_ci(lo: float, hi: float, digits: int = 3, signed: bool = False) -> str:
    """``[lo, hi]``, both with ``digits`` significant digits of the larger magnitude."""
    ref = max(abs(float(lo)), abs(float(hi)))
    if ref == 0.0 or not math.isfinite(ref):
        return f"[{fmt(lo, digits, signed)}, {fmt(hi, digits, signed)}]"
    mag = math.floor(math.log10(ref))
    if -4 <= mag < 6:
        decimals = max(digits - 1 - mag, 0)
        s = "+" if signed else ""
        return f"[{float(lo):{s}.{decimals}f}, {float(hi):{s}.{decimals}f}]"
    return f"[{fmt(lo, digits, signed)}, {fmt(hi, digits, signed)}]"


def ci_cells(lows, highs, scale: float = 1.0, digits: int = 3, signed: bool = False) -> list[str]:
    """Table cells ``[lo, hi]`` (:func:`fmt_ci` of ``scale`` times each limit), one per row of
    the two sequences; ``undefined`` where either limit is not finite (no CI)."""
    return [
        fmt_ci(scale * lo, scale * hi, digits, signed)
        if math.isfinite(lo) and math.isfinite(hi)
        else "undefined"
        for lo, hi in zip(lows, highs, strict=True)
    ]


def escape(text: str) -> str:
    """``text`` safe inside a Markdown table cell: ``|`` escaped, newlines as spaces."""
    return text.replace("|", "\\|").replace("\n", " ")


def markdown_table(
    df: pd.DataFrame, digits: int = 4, missing: str | None = None, signed: Sequence[str] = ()
) -> str:
    """Markdown table without index. Integer columns (and float columns whose values are all
    whole numbers) print as integers, other floats with ``digits`` significant digits (per
    cell). NaN/inf cells raise ``ValueError`` naming the column unless ``missing`` gives the
    text to print instead (explain it next to the table); ``signed`` columns get a + sign.
    A ``|`` inside a text cell is escaped (it would end the cell)."""
    out = pd.DataFrame(index=df.index)
    align = []
    for col in df.columns:
        s = df[col]
        text = pd.api.types.is_bool_dtype(s) or not pd.api.types.is_numeric_dtype(s)
        align.append("left" if text else "right")
        if text:
            bad = s.isna()
            if bad.any() and missing is None:
                raise ValueError(f"table column {col!r} has {int(bad.sum())} missing cell(s)")
            cells = s.astype(object).where(~bad, missing).astype(str)
            out[col] = cells.str.replace("|", "\\|", regex=False)  # a bare | ends the cell
            continue
        x = s.astype(float)
        finite = np.isfinite(x)
        if (~finite).any() and missing is None:
            raise ValueError(
                f"table column {col!r} has {int((~finite).sum())} NaN/inf cell(s); pass "
                "missing= with the reason, or drop them"
            )
        whole = bool(finite.any()) and bool((x[finite] == np.round(x[finite])).all())
        whole = whole and (pd.api.types.is_integer_dtype(s) or bool((x[finite].abs() < 1e15).all()))
        cells = []
        for v, ok in zip(x, finite, strict=True):
            if not ok:
                cells.append(missing)
            elif whole:
                cells.append(("+" if col in signed and v > 0 else "") + str(int(v)))
            else:
                cells.append(fmt(v, digits, col in signed))
        out[col] = cells
    return out.to_markdown(index=False, disable_numparse=True, colalign=align)


def param_text(x: float | int) -> str:
    """A configuration value as text: whole numbers without decimals, others with the fewest
    significant digits that give the value back exactly (``0.25``, not ``0.250``)."""
    xf = float(x)
    if xf.is_integer():
        return fmt(int(xf))
    for digits in range(1, 16):
        text = fmt(xf, digits)
        if float(text) == xf:
            return text
    return fmt(xf, 6)


def range_text(values: Sequence[float], digits: int = 3, signed: bool = False) -> str:
    """``lo to hi`` of ``values`` (one number if they are all equal)."""
    lo, hi = float(np.min(values)), float(np.max(values))
    if lo == hi:
        return fmt(lo, digits, signed)
    return f"{fmt(lo, digits, signed)} to {fmt(hi, digits, signed)}"
