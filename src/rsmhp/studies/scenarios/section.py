"""Report section of the summary across scenarios (:mod:`rsmhp.studies.scenarios.summarise`): one
sentence per group in the main text, the per-method table and the per-scenario table in the
appendix. Numbers come from the tables; nothing is a claim."""

from __future__ import annotations

import pandas as pd

from rsmhp.report.ledger import Section
from rsmhp.report.markdown import ci_cells, fmt, markdown_table
from rsmhp.report.palette import method_label
from rsmhp.studies.scenarios.summarise import ALL_GROUP

__all__ = ["ORDER", "TABLES", "scenarios_section", "scenarios_tables"]

#: after the long-horizon and optimiser sections
ORDER = 35
#: table stems (results/tables/<stem>.md)
TABLES = ("scn_improvement", "scn_per_scenario")


def scenarios_tables(summary: pd.DataFrame, per: pd.DataFrame) -> dict[str, str]:
    """``scn_improvement`` (per group and method: scenarios, probability of improvement over
    NBO with its 95% interval, share of scenarios above 1/2) and ``scn_per_scenario`` (per
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
        "scn_improvement": markdown_table(t, digits=3),
        "scn_per_scenario": markdown_table(p, digits=3, signed=("mean error − NBO's (m)",)),
    }


def _one(r) -> str:
    return f"{method_label(r.method)} {fmt(r.p_improve, 2)} [{fmt(r.low, 2)}, {fmt(r.high, 2)}]"


def _group_text(summary: pd.DataFrame, group: str) -> str:
    """The group's highest and lowest method with their intervals (all in the appendix)."""
    g = summary[summary["group"] == group].sort_values("p_improve", ascending=False)
    n = int(g["scenarios"].max())
    top, low = g.iloc[0], g.iloc[-1]
    if len(g) == 1:
        return f"{group} ({n}): {_one(top)}"
    return f"{group} ({n}, {len(g)} methods): highest {_one(top)}, lowest {_one(low)}"


def scenarios_section(summary: pd.DataFrame, tables: dict[str, str]) -> Section:
    """The section (order :data:`ORDER`): in the main text the probability of improvement
    over NBO of every method on each group of scenarios, the figure; the tables in the
    appendix."""
    groups = [g for g in dict.fromkeys(summary["group"]) if g != ALL_GROUP]
    if summary.empty:
        body = "No scenario has paired closed-loop runs of a method and NBO."
    else:
        body = (
            "P(a method's closed-loop run beats NBO's paired run), mean over scenarios, 95% "
            "stratified bootstrap, descriptive (appendix: every method): "
            + "; ".join(_group_text(summary, g) for g in groups)
            + ". Wins, not metres: most runs can be won by centimetres (UAV-2: equivalent)."
        )
    appendix = "\n".join(
        [
            "A scenario is a map cell (decision study, H = 6, its stream) or a (model, H) of "
            "the long-horizon closed loop (confirmatory stream); in each, run r of every "
            "method faces the same draw. Per scenario p_s = share of runs where the method's "
            "mean location error is below NBO's (ties 1/2); per group the mean of p_s over "
            "its scenarios, 95% percentile interval of a bootstrap that resamples runs "
            "within every scenario.",
            "",
            tables["scn_improvement"],
            "",
            "Per scenario:",
            "",
            tables["scn_per_scenario"],
        ]
    )
    return Section(
        key="scenarios",
        title="Across scenarios: probability of beating NBO",
        order=ORDER,
        body=body + "\n\n![Probability of beating NBO](figures/scn_improvement.png)\n\n"
        "*P(run beats NBO's paired run) per method and group of scenarios; bars: 95% "
        "stratified bootstrap.*",
        figures=["scn_improvement"],
        appendix=appendix,
    )
