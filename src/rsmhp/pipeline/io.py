"""Reading and writing intermediate tables with clear errors for corrupt or foreign files.

Code stamps. Inside a rule script (:func:`rsmhp.pipeline.script.rule_logging` activates
:func:`stamping`) every table written here records the code that made it: a last column
:data:`CODE_COLUMN` holding ``<rule>:<digest>`` (:mod:`rsmhp.pipeline.code_digest`) in every row,
for CSV and Parquet alike (:func:`write_json` adds the same as a top-level field). Apart from
that column a table's bytes are what they were without it. :func:`read_table` checks that a
file's rows hold one stamp and drops the column, so analysis code never sees it;
:func:`recorded_code` reads a file's stamp cheaply (first data row, or the Parquet column)
for the checks of :func:`rsmhp.pipeline.contracts.check_codes`. Outside a rule nothing is stamped.
"""

from __future__ import annotations

import csv
import json
import os
import tempfile
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from typing import Any

import pandas as pd

__all__ = [
    "CODE_COLUMN",
    "IntermediateFileError",
    "read_table",
    "recorded_code",
    "stamping",
    "write_csv",
    "write_json",
    "write_parquet",
    "write_text",
]

#: the column (and JSON field) that records ``<rule>:<digest>`` of the code that wrote a file
CODE_COLUMN = "code"

_STAMP: ContextVar[str | None] = ContextVar("rsmhp_code_stamp", default=None)


class IntermediateFileError(RuntimeError):
    """An intermediate result file is missing, unreadable, or lacks required columns."""


@contextmanager
def stamping(stamp: str | None) -> Iterator[None]:
    """Within the block, tables written by this module record ``stamp`` (``<rule>:<digest>``;
    None: nothing is recorded)."""
    token = _STAMP.set(stamp)
    try:
        yield
    finally:
        _STAMP.reset(token)


def _stamped(df: pd.DataFrame) -> pd.DataFrame:
    stamp = _STAMP.get()
    if stamp is None:
        return df
    return df.drop(columns=CODE_COLUMN, errors="ignore").assign(**{CODE_COLUMN: stamp})


def recorded_code(path: str | os.PathLike) -> str | None:
    """The ``<rule>:<digest>`` a file records (its first data row's :data:`CODE_COLUMN`, or
    the JSON field), or None if it records none or cannot be read (the contracts report
    unreadable files)."""
    path = Path(path)
    try:
        if path.suffix == ".parquet":
            import pyarrow.parquet as pq

            if CODE_COLUMN not in pq.read_schema(path).names:
                return None
            column = pq.read_table(path, columns=[CODE_COLUMN]).column(0)
            value = column[0].as_py() if len(column) else None
        elif path.suffix == ".csv":
            with open(path, newline="", encoding="utf-8") as fh:
                reader = csv.reader(fh)
                header, row = next(reader, []), next(reader, [])
            if CODE_COLUMN not in header or len(row) != len(header):
                return None
            value = row[header.index(CODE_COLUMN)]
        elif path.suffix == ".json":
            data = json.loads(path.read_text(encoding="utf-8"))
            value = data.get(CODE_COLUMN) if isinstance(data, dict) else None
        else:
            return None
    except Exception:  # unreadable: the contract check names the problem
        return None
    return value if isinstance(value, str) and value else None


def read_table(
    path: str | os.PathLike, required: Iterable[str], *, min_rows: int = 1
) -> pd.DataFrame:
    """Read a CSV or Parquet file and check it has the ``required`` columns and rows.

    Raises :class:`IntermediateFileError` naming the file and what is wrong (and suggesting the
    rule to rerun), instead of failing later with a KeyError deep in the analysis.
    """
    path = Path(path)
    try:
        if path.suffix == ".parquet":
            df = pd.read_parquet(path)
        else:
            df = pd.read_csv(path)
    except FileNotFoundError as exc:
        raise IntermediateFileError(f"{path}: file not found") from exc
    except Exception as exc:  # pandas/pyarrow raise many parser error types
        raise IntermediateFileError(
            f"{path}: cannot be parsed ({type(exc).__name__}: {exc}); delete it and rerun the "
            "rule that produces it"
        ) from exc
    missing = [c for c in required if c not in df.columns]
    if missing:
        raise IntermediateFileError(
            f"{path}: missing column(s) {missing}; found {list(df.columns)}. The file is corrupt "
            "or from another version: delete it and rerun the rule that produces it"
        )
    if CODE_COLUMN in df.columns:
        stamps = df[CODE_COLUMN].dropna().astype(str).unique()
        if len(stamps) > 1:
            raise IntermediateFileError(
                f"{path}: its rows were made by {len(stamps)} versions of the code "
                f"({', '.join(sorted(stamps))}); delete it and rerun the rule that produces it"
            )
        df = df.drop(columns=CODE_COLUMN)
    if len(df) < min_rows:
        raise IntermediateFileError(f"{path}: has {len(df)} rows, expected at least {min_rows}")
    numeric = df.select_dtypes("number")
    if numeric.isna().all(axis=None) and len(numeric.columns):
        raise IntermediateFileError(f"{path}: every numeric value is missing")
    return df


def _umask() -> int:
    """The process umask (read from /proc where available, which changes nothing; else set
    and restored at once)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except OSError:
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _atomic(path: str | os.PathLike, write) -> None:
    """Write through a temporary file in the target directory, then rename it over ``path``
    (a reader never sees a half-written file; a failed write leaves the old file). The file
    gets the mode an ordinary ``open`` would give (0666 minus the umask), not mkstemp's 0600."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        write(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_csv(df: pd.DataFrame, path: str | os.PathLike) -> None:
    """Write ``df`` atomically (temp file + rename) with full float precision, no index; in
    a rule, with the code stamp as last column (module docstring)."""
    out = _stamped(df)
    _atomic(path, lambda tmp: out.to_csv(tmp, index=False, lineterminator="\n"))


def write_parquet(df: pd.DataFrame, path: str | os.PathLike) -> None:
    """Write ``df`` atomically as Parquet (pyarrow), no index; in a rule, with the code stamp
    as last column (module docstring)."""
    out = _stamped(df)
    _atomic(path, lambda tmp: out.to_parquet(tmp, index=False, engine="pyarrow"))


def write_json(data: dict[str, Any], path: str | os.PathLike, **dumps: Any) -> None:
    """Write ``data`` atomically as JSON (``json.dumps`` keyword arguments ``dumps``, default
    ``indent=2``); in a rule, with the code stamp as field :data:`CODE_COLUMN`."""
    stamp = _STAMP.get()
    out = dict(data) if stamp is None else {**data, CODE_COLUMN: stamp}
    write_text(json.dumps(out, **({"indent": 2} | dumps)) + "\n", path)


def write_text(text: str, path: str | os.PathLike) -> None:
    """Write text atomically."""
    _atomic(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
