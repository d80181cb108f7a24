"""The one-page answer (rsmhp.report.findings): which claims the main text shows, how a
verdict reads, and the "What we found" sentences."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pandas as pd

from rsmhp.report.findings import (
    MAIN_CLAIMS,
    MAX_MAIN,
    anchor,
    best_sentence,
    found_values,
    main_rows,
    verdict_text,
)
from rsmhp.report.ledger import Claim, KeyNumber
from rsmhp.report.statements import judge_all
from rsmhp.report.templates import render

ROOT = Path(__file__).resolve().parents[2]


def _claim(cid, verdict, value, lo, hi, margin=None, n=None):
    key = KeyNumber("d", value, lo, hi, "m", "statistical", null=0.0, margin=margin, n=n)
    return Claim(cid, "c", "p", key, verdict, "r", setup="s")


def test_at_most_ten_main_claims_fixed_in_code():
    assert 1 <= len(MAIN_CLAIMS) <= MAX_MAIN == 10
    ids = [cid for m in MAIN_CLAIMS for _, cid in m.setups]
    assert len(ids) == len(set(ids))
    published = {c["id"]: c for c in json.loads((ROOT / "paper/claims.json").read_text())["claims"]}
    # every id is a claim of the full pipeline; none is a check of our machinery
    assert set(ids) <= published.keys()
    assert not any(published[i].get("check") for i in ids)


def test_an_equivalence_whose_ci_excludes_zero_says_so():
    assert verdict_text(_claim("A", "equivalent", -0.004, -0.0088, -0.0002, margin=0.1)) == (
        "equivalent (difference significant but below Δ = 0.100 m)"
    )
    assert verdict_text(_claim("A", "equivalent", 0.01, -0.05, 0.07, margin=0.1)) == "equivalent"
    assert verdict_text(_claim("A", "supported", -0.4, -0.5, -0.3)) == "supported"
    # Holm's correction made it inconclusive: said, with what it was without it
    from dataclasses import replace

    holm = replace(
        _claim("A", "inconclusive", -0.05, -0.2, 0.08),
        rule="r. Holm over 11 FR/HZ claims: p = 0.0512 ≥ 0.05: equivalent without it, "
        "becomes inconclusive",
    )
    assert verdict_text(holm) == "inconclusive (after Holm, p = 0.0512; equivalent without it)"


def test_main_rows_put_the_setups_side_by_side_with_power():
    claims = [
        _claim("FR-3-paper", "supported", -2.49, -2.89, -2.09, margin=0.25, n=80),
        _claim("FR-3-footprint150", "not supported", 54.2, 34.8, 73.6, margin=0.25, n=150),
    ]
    rows = main_rows(claims)
    assert [r["name"] for r in rows] == ["Tree search at 1 ms"]
    paper, fp = rows[0]["setups"]
    assert paper.startswith("**UAV paper** [FR-3-paper](appendix.md#fr-3-paper): -2.49 ")
    assert "→ **supported**; n = 80, " in paper and fp.startswith("**UAV footprint150**")


def test_best_sentence_names_clear_bests_and_where_none_is():
    best = pd.DataFrame(
        {
            "group": ["budget"] * 4 + ["horizon"] * 2,
            "model": ["paper"] * 6,
            "value": [0.5, 1, 2, 4, 2, 24],
            "best": ["tree", "tree", "sigma", "tree", "NBO", "RQMC"],
            "clear": [True, True, False, True, False, False],
        }
    )
    assert best_sentence(best) == (
        "by budget on 'paper': tree at 0.5 to 1 ms, tree at 4 ms, no clear best at 2 ms; "
        "by horizon on 'paper': no clear best in any of its 2 cells"
    )
    labelled = best.assign(best_label=["T"] * 6, clear=[True, False, False, True, True, True])
    assert best_sentence(labelled).startswith(
        "by budget on 'paper': T at 0.5 ms, T at 4 ms, no clear best at 1 to 2 ms; "
        "by horizon on 'paper': T at H = 2 to 24"
    )
    assert best_sentence(None) == ""


def test_what_we_found_has_at_most_seven_sentences_each_linked():
    data = json.loads((ROOT / "paper/claims.json").read_text(encoding="utf-8"))
    claims = [Claim.from_dict(c) for c in data["claims"]]
    judgements, _ = judge_all(claims)
    text = render("rsmhp.report", "findings.md", **found_values(judgements, claims))
    sentences = re.findall(r"^\d+\. .+$", text, flags=re.MULTILINE)
    assert 1 <= len(sentences) <= 7
    # every claim id named with a number is a link to its details
    for cid in re.findall(r"\[([A-Z]+-[0-9A-Za-z-]+)\]\(appendix\.md#([a-z0-9-]+)\)", text):
        assert anchor(cid[0]) == cid[1]
    assert "nan" not in text.lower()
    # the statements' tally adds up to the statements judged
    first = sentences[0]
    assert sum(int(n) for n in re.findall(r"(?<![S\d])(\d+) (?:is|are) ", first)) == len(judgements)
