"""LQG report section from its templates (``section.md``, ``appendix.md``): every value the
section computes reaches a template, every placeholder is filled, a missing value raises, and
each optional sentence appears exactly when its data exist. Every macro of the claims' words
(``claims.md``) is used, and no template line is longer than 100 characters."""

from __future__ import annotations

import dataclasses
import re
from importlib import resources
from typing import Any

import jinja2
import pytest
from jinja2 import meta

from rsmhp.report import templates
from rsmhp.studies.lqg import section as narrative
from rsmhp.studies.lqg import summarise as analysis
from rsmhp.studies.lqg.simulate import run_convergence, run_linear_cost, run_nbo_error
from tests.core.test_seeding import BASE

PACKAGE = "rsmhp.studies.lqg"
EPS = [0.25, 1.0]
LINEAR_CFG = {"linear_cost": {"H": 3, "n": [10, 50], "replicates": 40}}
#: what a template left unfilled would print
UNFILLED = re.compile(r"\{\{|\}\}|\{%|%\}|\{#|#\}|\bNone\b|Undefined")


def _source(template: str) -> str:
    return resources.files(PACKAGE).joinpath(template).read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def rendered() -> dict[str, Any]:
    """The section of a small run, with the values each template was rendered with."""
    conv = run_convergence(BASE, seed=2)
    nbo = analysis.summarize_nbo_error(run_nbo_error(BASE, seed=2))
    summary = analysis.summarize_convergence(conv, EPS)
    tables = narrative.lqg_tables(summary, nbo, EPS)
    linear = analysis.linear_cost_check(run_linear_cost(LINEAR_CFG, seed=2), [2.0])
    calls: dict[str, dict[str, Any]] = {}

    def recording(package: str, template: str, /, **values: Any) -> str:
        calls[template] = values
        return templates.render(package, template, **values)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(narrative, "render", recording)
        section = narrative.lqg_section(summary, nbo, conv, EPS, tables, linear)
    return {"section": section, "values": calls, "tables": tables}


def test_section_is_rendered_from_both_templates(rendered):
    sec = rendered["section"]
    assert set(rendered["values"]) == {"section.md", "appendix.md"}
    for text in (sec.body, sec.appendix):
        assert not UNFILLED.search(text), UNFILLED.search(text)
        assert not text.endswith("\n") and not text.startswith("\n")
    for stem in narrative.TABLES:
        assert rendered["tables"][stem] in sec.appendix
    for name in narrative.FIGURES:
        assert f"(figures/{name}.png)" in sec.body


def _every_branch(values: dict[str, Any]) -> dict[str, Any]:
    """``values`` with every optional sentence of the templates switched on."""
    if "results" not in values:
        return values
    results = dataclasses.replace(values["results"], cheb_bound_ratio="0.33")
    assert results.linear is not None
    return {**values, "results": results, "z_clipped": 3}


@pytest.mark.parametrize("template", ["section.md", "appendix.md"])
def test_templates_use_exactly_the_values_passed(rendered, template):
    """The names a template reads are the names Python passes, and dropping any one of them
    raises (StrictUndefined) instead of printing an empty string."""
    values = _every_branch(rendered["values"][template])
    env = jinja2.Environment()
    used = meta.find_undeclared_variables(env.parse(_source(template)))
    assert used == set(values)
    for name in values:
        rest = {k: v for k, v in values.items() if k != name}
        with pytest.raises(jinja2.UndefinedError, match=name):
            templates.render(PACKAGE, template, **rest)


@pytest.mark.parametrize(
    ("bundle", "prefix"),
    [
        (narrative.ModelText, "model"),
        (narrative.NboRunText, "nbo_run"),
        (narrative.ResultsText, "results"),
        (narrative.LinearText, "results.linear"),
    ],
)
def test_every_field_of_a_value_bundle_is_printed(bundle, prefix):
    text = _source("section.md") + _source("appendix.md")
    for field in dataclasses.fields(bundle):
        assert f"{prefix}.{field.name}" in text, (bundle.__name__, field.name)


def test_a_missing_field_raises(rendered):
    values = dict(rendered["values"]["section.md"])
    model = dataclasses.asdict(values["model"])
    del model["sigma"]
    values["model"] = type("Partial", (), model)()
    with pytest.raises(jinja2.UndefinedError, match="sigma"):
        templates.render(PACKAGE, "section.md", **values)


def _body(values: dict[str, Any], **results: Any) -> str:
    changed = {**values, "results": dataclasses.replace(values["results"], **results)}
    return templates.render(PACKAGE, "section.md", **changed)


def test_optional_sentences_follow_their_data(rendered):
    values = rendered["values"]["section.md"]
    res = values["results"]
    base = templates.render(PACKAGE, "section.md", **values)
    # the linear-cost sentence closes the results paragraph, which stays one line
    lin = res.linear
    tail = f"({lin.name} = {lin.value}; LIN-1 {lin.verdict}).\n\n![Fig. 3"
    assert tail in base
    assert "(LQG-4).\n\n![Fig. 3" in _body(values, linear=None)
    # the Chebyshev bound: a ratio where it is informative, else said so
    bounded = _body(values, cheb_bound_ratio="0.33")
    assert (
        "p = " + res.cheb_min_p + "), and that probability is at most 0.33 × Prop. 3's" in bounded
    )
    vacuous = _body(values, cheb_bound_ratio=None)
    assert (
        f"p = {res.cheb_min_p}); Prop. 3's Chebyshev bound Var(g)/(Pε²) is not below 1 in "
        "any cell (LQG-3)." in vacuous
    )
    # points of the residual panel beyond its edge are counted in the caption
    clipped = templates.render(PACKAGE, "section.md", **{**values, "z_clipped": 3})
    assert clipped.endswith("limits of LQG-1 (3 beyond ±8 drawn at the panel edge).*\n")
    assert base.endswith("Bonferroni limits of LQG-1.*\n") == (values["z_clipped"] == 0)
    # the paragraphs: setting, results, then four figures with their captions
    assert len(base.rstrip("\n").split("\n\n")) == 2 + 2 * len(narrative.FIGURES)


def test_rendered_numbers_are_the_summaries(rendered):
    sec, values = rendered["section"], rendered["values"]["section.md"]
    model, run = values["model"], values["nbo_run"]
    assert isinstance(model, narrative.ModelText) and model.u == "0.55, 0.17"
    assert f"H = {model.horizon}, u = ({model.u}), P ∈ {{20, 40, 60}}; a = 0.5 is our" in sec.body
    assert f"({run.replicates} replicates of P = {run.p}, u_k = {run.u})." in sec.body
    assert f"(LQG-1 limit ± {run.limit}):" in sec.appendix


def test_every_macro_of_the_claims_template_is_used():
    """The claims' words (``claims.md``, :data:`rsmhp.studies.lqg.claims.WORDS`) hold no macro
    that neither the claims module nor one of its specs nor another macro uses."""
    from rsmhp.studies.lqg import claims
    from tests.studies.uav.test_uav_claims import unused_macros

    assert claims.WORDS.package == PACKAGE
    assert unused_macros(claims) == set()


@pytest.mark.parametrize("template", ["section.md", "appendix.md", "claims.md"])
def test_template_lines_are_wrapped(template):
    """Long lines are continued with a backslash, so a diff shows the sentence that changed."""
    long = [line for line in _source(template).split("\n") if len(line) > 100]
    assert long == []
