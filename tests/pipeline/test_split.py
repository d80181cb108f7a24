"""Jobs split into chunks and merged (rsmhp.pipeline.split) and the config key ``split``.

Oracles: the chunks of a split are the items in order, contiguous, near-equal and non-empty;
the long-horizon count by hand; a restricted contract accepts exactly its chunk's rows; a merge
of shuffled chunks gives the rows of the unsplit table in its order; bad ``split`` values are
refused naming the key and what is allowed; the whole-config hash and every rule but the
split ones leave ``split`` out (the Snakefile's NUMBERS_CONFIG).
"""

from __future__ import annotations

import copy
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from rsmhp.pipeline.config import ConfigError, check_config
from rsmhp.pipeline.contracts import Contract, check_table
from rsmhp.pipeline.io import IntermediateFileError, write_csv
from rsmhp.pipeline.split import (
    SPLIT_RULES,
    chunk,
    horizon_jobs,
    merge_checked,
    merge_ordered,
    n_chunks,
    restrict,
)

ROOT = Path(__file__).resolve().parents[2]
DEFAULT = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


@pytest.mark.parametrize(("n", "jobs"), [(10, 1), (10, 3), (10, 4), (3, 8), (150, 12), (1, 1)])
def test_chunks_are_contiguous_near_equal_and_cover_the_items(n, jobs):
    parts = [chunk(range(n), jobs, k) for k in range(n_chunks(n, jobs))]
    assert len(parts) == min(n, jobs)
    assert [i for p in parts for i in p] == list(range(n))
    assert max(map(len, parts)) - min(map(len, parts)) <= 1 and min(map(len, parts)) >= 1
    with pytest.raises(ValueError, match=rf"chunk {len(parts)} out of range"):
        chunk(range(n), jobs, len(parts))


def test_counts_refuse_bad_values():
    with pytest.raises(ValueError, match="jobs must be >= 1, got 0"):
        n_chunks(5, 0)
    with pytest.raises(TypeError, match="jobs must be an integer >= 1, got str"):
        chunk([1, 2], "2", 0)
    with pytest.raises(ValueError, match=r"H = 30 is not among the horizons"):
        horizon_jobs(2, 30, [6, 24])


def test_long_horizon_jobs_scale_with_h():
    hs = [2, 4, 6, 8, 12, 16, 24]
    assert [horizon_jobs(2, h, hs) for h in hs] == [1, 1, 1, 1, 1, 2, 2]
    assert [horizon_jobs(4, h, [6, 12, 24]) for h in (6, 12, 24)] == [1, 2, 4]
    assert [horizon_jobs(1, h, hs) for h in hs] == [1] * len(hs)


def _contract() -> Contract:
    keys = [(m, r) for m in ("b", "a") for r in range(5)]
    return Contract(
        rule="sim",
        columns=["method", "run", "x"],
        text=("method",),
        integer=("run",),
        keys=("method", "run"),
        expected=pd.DataFrame(keys, columns=["method", "run"]),
    )


def _table() -> pd.DataFrame:
    """Method-major ("b" before "a": the configured order, not the alphabet), runs ascending."""
    rng = np.random.default_rng(3)
    rows = [(m, r, rng.standard_normal()) for m in ("b", "a") for r in range(5)]
    return pd.DataFrame(rows, columns=["method", "run", "x"])


def test_restricted_contract_accepts_exactly_its_chunk():
    table = _table()
    part = restrict(_contract(), {"run": [1, 2]})
    check_table(table[table.run.isin([1, 2])], "chunk", part)
    with pytest.raises(IntermediateFileError, match="missing"):
        check_table(table[table.run == 1], "chunk", part)
    by_frame = restrict(_contract(), pd.DataFrame({"method": ["a"], "run": [4]}))
    assert by_frame.expected.values.tolist() == [["a", 4]]


def test_merge_puts_shuffled_chunks_back_in_the_unsplit_order(tmp_path):
    table = _table()
    runs = [chunk(range(5), 3, k) for k in range(3)]
    parts = [table[table.run.isin(r)].reset_index(drop=True) for r in runs]
    merged = merge_ordered(parts[::-1], ("method", "run"), {"method": ["b", "a"]})
    pd.testing.assert_frame_equal(merged, table)
    # through files, as the merge rules do: the bytes of the unsplit table
    paths = []
    for k, p in enumerate(parts):
        paths.append(tmp_path / f"{k}.csv")
        write_csv(p, paths[-1])
    whole = _contract()
    got = merge_checked(
        [str(p) for p in paths],
        [restrict(whole, {"run": r}) for r in runs],
        whole,
        ("method", "run"),
        {"method": ["b", "a"]},
    )
    write_csv(got, tmp_path / "merged.csv")
    write_csv(table, tmp_path / "unsplit.csv")
    assert (tmp_path / "merged.csv").read_bytes() == (tmp_path / "unsplit.csv").read_bytes()
    # a chunk with another chunk's rows is refused, naming the file
    write_csv(parts[1], paths[0])
    with pytest.raises(IntermediateFileError, match=r"0\.csv"):
        merge_checked(
            [str(p) for p in paths],
            [restrict(whole, {"run": r}) for r in runs],
            whole,
            ("method", "run"),
            {"method": ["b", "a"]},
        )
    with pytest.raises(ValueError, match=r"method values \['c'\] not in"):
        merge_ordered([table.assign(method="c")], ("method",), {"method": ["b", "a"]})


# ----------------------------------------------------------------------------- config


def test_default_config_names_every_split_rule():
    assert set(DEFAULT["split"]) == set(SPLIT_RULES)
    check_config(DEFAULT)
    tiny = yaml.safe_load((ROOT / "tests/config/tiny.yaml").read_text())
    assert all(tiny["split"][r] >= 2 for r in SPLIT_RULES)  # the workflow tests split every rule


@pytest.mark.parametrize(
    ("key", "value", "expected"),
    [
        ("frontier_confirm", 0, r"split\.frontier_confirm: 0 .*allowed: integer in \[1, 1000\]"),
        ("horizon_uav", 2.0, r"split\.horizon_uav: 2\.0"),
        ("decisions_uav", "4", r"split\.decisions_uav: '4'"),
        ("estimators_ablation", 5000, r"split\.estimators_ablation: 5000 .*\[1, 1000\]"),
        ("frontier_tune", 2, r"split\.frontier_tune: unknown key"),
    ],
)
def test_bad_split_values_are_named(key, value, expected):
    cfg = copy.deepcopy(DEFAULT)
    cfg["split"][key] = value
    with pytest.raises(ConfigError, match=expected):
        check_config(cfg)


def test_split_is_no_number_of_the_config():
    """Like run_store, `split` changes no number: the rules that record the whole config get
    it without `split`, and no rule but the split ones and their merges reads it."""
    common = (ROOT / "workflow/rules/common.smk").read_text()
    assert re.search(r"NUMBERS_CONFIG = \{[^}]*\(\"run_store\", \"split\"\)", common), common[:2000]
    readers = set()
    for smk in (ROOT / "workflow/rules").glob("*.smk"):
        # a rule's block: its header and the indented lines under it
        for name, body in re.findall(r"^rule (\w+):\n((?:(?:    .*)?\n)*)", smk.read_text(), re.M):
            if any(s in body for s in ("SPLIT[", "HZ_UNITS[")):
                readers.add(name)
    assert readers == set(SPLIT_RULES) | {f"{r}_merge" for r in SPLIT_RULES}, readers
