"""The frontier sections' prose templates (``section.md`` and ``appendix.md``: the exploratory
design; ``confirm.md`` and ``confirm_appendix.md``: the confirmatory run), rendered on small
data: every name a template uses is a value its section passes and no other, the rendered text
keeps no template syntax, and a missing value is an error (StrictUndefined), never an empty
string."""

from __future__ import annotations

from pathlib import Path

import jinja2
import pytest
from jinja2 import meta

from rsmhp.report.templates import render
from rsmhp.studies.frontier import claims, section
from rsmhp.studies.frontier.summarise import summarize_frontier
from tests.pipeline.test_protocol import PREREG, _confirm_tables
from tests.studies.frontier.test_frontier_claims import N_RUNS, _cfg, _tables

PACKAGE = "rsmhp.studies.frontier"
HERE = Path(section.__file__).parent
SYNTAX = ("{{", "}}", "{%", "%}", "{#", "#}")


@pytest.fixture
def rendered(monkeypatch) -> dict[str, tuple[dict, str]]:
    """``{template: (values, text)}`` of every template the two sections render."""
    calls: dict[str, tuple[dict, str]] = {}
    real = section.render

    def spy(package, template, /, **values):
        text = real(package, template, **values)
        calls[template] = (values, text)
        return text

    monkeypatch.setattr(section, "render", spy)
    _exploratory()
    _confirm()
    return calls


def _exploratory():
    runs, regret = _tables()
    summary = summarize_frontier(runs, regret)
    cfg = {**_cfg(), "runs": N_RUNS, "regret_runs": 2, "regret_steps": [0, 1, 2, 3, 4],
           "track_loss_error": 50.0}  # fmt: skip
    tables = section.frontier_tables(summary, cfg)
    inputs = section.FrontierInputs(runs, regret, summary, tables, cfg, seed=11, horizon=6)
    return section.frontier_section(inputs)


def _confirm():
    from rsmhp.studies.frontier.claims import confirm_claims
    from rsmhp.studies.frontier.summarise import ladder, summarize_configs

    runs, timing, chosen = _confirm_tables()
    s = summarize_configs(runs, timing)
    lad = ladder(runs, s, chosen, [0.5, 2.0])
    claims = confirm_claims(runs, s, lad, PREREG, chosen, "f" * 64)
    tuned = {"provenance": {"candidates": 7, "runs per candidate": 4}, "chosen": {}}
    old = {"id": "FR-2-y", "key": {"value": 2.0, "unit": "m"}, "verdict": "inconclusive"}
    inputs = section.ConfirmInputs(
        summary=s,
        lad=lad,
        claims=claims,
        tables=section.confirm_tables(s, lad, tuned),
        prereg={**PREREG, "power_text": "power p"},
        prereg_meta={"path": "p.yaml", "sha256": "f" * 64, "commit": "c" * 40},
        tuned=tuned,
        exploratory=[old],
        superseded={"what": "budgeted on medians.", "claims": [old],
                    "preregistration": {"sha256": "e" * 64, "commit": "d" * 40}},
    )  # fmt: skip
    return section.confirm_section(inputs)


def test_every_template_gets_exactly_the_values_it_uses(rendered):
    # every template beside the code is rendered by the sections, or is the words of the
    # claims module (claims.md: rsmhp.report.templates.Words, rendered by the claims' tests)
    words = {claims.WORDS.template} if claims.WORDS.package == PACKAGE else set()
    assert words == {"claims.md"}
    assert set(rendered) == {p.name for p in HERE.glob("*.md")} - words
    env = jinja2.Environment()
    for name, (values, text) in rendered.items():
        used = meta.find_undeclared_variables(env.parse((HERE / name).read_text("utf-8")))
        assert used == set(values), name
        assert not any(s in text for s in SYNTAX), name
        # one paragraph per line, one blank line between; the file's last newline (the
        # section drops it)
        assert text.endswith("\n") and not text.endswith("\n\n"), name
        assert "\n\n\n" not in text, name
        prose = [line for line in text.splitlines() if not line.startswith("|")]
        assert not any("  " in line or line != line.strip() for line in prose), name


def test_the_prose_is_complete(rendered):
    def text(name: str) -> str:
        return rendered[name][1].removesuffix("\n")

    body = text("section.md")
    assert body.startswith("**Exploratory design** (published up to 76a0c01;")
    assert "Exploratory comparisons (not claims): FR-1 (RQMC − RS-MHP" in body
    assert "Closed loop against NBO on 'm' (12 paired runs): " in body
    assert body.endswith("dotted: the planning budget of FR-1..3.*")
    appendix = text("appendix.md")
    assert "track loss (final error above 50 m)" in appendix and "(2000 resamples)" in appendix
    assert "the 56 equally weighted cubature points" in appendix and "(n = 28)" in appendix
    body = text("confirm.md")
    assert "7 candidate configurations" in body and "in 4 closed-loop runs each" in body
    assert "(?, commit ?; `config/tuned.yaml`)" in body  # no date or commit in the provenance
    assert "(30 on 'm'; power p)" in body and "on a stream of its own ('confirm')" in body
    assert "Preregistered claims (before Holm's correction): FR-" in body
    assert "is superseded: appendix, not counted.\n\n![Confirmatory ladder]" in body
    appendix = text("confirm_appendix.md")
    assert "Tree search: 1 tuned configurations; their plans take 2.00 to 2.00 of" in appendix
    assert "Lowest mean closed-loop error per budget (descriptive, not a claim): 'm': 0.5 ms:" in (
        appendix
    )
    assert "(preregistration sha256 eeeeeeeeeeee, commit dddddddddd; superseded" in appendix
    assert appendix.endswith("| FR-2-y  | +2.00 m      | inconclusive   |")


def test_a_missing_value_is_an_error(rendered):
    for name, (values, _) in rendered.items():
        for missing in values:
            rest = {k: v for k, v in values.items() if k != missing}
            with pytest.raises(jinja2.UndefinedError, match=f"'{missing}' is undefined"):
                render(PACKAGE, name, **rest)


def test_a_missing_field_is_an_error():
    values = {"families": "RS-MHP", "models": "'m'", "runs": 3, "regret_runs": 2,
              "budget_ms": "2", "members": "RS-MHP N_T=8", "closed_loop": [],
              "comparisons": [{"claims": "FR-1", "results": []}]}  # fmt: skip
    with pytest.raises(jinja2.UndefinedError, match="compared"):
        render(PACKAGE, "section.md", **values)


def test_every_macro_of_the_claims_template_is_used():
    """The claims' words (``claims.md``, :data:`rsmhp.studies.frontier.claims.WORDS`) hold no
    macro that neither the claims module nor one of its specs nor another macro uses."""
    from tests.studies.uav.test_uav_claims import unused_macros

    assert claims.WORDS.package == PACKAGE
    assert unused_macros(claims) == set()


@pytest.mark.parametrize("template", sorted(p.name for p in HERE.glob("*.md")))
def test_template_lines_are_wrapped(template):
    """Long lines are continued with a backslash, so a diff shows the sentence that changed."""
    source = (HERE / template).read_text(encoding="utf-8")
    assert [line for line in source.split("\n") if len(line) > 100] == []
