"""The report's own words in templates (rsmhp.report: statements.md, report.md, ...): short
lines, one line per macro, covered by the report rule's code digest, and the statements' words
taken from their template."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from rsmhp.pipeline.code_digest import describe
from rsmhp.report import findings
from rsmhp.report import statements as pp
from rsmhp.report.templates import Words

ROOT = Path(__file__).resolve().parents[2]
REPORT = ROOT / "src/rsmhp/report"
#: the report's templates and the macros' templates among them
TEMPLATES = (
    "statements.md",
    "findings.md",
    "main_claims.md",
    "report.md",
    "report_appendix.md",
    "report_words.md",
)
MACROS = ("statements.md", "main_claims.md", "report_words.md")


@pytest.mark.parametrize("name", TEMPLATES)
def test_template_lines_are_short(name: str) -> None:
    long = [
        (i, len(line))
        for i, line in enumerate((REPORT / name).read_text(encoding="utf-8").splitlines(), 1)
        if len(line) > 100
    ]
    assert not long, f"{name}: lines over 100 characters (line, length): {long}"


@pytest.mark.parametrize("name", TEMPLATES)
def test_the_report_rule_reruns_when_a_template_changes(name: str) -> None:
    modules = describe(ROOT / "workflow/scripts/report.py").modules
    assert f"rsmhp.report/{name}" in modules


@pytest.mark.parametrize("name", MACROS)
def test_every_macro_renders_one_line(name: str) -> None:
    words = Words("rsmhp.report", name)
    source = (REPORT / name).read_text(encoding="utf-8")
    macros = re.findall(r"\{% macro (\w+)\(([^)]*)\) %\}", source)
    assert macros
    for macro, args in macros:
        values = {a.split("=")[0].strip(): "X" for a in args.split(",") if a.strip()}
        if macro == "scope":
            values.update(on_paper="supported", on_variants=None)
        text = words(macro, **values)
        assert text and "\n" not in text and "  " not in text, (macro, text)
        assert text == text.strip(), (macro, text)


def test_statements_take_their_words_from_the_template() -> None:
    source = (REPORT / "statements.md").read_text(encoding="utf-8")
    said = set(re.findall(r"\{% macro (s\d+)_says\(\) %\}", source))
    assert said == {s.id.lower() for s in pp.STATEMENTS}
    for s in pp.STATEMENTS:
        assert s.says == pp.WORDS(f"{s.id.lower()}_says")
        has_note = f"{s.id.lower()}_note" in pp.WORDS
        assert (s.note == pp.WORDS(f"{s.id.lower()}_note")) if has_note else s.note == ""
    # a wrapped paragraph renders as one line (the proof gap of Prop. 1, S2's note)
    assert "Cov(g_i, g_j) = 0 when |i − j| > N" in pp.STATEMENTS[1].note


def test_a_statements_scope_in_words() -> None:
    assert pp.WORDS("scope", on_paper="not tested", paper="", on_variants=None, variants="") == (
        "not tested on the paper's setups"
    )
    assert pp.WORDS(
        "scope", on_paper="mixed", paper="A-1 supported", on_variants="equivalent", variants="V-1"
    ) == ("mixed on the paper's setups (A-1 supported); absent (equivalent) on the variants (V-1)")


def test_main_claims_take_their_words_from_the_template() -> None:
    source = (REPORT / "main_claims.md").read_text(encoding="utf-8")
    macros = re.findall(r"\{% macro (says_\w+)\(\) %\}", source)
    assert len(macros) == len(findings.MAIN_CLAIMS)
    assert sorted(findings.WORDS(m) for m in macros) == sorted(m.says for m in findings.MAIN_CLAIMS)


def test_power_and_best_read_as_sentences() -> None:
    words = findings.WORDS
    with_holm = "n = 80, post hoc 320 for 80% power before Holm"
    assert words("power", n=80, need=320, holm=True) == with_holm
    assert words("power", n=80, need=320, holm=False) == "n = 80, post hoc 320 for 80% power"
    assert words("power_undecided", n=5) == "n = 5, no n decides it at this estimate"
    cells = words("best_at", method="tree", cells="H = " + words("span", first="2", last="24"))
    assert words("best_by", group="horizon", model="paper", cells=cells) == (
        "by horizon on 'paper': tree at H = 2 to 24"
    )
