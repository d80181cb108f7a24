"""Report section of the scenarios study: in the main text, first the best method per cell
(:mod:`rsmhp.studies.scenarios.best`: one sentence per group), then the probability of beating
NBO (:mod:`rsmhp.studies.scenarios.summarise`: one sentence per group, its figure); in the
appendix the best-method figure ``scenarios_best`` (the report's main text opens with it) and
table, the per-method and the per-scenario tables. Numbers come from the tables; nothing is a
claim. The prose is in the templates ``section.md`` (main text) and ``appendix.md`` beside this
module."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import pandas as pd

from rsmhp.models.uav import methods
from rsmhp.report.ledger import Section
from rsmhp.report.markdown import ci_cells, fmt, markdown_table, param_text
from rsmhp.report.naming import depth_name
from rsmhp.report.palette import method_label
from rsmhp.report.templates import render
from rsmhp.studies.scenarios import TABLES
from rsmhp.studies.scenarios.best import BUDGET, GROUPS, HORIZON, SCENARIO, rollout_of
from rsmhp.studies.scenarios.summarise import ALL_GROUP

__all__ = [
    "GROUP_NAMES",
    "ORDER",
    "TABLES",
    "best_table",
    "config_label",
    "family_label",
    "scenarios_section",
    "scenarios_tables",
]

#: after the long-horizon and optimiser sections
ORDER = 35

#: how the text and the table name each group of :data:`rsmhp.studies.scenarios.best.GROUPS`
GROUP_NAMES = {
    BUDGET: "equal compute, per budget",
    HORIZON: "long horizons, per H",
    SCENARIO: "map scenarios (H = 6), per cell",
}


def config_label(method: str, member: str) -> str:
    """A method's label (:func:`rsmhp.report.palette.method_label` of its ``member``), with the
    optimiser budget of a configuration (``rsmhp_nt16/it300/r1``: ``RS-MHP N_T=16 (it300/r1)``)."""
    label = method_label(member)
    if method != member and method.startswith(f"{member}/"):
        return f"{label} ({method[len(member) + 1 :]})"
    return label


def _axis_text(group: str, value: float) -> str:
    text = param_text(value)
    return {BUDGET: f"{text} ms", HORIZON: f"H = {text}", SCENARIO: f"q = {text}"}.get(group, text)


def best_table(best: pd.DataFrame, paired: pd.DataFrame) -> str:
    """``scenarios_best``: one row per cell of the figure (group, row, column, runs, methods):
    the best method and its mean error, the runner-up with its paired difference from the best
    and the 95% t interval, every method tied with the best, and whether the best is clear."""
    labels = {
        (r.group, r.model, r.value, r.method): config_label(r.method, r.member)
        for r in paired.itertuples(index=False)
    }

    def tied(r) -> str:
        names = [] if pd.isna(r.tied) else [m for m in str(r.tied).split(";") if m]
        return ", ".join(labels[(r.group, r.model, r.value, m)] for m in names) or "none"

    t = pd.DataFrame(
        {
            "group": best["group"].map(lambda g: GROUP_NAMES.get(g, g)),
            "row": best["model"],
            "column": [_axis_text(g, a) for g, a in zip(best["group"], best["value"], strict=True)],
            "runs": best["runs"].astype(int),
            "methods": best["methods"].astype(int),
            "best": [depth_name(config_label(m, b), d, rollout_of(b)) for m, b, d in
                     zip(best["best"], best["best_member"], best["best_depth"], strict=True)],
            "its mean error (m)": best["best_mean"],
            "runner-up": [config_label(m, b) for m, b in
                          zip(best["runner_up"], best["runner_up_member"], strict=True)],
            "runner-up − best (m)": best["runner_up_diff"],
            "95% CI": ci_cells(best["runner_up_low"], best["runner_up_high"], signed=True),
            "tied with the best": [tied(r) for r in best.itertuples(index=False)],
            "clear": best["clear"].map({True: "yes", False: "no"}),
        }
    )  # fmt: skip
    return markdown_table(t, digits=3, signed=("runner-up − best (m)",))


def scenarios_tables(
    summary: pd.DataFrame, per: pd.DataFrame, best: pd.DataFrame, paired: pd.DataFrame
) -> dict[str, str]:
    """``scenarios_best`` (:func:`best_table`), ``scenarios_improvement`` (per group and method:
    scenarios, probability of improvement over NBO with its 95% interval, share of scenarios
    above 1/2) and ``scenarios_per_scenario`` (per scenario and method: paired runs,
    probability, mean difference)."""
    t = pd.DataFrame(
        {
            "scenarios": summary["group"],
            "method": summary["method"].map(method_label),
            "n": summary["scenarios"].astype(int),
            "P(beats NBO)": summary["p_improve"],
            "95% CI": ci_cells(summary["low"], summary["high"]),
            "share of scenarios > 1/2": summary["share_above_half"],
            "mean error − NBO's (m)": summary["mean_diff"],
            "scenarios worse on average": summary["worse_scenarios"].astype(int),
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
        "scenarios_best": best_table(best, paired),
        "scenarios_improvement": markdown_table(t, digits=3, signed=("mean error − NBO's (m)",)),
        "scenarios_per_scenario": markdown_table(p, digits=3, signed=("mean error − NBO's (m)",)),
    }


@dataclass(frozen=True)
class Estimate:
    """One method on a group of scenarios, formatted: its probability of beating NBO ``p`` in
    ``[low, high]`` beside its mean paired difference from NBO ``diff`` (m) and the scenarios
    where it is worse than NBO on average (``worse`` of ``n``)."""

    label: str
    p: str
    low: str
    high: str
    diff: str
    worse: int
    n: int


@dataclass(frozen=True)
class GroupText:
    """What the main text says of a group of scenarios: its size and every method in the
    registry's order (``methods``), never ranked by its probability of beating NBO alone."""

    group: str
    scenarios: int
    methods: list[Estimate]


def _estimate(r: pd.Series) -> Estimate:
    return Estimate(
        method_label(r["method"]), fmt(r["p_improve"], 2), fmt(r["low"], 2), fmt(r["high"], 2),
        fmt(r["mean_diff"], 3, True), int(r["worse_scenarios"]), int(r["scenarios"]),
    )  # fmt: skip


def _group_text(summary: pd.DataFrame, group: str) -> GroupText:
    """The group's methods, in the table's (registry) order, each with its probability of
    beating NBO and its mean difference in metres beside it (all in the appendix)."""
    g = summary[summary["group"] == group]
    return GroupText(
        group=group,
        scenarios=int(g["scenarios"].max()),
        methods=[_estimate(r) for _, r in g.iterrows()],
    )


@dataclass(frozen=True)
class Count:
    """How many cells (``n``) a family (``label``) is the clear best in."""

    label: str
    n: int


@dataclass(frozen=True)
class BestText:
    """What the main text says of one group of the best-method grid: its cells and the
    smallest and largest runs per cell, how many have a clear best and the families of those
    (``clear_best``, most frequent first), how many are tied and the smallest and largest
    number of methods tied with the best there (0 without a tie), and the families that are
    best in the most cells (``top``, every one of them on a tie, each best in ``top_n``)."""

    name: str
    cells: int
    runs_min: int
    runs_max: int
    clear: int
    clear_best: list[Count]
    tied: int
    tie_min: int
    tie_max: int
    top: list[str]
    top_n: int


def _counts(labels: list[str]) -> list[tuple[str, int]]:
    """``(label, count)``, most frequent first (ties: first seen)."""
    counts = {lab: labels.count(lab) for lab in dict.fromkeys(labels)}
    return sorted(counts.items(), key=lambda kv: -kv[1])


def family_label(family: str) -> str:
    """A registered family's label (``dpw``: ``tree search``); the name itself otherwise."""
    fams = {c.family: c for c in methods.families()}
    return fams[family].family_label if family in fams else str(family)


def _best_text(best: pd.DataFrame, group: str) -> BestText:
    """The group's sentence values from the best-method table, by family (the figure's colours;
    the members and their optimiser budgets are in the appendix table)."""
    g = best[best["group"] == group]
    labels = [family_label(f) for f in g["best_family"]]
    clear = g["clear"].astype(bool).to_numpy()
    runs = sorted(set(g["runs"].astype(int)))
    tied = g.loc[~clear, "n_tied"].astype(int).tolist()
    winners = [lab for lab, c in zip(labels, clear, strict=True) if c]
    counts = _counts(labels)
    top_n = counts[0][1]
    return BestText(
        name=GROUP_NAMES.get(group, group),
        cells=len(g),
        runs_min=runs[0],
        runs_max=runs[-1],
        clear=int(clear.sum()),
        clear_best=[Count(lab, n) for lab, n in _counts(winners)],
        tied=len(tied),
        tie_min=min(tied, default=0),
        tie_max=max(tied, default=0),
        top=[lab for lab, n in counts if n == top_n],  # every family at the highest count
        top_n=top_n,
    )


def _render(template: str, **values: Any) -> str:
    """``template`` filled with ``values``, without the newline that ends the file."""
    return render(__package__, template, **values).removesuffix("\n")


def scenarios_section(
    summary: pd.DataFrame,
    tables: dict[str, str],
    best: pd.DataFrame,
    streams: Mapping[str, str | None] | None = None,
) -> Section:
    """The section (order :data:`ORDER`; text in ``section.md`` and ``appendix.md``): in the
    main text the best method per cell of each group (``best``,
    :data:`rsmhp.studies.scenarios.best.BEST_COLUMNS`), then the probability of improvement
    over NBO of every method on each group of scenarios with its figure; in the appendix the
    best-method figure (listed in ``figures``: the report's main text opens with it,
    :data:`rsmhp.report.render.SUMMARY_FIGURE`), the tables and the seed stream of each
    group's runs (``streams``: group -> stream name, e.g. ``{"equal compute": "confirm2"}``)."""
    groups = [g for g in dict.fromkeys(summary["group"]) if g != ALL_GROUP]
    best_groups = [g for g in GROUPS if g in set(best["group"])]
    best_groups += [g for g in dict.fromkeys(best["group"]) if g not in best_groups]
    return Section(
        key="scenarios",
        title="Across scenarios: the best method per cell, and the probability of beating NBO",
        order=ORDER,
        body=_render(
            "section.md",
            best=[_best_text(best, g) for g in best_groups],
            empty=summary.empty,
            groups=[_group_text(summary, g) for g in groups],
        ),
        figures=["scenarios_best", "scenarios_improvement"] if len(best) else
        ["scenarios_improvement"],
        appendix=_render(
            "appendix.md",
            has_best=not best.empty,
            best_table=tables["scenarios_best"],
            improvement_table=tables["scenarios_improvement"],
            per_scenario_table=tables["scenarios_per_scenario"],
            streams=dict(streams or {}),
        ),
    )  # fmt: skip
