"""Choices made after their data (rsmhp.report.disclosures): which claims a disclosure
touches, how their verdicts read, the main text's list; and the main text's mention of an
earlier seed stream's other verdicts (rsmhp.report.findings.other_streams)."""

from __future__ import annotations

import subprocess

import pandas as pd
import pytest

from rsmhp.report.disclosures import (
    DISCLOSURES,
    Disclosure,
    disclosure_lines,
    disclosures_of,
    verdict_note,
)
from rsmhp.report.findings import other_streams, verdict_text
from rsmhp.report.history import COLUMNS
from rsmhp.report.ledger import Claim, KeyNumber


def _claim(cid: str, verdict: str = "equivalent") -> Claim:
    key = KeyNumber("d", 0.01, -0.05, 0.07, "m", "statistical", null=0.0, margin=0.25)
    return Claim(cid, "c", "p", key, verdict, "r", setup="s")


def test_a_disclosure_touches_its_ids_and_their_setups_only():
    d = Disclosure(("DEC-7", "UAV-1"), "margin_after_result")
    assert d.touches("DEC-7") and d.touches("DEC-7-footprint150") and d.touches("UAV-1")
    assert not d.touches("DEC-70") and not d.touches("UAV-10") and not d.touches("DEC-6")


def test_the_audited_choices_are_disclosed_beside_their_verdicts():
    """UAV-1..3 and DEC-6/7: margins set after the first result; DEC-8b: moved after its
    result; other claims read as before."""
    for cid in ("UAV-1", "UAV-2", "UAV-3", "DEC-6", "DEC-7-footprint150"):
        assert verdict_text(_claim(cid)) == (
            "equivalent (exploratory: margin set after the first result)"
        ), cid
    assert verdict_text(_claim("DEC-8b", "inconclusive")) == (
        "inconclusive (moved to the variants after its result)"
    )
    for cid in ("UAV-4", "DEC-8a", "FR-3-paper", "LQG-1"):
        assert verdict_note(_claim(cid)) == "" and verdict_text(_claim(cid)) == "equivalent"
    assert [d.macro for d in disclosures_of("DEC-6")] == ["margin_after_result"]


def test_the_disclosed_commits_exist_in_this_order():
    """Every commit a disclosure names is in this repository's history, and the margins came
    after the result they judge was published."""

    def date(commit: str) -> int:
        out = subprocess.run(
            ["git", "log", "-1", "--format=%ct", commit], capture_output=True, text=True
        )
        if out.returncode != 0:
            pytest.skip("not a git checkout with the project's history")
        return int(out.stdout)

    margin = DISCLOSURES[0].values
    assert date(margin["published"]) < date(margin["margin_commit"])
    assert date(DISCLOSURES[1].values["commit"]) > 0


def test_the_main_text_lists_the_disclosures_of_this_runs_claims():
    claims = [_claim("UAV-2"), _claim("DEC-6"), _claim("LQG-1")]
    lines = disclosure_lines(claims)
    assert len(lines) == 1 and lines[0].startswith("UAV-2, DEC-6: the equivalence margins")
    assert "cae91a3" in lines[0] and "d90d881" in lines[0] and "exploratory" in lines[0]
    assert disclosure_lines([_claim("LQG-1")]) == []
    both = disclosure_lines([_claim("DEC-8b", "inconclusive"), _claim("UAV-1")])
    assert [line.split(":")[0] for line in both] == ["UAV-1", "DEC-8b"]


def _history(rows: list[tuple]) -> pd.DataFrame:
    full = [(*r, "2026-11-26 20:15", *v) for r, v in rows]
    return pd.DataFrame(
        [(c, k, lab, d, v, x, lo, hi, "") for c, k, lab, d, v, x, lo, hi in full],
        columns=list(COLUMNS),
    )


def test_other_streams_names_the_claims_an_earlier_stream_judged_otherwise():
    label = "first confirmatory run (stream 'confirm', run 2026-11-26)"
    hist = _history(
        [
            (("FR-1-paper", "stream", label), ("equivalent", 0.06, -0.06, 0.19)),
            (("FR-2-paper", "stream", label), ("equivalent", 0.1, 0.0, 0.2)),
            (("FR-3-paper", "published", "abc1234"), ("not supported", 0.8, 0.6, 1.0)),
            (("LQG-1", "stream", label), ("not supported", 0.8, 0.6, 1.0)),
        ]
    )
    claims = [_claim("FR-1-paper", "inconclusive"), _claim("FR-2-paper", "equivalent")]
    out = other_streams(claims, hist, "appendix.md")
    assert out == [
        {"label": label, "n": 2, "claims": [("[FR-1-paper](appendix.md#fr-1-paper)", "equivalent")]}
    ]
    assert other_streams(claims, None) == [] and other_streams([claims[1]], hist) == []
