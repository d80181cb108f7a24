"""Optimiser split of the UAV open-loop regret, report section (order 34, right after the
long-horizon section, order 33): the definitions, the measured split by model and horizon,
the optimiser's iterations and convergence, and which budget removes the optimisation part;
the table ``hz_optimiser`` and the figure ``hz_optimiser``. A measurement: no claims.

Every number of the text is read from the summary (:func:`optimiser_summary`) or the config
(``horizon.optimiser``, ``uav.planner``); none is typed. :func:`horizon_note` is the sentence
the long-horizon section (:mod:`rsmhp.studies.horizon.section`) uses to say which regret it shows.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.report.ledger import Section
from rsmhp.report.markdown import ci_cells, fmt, markdown_table, range_text
from rsmhp.report.palette import method_label
from rsmhp.studies.horizon.figures_optimiser import (
    FIGURES,
    budget_label,
    budget_order,
    largest_budget,
)
from rsmhp.studies.horizon.simulate_optimiser import budgets as config_budgets
from rsmhp.studies.horizon.summarise_optimiser import SUMMARY_COLUMNS as SPLIT_SUMMARY_COLUMNS
from rsmhp.studies.horizon.summarise_optimiser import summarize_split

__all__ = [
    "FIGURES",
    "KEY",
    "ORDER",
    "SUMMARY_COLUMNS",
    "TABLES",
    "TITLE",
    "budget_table",
    "horizon_note",
    "optimiser_section",
    "optimiser_summary",
    "optimiser_tables",
    "removing_budget",
]

KEY = "horizon_optimiser"
TITLE = "Optimiser error apart from approximation error"
#: right after the long-horizon section (33)
ORDER = 34
TABLES = ("hz_optimiser",)

_GROUP = ["model", "H", "method", "family", "maxiter", "restarts"]

#: the summary of :func:`rsmhp.studies.horizon.summarise_optimiser.summarize_split` and the share of
#: plans that stopped at 0 iterations (at the warm start)
SUMMARY_COLUMNS = [*SPLIT_SUMMARY_COLUMNS, "zero_nit_share"]


def optimiser_summary(table: pd.DataFrame) -> pd.DataFrame:
    """:func:`rsmhp.studies.horizon.summarise_optimiser.summarize_split` of the split rows, with
    ``zero_nit_share``: per (model, H, method, budget) the share of plans whose optimiser
    stopped at 0 iterations (the plan is the warm start)."""
    out = summarize_split(table)
    zero = (
        (table["nit"].astype(int) == 0)
        .groupby([table[c] for c in _GROUP], sort=False)
        .mean()
        .rename("zero_nit_share")
        .reset_index()
    )
    out = out.merge(zero, on=_GROUP, how="left", validate="one_to_one")
    return out[SUMMARY_COLUMNS]


def optimiser_tables(summary: pd.DataFrame) -> dict[str, str]:
    """Markdown table ``hz_optimiser``: per model, H, method and budget the states, the mean
    total, approximation and optimisation regret (%) with 95% cluster-t CIs over runs, mean
    iterations, shares of converged plans, of plans at 0 iterations and of states whose
    near-global minimiser came from the polish."""
    s = summary
    t = pd.DataFrame(
        {
            "model": s["model"],
            "H": s["H"].astype(int),
            "method": s["method"].map(method_label),
            "budget": [
                budget_label((int(i), int(r)))
                for i, r in zip(s["maxiter"], s["restarts"], strict=True)
            ],
            "states": s["states"].astype(int),
            "R %": s["regret_pct"],
            "95% CI": ci_cells(s["regret_lo"], s["regret_hi"]),
            "A %": s["approx_pct"],
            "95% CI ": ci_cells(s["approx_lo"], s["approx_hi"]),
            "O %": s["optim_pct"],
            "95% CI  ": ci_cells(s["optim_lo"], s["optim_hi"], signed=True),
            "iterations": s["mean_nit"],
            "converged %": 100 * s["converged_share"],
            "0 iterations %": 100 * s["zero_nit_share"],
            "x* from polish %": 100 * s["polish_star_share"],
        }
    )
    return {"hz_optimiser": markdown_table(t, digits=3, signed=("O %",))}


def _weighted(g: pd.DataFrame, col: str) -> float:
    """Mean of a per-cell column over all plans of ``g`` (weights: the cells' states)."""
    w = g["states"].to_numpy(float)
    return float(np.sum(w * g[col].to_numpy(float)) / np.sum(w))


def _at(summary: pd.DataFrame, budget: tuple[int, int]) -> pd.DataFrame:
    return summary[(summary["maxiter"] == budget[0]) & (summary["restarts"] == budget[1])]


def budget_table(summary: pd.DataFrame) -> pd.DataFrame:
    """One row per budget (config order) over every (model, H, method) cell: mean iterations,
    converged share and share at 0 iterations over all plans (%), the mean over cells of the
    total and optimisation regret (%), the largest optimisation part (%) and the cells whose
    optimisation part is at most their approximation part."""
    rows = []
    for b in budget_order(summary):
        g = _at(summary, b)
        rows.append(
            {
                "budget": budget_label(b),
                "iterations": _weighted(g, "mean_nit"),
                "converged %": 100 * _weighted(g, "converged_share"),
                "0 iterations %": 100 * _weighted(g, "zero_nit_share"),
                "R %": float(g["regret_pct"].mean()),
                "O %": float(g["optim_pct"].mean()),
                "largest O %": float(g["optim_pct"].max()),
                "cells with O ≤ A": f"{int((g['optim_pct'] <= g['approx_pct']).sum())} of {len(g)}",
            }
        )
    return pd.DataFrame(rows)


def removing_budget(summary: pd.DataFrame) -> tuple[int, int] | None:
    """The first budget (config order) at which the optimisation part is at most the
    approximation part in every (model, H, method) cell; None if no budget does."""
    for b in budget_order(summary):
        g = _at(summary, b)
        if len(g) and bool((g["optim_pct"] <= g["approx_pct"]).all()):
            return b
    return None


def _pct(values: Sequence[float] | pd.Series) -> str:
    return f"{range_text(np.asarray(values, dtype=float), 2)}%"


def _budget_config_text(cfg: Mapping[str, Any]) -> str:
    parts = []
    for maxiter, maxfun, restarts in config_budgets(cfg):
        parts.append(f"{budget_label((maxiter, restarts))} (maxfun {maxfun})")
    return "; ".join(parts)


def _planner_match(cfg: Mapping[str, Any], planner: Mapping[str, Any] | None) -> str:
    """Whether the first budget is uav.planner's (the closed-loop studies' budget)."""
    maxiter, maxfun, restarts = config_budgets(cfg)[0]
    if planner is None:
        return "The first budget is the default the others are compared with."
    mine = (int(planner["maxiter"]), int(planner["maxfun"]), int(planner.get("restarts", 0)))
    if mine == (maxiter, maxfun, restarts):
        return (
            "The first budget is uav.planner's, the budget of every closed-loop study and of "
            "the long-horizon section's regret."
        )
    return (
        f"The first budget is the default the others are compared with; uav.planner's ("
        f"{budget_label((mine[0], mine[2]))}, maxfun {mine[1]}), the budget of the "
        "closed-loop studies, differs from it."
    )


def _definitions(cfg: Mapping[str, Any]) -> str:
    return (
        "At each belief state a method m plans by minimising its own cost J_m (the sum over "
        "its hypotheses of the trace of the predicted covariance, Σ tr P) from the warm start "
        "under an optimiser budget b (iterations, evaluations, restarts). Every plan is scored "
        "on the decision study's evaluation cost J_ev (independent hypotheses, the same for "
        "every method and budget). **Total regret** R(m, b) = (J_ev(plan) − J_ref) / J_ref, "
        "against the best plan found, J_ref (the lowest J_ev of every plan evaluated at the "
        "state, a multi-start polish of J_ev included). **Approximation regret** A(m) = the "
        "regret of x*_m, the near-global minimiser of the method's own cost (the best on J_m "
        f"of the budget plans and of a polish, {int(cfg['polish_maxiter'])} iterations, from "
        f"{int(cfg['polish_starts'])} uniform starts and from every budget plan): what even a "
        "perfect optimiser of J_m loses because J_m ≠ J_ev. **Optimisation regret** O(m, b) = "
        "R − A: what the optimiser loses by stopping at a poorer point of J_m (it can be "
        "negative: a poorer minimiser of J_m can be better on J_ev by chance)."
    )


def _setting(summary: pd.DataFrame, cfg: Mapping[str, Any], planner: Mapping | None) -> str:
    models = list(dict.fromkeys(summary["model"]))
    hs = sorted(int(h) for h in summary["H"].unique())
    methods = list(dict.fromkeys(summary["method"]))
    states = summary["states"].astype(int)
    n_states = (
        f"{int(states.iloc[0])} states per (model, H)"
        if states.nunique() == 1
        else f"{int(states.min())} to {int(states.max())} states per (model, H)"
    )
    return (
        f"H ∈ {{{', '.join(map(str, hs))}}} on {', '.join(repr(m) for m in models)}; belief "
        f"states of {int(cfg['runs'])} NBO runs at steps "
        f"{', '.join(str(int(s)) for s in sorted(cfg['steps']))} ({n_states}, the same at "
        f"every H); methods {', '.join(method_label(m) for m in methods)}; budgets "
        f"{_budget_config_text(cfg)}. {_planner_match(cfg, planner)} Means over states, "
        "95% cluster-t CIs over runs (table hz_optimiser in the appendix)."
    )


def _split_text(summary: pd.DataFrame, first: tuple[int, int], big: tuple[int, int]) -> str:
    """Per model and H, the ranges over methods of R, A and O at the default budget, and R
    and O at the largest H and budget."""
    out = []
    hs = sorted(int(h) for h in summary["H"].unique())
    h_hi = hs[-1]
    for model, s in summary.groupby("model", sort=False):
        d = _at(s, first)
        cells = []
        for h in hs:
            g = d[d["H"] == h]
            if g.empty:
                continue
            cells.append(
                f"H = {h}: R {_pct(g['regret_pct'])}, A {_pct(g['approx_pct'])}, O "
                f"{_pct(g['optim_pct'])}"
            )
        text = f"'{model}', {budget_label(first)}: " + "; ".join(cells)
        g = _at(s, big)
        g = g[g["H"] == h_hi]
        if big != first and not g.empty:
            text += (
                f"; with {budget_label(big)} at H = {h_hi}: R {_pct(g['regret_pct'])}, O "
                f"{_pct(g['optim_pct'])}"
            )
        out.append(text + ".")
    return (
        "Measured split (ranges over the methods; per method in table hz_optimiser): "
        + " ".join(out)
    )


def _iterations_text(summary: pd.DataFrame, first: tuple[int, int]) -> str:
    """Iterations, convergence and plans at 0 iterations at the default budget; what more
    iterations without restarts change."""
    d = _at(summary, first)
    conv = 100 * _weighted(d, "converged_share")
    zero = 100 * _weighted(d, "zero_nit_share")
    stopped = (
        f"{fmt(zero, 2)}% of the plans stopped at 0 iterations, i.e. they are the warm start itself"
        if zero > 0
        else "no plan stopped at 0 iterations"
    )
    text = (
        f"At {budget_label(first)} the optimiser used {range_text(d['mean_nit'].to_numpy(), 2)} "
        "iterations on average (per model, H and method) and reported convergence for "
        f"{fmt(conv, 2)}% of the plans; {stopped}."
    )
    if zero > 0:
        text += (
            " 'Converged' is therefore no sign of a good plan here: the warm start (the "
            "previous plan shifted by one step, its last control held) keeps controls at the "
            "bounds of the control box, where the projected gradient can be zero, so the "
            "optimiser's first convergence test passes before any step and the plan keeps "
            "its optimisation regret."
        )
    plain = sorted(b for b in budget_order(summary) if b[1] == first[1])
    if len(plain) > 1:
        lo, hi = _at(summary, plain[0]), _at(summary, plain[-1])
        text += (
            f" Raising maxiter from {plain[0][0]} to {plain[-1][0]} (restarts {first[1]}) "
            "moves the mean optimisation part over the cells from "
            f"{fmt(float(lo['optim_pct'].mean()), 2)}% to {fmt(float(hi['optim_pct'].mean()), 2)}"
            f"% (mean iterations {fmt(_weighted(lo, 'mean_nit'), 2)} and "
            f"{fmt(_weighted(hi, 'mean_nit'), 2)} over all plans)."
        )
    return text


def _removal_text(summary: pd.DataFrame) -> str:
    b = removing_budget(summary)
    order = budget_order(summary)
    big = largest_budget(order)
    g = _at(summary, big)
    if b is not None and b == order[0]:
        return (
            f"Already at the default budget, {budget_label(b)}, the optimisation part is at "
            "most the approximation part in every (model, H, method) cell (per budget below)."
        )
    if b is not None:
        return (
            f"The first budget at which the optimisation part is at most the approximation "
            f"part in every (model, H, method) cell is {budget_label(b)} (per budget below)."
        )
    return (
        "No configured budget brings the optimisation part down to the approximation part "
        f"in every (model, H, method) cell; the largest, {budget_label(big)}, does so in "
        f"{int((g['optim_pct'] <= g['approx_pct']).sum())} of {len(g)} cells, its largest "
        f"optimisation part is {fmt(float(g['optim_pct'].max()), 2)}% (per budget below)."
    )


_FIGURE = [
    "![Optimiser split by horizon](figures/hz_optimiser.png)",
    "",
    "*Open-loop regret (% of the best plan found, symmetric log scale) by horizon, per "
    "method: total at the default budget (solid), total at the largest budget (dashed) and "
    "the approximation part (dotted); the optimisation part is the gap between a total and "
    "the approximation part. Bars: 95% cluster-t CIs over runs, cut at 0 (both regrets are "
    "at least 0 at every state).*",
]


def optimiser_section(
    summary: pd.DataFrame,
    tables: Mapping[str, str],
    cfg: Mapping[str, Any],
    planner: Mapping[str, Any] | None = None,
) -> Section:
    """The section (module doc) from :func:`optimiser_summary`; ``cfg`` is
    ``horizon.optimiser``, ``planner`` ``uav.planner`` (maxiter, maxfun, restarts: whether
    the first budget is the closed-loop studies')."""
    if summary.empty:
        raise ValueError("optimiser summary is empty: no (model, H) was run")
    order = budget_order(summary)
    first, big = order[0], largest_budget(order)
    per_budget = markdown_table(budget_table(summary), digits=3, signed=("O %", "largest O %"))
    # the main text: the split and what removes it; definitions, setting and the per-budget
    # table in the appendix (main-text budget of the report)
    body = "\n".join(
        [
            "R = total open-loop regret of a plan, A = the regret of the near-global "
            "minimiser of the method's own cost (approximation), O = R − A (optimisation); "
            "definitions and setting in the appendix.",
            "",
            _split_text(summary, first, big),
            "",
            _iterations_text(summary, first),
            "",
            _removal_text(summary),
            "",
            *_FIGURE,
        ]
    )
    appendix = "\n".join(
        [
            _definitions(cfg),
            "",
            _setting(summary, cfg, planner),
            "",
            "Per budget, over every (model, H, method) cell (iterations, converged and 0 "
            "iterations: over all plans; R and O: mean of the cells' means):",
            "",
            per_budget,
            "",
            "Optimiser split per model, horizon, method and budget: R, A, O = total, "
            "approximation and optimisation regret (percent of the best plan found, mean over "
            "belief states, 95% cluster-t CIs over runs: jackknife leaving out one run with its "
            "states, t with runs − 1 df; R = A + O for the means, not the bounds); iterations: "
            "mean over states (summed over restarts); converged: the winning optimisation "
            "stopped on a tolerance, not on its budget; 0 iterations: the plan is the warm "
            "start; x* from polish: states whose near-global minimiser of the method's own "
            "cost came from the polish rather than a budget plan:",
            "",
            tables["hz_optimiser"],
        ]
    )
    return Section(
        key=KEY,
        title=TITLE,
        order=ORDER,
        body=body,
        claims=[],
        figures=list(FIGURES),
        appendix=appendix,
    )


def horizon_note(summary: pd.DataFrame | None) -> str:
    """The long-horizon section's pointer to this one: at the largest H of ``summary`` and
    the default budget, the optimisation and approximation parts over models and methods
    (and whether the optimisation part is the larger in every cell); without a summary, the
    pointer alone."""
    pointer = f"section '{TITLE}'"
    if summary is None or summary.empty:
        return f"How much of it is optimisation error rather than approximation is in {pointer}."
    first = budget_order(summary)[0]
    h_hi = int(summary["H"].max())
    g = _at(summary, first)
    g = g[g["H"] == h_hi]
    dominates = bool((g["optim_pct"] > g["approx_pct"]).all())
    return (
        f"At H = {h_hi} and {budget_label(first)} ({pointer}) the optimisation part of the "
        f"open-loop regret is {_pct(g['optim_pct'])} and the approximation part "
        f"{_pct(g['approx_pct'])} "
        "(over models and methods)"
        + ("; the optimisation part dominates in every case." if dominates else ".")
    )
