"""Earlier verdicts of each claim (rsmhp.report.history): the table, adding a run, and the
fragility line of a verdict that moved."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pandas as pd
import pytest

from rsmhp.report.history import COLUMNS, add_claims, fragility, load_history, main
from rsmhp.report.ledger import Claim, KeyNumber

ROOT = Path(__file__).resolve().parents[2]


def _claim(cid="U-3", verdict="equivalent", value=-0.08, lo=-0.24, hi=0.07):
    key = KeyNumber("d", value, lo, hi, "m", "statistical", null=0.0)
    return Claim(cid, "c", "p", key, verdict, "r", setup="s")


def _record(cid, verdict, value):
    return {"id": cid, "verdict": verdict, "key": {"value": value, "ci_low": None, "ci_high": None}}


def test_stable_verdicts_are_not_fragile():
    h = add_claims(
        load_history(None), [_record("U-3", "equivalent", -0.1)], kind="implementation",
        label="a", date="2026-01-01",
    )  # fmt: skip
    assert fragility(_claim(), h) == ""
    assert fragility(_claim("other"), h) == ""


def test_a_verdict_that_moved_names_each_kind_and_the_sign_change():
    h = load_history(None)
    for label, date, verdict, value in [
        ("a", "2026-01-01", "inconclusive", 0.10),
        ("b", "2026-01-02", "inconclusive", 0.09),
        ("c", "2026-01-03", "equivalent", -0.05),
    ]:
        h = add_claims(
            h, [_record("U-3", verdict, value)], kind="implementation", label=label, date=date
        )
    h = add_claims(
        h, [_record("U-3", "equivalent", math.nan)], kind="machine", label="drill",
        date="2026-01-02", against={"U-3": "inconclusive"},
    )  # fmt: skip
    h = add_claims(
        h, [_record("U-3", "equivalent", -0.01)], kind="stream", label="explore", date="x"
    )
    line = fragility(_claim(), h)
    assert line.startswith(
        "published runs: inconclusive (a to b, 2 runs) → equivalent (c to this run, 2 runs); "
    )
    assert "another machine (drill): equivalent where the native run gave inconclusive" in line
    assert "another seed stream" not in line  # same verdict as this run
    assert line.endswith("key number changed sign (+0.0900 in b, -0.0800 now)")


def test_adding_the_same_run_twice_replaces_its_rows():
    h = add_claims(load_history(None), [_record("A", "supported", 1.0)], kind="stream",
                   label="s", date="d")  # fmt: skip
    h = add_claims(h, [_record("A", "inconclusive", 2.0)], kind="stream", label="s", date="d")
    assert len(h) == 1 and h.iloc[0]["verdict"] == "inconclusive"
    with pytest.raises(ValueError, match="kind must be one of"):
        add_claims(h, [], kind="other", label="s", date="d")


def test_bad_tables_are_refused_naming_the_row(tmp_path):
    p = tmp_path / "h.csv"
    pd.DataFrame(
        [["A", "implementation", "x", "d", "maybe", 1, "", "", ""]], columns=COLUMNS
    ).to_csv(p, index=False)
    with pytest.raises(ValueError, match=r"row 2: verdict must be one of"):
        load_history(p)
    p.write_text("claim,kind\nA,implementation\n")
    with pytest.raises(ValueError, match="columns must be"):
        load_history(p)


def test_cli_adds_a_claims_file(tmp_path, capsys):
    claims = tmp_path / "claims.json"
    claims.write_text(
        json.dumps({"commit": "abcdef1234", "claims": [_record("A", "supported", 1)]})
    )
    hist = tmp_path / "h.csv"
    assert main(["add", str(claims), "--kind", "implementation", "--history", str(hist)]) == 0
    h = load_history(hist)
    assert list(h["label"]) == ["abcdef1"] and list(h["verdict"]) == ["supported"]
    assert main(["add", str(tmp_path / "missing.json"), "--kind", "stream",
                 "--history", str(hist)]) == 2  # fmt: skip
    assert "error:" in capsys.readouterr().err


def test_the_committed_history_loads_and_covers_the_published_claims():
    h = load_history(ROOT / "paper/history.csv")
    published = json.loads((ROOT / "paper/claims.json").read_text(encoding="utf-8"))
    ids = {c["id"] for c in published["claims"]}
    assert ids <= set(h.loc[h["kind"] == "implementation", "claim"])


def test_this_runs_own_published_row_is_not_an_earlier_run():
    h = load_history(None)
    for label, verdict in [("a", "inconclusive"), ("b", "equivalent")]:
        h = add_claims(
            h, [_record("U-3", verdict, -0.05)], kind="implementation", label=label, date=label
        )
    # make publish added run b's row; rendering run b again must not count it twice
    assert fragility(_claim(), h, run="b") == (
        "published runs: inconclusive (a) → equivalent (this run)"
    )
    assert fragility(_claim(), h).endswith("equivalent (b to this run, 2 runs)")
