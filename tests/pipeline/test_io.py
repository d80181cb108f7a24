"""Atomic output files: readable like ordinary files (mode from the umask), nothing left
behind, the old file kept when a write fails."""

from __future__ import annotations

import os
import stat

import pandas as pd
import pytest

from rsmhp.pipeline.io import (
    IntermediateFileError,
    read_table,
    recorded_code,
    stamping,
    write_csv,
    write_json,
    write_parquet,
    write_text,
)


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


# ----------------------------------------------------------------------------- code stamps


def test_tables_written_in_a_rule_record_its_code_and_nothing_else_changes(tmp_path):
    """The stamp is one last column; without it the bytes are those of an unstamped write."""
    df = pd.DataFrame({"a": [1, 2], "x": [0.1, 1 / 3], "s": ["p", "q,r"]})
    write_csv(df, tmp_path / "plain.csv")
    write_parquet(df, tmp_path / "plain.parquet")
    with stamping("make_t:0123456789ab"):
        write_csv(df, tmp_path / "t.csv")
        write_parquet(df, tmp_path / "t.parquet")
        write_json({"k": 1}, tmp_path / "t.json")
        write_csv(df.assign(code="an old stamp"), tmp_path / "restamped.csv")
    write_csv(df, tmp_path / "after.csv")  # outside the block: no stamp
    plain = (tmp_path / "plain.csv").read_text().splitlines()
    stamped = (tmp_path / "t.csv").read_text().splitlines()
    assert stamped[0] == plain[0] + ",code"
    assert stamped[1:] == [line + ",make_t:0123456789ab" for line in plain[1:]]
    assert (tmp_path / "restamped.csv").read_text() == (tmp_path / "t.csv").read_text()
    assert (tmp_path / "after.csv").read_text() == (tmp_path / "plain.csv").read_text()
    back = pd.read_parquet(tmp_path / "t.parquet")
    assert list(back.columns) == ["a", "x", "s", "code"]
    pd.testing.assert_frame_equal(
        back.drop(columns="code"), pd.read_parquet(tmp_path / "plain.parquet")
    )
    for name in ("t.csv", "t.parquet", "t.json"):
        assert recorded_code(tmp_path / name) == "make_t:0123456789ab", name
    for name in ("plain.csv", "plain.parquet", "missing.csv"):
        assert recorded_code(tmp_path / name) is None, name


def test_read_table_drops_the_stamp_and_refuses_a_file_of_two_code_versions(tmp_path):
    df = pd.DataFrame({"a": [1, 2, 3]})
    with stamping("make_t:0123456789ab"):
        write_csv(df, tmp_path / "t.csv")
    back = read_table(tmp_path / "t.csv", ["a"])
    pd.testing.assert_frame_equal(back, df)
    mixed = pd.read_csv(tmp_path / "t.csv")
    mixed.loc[2, "code"] = "make_t:ba9876543210"
    mixed.to_csv(tmp_path / "mixed.csv", index=False)
    with pytest.raises(IntermediateFileError, match="2 versions of the code") as err:
        read_table(tmp_path / "mixed.csv", ["a"])
    assert "make_t:0123456789ab, make_t:ba9876543210" in str(err.value)
