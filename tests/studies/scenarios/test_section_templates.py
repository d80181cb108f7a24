"""The scenarios section's prose templates (``section.md``, ``appendix.md``), rendered on small
data: every name a template uses is a value the section passes and no other, the rendered text
keeps no template syntax, and a missing value is an error (StrictUndefined), never an empty
string."""

from __future__ import annotations

from pathlib import Path

import jinja2
import numpy as np
import pytest
from jinja2 import meta

from rsmhp.report.templates import render
from rsmhp.studies.scenarios import section
from rsmhp.studies.scenarios.best import best_family
from rsmhp.studies.scenarios.summarise import (
    HORIZON_GROUP,
    MAP_GROUP,
    improvement_summary,
    per_scenario,
    scenario_runs,
)
from tests.studies.scenarios.test_best import _three_groups
from tests.studies.scenarios.test_scenarios import _tables

PACKAGE = "rsmhp.studies.scenarios"
HERE = Path(section.__file__).parent
SYNTAX = ("{{", "}}", "{%", "%}", "{#", "#}")


@pytest.fixture
def data():
    runs = scenario_runs(*_tables(np.random.default_rng(5)))
    s = improvement_summary(runs, n_boot=200, seed=0)
    best = best_family(_three_groups(np.random.default_rng(6)))
    return s, section.scenarios_tables(s, per_scenario(runs), best.cells, best.paired), best.cells


@pytest.fixture
def rendered(monkeypatch, data) -> dict[str, tuple[dict, str]]:
    """``{template: (values, text)}`` of every template the section renders."""
    calls: dict[str, tuple[dict, str]] = {}
    real = section.render

    def spy(package, template, /, **values):
        text = real(package, template, **values)
        calls[template] = (values, text)
        return text

    monkeypatch.setattr(section, "render", spy)
    section.scenarios_section(*data)
    return calls


def test_every_template_gets_exactly_the_values_it_uses(rendered):
    assert set(rendered) == {p.name for p in HERE.glob("*.md")}
    env = jinja2.Environment()
    for name, (values, text) in rendered.items():
        used = meta.find_undeclared_variables(env.parse((HERE / name).read_text("utf-8")))
        assert used == set(values), name
        assert not any(s in text for s in SYNTAX), name
        # the file's last newline (the section drops it), one blank line between paragraphs
        assert text.endswith("\n") and not text.endswith("\n\n"), name
        assert "\n\n\n" not in text, name
        prose = [line for line in text.splitlines() if not line.startswith("|")]
        assert not any("  " in line or line != line.strip() for line in prose), name


def test_the_prose_is_complete(data):
    summary, tables, best = data
    sec = section.scenarios_section(summary, tables, best)
    assert sec.body.startswith(
        "Which method gives the lowest closed-loop mean location error, cell by cell (figure "
    )
    for name in section.GROUP_NAMES.values():  # one sentence part per group, in order
        assert f"{name} (" in sec.body
    assert "equal compute, per budget (2 cells of 4 runs): " in sec.body
    assert "; long horizons, per H (4 cells of 6 runs): " in sec.body
    # the figure is in the appendix (the report's main text opens with it), listed in figures
    assert "scenarios_best.png" not in sec.body and "scenarios_improvement.png" in sec.body
    assert sec.figures == ["scenarios_best", "scenarios_improvement"]
    assert sec.appendix.startswith(
        "![Best method per cell](figures/scenarios_best.png)\n\n*Per cell the method with the "
    )
    assert "*\n\nBest method per cell (figure scenarios_best): in every cell" in sec.appendix
    assert f"\n\n{tables['scenarios_best']}\n\nA scenario is a map cell" in sec.appendix
    # without best-method cells the section opens with the probability of beating NBO
    sec = section.scenarios_section(summary, tables, best.iloc[:0])
    assert sec.figures == ["scenarios_improvement"]
    assert sec.appendix.startswith("Best method per cell (figure scenarios_best): in every cell")
    assert sec.body.startswith("P(a method's closed-loop run beats NBO's paired run), mean over")
    assert f"(appendix: every scenario): {MAP_GROUP} (2 scenarios): " in sec.body
    assert f". {HORIZON_GROUP} (3 scenarios): " in sec.body
    assert "neither ranks the methods alone" in sec.body and "highest" not in sec.body
    assert sec.body.endswith("bars: 95% stratified bootstrap.*")
    assert sec.appendix.endswith(tables["scenarios_per_scenario"])
    assert f"\n\n{tables['scenarios_improvement']}\n\nPer scenario:\n\n" in sec.appendix
    # a group with one method names it once; no data: one sentence
    one = section.scenarios_section(summary.groupby("group").head(1), tables, best.iloc[:0])
    assert f"{MAP_GROUP} (2 scenarios): " in one.body
    assert "; " not in one.body.split(MAP_GROUP)[1].split(". ")[0]  # one method
    empty = section.scenarios_section(summary.iloc[:0], tables, best.iloc[:0])
    assert empty.body.startswith("No scenario has paired closed-loop runs of a method and NBO.\n\n")


def test_a_missing_value_is_an_error(rendered):
    for name, (values, _) in rendered.items():
        for missing in values:
            rest = {k: v for k, v in values.items() if k != missing}
            with pytest.raises(jinja2.UndefinedError, match=f"'{missing}' is undefined"):
                render(PACKAGE, name, **rest)
    group = {"group": "g", "scenarios": 2}  # no "methods"
    with pytest.raises(jinja2.UndefinedError, match="methods"):
        render(PACKAGE, "section.md", best=[], empty=False, groups=[group])


@pytest.mark.parametrize("template", sorted(p.name for p in HERE.glob("*.md")))
def test_template_lines_are_wrapped(template):
    """Long lines are continued with a backslash, so a diff shows the sentence that changed."""
    source = (HERE / template).read_text(encoding="utf-8")
    assert [line for line in source.split("\n") if len(line) > 100] == []
