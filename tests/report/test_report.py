"""The report's building blocks (formatting, claims, rendering), `make verify`'s comparison,
and the published report's contract (size, claims file, README block generated from it)."""

from __future__ import annotations

import json
import math
import re
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from rsmhp.report import verify as vfy
from rsmhp.report.findings import MAIN_CLAIMS, MAX_MAIN, anchor, key_text, verdict_text
from rsmhp.report.history import load_history
from rsmhp.report.ledger import Claim, KeyNumber, Section, claims_records
from rsmhp.report.markdown import fmt, fmt_ci, markdown_table
from rsmhp.report.readme import MARK_BEGIN, MARK_END, splice
from rsmhp.report.render import glance_table, render_appendix, render_report
from rsmhp.report.statements import Statement

#: the statements the constructed claims below are evidence for
STATEMENTS = (
    Statement("S1", "Sec. I", "A beats B", ("A-*",)),
    Statement("S2", "Sec. II", "C may fail", ("Z-1", "V-1"), hedged=True, note="a note"),
)

ROOT = Path(__file__).resolve().parents[2]


def _claim(
    cid="X-1",
    verdict="inconclusive",
    value=0.1,
    lo=-0.2,
    hi=0.4,
    repro="statistical",
    part="paper",
    contrary="",
):
    key = KeyNumber("paired difference", value, lo, hi, "m", repro, null=0.0)
    return Claim(
        cid,
        "A beats B",
        "Sec. I: A beats B",
        key,
        verdict,
        "CI below 0: supported",
        part=part,
        setup=f"setup of {cid}",
        contrary=contrary,
    )


# ---------------------------------------------------------------- formatting


@pytest.mark.parametrize(
    ("x", "digits", "signed", "expected"),
    [
        (200.0, 3, False, "200"),
        (200, 3, True, "+200"),
        (12.50241, 4, False, "12.50"),
        (18.8765, 3, False, "18.9"),
        (0.000854, 3, False, "0.000854"),
        (3.4e-32, 2, False, "3.4e-32"),
        (-0.039, 2, True, "-0.039"),
        (0.1, 3, True, "+0.100"),
        (446.3, 3, False, "446"),
        (2.5e7, 3, False, "25000000"),
        (0.0, 3, False, "0"),
    ],
)
def test_fmt_significant_digits(x, digits, signed, expected):
    assert fmt(x, digits, signed) == expected


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf, np.float64("nan")])
def test_fmt_refuses_absent_values(bad):
    with pytest.raises(ValueError, match="absent"):
        fmt(bad)


def test_fmt_ci_shares_the_decimals_of_the_larger_limit():
    assert fmt_ci(-0.166, 0.081, 3, signed=True) == "[-0.166, +0.081]"
    assert fmt_ci(18.814, 18.878, 5) == "[18.814, 18.878]"


def test_markdown_table_integers_digits_and_missing():
    df = pd.DataFrame(
        {"P": [100.0, 200.0], "n": np.array([200, 200]), "mean": [18.851234, 1e-7], "m": ["a", "b"]}
    )
    text = markdown_table(df, digits=3)
    assert "100.0" not in text and "| 200 |" in text.replace("  ", " ").replace("  ", " ")
    assert "18.9" in text and "1.00e-07" in text
    bad = df.assign(mean=[1.0, math.nan])
    with pytest.raises(ValueError, match="'mean'"):
        markdown_table(bad)
    shown = markdown_table(bad, missing="n/a (exact)")
    assert "n/a (exact)" in shown and "nan" not in shown
    assert "+1" in markdown_table(pd.DataFrame({"d": [1.0, -2.0]}), signed=("d",))
    piped = markdown_table(pd.DataFrame({"key": ["max |z|"], "v": [2.5]}))
    assert "max \\|z\\|" in piped and all(
        len(re.findall(r"(?<!\\)\|", row)) == 3 for row in piped.splitlines()
    )


# ---------------------------------------------------------------- claims


def test_key_number_and_claim_validation():
    with pytest.raises(ValueError, match="finite"):
        KeyNumber("x", math.nan)
    with pytest.raises(ValueError, match="both CI limits"):
        KeyNumber("x", 1.0, ci_low=0.0)
    with pytest.raises(ValueError, match="needs its CI"):
        KeyNumber("x", 1.0, reproducible="statistical")
    with pytest.raises(ValueError, match="reproducible"):
        KeyNumber("x", 1.0, reproducible="sometimes")
    with pytest.raises(ValueError, match="CI"):
        KeyNumber("x", 1.0, 2.0, 0.0)
    with pytest.raises(ValueError, match="verdict"):
        _claim(verdict="probably")
    # a CI that admits the opposite (contains the null) cannot support the claim
    with pytest.raises(ValueError, match=r"contains 0\.0"):
        _claim(verdict="supported", lo=-0.2, hi=0.4)
    assert _claim(verdict="supported", value=-0.3, lo=-0.5, hi=-0.1).verdict == "supported"
    with pytest.raises(ValueError, match="rule"):
        Claim("X", "c", "p", KeyNumber("x", 1.0), "supported", "  ")


def test_section_roundtrip_and_rendering(tmp_path):
    a = Section(
        "zzz",
        "Later study",
        5,
        "Body of the later study.\n\n![f](figures/f.png)",
        claims=[_claim("Z-1")],
        figures=["f"],
        appendix="| t |\n|---|\n| 1 |",
    )
    b = Section(
        "aaa",
        "Earlier study",
        1,
        "Body.",
        claims=[_claim("A-1", "supported", -0.3, -0.5, -0.1, "bitwise")],
    )
    a.save(tmp_path / "a.json")
    assert Section.load(tmp_path / "a.json") == a
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(ValueError, match="not a valid report section"):
        Section.load(tmp_path / "bad.json")
    prov = {"commit": "abc", "config sha256": "0123", "numpy": "2"}
    main = render_report([a, b], prov, statements=STATEMENTS)
    # the answer first, then the statements, the main claims, the studies' index
    order = [
        "## What we found",
        "## The paper's statements",
        "## The main claims",
        "## The studies",
    ]
    assert [main.index(h) for h in order] == sorted(main.index(h) for h in order)
    assert "## Earlier study" not in main and "Body of the later study" not in main
    assert "| Earlier study | – | appendix C1 |" in main
    assert "| Later study | [f](figures/f.png) | appendix C2 |" in main
    # each statement once, judged on the paper's setups; the hedged one with no piece shown
    assert "2 statements of the paper" in main
    assert (
        "On the paper's setups: 1 supported, 0 not supported, 0 equivalent, 1 inconclusive" in main
    )
    assert (
        "| S1 | A beats B (Sec. I) | **supported**: [A-1](appendix.md#a-1) supported | – |" in main
    )
    assert "| S2 | C may fail (Sec. II; hedged) | **inconclusive**: [Z-1](appendix.md#z-1)" in main
    assert "1 of the 2" not in main and "Of the 2 key numbers 1 reproduce bitwise" in main
    assert "CI below 0: supported" not in main  # rules are in the appendix, linked
    app = render_appendix([a, b], {"seed": 2}, prov, statements=STATEMENTS)
    assert "### Z-1\n\n- Verdict: **inconclusive**" in app and "| t |" in app and "seed: 2" in app
    assert "- Part: the paper; setup: setup of Z-1" in app and "- S2: a note" in app
    assert "## C1. Earlier study\n\nBody." in app and "Body of the later study" in app
    assert "CI below 0: supported" in app
    assert (
        "(statistically reproducible)" in app
        and "(bitwise reproducible)" in app
        and "- config sha256: `0123`" in app
    )
    recs = claims_records([a, b])
    assert [r["id"] for r in recs] == ["A-1", "Z-1"]
    assert Claim.from_dict(json.loads(json.dumps(recs[1]))) == a.claims[0]
    glance = glance_table([c for s in (b, a) for c in s.claims], STATEMENTS)
    assert glance.count("\n") == 3 and "| S2 | C may fail (Sec. II) | inconclusive (Z-1" in glance
    # a claim of the paper that no statement lists is refused (it would be counted nowhere)
    with pytest.raises(ValueError, match="Q-1"):
        render_report(
            [Section("q", "Q", 1, "b", claims=[_claim("Q-1")])], prov, statements=STATEMENTS
        )


def test_variants_checks_and_contrary_evidence_are_apart():
    """Variant evidence is judged apart from the paper's setups; checks of our machinery
    have an appendix part and a count of their own; contrary cells are printed."""
    s = Section(
        "s",
        "Study",
        1,
        "Body.",
        claims=[
            _claim("A-1", "supported", -0.3, -0.5, -0.1),
            _claim("A-2", "not supported", 0.3, 0.1, 0.5, contrary="cell q = 4: +0.26 m"),
            _claim("V-1", "supported", -0.3, -0.5, -0.1, part="beyond"),
            replace(_claim("C-1", "supported", -0.3, -0.5, -0.1, part="beyond"), check=True),
        ],
    )
    stmts = (Statement("S1", "Sec. I", "A beats B", ("A-*",), variants=("V-1",)),)
    main = render_report([s], {}, statements=stmts)
    assert "| S1 | A beats B (Sec. I) | **mixed**: [A-1](appendix.md#a-1) supported, " in main
    assert "| **supported**: [V-1](appendix.md#v-1) supported |" in main
    assert "1 checks of our machinery in a part of their own" in main
    app = render_appendix([s], {}, {}, statements=stmts)
    assert "- S1 (mixed): supported: A-1; not supported: A-2" in app
    assert "2 claims test the paper's statements on its setups: 1 supported, 1 not supported" in app
    assert "1 claims go beyond the paper" in app and ": 1 supported, 0 not supported" in app
    assert "1 checks of our simulation" in app
    ledger = app[app.index("### A2") : app.index("### A3")]
    checks = app[app.index("### A3") : app.index("### A4")]
    assert "| C-1 |" in checks and "| C-1 |" not in ledger and "| V-1 |" in ledger
    assert "| cell q = 4: +0.26 m |" in ledger
    assert "- Verdict: **supported** (a check of our machinery)" in app


def test_splice_replaces_only_the_marked_block():
    text = f"intro\n{MARK_BEGIN}\nold\n{MARK_END}\noutro\n"
    out = splice(text, "new table\n")
    assert out == f"intro\n{MARK_BEGIN}\nnew table\n{MARK_END}\noutro\n"
    assert splice(out, "new table") == out
    with pytest.raises(ValueError, match="markers"):
        splice("no markers", "x")


# ---------------------------------------------------------------- verify


def _file(path, claims, sha="cfg"):
    path.write_text(json.dumps({"config sha256": sha, "claims": [asdict(c) for c in claims]}))
    return path


def test_verify_tolerances_and_statuses():
    ref = [
        _claim("S-1", value=0.1, lo=-0.2, hi=0.4),
        _claim("B-1", "supported", -0.3, -0.5, -0.1, "bitwise"),
    ]
    same = vfy.compare(ref, ref)
    assert (same["status"] == "ok").all() and (same["difference"] == 0).all()
    # statistical tolerance: z (Bonferroni over 1 claim: 1.96) * sqrt(2) * se, se = 0.6/3.92
    se = 0.6 / (2 * 1.959963984540054)
    tol = 1.959963984540054 * math.sqrt(2) * se
    assert vfy.tolerance(ref[0], ref[0], 1) == pytest.approx(tol)
    near = [replace(ref[0], key=replace(ref[0].key, value=0.1 + 0.99 * tol)), ref[1]]
    far = [replace(ref[0], key=replace(ref[0].key, value=0.1 + 1.01 * tol)), ref[1]]
    assert list(vfy.compare(ref, near)["status"]) == ["ok", "ok"]
    assert vfy.compare(ref, far)["status"][0] == "outside tolerance"
    # bitwise: 1e-9 relative
    moved = [ref[0], replace(ref[1], key=replace(ref[1].key, value=-0.3 * (1 + 1e-6)))]
    assert vfy.compare(ref, moved)["status"][1] == "outside tolerance"
    rounding = [ref[0], replace(ref[1], key=replace(ref[1].key, value=-0.3 * (1 + 1e-13)))]
    assert vfy.compare(ref, rounding)["status"][1] == "ok"
    flipped = [replace(ref[0], verdict="not supported"), ref[1]]
    assert vfy.compare(ref, flipped)["status"][0] == "verdict flipped"
    st = vfy.compare(ref, [ref[0], _claim("N-1")])["status"].tolist()
    assert st == ["ok", "missing in this run", "new in this run (publish a new reference)"]
    renamed = [replace(ref[0], key=replace(ref[0].key, name="other")), ref[1]]
    assert vfy.compare(ref, renamed)["status"][0].startswith("key number redefined")


def test_verify_cli(tmp_path, capsys):
    claims = [_claim("S-1"), _claim("B-1", "supported", -0.3, -0.5, -0.1, "bitwise")]
    ref = _file(tmp_path / "ref.json", claims)
    run = _file(tmp_path / "run.json", claims)
    out = tmp_path / "v" / "verify.md"
    assert vfy.main(["--reference", str(ref), "--run", str(run), "--output", str(out)]) == 0
    assert out.read_text().startswith("# verify: PASS") and "2 of 2 claims agree" in out.read_text()
    flip = _file(tmp_path / "flip.json", [replace(claims[0], verdict="not supported"), claims[1]])
    assert vfy.main(["--reference", str(ref), "--run", str(flip)]) == 1
    assert "# verify: FAIL" in capsys.readouterr().out
    other = _file(tmp_path / "other.json", claims, sha="different")
    assert vfy.main(["--reference", str(ref), "--run", str(other)]) == 2
    assert "same configuration" in capsys.readouterr().err
    assert vfy.main(["--reference", str(tmp_path / "none.json"), "--run", str(run)]) == 2
    (tmp_path / "list.json").write_text("[]")
    assert vfy.main(["--reference", str(tmp_path / "list.json"), "--run", str(run)]) == 2


# ---------------------------------------------------------------- the published report


def test_published_report_matches_its_claims_and_the_readme():
    """paper/ is what `make publish` copied from one run: the main text is one page (<= 25 KB)
    that opens with the findings and the summary figure, shows at most ten claims (those of
    MAIN_CLAIMS, with their verdicts) and every statement; the appendix has every claim; no
    nan/inf; the README's results block is the glance table of the same claims."""
    main = (ROOT / "paper/replication.md").read_text(encoding="utf-8")
    appendix = (ROOT / "paper/appendix.md").read_text(encoding="utf-8")
    data = json.loads((ROOT / "paper/claims.json").read_text(encoding="utf-8"))
    claims = [Claim.from_dict(c) for c in data["claims"]]
    assert len(main.encode()) <= 25_000
    assert main.index("## What we found") < main.index("](figures/scenarios_best.png)")
    assert main.index("](figures/scenarios_best.png)") < main.index("## The paper's statements")
    found = main[main.index("## What we found") : main.index("![")]
    sentences = re.findall(r"^\d+\. ", found, flags=re.MULTILINE)
    assert 1 <= len(sentences) <= 7
    for text in (main, appendix):
        assert not re.search(r"\b(nan|inf)\b", text, flags=re.IGNORECASE)
    by_id = {c.id: c for c in claims}
    table = main[main.index("## The main claims") : main.index("## The studies")]
    rows = [line for line in table.splitlines() if line.startswith("| ") and "---" not in line]
    assert 1 < len(rows) <= MAX_MAIN + 1  # header + at most ten claims
    for m in MAIN_CLAIMS:
        for _, cid in m.setups:
            assert f"[{cid}](appendix.md#{anchor(cid)}): {key_text(by_id[cid])} → " in table
            assert f"**{verdict_text(by_id[cid])}**" in table
    for c in claims:
        assert f"### {c.id}\n\n- Verdict: **{verdict_text(c)}**" in appendix
        assert f"| {c.id} | {c.claim.replace('|', chr(92) + '|')} |" in appendix
    for st in data["statements"]:
        assert f"| {st['id']} | " in main and f"**{st['verdict']}**" in main
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    block = readme[readme.index(MARK_BEGIN) + len(MARK_BEGIN) : readme.index(MARK_END)]
    history = load_history(ROOT / "paper" / "history.csv")
    assert block.strip() == glance_table(claims, history=history).strip()
    for fig in re.findall(r"\]\((figures/[^)]+)\)", main):
        assert (ROOT / "paper" / fig).is_file(), fig


def test_every_snakemake_report_caption_is_valid_restructuredtext():
    """`|x|` is a substitution in reStructuredText: captions must escape it (docutils reports
    an ERROR and the HTML report shows the error box instead of the caption)."""
    import io

    import docutils.core
    import jinja2

    captions = sorted((ROOT / "workflow/report").glob("*.rst"))
    assert captions
    for path in captions:
        err = io.StringIO()
        text = path.read_text(encoding="utf-8")
        if path.name == "workflow.rst":  # the landing page: Jinja first, as Snakemake does
            text = jinja2.Template(text).render(files=[], snakemake=None, categories={})
            assert "The summary has not been written yet" in text
        docutils.core.publish_doctree(
            text,
            settings_overrides={"warning_stream": err, "report_level": 2},
        )
        assert not err.getvalue(), f"{path.name}: {err.getvalue()}"


def test_verify_fails_when_a_statement_of_the_paper_changes_its_verdict(tmp_path):
    claims = [_claim("A-1", "supported", -0.3, -0.5, -0.1, "bitwise")]
    stmt = {"id": "S1", "verdict": "supported"}

    def write(name, statements):
        data = {"config sha256": "c", "claims": [asdict(c) for c in claims]}
        if statements is not None:
            data["statements"] = statements
        (tmp_path / name).write_text(json.dumps(data))
        return tmp_path / name

    ref = write("ref.json", [stmt])
    assert vfy.verify(ref, write("same.json", [stmt]))[0]
    ok, text = vfy.verify(ref, write("flip.json", [{**stmt, "verdict": "mixed"}]))
    assert not ok and text.startswith("# verify: FAIL") and "S1: supported -> mixed" in text
    ok, text = vfy.verify(ref, write("more.json", [stmt, {"id": "S2", "verdict": "mixed"}]))
    assert not ok and "S2: - -> mixed" in text
    assert vfy.verify(write("old.json", None), write("new.json", [stmt]))[0]  # old reference


def test_verify_fails_when_a_run_loses_the_statements(tmp_path):
    claims = [_claim("A-1", "supported", -0.3, -0.5, -0.1, "bitwise")]
    ref, run = tmp_path / "ref.json", tmp_path / "run.json"
    data = {"config sha256": "c", "claims": [asdict(c) for c in claims]}
    ref.write_text(json.dumps({**data, "statements": [{"id": "S1", "verdict": "supported"}]}))
    run.write_text(json.dumps(data))
    ok, text = vfy.verify(ref, run)
    assert not ok and "S1: supported -> -" in text


def test_verify_refuses_runs_judged_under_another_preregistration(tmp_path, capsys):
    """claims.json records the preregistration (path, sha256, commit) its confirmatory claims
    were judged under; verify compares only runs of the same one (exit 2 otherwise)."""
    claims = [_claim("FR-1-m", "supported", -0.3, -0.5, -0.1)]

    def write(name, pre):
        path = _file(tmp_path / name, claims)
        data = json.loads(path.read_text())
        data["preregistration"] = pre
        path.write_text(json.dumps(data))
        return path

    pre = {"path": "config/preregistration.yaml", "sha256": "a" * 64, "commit": "c" * 40}
    ref, same = write("ref.json", pre), write("same.json", pre)
    assert vfy.main(["--reference", str(ref), "--run", str(same)]) == 0
    other = write("other.json", {**pre, "sha256": "b" * 64})
    assert vfy.main(["--reference", str(ref), "--run", str(other)]) == 2
    err = capsys.readouterr().err
    assert "preregistration sha256 " + "b" * 64 in err and "a" * 64 in err
    none = write("none.json", {})
    assert vfy.main(["--reference", str(ref), "--run", str(none)]) == 2
