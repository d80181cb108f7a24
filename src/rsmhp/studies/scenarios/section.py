"""Report section of the summary across scenarios (:mod:`rsmhp.studies.scenarios.summarise`): one
sentence per group in the main text, the per-method table and the per-scenario table in the
appendix. Numbers come from the tables; nothing is a claim. The prose is in the templates
``section.md`` (main text) and ``appendix.md`` beside this module."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import pandas as pd

from rsmhp.report.ledger import Section
from rsmhp.report.markdown import ci_cells, fmt, markdown_table
from rsmhp.report.palette import method_label
from rsmhp.report.templates import render
from rsmhp.studies.scenarios.summarise import ALL_GROUP

__all__ = ["ORDER", "TABLES", "scenarios_section", "scenarios_tables"]

#: after the long-horizon and optimiser sections
ORDER = 35
#: table stems (results/tables/<stem>.md)
TABLES = ("scenarios_improvement", "scenarios_per_scenario")


def scenarios_tables(summary: pd.DataFrame, per: pd.DataFrame) -> dict[str, str]:
    """``scenarios_improvement`` (per group and method: scenarios, probability of improvement over
    NBO with its 95% interval, share of scenarios above 1/2) and ``scenarios_per_scenario`` (per
    scenario and method: paired runs, probability, mean difference)."""
    t = pd.DataFrame(
        {
            "scenarios": summary["group"],
            "method": summary["method"].map(method_label),
            "n": summary["scenarios"].astype(int),
            "P(beats NBO)": summary["p_improve"],
            "95% CI": ci_cells(summary["low"], summary["high"]),
            "share of scenarios > 1/2": summary["share_above_half"],
        }
    )
    p = pd.DataFrame(
        {
            "scenario": per["scenario"],
            "method": per["method"].map(method_label),
            "runs": per["runs"].astype(int),
            "P(beats NBO)": per["p_improve"],
            "mean error − NBO's (m)": per["mean_diff"],
        }
    )
    return {
        "scenarios_improvement": markdown_table(t, digits=3),
        "scenarios_per_scenario": markdown_table(p, digits=3, signed=("mean error − NBO's (m)",)),
    }


@dataclass(frozen=True)
class Estimate:
    """One method's probability of beating NBO on a group, formatted: ``p`` in ``[low, high]``."""

    label: str
    p: str
    low: str
    high: str


@dataclass(frozen=True)
class GroupText:
    """What the main text says of a group of scenarios: its size, and its highest and lowest
    method (``lowest`` is ``None`` when the group has one method)."""

    group: str
    scenarios: int
    methods: int
    highest: Estimate
    lowest: Estimate | None


def _estimate(r: pd.Series) -> Estimate:
    return Estimate(
        method_label(r["method"]), fmt(r["p_improve"], 2), fmt(r["low"], 2), fmt(r["high"], 2)
    )


def _group_text(summary: pd.DataFrame, group: str) -> GroupText:
    """The group's highest and lowest method with their intervals (all in the appendix)."""
    g = summary[summary["group"] == group].sort_values("p_improve", ascending=False)
    top, low = g.iloc[0], g.iloc[-1]
    return GroupText(
        group=group,
        scenarios=int(g["scenarios"].max()),
        methods=len(g),
        highest=_estimate(top),
        lowest=_estimate(low) if len(g) > 1 else None,
    )


def _render(template: str, **values: Any) -> str:
    """``template`` filled with ``values``, without the newline that ends the file."""
    return render(__package__, template, **values).removesuffix("\n")


def scenarios_section(summary: pd.DataFrame, tables: dict[str, str]) -> Section:
    """The section (order :data:`ORDER`; text in ``section.md`` and ``appendix.md``): in the
    main text the probability of improvement over NBO of every method on each group of
    scenarios, the figure; the tables in the appendix."""
    groups = [g for g in dict.fromkeys(summary["group"]) if g != ALL_GROUP]
    return Section(
        key="scenarios",
        title="Across scenarios: probability of beating NBO",
        order=ORDER,
        body=_render(
            "section.md",
            empty=summary.empty,
            groups=[_group_text(summary, g) for g in groups],
        ),
        figures=["scenarios_improvement"],
        appendix=_render(
            "appendix.md",
            improvement_table=tables["scenarios_improvement"],
            per_scenario_table=tables["scenarios_per_scenario"],
        ),
    )
