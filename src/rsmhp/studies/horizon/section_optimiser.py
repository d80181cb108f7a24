"""Optimiser split of the UAV open-loop regret, report section (order 34, right after the
long-horizon section, order 33): the definitions, the measured split by model and horizon,
the optimiser's iterations and convergence, and which budget removes the optimisation part;
the table ``horizon_optimiser`` and the figure ``horizon_optimiser``. A measurement: no claims.

Every number of the text is read from the summary (:func:`optimiser_summary`) or the config
(``horizon.optimiser``, ``uav.planner``); none is typed. :func:`horizon_note` is the sentence
the long-horizon section (:mod:`rsmhp.studies.horizon.section`) uses to say which regret it shows.
The prose is in the Markdown templates beside this module (``section_optimiser.md``, the main
text; ``section_optimiser_appendix.md``; ``horizon_note.md``); this module computes the values
they are filled with (:mod:`rsmhp.report.templates`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.report.ledger import Section
from rsmhp.report.markdown import ci_cells, fmt, markdown_table, range_text
from rsmhp.report.palette import method_label
from rsmhp.report.templates import render
from rsmhp.studies.horizon import OPTIMISER_TABLES as TABLES
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
_PACKAGE = "rsmhp.studies.horizon"

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
    """Markdown table ``horizon_optimiser``: per model, H, method and budget the states, the mean
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
    return {"horizon_optimiser": markdown_table(t, digits=3, signed=("O %",))}


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


def _render(template: str, **values: Any) -> str:
    """The template ``template`` beside this module (:func:`rsmhp.report.templates.render`)
    filled with ``values``, without the newline that ends the file: a paragraph or a section
    text, not a file."""
    return render(_PACKAGE, template, **values).removesuffix("\n")


def _planner_values(cfg: Mapping[str, Any], planner: Mapping[str, Any] | None) -> dict | None:
    """Whether the first budget is uav.planner's (the closed-loop studies' budget): None
    without a planner, else ``same`` and uav.planner's budget label and maxfun."""
    if planner is None:
        return None
    maxiter, maxfun, restarts = config_budgets(cfg)[0]
    mine = (int(planner["maxiter"]), int(planner["maxfun"]), int(planner.get("restarts", 0)))
    return {
        "same": mine == (maxiter, maxfun, restarts),
        "budget": budget_label((mine[0], mine[2])),
        "maxfun": mine[1],
    }


def _appendix_values(
    summary: pd.DataFrame, cfg: Mapping[str, Any], planner: Mapping | None
) -> dict[str, Any]:
    """The values of the definitions and the setting (``section_optimiser_appendix.md``)."""
    states = summary["states"].astype(int)
    hs = sorted(int(h) for h in summary["H"].unique())
    return {
        "polish_maxiter": int(cfg["polish_maxiter"]),
        "polish_starts": int(cfg["polish_starts"]),
        "horizons": "{" + ", ".join(map(str, hs)) + "}",
        "models": ", ".join(repr(m) for m in dict.fromkeys(summary["model"])),
        "runs": int(cfg["runs"]),
        "steps": ", ".join(str(int(s)) for s in sorted(cfg["steps"])),
        "states_min": int(states.min()),
        "states_max": int(states.max()),
        "methods": ", ".join(method_label(m) for m in dict.fromkeys(summary["method"])),
        "budgets": [
            {"label": budget_label((maxiter, restarts)), "maxfun": maxfun}
            for maxiter, maxfun, restarts in config_budgets(cfg)
        ],
        "planner": _planner_values(cfg, planner),
    }


def _split_values(
    summary: pd.DataFrame, first: tuple[int, int], big: tuple[int, int]
) -> list[dict[str, Any]]:
    """Per model and H, the ranges over methods of R, A and O at the default budget; R and O
    at the largest H and budget (``big``: None where that is the default or was not run)."""
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
                {
                    "H": h,
                    "R": _pct(g["regret_pct"]),
                    "A": _pct(g["approx_pct"]),
                    "O": _pct(g["optim_pct"]),
                }
            )
        g = _at(s, big)
        g = g[g["H"] == h_hi]
        top = (
            {"R": _pct(g["regret_pct"]), "O": _pct(g["optim_pct"])}
            if big != first and not g.empty
            else None
        )
        out.append({"model": model, "cells": cells, "big": top})
    return out


def _iteration_values(summary: pd.DataFrame, first: tuple[int, int]) -> dict[str, Any]:
    """Iterations, convergence and plans at 0 iterations at the default budget (``zero``:
    None if no plan stopped there); what more iterations without restarts change (``more``:
    None with only one such budget)."""
    d = _at(summary, first)
    zero = 100 * _weighted(d, "zero_nit_share")
    plain = sorted(b for b in budget_order(summary) if b[1] == first[1])
    more = None
    if len(plain) > 1:
        lo, hi = _at(summary, plain[0]), _at(summary, plain[-1])
        more = {
            "maxiter_lo": plain[0][0],
            "maxiter_hi": plain[-1][0],
            "restarts": first[1],
            "optim_lo": fmt(float(lo["optim_pct"].mean()), 2),
            "optim_hi": fmt(float(hi["optim_pct"].mean()), 2),
            "iterations_lo": fmt(_weighted(lo, "mean_nit"), 2),
            "iterations_hi": fmt(_weighted(hi, "mean_nit"), 2),
        }
    return {
        "iterations": range_text(d["mean_nit"].to_numpy(), 2),
        "converged": fmt(100 * _weighted(d, "converged_share"), 2),
        "zero": fmt(zero, 2) if zero > 0 else None,
        "more": more,
    }


def _removal_values(summary: pd.DataFrame) -> dict[str, Any]:
    """The first budget that removes the optimisation part (``removing``, its label; None if
    none does) and, if none does, the largest budget's cells (``largest``)."""
    b = removing_budget(summary)
    largest = None
    if b is None:
        g = _at(summary, largest_budget(budget_order(summary)))
        largest = {
            "cells_ok": int((g["optim_pct"] <= g["approx_pct"]).sum()),
            "cells": len(g),
            "optim_max": fmt(float(g["optim_pct"].max()), 2),
        }
    return {"removing": None if b is None else budget_label(b), "largest": largest}


def optimiser_section(
    summary: pd.DataFrame,
    tables: Mapping[str, str],
    cfg: Mapping[str, Any],
    planner: Mapping[str, Any] | None = None,
) -> Section:
    """The section (module doc) from :func:`optimiser_summary`; ``cfg`` is
    ``horizon.optimiser``, ``planner`` ``uav.planner`` (maxiter, maxfun, restarts: whether
    the first budget is the closed-loop studies'). The text is ``section_optimiser.md``
    (main text: the split and what removes it) and ``section_optimiser_appendix.md``
    (definitions, setting, the per-budget table and ``horizon_optimiser``)."""
    if summary.empty:
        raise ValueError("optimiser summary is empty: no (model, H) was run")
    order = budget_order(summary)
    first, big = order[0], largest_budget(order)
    per_budget = markdown_table(budget_table(summary), digits=3, signed=("O %", "largest O %"))
    body = _render(
        "section_optimiser.md",
        first=budget_label(first),
        big=budget_label(big),
        h_hi=int(summary["H"].max()),
        split=_split_values(summary, first, big),
        **_iteration_values(summary, first),
        **_removal_values(summary),
    )
    appendix = _render(
        "section_optimiser_appendix.md",
        **_appendix_values(summary, cfg, planner),
        per_budget=per_budget,
        table=tables["horizon_optimiser"],
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
    """The long-horizon section's pointer to this one (``horizon_note.md``): at the largest H
    of ``summary`` and the default budget, the optimisation and approximation parts over
    models and methods (and whether the optimisation part is the larger in every cell);
    without a summary, the pointer alone."""
    if summary is None or summary.empty:
        return _render(
            "horizon_note.md",
            title=TITLE,
            h_hi=None,
            first=None,
            optim=None,
            approx=None,
            dominates=False,
        )
    first = budget_order(summary)[0]
    h_hi = int(summary["H"].max())
    g = _at(summary, first)
    g = g[g["H"] == h_hi]
    return _render(
        "horizon_note.md",
        title=TITLE,
        h_hi=h_hi,
        first=budget_label(first),
        optim=_pct(g["optim_pct"]),
        approx=_pct(g["approx_pct"]),
        dominates=bool((g["optim_pct"] > g["approx_pct"]).all()),
    )
