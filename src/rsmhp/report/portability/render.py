"""The portability drill's report as Markdown (:func:`render`): result line, the emulation as
measured, claims, tables and every differing column.

The tables are plain pipe tables without padding (:func:`_md`), not
:func:`rsmhp.report.markdown.markdown_table`: that one pads and aligns its columns, and the
report's cells are preformatted text already."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from rsmhp.report.markdown import escape
from rsmhp.report.portability.emulation import blas_cores

__all__ = ["render"]


def _g(x: Any, digits: int = 2) -> str:
    """``x`` with ``digits`` significant digits (integers in full); ``-`` if absent or not
    finite."""
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    if isinstance(x, int | np.integer):
        return str(int(x))
    return "0" if x == 0 else f"{x:.{digits}g}"


def _md(header: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    """A Markdown pipe table of preformatted cells (escaped, not padded)."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(escape(str(c)) for c in row) + " |" for row in rows]
    return "\n".join(lines)


#: the numbers shown of a differing column (:func:`rsmhp.report.portability.compare_frames`)
_NUMBER_HEADER = ["max abs", "max rel", "max abs / column max", "max ulps"]


def _worst(cols: Sequence[Mapping[str, Any]], key: str) -> Any:
    """The largest finite ``key`` over the columns ``cols``; None if there is none."""
    vals = [c[key] for c in cols if c.get(key) is not None and math.isfinite(c[key])]
    return max(vals, default=None)


def _numbers(c: Mapping[str, Any]) -> list[str]:
    """The cells of :data:`_NUMBER_HEADER` of a differing column ``c``."""
    return [
        _g(c.get("max abs")),
        _g(c.get("max rel")),
        _g(c.get("max abs / column max")),
        _g(c.get("max ulps")),
    ]


def _numba_row(emu: Mapping[str, Any]) -> list[str]:
    """The row of numba's target CPU (features), native and inside the emulated run."""
    nat, inside = emu["native"], emu["inside the emulated run"]
    n_feat = nat["numba_features"].count("+")
    return [
        "numba target CPU (features)",
        f"{nat['numba_cpu']} ({n_feat} features on"
        + (", e.g. avx512f, fma)" if "+avx512f" in nat["numba_features"] else ")"),
        _emulated(
            emu,
            "numba",
            ", ".join(inside["numba target CPUs"]) or "-",
        )
        + " ("
        + (", ".join(inside["numba features"]) or "-").replace("(none)", "no features")
        + ")",
        "inside the run: the code generator of every compiled rsmhp kernel in "
        f"{inside['processes with compiled kernels']} processes "
        f"({', '.join(inside['rules with compiled kernels']) or 'none'})",
    ]


def _kernels_row(emu: Mapping[str, Any]) -> list[str]:
    """The row of the kernels compiled and loaded in the emulated run, and its cache."""
    inside = emu["inside the emulated run"]
    kernels = inside["kernels"].values()
    cached = sorted({c for v in emu["emulated numba cache"].values() for c in v})
    return [
        "kernels compiled / loaded",
        "the host's cache beside the source",
        f"{sum(k['compiled'] for k in kernels)} / {sum(k['loaded'] for k in kernels)} "
        f"({len(inside['kernels'])} kernels)",
        "inside the run: numba's cache statistics; the run's own cache (empty at the "
        f"start) holds kernels for {', '.join(cached) or '-'}",
    ]


def _openblas_row(emu: Mapping[str, Any]) -> list[str]:
    """The row of the OpenBLAS core type, native and inside the emulated run."""
    nat, inside = emu["native"], emu["inside the emulated run"]
    return [
        "OpenBLAS core type",
        ", ".join(blas_cores(emu["native run blas (provenance.json)"]))
        or ", ".join(nat["openblas"]),
        _emulated(emu, "openblas", ", ".join(inside["openblas core types"]) or "-"),
        "threadpoolctl inside the run; provenance.json: native "
        f"{_blas_line(emu['native run blas (provenance.json)'])}, emulated "
        f"{_blas_line(emu['emulated run blas (provenance.json)'])}",
    ]


def _blas_line(blas: str | None) -> str:
    """A run's provenance ``blas`` line, or why there is none (the report rule writes it)."""
    return f"`{blas}`" if blas else "none (the run made no report)"


def _numpy_row(emu: Mapping[str, Any]) -> list[str]:
    """The row of numpy's SIMD dispatch, native and inside the emulated run."""
    nat, inside = emu["native"], emu["inside the emulated run"]
    return [
        "numpy SIMD dispatch",
        ", ".join(nat["numpy_simd"]) or "none",
        _emulated(emu, "numpy", ", ".join(inside["numpy SIMD extensions"]) or "none (baseline)"),
        "numpy's CPU features inside the run",
    ]


def _emulated(emu: Mapping[str, Any], component: str, text: str) -> str:
    """``text``, marked when ``component`` was not emulated."""
    return text if component in set(emu["components"]) else f"{text} (not emulated)"


def _head(drill: Mapping[str, Any]) -> list[str]:
    """Result line and the runs compared, and whether the emulation took effect."""
    emu = drill["emulation"]
    return [
        f"# Portability drill: {drill['result']}",
        "",
        f"Native run `{drill['native']}`, emulated run `{drill['emulated']}`, reference "
        f"`{drill['reference']}`, config sha256 `{drill['config sha256']}`. "
        + _scope(drill)
        + (
            "The emulation took effect (below, as measured)."
            if emu["effective"]
            else "**The emulation did not take effect:** " + "; ".join(emu["problems"]) + "."
        ),
    ]


def _scope(drill: Mapping[str, Any]) -> str:
    """What the drill covers when its targets are not the whole report (else nothing)."""
    sections = drill.get("sections")
    if sections is None:
        return ""
    return (
        f"Targets `{' '.join(drill.get('targets', []))}`: only the claims of the report "
        f"sections {', '.join(f'`{s}`' for s in sections)} and the emulated run's "
        f"{len(drill['tables'])} tables are compared (the configuration's hash is the native "
        "run's report's; the emulated run, with the same config files, made no report). "
    )


def _emulation_part(drill: Mapping[str, Any]) -> list[str]:
    """What was emulated: native vs the emulated run, as measured."""
    emu = drill["emulation"]
    inside = emu["inside the emulated run"]
    rows = [_numba_row(emu), _kernels_row(emu), _openblas_row(emu), _numpy_row(emu)]
    return [
        "## What was emulated",
        "",
        _md(["", "native (this machine)", "emulated run", "measured"], rows),
        "",
        f"{inside['processes recorded']} processes of the emulated run left a record. "
        "Environment of the emulated run: `"
        + " ".join(f"{k}={v}" for k, v in drill["env"].items())
        + "`.",
    ]


_CLAIMS_HEADER = [
    "id",
    "class",
    "native",
    "emulated − native",
    "relative",
    "bitwise",
    "tolerance",
    "verdict (reference / native / emulated)",
    "verify (emulated)",
]


def _claim_cells(r: Mapping[str, Any]) -> list[Any]:
    """One row of the claims table (a row of :func:`compare_claims`)."""
    return [
        r["id"],
        r["reproducible"],
        _g(r["native"], 6),
        _g(r["emulated - native"]),
        _g(r["relative"]),
        "yes" if r["bitwise equal"] else "**no**",
        _g(r["tolerance"]),
        " / ".join((r["verdict (reference)"], r["verdict (native)"], r["verdict (emulated)"]))
        + ("" if r["same verdict"] else " **differs**"),
        r["verify (emulated)"],
    ]


def _claims_part(drill: Mapping[str, Any]) -> list[str]:
    """Both runs' ``make verify`` against the reference, and one row per claim."""
    claims = drill["claims"]
    return [
        "## Claims",
        "",
        f"`make verify` against the reference: native **{drill['verify native']}**, emulated "
        f"**{drill['verify emulated']}**. Verdicts the same (reference, native, emulated) in "
        f"{sum(r['same verdict'] for r in claims)} of {len(claims)} claims; key number "
        f"bitwise equal (emulated vs native) in {sum(r['bitwise equal'] for r in claims)}. "
        "Tolerance: `make verify`'s, of the emulated run against the reference.",
        "",
        _md(_CLAIMS_HEADER, [_claim_cells(r) for r in claims]),
    ]


def _table_cells(t: Mapping[str, Any]) -> list[Any]:
    """One row of the tables table (an entry of :func:`compare_results`)."""
    return [
        t["table"],
        t["expected"],
        t["status"],
        ", ".join(f"{k} ({v['cells']}/{v['of']})" for k, v in t["columns"].items())
        or t.get("detail", "-"),
        *_numbers({k: _worst(list(t["columns"].values()), k) for k in _NUMBER_HEADER}),
    ]


def _tables_part(tables: Sequence[Mapping[str, Any]]) -> list[str]:
    """How many tables are bitwise identical, and one row per table."""
    return [
        "## Tables",
        "",
        f"{sum(t['status'] == 'identical' for t in tables)} of {len(tables)} tables under "
        "`results/` are bitwise identical in the two runs (columns of measured times and the "
        "`code` stamp set aside). `expected`: the README's class of the study. For a table "
        "that differs: the columns that differ (cells that differ / all cells) and, worst over "
        "its numeric columns, the largest absolute difference, relative difference "
        "|a − b| / max(|a|, |b|) (large where a value is near 0), absolute difference relative "
        "to the column's largest magnitude, and distance in units in the last place (cells of "
        "the same sign, both non-zero).",
        "",
        _md(
            ["table", "expected", "status", "differing columns", *_NUMBER_HEADER],
            [_table_cells(t) for t in tables],
        ),
    ]


def _stamps_part(tables: Sequence[Mapping[str, Any]]) -> list[str]:
    """A warning naming the tables other code made in the two runs (none if there is none)."""
    stamps = [t["table"] for t in tables if "code stamps" in t]
    if not stamps:
        return []
    return [
        "",
        f"**Warning:** other code made the native and the emulated version of "
        f"{', '.join(stamps)} (their `code` stamps differ): those differences are not the "
        "emulation's alone.",
    ]


def _details_part(tables: Sequence[Mapping[str, Any]]) -> list[str]:
    """Every differing column of every table (none if there is none)."""
    details = [
        [t["table"], col, f"{c['cells']}/{c['of']}", *_numbers(c)]
        for t in tables
        for col, c in t["columns"].items()
    ]
    if not details:
        return []
    return [
        "",
        "### Differing columns",
        "",
        _md(["table", "column", "cells", *_NUMBER_HEADER], details),
    ]


def render(drill: Mapping[str, Any]) -> str:
    """The drill as Markdown: result line, the emulation as measured, claims, tables, and
    every differing column."""
    tables = drill["tables"]
    lines = [
        *_head(drill),
        "",
        *_emulation_part(drill),
        "",
        *_claims_part(drill),
        "",
        *_tables_part(tables),
        *_stamps_part(tables),
        *_details_part(tables),
    ]
    return "\n".join(lines) + "\n"
