"""What the portability drill compares: every table of the two ``results/`` trees
(:func:`compare_results`, :func:`compare_frames`: bitwise, or per column the largest
differences) and every claim of the reference, the native and the emulated run
(:func:`compare_claims`)."""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

__all__ = [
    "CODE_COLUMN",
    "compare_claims",
    "compare_frames",
    "compare_results",
    "expected_class",
    "is_timing_column",
    "read_table",
    "section_claims",
]

#: the code stamp column of every table (rsmhp.pipeline.io.CODE_COLUMN; not imported, so this module
#: stays outside the code digest of every rule)
CODE_COLUMN = "code"

#: read_csv arguments that parse every float exactly (pandas 3's default parser does;
#: before it, the round-trip parser)
_CSV_EXACT = {} if int(pd.__version__.split(".")[0]) >= 3 else {"float_precision": "round_trip"}

_TIMING = re.compile(r"(.*_)?(seconds|ms)(_.*)?|cpu_.*")

#: tables of the statistically reproducible studies (README: UAV closed loop, UAV decisions)
_STATISTICAL = ("uav/", "decisions/uav_", "decisions/map/")


def is_timing_column(name: str) -> bool:
    """A measured time (``cpu_seconds``, ``plan_seconds``, ``plan_seconds_per_run``,
    ``seconds``, ``cpu_median``, ``plan_ms``, ...): set aside, it differs between any two
    executions."""
    return bool(_TIMING.fullmatch(str(name)))


def expected_class(table: str) -> str:
    """How the README says a table (path relative to ``results/``) reproduces: ``bitwise``
    (LQG, estimator, LQG decision study) or ``statistical`` (UAV, UAV decision study)."""
    return "statistical" if table.startswith(_STATISTICAL) else "bitwise"


def _numeric_diff(a: pd.Series, b: pd.Series) -> dict[str, Any] | None:
    """None if the columns are bitwise equal (NaN equal to NaN), else how they differ: the
    number of differing ``cells`` (``of`` all), of them ``non-finite`` (NaN or inf on one
    side only), and over the finite ones the largest absolute difference, relative
    difference ``|a - b| / max(|a|, |b|)``, absolute difference relative to the column's
    largest magnitude, and distance in units in the last place (over cells with the same
    sign on both sides, both non-zero: elsewhere it counts the floats in between, e.g.
    about 4.6e18 from 0.0 to 1e-17; None if there is none, and for integer columns)."""
    x = a.to_numpy(dtype=np.float64, na_value=np.nan)
    y = b.to_numpy(dtype=np.float64, na_value=np.nan)
    both_int = pd.api.types.is_integer_dtype(a) and pd.api.types.is_integer_dtype(b)
    if both_int:
        same = a.to_numpy() == b.to_numpy()
    else:
        same = (x.view(np.int64) == y.view(np.int64)) | (np.isnan(x) & np.isnan(y))
    if same.all():
        return None
    finite = np.isfinite(x) & np.isfinite(y)
    col_max = float(np.max(np.maximum(np.abs(x[finite]), np.abs(y[finite])), initial=0.0))
    finite &= ~same
    d = np.abs(x[finite] - y[finite])
    scale = np.maximum(np.abs(x[finite]), np.abs(y[finite]))
    rel = np.divide(d, scale, out=np.zeros_like(d), where=scale > 0)
    ulps = None
    comparable = finite & (x != 0) & (y != 0) & (np.signbit(x) == np.signbit(y))
    if comparable.any() and not both_int:
        # same sign, both non-zero: the bit patterns count the floats in between
        ulps = int(np.abs(x[comparable].view(np.int64) - y[comparable].view(np.int64)).max())
    return {
        "cells": int((~same).sum()),
        "of": len(same),
        "non-finite": int((~same & ~np.isfinite(x) | ~same & ~np.isfinite(y)).sum()),
        "max abs": float(d.max()) if d.size else math.nan,
        "max rel": float(rel.max()) if rel.size else math.nan,
        "max abs / column max": float(d.max()) / col_max if d.size and col_max > 0 else math.nan,
        "max ulps": ulps,
    }


def compare_frames(native: pd.DataFrame, emulated: pd.DataFrame) -> dict[str, Any]:
    """Compare two versions of one table, timing columns and the code stamp set aside:
    ``status`` ``identical`` (every other cell bit for bit), ``differs`` (``columns``: per
    differing column the number of cells, largest absolute and relative difference, largest
    distance in ulps; text columns: the number of cells), ``columns differ`` or ``rows
    differ``; ``set aside``: the columns left out."""
    aside = [
        c
        for c in dict.fromkeys([*native.columns, *emulated.columns])
        if c == CODE_COLUMN or is_timing_column(c)
    ]
    a, b = (
        native.drop(columns=aside, errors="ignore"),
        emulated.drop(columns=aside, errors="ignore"),
    )
    out: dict[str, Any] = {"set aside": aside, "rows": len(a), "columns": {}}
    if list(a.columns) != list(b.columns):
        out["status"] = "columns differ"
        out["detail"] = (
            f"only native: {sorted(set(a.columns) - set(b.columns))}, only emulated: "
            f"{sorted(set(b.columns) - set(a.columns))}"
            + ("" if set(a.columns) != set(b.columns) else ", order differs")
        )
        return out
    if len(a) != len(b):
        out["status"] = "rows differ"
        out["detail"] = f"{len(a)} rows native, {len(b)} emulated"
        return out
    for col in a.columns:
        sa, sb = a[col], b[col]
        numeric = all(
            pd.api.types.is_numeric_dtype(s) and not pd.api.types.is_bool_dtype(s) for s in (sa, sb)
        )
        if numeric:
            diff = _numeric_diff(sa, sb)
        else:
            ta, tb = sa.astype(object), sb.astype(object)
            same = (ta == tb).to_numpy(dtype=bool) | (ta.isna() & tb.isna()).to_numpy()
            diff = None if same.all() else {"cells": int((~same).sum()), "of": len(same)}
        if diff is not None:
            out["columns"][col] = diff
    out["status"] = "differs" if out["columns"] else "identical"
    return out


def read_table(path: str | os.PathLike) -> pd.DataFrame:
    """A CSV (floats parsed exactly: the workflow writes them with full precision) or
    Parquet table."""
    path = Path(path)
    if path.suffix == ".parquet":
        return pd.read_parquet(path)
    return pd.read_csv(path, **_CSV_EXACT)


def _tables(results: Path) -> set[str]:
    if not results.is_dir():
        return set()
    return {
        str(p.relative_to(results))
        for p in results.rglob("*")
        if p.suffix in (".csv", ".parquet")
        and p.is_file()
        and p.relative_to(results).parts[0] != "portability"
    }


def _stamps(df: pd.DataFrame) -> set[str]:
    return set(df[CODE_COLUMN].dropna().astype(str)) if CODE_COLUMN in df else set()


def compare_results(
    native: str | os.PathLike, emulated: str | os.PathLike, emulated_only: bool = False
) -> list[dict[str, Any]]:
    """One entry per CSV/Parquet table under either ``results`` directory (``portability/``
    aside), in path order: :func:`compare_frames` of the two versions with the table's
    ``table`` path, ``expected`` class (:func:`expected_class`) and, when the code stamps of
    the two differ (other code made them), ``code stamps``; ``status`` ``missing (native)``
    or ``missing (emulated)`` when only one run has it. ``emulated_only``: only the tables of
    the emulated run (a drill of some targets: the native run's others are not in it)."""
    native, emulated = Path(native), Path(emulated)
    out = []
    names = _tables(emulated) if emulated_only else _tables(native) | _tables(emulated)
    for rel in sorted(names):
        entry: dict[str, Any] = {"table": rel, "expected": expected_class(rel)}
        if not (native / rel).is_file() or not (emulated / rel).is_file():
            side = "native" if not (native / rel).is_file() else "emulated"
            out.append({**entry, "status": f"missing ({side})", "columns": {}, "set aside": []})
            continue
        a, b = read_table(native / rel), read_table(emulated / rel)
        entry.update(compare_frames(a, b))
        if _stamps(a) != _stamps(b):
            entry["code stamps"] = {"native": sorted(_stamps(a)), "emulated": sorted(_stamps(b))}
        out.append(entry)
    return out


def section_claims(report_dir: str | os.PathLike) -> dict[str, list[Any]]:
    """The claims of every report section a run made, ``{section: [Claim, ...]}`` in name
    order, from ``<report_dir>/<section>.json`` (``results/report/``, each study's summary
    rule writes one; the report rule gathers them into ``results/paper/claims.json``). A
    clear ``ValueError`` names a section file that is not of that form."""
    from rsmhp.report.ledger import Claim

    out: dict[str, list[Any]] = {}
    for path in sorted(Path(report_dir).glob("*.json")):
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
            out[path.stem] = [Claim.from_dict(c) for c in data["claims"]]
        except (ValueError, TypeError, KeyError) as exc:
            raise ValueError(f"{path}: not a report section with a list 'claims' ({exc})") from exc
    return out


def compare_claims(
    reference: Sequence[Any],
    native: Sequence[Any],
    emulated: Sequence[Any],
    n_statistical: int | None = None,
) -> list[dict[str, Any]]:
    """One row per claim (reference order, then claims only in a run): the key number of
    the reference, the native and the emulated run, emulated minus native (absolute and
    relative), whether it is bitwise equal, ``make verify``'s status of each run against
    the reference (:func:`rsmhp.report.verify.compare`; ``n_statistical``, the whole
    reference's statistical claims when only some are compared, so the tolerance is
    ``make verify``'s) and whether all three verdicts are the same. Claims are
    :class:`rsmhp.report.ledger.Claim`."""
    from rsmhp.report.verify import compare

    ver_native = compare(reference, native, n_statistical).set_index("id")
    ver_emul = compare(reference, emulated, n_statistical).set_index("id")
    by = [{c.id: c for c in claims} for claims in (reference, native, emulated)]
    ids = list(dict.fromkeys([*by[0], *by[1], *by[2]]))
    return [_claim_row(cid, *(b.get(cid) for b in by), ver_native, ver_emul) for cid in ids]


def _claim_row(
    cid: str, ref: Any, nat: Any, emu: Any, ver_native: pd.DataFrame, ver_emul: pd.DataFrame
) -> dict[str, Any]:
    """The row of :func:`compare_claims` of claim ``cid`` (each of ``ref``, ``nat``, ``emu``
    None where that run lacks it), with ``make verify``'s comparisons (indexed by id)."""
    some = ref or nat or emu
    value = [c.key.value if c else math.nan for c in (ref, nat, emu)]
    diff = value[2] - value[1]
    scale = max(abs(value[1]), abs(value[2]))
    return {
        "id": cid,
        "key number": some.key.name + (f" ({some.key.unit})" if some.key.unit else ""),
        "reproducible": some.key.reproducible,
        "reference": value[0],
        "native": value[1],
        "emulated": value[2],
        "emulated - native": diff,
        "relative": abs(diff) / scale if scale > 0 else (0.0 if diff == 0 else math.nan),
        "bitwise equal": bool(
            nat and emu and np.float64(value[1]).tobytes() == np.float64(value[2]).tobytes()
        ),
        "emulated - reference": value[2] - value[0],
        "tolerance": float(ver_emul.loc[cid, "tolerance"]) if cid in ver_emul.index else math.nan,
        "verdict (reference)": ref.verdict if ref else "-",
        "verdict (native)": nat.verdict if nat else "-",
        "verdict (emulated)": emu.verdict if emu else "-",
        "same verdict": bool(ref and nat and emu and ref.verdict == nat.verdict == emu.verdict),
        "verify (native)": str(ver_native.loc[cid, "status"]) if cid in ver_native.index else "-",
        "verify (emulated)": str(ver_emul.loc[cid, "status"]) if cid in ver_emul.index else "-",
    }
