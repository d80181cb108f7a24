"""Contracts of the intermediate tables: what an aggregation step may assume about its inputs.

A simulation rule writes a table; an aggregation rule reads it. Between the two the file can
be truncated (a killed job, a full disk), edited, garbled or left over from another config.
Before any statistic is computed, :func:`read_checked` verifies a file against its
:class:`Contract`, which the producing experiment module derives from the *config* (not from
the file):

* the file is complete: a CSV ends with a newline (``write_csv`` always writes one, so a
  missing final newline means the last row was cut), a Parquet file parses;
* the required columns are present;
* dtypes: text columns hold non-empty text, boolean columns booleans, every other column
  numbers; integer columns hold whole numbers;
* finiteness: numeric columns hold finite numbers, except the ``nullable`` ones, which may be
  empty (NaN) where the producer leaves a value undefined, but never infinite;
* constants: columns that the config fixes (a model parameter, a sample size) hold that
  value in every row (numbers to a relative 1e-12: a CSV round trip may move the last bit);
* completeness: the key columns identify rows uniquely and their set equals the ``expected``
  key rows exactly (no row missing, none extra).

Every failure raises :class:`rsmhp.pipeline.io.IntermediateFileError` naming the file, the column or
the missing keys (a few examples and the count), and the rule that produces the file.

Code. Every table a rule writes records ``<rule>:<digest>`` of the code that made it
(:mod:`rsmhp.pipeline.io`, :mod:`rsmhp.pipeline.code_digest`). Before a rule computes anything,
:func:`check_codes` (called by :func:`rsmhp.pipeline.script.rule_logging` on all the rule's inputs)
refuses inputs made by different versions of one producing rule's code (a partial rerun
that mixed them) or by code other than what the producing rule's code gives now (stale).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.pipeline.io import IntermediateFileError, read_table, recorded_code

__all__ = ["Contract", "check_codes", "check_table", "read_checked"]

_EXAMPLES = 3


@dataclass(frozen=True)
class Contract:
    """What a table must hold.

        ``columns`` are required (in any order; more are allowed); ``text`` and ``boolean`` name
        the non-numeric ones, every other required column must be numeric; ``integer`` columns
        hold whole numbers; ``nullable`` numeric columns may be NaN (never infinite); ``keys``
        identify a row and ``expected`` (a frame with exactly the ``keys`` columns) lists every
        key row the config asks for, or is None to check uniqueness only; ``values`` maps columns
    to the value every row must hold. ``rule`` names the rule
        that writes the file.
    """

    rule: str
    columns: Sequence[str]
    text: Sequence[str] = ()
    boolean: Sequence[str] = ()
    integer: Sequence[str] = ()
    nullable: Sequence[str] = ()
    keys: Sequence[str] = ()
    expected: pd.DataFrame | None = field(default=None, compare=False)
    values: Mapping[str, Any] = field(default_factory=dict)
    min_rows: int = 1

    def __post_init__(self) -> None:
        unknown = [
            c
            for group in (
                self.text,
                self.boolean,
                self.integer,
                self.nullable,
                self.keys,
                self.values,
            )
            for c in group
            if c not in self.columns
        ]
        if unknown:
            raise ValueError(f"Contract: columns {unknown} are not among columns {self.columns}")
        if self.expected is not None and list(self.expected.columns) != list(self.keys):
            raise ValueError(
                f"Contract.expected: columns {list(self.expected.columns)} must equal keys "
                f"{list(self.keys)}"
            )


def _fail(path: Path, contract: Contract, what: str) -> IntermediateFileError:
    return IntermediateFileError(
        f"{path}: {what}. The file is incomplete, corrupt or from another config: delete it "
        f"and rerun rule {contract.rule} (e.g. `snakemake -j2 --forcerun {contract.rule}`)"
    )


def _key_text(keys: Sequence[str], row: Sequence) -> str:
    return ", ".join(
        f"{k}={v!r}" if isinstance(v, str) else f"{k}={v:g}" for k, v in zip(keys, row, strict=True)
    )


def _check_dtypes(df: pd.DataFrame, path: Path, contract: Contract) -> pd.DataFrame:
    text, boolean = set(contract.text), set(contract.boolean)
    out = df.copy()
    for col in contract.columns:
        values = out[col]
        if col in text:
            empty = values.isna() | (values.astype(str).str.len() == 0)
            if empty.any():
                raise _fail(
                    path, contract, f"column {col!r} is empty in data row {int(empty.idxmax()) + 1}"
                )
            continue
        if col in boolean:
            if values.dtype != bool:
                bad = ~values.astype(str).isin(["True", "False"])
                if bad.any():
                    i = int(bad.idxmax())
                    raise _fail(
                        path,
                        contract,
                        f"column {col!r} is not boolean (data row {i + 1}: {values[i]!r})",
                    )
                out[col] = values.astype(str) == "True"
            continue
        if not pd.api.types.is_numeric_dtype(values) or values.dtype == bool:
            num = pd.to_numeric(values, errors="coerce")
            bad = num.isna() & values.notna()
            if bad.any() or values.dtype == bool:
                i = bad.idxmax() if bad.any() else values.index[0]
                raise _fail(
                    path,
                    contract,
                    f"column {col!r} has the non-numeric value {values[i]!r} in data row "
                    f"{int(i) + 1}",
                )
            out[col] = values = num
        arr = values.to_numpy(dtype=float)
        nan, inf = np.isnan(arr), np.isinf(arr)
        if inf.any() or (nan.any() and col not in contract.nullable):
            i = int(np.flatnonzero(inf | (nan if col not in contract.nullable else False))[0])
            raise _fail(
                path,
                contract,
                f"column {col!r} has the non-finite value {float(arr[i])!r} in data row {i + 1} "
                f"(allowed: finite numbers{', or empty' if col in contract.nullable else ''})",
            )
        if col in contract.integer:
            frac = ~nan & (arr != np.round(arr))
            if frac.any():
                i = int(np.flatnonzero(frac)[0])
                raise _fail(
                    path,
                    contract,
                    f"column {col!r} has the non-integer value {float(arr[i])!r} in data row "
                    f"{i + 1}",
                )
            if not nan.any() and values.dtype.kind == "f":
                out[col] = values.astype(np.int64)
    return out


def _plain(value: Any) -> Any:
    """A numpy scalar as the Python value (for messages)."""
    return value.item() if isinstance(value, np.generic) else value


def _check_values(df: pd.DataFrame, path: Path, contract: Contract) -> None:
    for col, want in contract.values.items():
        have = df[col]
        if isinstance(want, str):
            bad = have.astype(str) != want
        else:
            bad = ~np.isclose(have.to_numpy(dtype=float), float(want), rtol=1e-12, atol=0.0)
        if bad.any():
            i = int(np.flatnonzero(np.asarray(bad))[0])
            raise _fail(
                path,
                contract,
                f"column {col!r} is {_plain(have.iloc[i])!r} in data row {i + 1}, but the config "
                f"gives "
                f"{want!r}",
            )


def _check_keys(df: pd.DataFrame, path: Path, contract: Contract) -> None:
    keys = list(contract.keys)
    if not keys:
        return
    dup = df.duplicated(keys, keep="first")
    if dup.any():
        i = int(np.flatnonzero(dup.to_numpy())[0])
        raise _fail(
            path,
            contract,
            f"{int(dup.sum())} duplicate row(s), e.g. data row {i + 1} "
            f"({_key_text(keys, df[keys].iloc[i])})",
        )
    if contract.expected is None:
        return
    exp = contract.expected.drop_duplicates().reset_index(drop=True)
    have = df[keys].reset_index(drop=True)
    for k in keys:  # compare numbers as numbers (1 == 1.0), text as text
        if pd.api.types.is_numeric_dtype(exp[k]) and not pd.api.types.is_bool_dtype(exp[k]):
            exp[k], have[k] = exp[k].astype(float), have[k].astype(float)
        else:
            exp[k], have[k] = exp[k].astype(str), have[k].astype(str)
    merged = exp.merge(have, on=keys, how="outer", indicator=True)
    missing = merged[merged["_merge"] == "left_only"][keys]
    extra = merged[merged["_merge"] == "right_only"][keys]
    problems = []
    if len(missing):
        eg = "; ".join(_key_text(keys, r) for r in missing.head(_EXAMPLES).itertuples(index=False))
        problems.append(f"{len(missing)} of {len(exp)} expected rows are missing (e.g. {eg})")
    if len(extra):
        eg = "; ".join(_key_text(keys, r) for r in extra.head(_EXAMPLES).itertuples(index=False))
        problems.append(f"{len(extra)} row(s) the config does not ask for (e.g. {eg})")
    if problems:
        raise _fail(path, contract, " and ".join(problems))


def check_table(df: pd.DataFrame, path: str | os.PathLike, contract: Contract) -> pd.DataFrame:
    """Check ``df`` (read from ``path``) against ``contract``; return it with numeric columns
    as numbers (integer columns as int64). Raises
    :class:`rsmhp.pipeline.io.IntermediateFileError`."""
    path = Path(path)
    missing = [c for c in contract.columns if c not in df.columns]
    if missing:
        raise _fail(path, contract, f"missing column(s) {missing}; found {list(df.columns)}")
    if len(df) < contract.min_rows:
        raise _fail(path, contract, f"{len(df)} rows, expected at least {contract.min_rows}")
    df = _check_dtypes(df.reset_index(drop=True), path, contract)
    _check_values(df, path, contract)
    _check_keys(df, path, contract)
    return df


def read_checked(path: str | os.PathLike, contract: Contract) -> pd.DataFrame:
    """Read a CSV or Parquet intermediate and check it (see the module docstring)."""
    path = Path(path)
    if path.suffix != ".parquet" and path.exists() and path.stat().st_size:
        with open(path, "rb") as fh:
            fh.seek(-1, os.SEEK_END)
            if fh.read(1) != b"\n":
                raise _fail(path, contract, "the last row is cut off (no final newline)")
    try:
        df = read_table(path, (), min_rows=0)
    except IntermediateFileError as exc:  # unreadable: say which rule writes it
        what = str(exc).removeprefix(f"{path}: ").split("; delete it")[0]
        raise _fail(path, contract, what) from exc
    return check_table(df, path, contract)


def _files_text(files: Sequence[str]) -> str:
    shown = ", ".join(files[:_EXAMPLES])
    return shown + (f" and {len(files) - _EXAMPLES} more" if len(files) > _EXAMPLES else "")


def check_codes(
    paths: Iterable[str | os.PathLike], current: Callable[[str], str | None] | None = None
) -> dict[str, str]:
    """Refuse ``paths`` (a rule's inputs) unless, for every producing rule, the files it made
    record one and the same code digest and, where ``current(rule)`` gives the digest of that
    rule's code now, that one. Files that record no code (not tables, or written outside a
    rule) are not checked. Returns ``{path: "<rule>:<digest>"}`` of the recorded files.

    Raises :class:`rsmhp.pipeline.io.IntermediateFileError` naming the files, their digests and the
    rule to rerun (nothing is deleted or rewritten)."""
    stamps = {str(p): s for p in paths if (s := recorded_code(p)) is not None}
    by_rule: dict[str, dict[str, list[str]]] = {}
    for path, stamp in stamps.items():
        rule, _, digest = stamp.rpartition(":")
        by_rule.setdefault(rule or "?", {}).setdefault(digest, []).append(path)
    problems = []
    for stamp_rule, digests in sorted(by_rule.items()):
        now = current(stamp_rule) if current is not None and stamp_rule != "?" else None
        # "uav_simulate+nbo": rule uav_simulate, its jobs of the method family nbo
        name, _, families = stamp_rule.partition("+")
        rule = f"{name} (method families {families})" if families else name
        rerun = (
            f"rerun rule {name} (e.g. `snakemake -j2 --forcerun {name}`)"
            if name != "?"
            else "rerun the rule that produces them"
        )
        if len(digests) > 1:
            made = "; ".join(
                f"{_files_text(files)} by code {d}" for d, files in sorted(digests.items())
            )
            now_text = f" (the current code gives {now})" if now else ""
            problems.append(
                f"{made}: inputs made by different versions of the code of rule {rule}"
                f"{now_text}, e.g. by a partial rerun; nothing was computed: {rerun}"
            )
        elif now is not None and now not in digests:
            ((digest, files),) = digests.items()
            problems.append(
                f"{_files_text(files)}: made by code {digest} of rule {rule}, but its code now "
                f"gives {now} (an rsmhp module it imports changed since); nothing was "
                f"computed: {rerun}"
            )
    if problems:
        raise IntermediateFileError("\n".join(problems))
    return stamps
