"""Atomic output files: readable like ordinary files (mode from the umask), nothing left
behind, the old file kept when a write fails."""

from __future__ import annotations

import os
import stat

import pandas as pd
import pytest

from rsmhp.io import write_csv, write_parquet, write_text


@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002])
def test_outputs_honour_the_umask(tmp_path, mask):
    old = os.umask(mask)
    try:
        df = pd.DataFrame({"a": [1, 2]})
        write_csv(df, tmp_path / "t.csv")
        write_parquet(df, tmp_path / "t.parquet")
        write_text("x\n", tmp_path / "t.md")
    finally:
        os.umask(old)
    for name in ("t.csv", "t.parquet", "t.md"):
        mode = stat.S_IMODE((tmp_path / name).stat().st_mode)
        assert mode == 0o666 & ~mask, (name, oct(mode))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv", "t.md", "t.parquet"]


def test_a_failed_write_keeps_the_old_file(tmp_path):
    target = tmp_path / "t.csv"
    write_text("good\n", target)

    class Boom(pd.DataFrame):
        def to_csv(self, *args, **kwargs):
            raise RuntimeError("disk full")

    with pytest.raises(RuntimeError, match="disk full"):
        write_csv(Boom({"a": [1]}), target)
    assert target.read_text() == "good\n"
    assert [p.name for p in tmp_path.iterdir()] == ["t.csv"]  # no temporary file left
