"""Reading and writing intermediate tables with clear errors for corrupt or foreign files."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterable
from pathlib import Path

import pandas as pd

__all__ = ["IntermediateFileError", "read_table", "write_csv", "write_parquet", "write_text"]


class IntermediateFileError(RuntimeError):
    """An intermediate result file is missing, unreadable, or lacks required columns."""


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
    """Write ``df`` atomically (temp file + rename) with full float precision, no index."""
    _atomic(path, lambda tmp: df.to_csv(tmp, index=False, lineterminator="\n"))


def write_parquet(df: pd.DataFrame, path: str | os.PathLike) -> None:
    """Write ``df`` atomically as Parquet (pyarrow), no index."""
    _atomic(path, lambda tmp: df.to_parquet(tmp, index=False, engine="pyarrow"))


def write_text(text: str, path: str | os.PathLike) -> None:
    """Write text atomically."""
    _atomic(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
