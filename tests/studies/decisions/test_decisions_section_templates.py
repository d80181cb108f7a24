"""The decision study's report sections from their templates (``section_lqg.md``,
``section_lqg_appendix.md``, ``section_uav.md``, ``section_uav_appendix.md``): every name a
template reads is a value the section module passes, a missing value raises, nothing is left
unfilled, and the findings' optional sentences join with single spaces. The claims'
templates (``claims_lqg.md``, ``claims_uav.md``) hold no macro that nothing uses."""

from __future__ import annotations

import dataclasses
import re
from importlib import resources
from typing import Any

import jinja2
import pandas as pd
import pytest
from jinja2 import meta

from rsmhp.models.lqg import regret_summary as lqg_summary
from rsmhp.models.uav.scoring import REGRET_COLUMNS
from rsmhp.report import templates
from rsmhp.studies.decisions import claims_lqg, claims_uav, section_lqg, section_uav
from rsmhp.studies.decisions import summarise_uav as uav_summary
from tests.studies.decisions.test_decisions_lqg import CFG as LQG_CFG
from tests.studies.decisions.test_decisions_lqg import MODEL, _synthetic
from tests.studies.decisions.test_decisions_uav import (
    MAP_CFG,
    SECTION_CFG,
    _map_runs,
    _regret_rows,
)
from tests.studies.uav.test_uav_claims import unused_macros

PACKAGE = "rsmhp.studies.decisions"
#: what a template left unfilled would print
UNFILLED = re.compile(r"\{\{|\}\}|\{%|%\}|\{#|#\}|\bNone\b|Undefined")


def _source(template: str) -> str:
    return resources.files(PACKAGE).joinpath(template).read_text(encoding="utf-8")


def _recording(module, mp: pytest.MonkeyPatch) -> dict[str, dict[str, Any]]:
    """Record the values ``module`` renders each template with."""
    calls: dict[str, dict[str, Any]] = {}

    def recording(package: str, template: str, /, **values: Any) -> str:
        calls[template] = values
        return templates.render(package, template, **values)

    mp.setattr(module, "render", recording)
    return calls


@pytest.fixture(scope="module")
def rendered() -> dict[str, Any]:
    """Both sections of small synthetic runs, with the values of every template."""
    df = _synthetic(nbo_regret=0.0, pruned_slope=0.0)
    summary = lqg_summary.summarize_lqg_regret(df, MODEL)
    scaling = lqg_summary.lqg_scaling(summary)
    lqg_tables = section_lqg.lqg_tables(summary, scaling)
    regret = _regret_rows({"paper": (0.001, 0.001, 0.0002), "fp150": (0.05, 0.001, 0.01)})
    usummary = uav_summary.summarize_uav_regret(regret, 1, 500)
    runs = _map_runs(-2.0)
    m = uav_summary.summarize_map(runs, pd.DataFrame(columns=REGRET_COLUMNS), MAP_CFG, 1, 500)
    groups = uav_summary.summarize_map_groups(runs, m, 1, 500)
    uav_tables = section_uav.uav_tables(usummary, m)
    with pytest.MonkeyPatch.context() as mp:
        lqg_calls = _recording(section_lqg, mp)
        lqg = section_lqg.lqg_decision_section(summary, scaling, lqg_tables, MODEL, LQG_CFG)
        uav_calls = _recording(section_uav, mp)
        uav = section_uav.uav_decision_section(
            regret, usummary, m, groups, uav_tables, SECTION_CFG, 1
        )
    return {
        "sections": {"lqg": (lqg, lqg_tables), "uav": (uav, uav_tables)},
        "values": {**lqg_calls, **uav_calls},
    }


def test_every_template_is_rendered(rendered):
    """Every template beside the modules is a section template the sections render, or the
    words of a claims module (``claims_lqg.md``, ``claims_uav.md``: :class:`Words`)."""
    found = {p.name for p in resources.files(PACKAGE).iterdir() if p.name.endswith(".md")}
    words = {m.WORDS.template for m in (claims_lqg, claims_uav) if m.WORDS.package == PACKAGE}
    assert words == {"claims_lqg.md", "claims_uav.md"}
    assert (
        set(rendered["values"])
        == found - words
        == {
            "section_lqg.md",
            "section_lqg_appendix.md",
            "section_uav.md",
            "section_uav_appendix.md",
        }
    )


@pytest.mark.parametrize("module", [claims_lqg, claims_uav], ids=["lqg", "uav"])
def test_every_macro_of_the_claims_templates_is_used(module):
    assert unused_macros(module) == set()


@pytest.mark.parametrize("study", ["lqg", "uav"])
def test_sections_are_filled(rendered, study):
    section, tables = rendered["sections"][study]
    for text in (section.body, section.appendix):
        assert not UNFILLED.search(text), UNFILLED.search(text)
        assert not text.endswith("\n") and not text.startswith("\n")
        assert "\n\n\n" not in text
    assert "  " not in section.body  # no empty value between two spaces
    for table in tables.values():
        assert table in section.appendix
    for name in section.figures:
        assert f"](figures/{name}" in section.body


def _every_branch(template: str, values: dict[str, Any]) -> dict[str, Any]:
    """``values`` with every optional part of the findings present, so that every name the
    template reads is read."""
    if template == "section_lqg.md":
        assert values["dec1"] is not None and values["dec4"] is not None
        assert values["z_families"] and values["slope_ranges"]
    if template == "section_uav.md":
        assert values["dec6"] is not None and values["dec7"] and values["margin"] is not None
        assert values["dec8"]
    return values


@pytest.mark.parametrize(
    "template",
    ["section_lqg.md", "section_lqg_appendix.md", "section_uav.md", "section_uav_appendix.md"],
)
def test_templates_use_exactly_the_values_passed(rendered, template):
    """The names a template reads are the names Python passes, and dropping any one of them
    raises (StrictUndefined) instead of printing an empty string."""
    values = _every_branch(template, rendered["values"][template])
    used = meta.find_undeclared_variables(jinja2.Environment().parse(_source(template)))
    assert used == set(values)
    for name in values:
        rest = {k: v for k, v in values.items() if k != name}
        with pytest.raises(jinja2.UndefinedError, match=name):
            templates.render(PACKAGE, template, **rest)


def _findings(text: str) -> str:
    """The findings paragraph of a body: the one before the first figure."""
    paragraphs = text.split("\n\n")
    return paragraphs[next(i for i, p in enumerate(paragraphs) if p.startswith("![")) - 1]


def test_lqg_findings_join_the_sentences_present(rendered):
    values = rendered["values"]["section_lqg.md"]
    full = _findings(templates.render(PACKAGE, "section_lqg.md", **values))
    assert full.startswith("NBO's regret is at most") and "\n" not in full
    assert "). Simulated vs closed-form" in full and ". The pruned tree's regret" in full
    fewer = {**values, "dec1": None, "z_families": [], "dec4_u_shape": True}
    text = _findings(templates.render(PACKAGE, "section_lqg.md", **fewer))
    assert text.startswith("Log-log slopes of mean regret in P: ")
    assert "cells (a U shape), so no slope summarises it: " in text
    empty = {**fewer, "slope_ranges": [], "dec4": None}
    body = templates.render(PACKAGE, "section_lqg.md", **empty)
    assert "standard error.\n\n\n\n![LQG regret]" in body  # an empty paragraph, no stray text


def test_uav_findings_join_the_sentences_present(rendered):
    values = rendered["values"]["section_uav.md"]
    dec8 = [
        dataclasses.replace(values["dec8"][0], contrary="one run disagrees"),
        dataclasses.replace(values["dec8"][0], id="DEC-8b", footprint=False, contrary=""),
    ]
    changed = {**values, "dec6": None, "dec8": dec8}
    text = _findings(templates.render(PACKAGE, "section_uav.md", **changed))
    assert text.startswith("In '") and "\n" not in text
    assert ". Contrary: one run disagrees. On the map, without one, " in text
    assert re.search(r"\(DEC-8b \w[\w ]*\)\. The equivalence margin", text)
    bare = dataclasses.replace(values["margin"], share=None, lowest_better=None)
    text = _findings(templates.render(PACKAGE, "section_uav.md", **{**changed, "margin": bare}))
    assert text.endswith("decisions.claims.equivalence_margin_pp).")


def test_uav_variants_are_named_with_their_overrides(rendered):
    body = rendered["sections"]["uav"][0].body
    assert "'paper' (the reconstruction); 'fp150' (footprint radius 150 m);" in body
