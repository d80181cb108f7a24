"""Estimator-study report section from its templates (``section.md``, ``appendix.md``): every
value the section computes reaches a template, every placeholder is filled, a missing value
raises, and each optional sentence appears exactly when its data exist. Every macro of the
claims' words (``claims.md``) is used, and no template line is longer than 100 characters."""

from __future__ import annotations

import dataclasses
import re
from importlib import resources
from typing import Any

import jinja2
import pytest
from jinja2 import meta

from rsmhp.models.lqg.ablation import run_ablation
from rsmhp.report import templates
from rsmhp.studies.estimators import section as narrative
from rsmhp.studies.estimators import summarise as analysis

PACKAGE = "rsmhp.studies.estimators"
MODEL = {"a": 0.5, "x0": 0.0, "r": 10.0, "target": 1.0, "sigma": 1.0}
CFG = {
    "replicates": 12,
    "problems": [{"name": "lqg_paper", "kind": "scalar_lqg", "u": [0.55, 0.17]}],
    "schemes": [
        "mc",
        "antithetic",
        "sobol",
        "cubature",
        "gauss_hermite",
        "tree",
        "tree_pernode",
        "pruned",
        "nbo",
    ],
    "budgets": [16, 64],
    "tree_N": [2, 4, 8],
    "max_leaves": 64,
    "pruning": {"N": [4, 8], "M": [1, 2]},
}
#: what a template left unfilled would print
UNFILLED = re.compile(r"\{\{|\}\}|\{%|%\}|\{#|#\}|\bNone\b|Undefined")


def _source(template: str) -> str:
    return resources.files(PACKAGE).joinpath(template).read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def rendered() -> dict[str, Any]:
    """The section of a small ablation, with the values each template was rendered with."""
    df = run_ablation(CFG, MODEL, seed=11, n_jobs=1)
    problems = analysis.problems_from_config(CFG, MODEL)
    s = analysis.summarize_ablation(df, problems, seed=11)
    cheb = analysis.chebyshev_table(df, s, [2.0], problems)
    tabs = narrative.tables(df, s, cheb)
    calls: dict[str, dict[str, Any]] = {}

    def recording(package: str, template: str, /, **values: Any) -> str:
        calls[template] = values
        return templates.render(package, template, **values)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(narrative, "render", recording)
        section = narrative.estimators_section(df, s, cheb, tabs)
    return {"section": section, "values": calls, "tables": tabs}


def _every_branch(template: str, values: dict[str, Any]) -> dict[str, Any]:
    """``values`` with every optional sentence of ``template`` switched on."""
    if template == "section.md":
        found = dataclasses.replace(
            values["found"],
            tree_slopes="-1.1 to -1.0",
            leaf_ratio=narrative.LeafRatioText(leaves=64, ratio="3.1"),
            weighting=narrative.WeightingText(reached="a", short="b (N = 2, f = 0.5)"),
            pruning=narrative.PruningText(n=8, bias="93%"),
            chebyshev=narrative.ChebyshevText(below=1, cells=2, ratio="0.2", slopes="-1.0"),
            sobol=narrative.SobolText(ratio="6.2", n=64),
        )
        return {**values, "found": found}
    return {
        **values,
        "weighted_cells": narrative.WeightedCellsText(inside=1, cells=2, outside=("x",)),
        "exact_rules": narrative.ExactRulesText(cells=2, error="1e-15"),
        "best_gains": ["lqg_paper sobol 6.2x"],
    }


def test_section_is_rendered_from_both_templates(rendered):
    sec = rendered["section"]
    assert set(rendered["values"]) == {"section.md", "appendix.md"}
    for text in (sec.body, sec.appendix):
        assert not UNFILLED.search(text), UNFILLED.search(text)
        assert not text.endswith("\n") and not text.startswith("\n")
    for md in rendered["tables"].values():
        assert md in sec.appendix
    for name in narrative.FIGURES:
        assert f"(figures/{name}.png)" in sec.body
    # run, symbols, findings, the figures note, then each figure with its caption
    assert len(sec.body.split("\n\n")) == 4 + 2 * len(narrative.FIGURES)
    assert sec.body.startswith("**Run.** ") and "\n\n**Found.** " in sec.body


@pytest.mark.parametrize("template", ["section.md", "appendix.md"])
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
    text = templates.render(PACKAGE, template, **values)
    assert not UNFILLED.search(text), UNFILLED.search(text)


@pytest.mark.parametrize(
    ("bundle", "prefix"),
    [
        (narrative.RunText, "run"),
        (narrative.Findings, "found"),
        (narrative.LeafRatioText, "found.leaf_ratio"),
        (narrative.WeightingText, "found.weighting"),
        (narrative.PruningText, "found.pruning"),
        (narrative.ChebyshevText, "found.chebyshev"),
        (narrative.SobolText, "found.sobol"),
        (narrative.WeightedCellsText, "weighted_cells"),
        (narrative.ExactRulesText, "exact_rules"),
    ],
)
def test_every_field_of_a_value_bundle_is_printed(bundle, prefix):
    text = _source("section.md") + _source("appendix.md")
    for field in dataclasses.fields(bundle):
        assert f"{prefix}.{field.name}" in text, (bundle.__name__, field.name)


def test_findings_are_one_paragraph_of_the_sentences_that_exist(rendered):
    values = _every_branch("section.md", rendered["values"]["section.md"])
    full = templates.render(PACKAGE, "section.md", **values)
    found = next(p for p in full.split("\n\n") if p.startswith("**Found.** "))
    assert "\n" not in found and found.endswith(
        "the RMSE 6.2 times against MC at n = 64; "
        "cubature and Gauss-Hermite are exact for "
        "these quadratic costs."
    )
    assert (
        "(a trend; no finite-N closed form); at the largest N its CI contains 1 for a, "
        "but the tree is not yet at its limit for b (N = 2, f = 0.5). Pruning"
    ) in found
    assert "× the bound; its variance slope vs n is -1.0. Sobol'" in found
    # no finding at all: the label alone, with its space
    empty = dataclasses.replace(
        values["found"],
        tree_slopes=None,
        leaf_ratio=None,
        weighting=None,
        pruning=None,
        chebyshev=None,
        sobol=None,
    )
    text = templates.render(PACKAGE, "section.md", **{**values, "found": empty})
    assert "Σ halved.\n\n**Found.** \n\nFigures: " in text
    # optional clauses of the weighting and Chebyshev sentences
    only_short = dataclasses.replace(
        values["found"],
        weighting=narrative.WeightingText(reached="", short="b (N = 2, f = 0.5)"),
        chebyshev=narrative.ChebyshevText(below=1, cells=2, ratio="0.2", slopes=None),
    )
    text = templates.render(PACKAGE, "section.md", **{**values, "found": only_short})
    assert "closed form), but the tree is not yet at its limit for b (N = 2, f = 0.5). " in text
    assert "lies at 0.2 × the bound. Sobol'" in text


def test_appendix_optional_sentences(rendered):
    values = _every_branch("appendix.md", rendered["values"]["appendix.md"])
    full = templates.render(PACKAGE, "appendix.md", **values)
    assert (
        "(f = 1). The measured f lies between 0 and 1 (within its 95% CI) in 1 of 2 weighted "
        "cells and tends to grow with N or n; outside: x, about what 2 intervals at 95% leave "
        "outside by chance.\n\n**Why pruning" in full
    )
    assert "gain most. Cubature (2·H·d sigma points" in full
    assert "Best stochastic sampler per problem: lqg_paper sobol 6.2x. Exact rules" in full
    none = {
        **values,
        "weighted_cells": narrative.WeightedCellsText(inside=2, cells=2, outside=()),
        "exact_rules": None,
        "best_gains": [],
    }
    text = templates.render(PACKAGE, "appendix.md", **none)
    assert "in 2 of 2 weighted cells and tends to grow with N or n.\n\n**Why pruning" in text
    # the sentence after an absent note keeps its separating space (as the text always did)
    assert "gain most. \n\nWeighted estimators" in text
    assert "Best stochastic sampler per problem: none. Exact rules" in text
    text = templates.render(PACKAGE, "appendix.md", **{**none, "weighted_cells": None})
    assert "(f = 1). \n\n**Why pruning" in text


def test_every_macro_of_the_claims_template_is_used():
    """The claims' words (``claims.md``, :data:`rsmhp.studies.estimators.claims.WORDS`) hold no
    macro that neither the claims module nor one of its specs nor another macro uses."""
    from rsmhp.studies.estimators import claims
    from tests.studies.uav.test_uav_claims import unused_macros

    assert claims.WORDS.package == PACKAGE
    assert unused_macros(claims) == set()


@pytest.mark.parametrize("template", ["section.md", "appendix.md", "claims.md"])
def test_template_lines_are_wrapped(template):
    """Long lines are continued with a backslash, so a diff shows the sentence that changed."""
    long = [line for line in _source(template).split("\n") if len(line) > 100]
    assert long == []
