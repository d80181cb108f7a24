r"""The planner frontier: decision quality against planning compute, one curve per family.

Columns: model variants. Top row: open-loop relative regret minus NBO's at the same belief
states (percentage points); bottom row: closed-loop mean location error minus NBO's on the same
runs (m). x: planning milliseconds per step (median over runs, log scale). Each family is one
line through its members in order of compute, in the palette's family colour, with the 95%
bootstrap CI of every point as a vertical bar; NBO is the reference line at 0; the planning
budget of the equal-compute claims (``frontier.budget.ms_per_step``), when given,
is a dotted vertical line.

``frontier_confirm`` (:func:`confirm_figure`), the confirmatory run of the protocol: columns are
model variants; each family's tuned members along the budget ladder as one line; rows: closed-
loop mean location error minus NBO's (m, 95% t CIs over runs) against the planning
milliseconds per step the budget counts (the ladder's ``cost_ms``,
:func:`rsmhp.pipeline.protocol.budget_cost`; a hollow marker where the closed loop's time is the
larger), the same against model steps per planning step (machine-independent),
and the probability of improvement over the Monte-Carlo member at the same budget (95% t CIs)
against the budget.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.ticker import FixedLocator, FuncFormatter, LogLocator, NullFormatter

from rsmhp.models.uav import methods
from rsmhp.report.figures import theme
from rsmhp.report.palette import METHOD_COLOURS, method_colour
from rsmhp.studies.frontier import CONFIRM_FIGURES, FIGURES

__all__ = ["CONFIRM_FIGURES", "FIGURES", "confirm_figure", "frontier_figure"]


_ROWS = (
    ("regret_diff_pp", "open-loop regret − NBO's (pp)"),
    ("error_diff", "closed-loop mean error − NBO's (m)"),
)


#: the figure's two compute axes: (summary column, axis label)
_UNITS = (
    ("plan_ms", "planning ms per step (interleaved timing, median)"),
    ("work_per_step", "model steps per planning step (machine-independent)"),
)


def frontier_figure(summary: pd.DataFrame, budget_ms: float | None = None) -> plt.Figure:
    """The frontier of ``summary`` (:func:`rsmhp.studies.frontier.summarise.summarize_frontier`):
    per model two columns of panels, quality against planning time and against model steps per
    planning step (a unit the summary does not have, e.g. an older table without
    ``work_per_step``, is left out), with the planning budget ``budget_ms`` (ms per step)
    marked on the time axis if given."""
    theme()
    models = list(dict.fromkeys(summary["model"]))
    if not models:
        raise ValueError("frontier summary is empty")
    units = [
        u for u in _UNITS if u[0] in summary and np.isfinite(summary[u[0]].to_numpy(float)).any()
    ]
    fams = {c.family: c for c in methods.families()}
    cols = [(model, unit) for model in models for unit in units]
    fig, axes = plt.subplots(
        2, len(cols), figsize=(4.2 * len(cols), 7.0), squeeze=False, sharex="col"
    )
    for j, (model, (xcol, xlabel)) in enumerate(cols):
        s = summary[summary["model"] == model]
        for i, (col, label) in enumerate(_ROWS):
            ax = axes[i, j]
            ax.axhline(0.0, color=method_colour("nbo"), lw=1.2, ls="--", label="NBO")
            for fam, g in s.groupby("family", sort=False):
                if fams[fam].baseline:
                    continue
                g = g.sort_values(xcol)
                y = g[col].to_numpy(float)
                lo = y - g[f"{col}_low"].to_numpy(float)
                hi = g[f"{col}_high"].to_numpy(float) - y
                ax.errorbar(
                    g[xcol],
                    y,
                    yerr=np.vstack([lo, hi]),
                    color=METHOD_COLOURS[fams[fam].colour_key],
                    marker="o",
                    ms=4,
                    capsize=2,
                    lw=1.4,
                    label=fams[fam].family_label,
                )
            if budget_ms is not None and xcol == "plan_ms":
                ax.axvline(budget_ms, color="0.35", lw=1.0, ls=":", label="budget")
            ax.set_xscale("log")
            # plain numbers on the decades and 2, 5 between them; no crowded minor labels
            ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
            ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
            ax.xaxis.set_minor_formatter(NullFormatter())
            if i == 0:
                ax.set_title(model)
            if i == 1:
                ax.set_xlabel(xlabel)
            if j == 0:
                ax.set_ylabel(label)
    axes[0, -1].legend(fontsize="small", loc="best")
    fig.tight_layout()
    return fig


def confirm_figure(lad: pd.DataFrame) -> plt.Figure:
    """The confirmatory ladder (:func:`rsmhp.studies.frontier.summarise.ladder`), see the module
    docstring."""
    theme()
    models = list(dict.fromkeys(lad["model"]))
    if not models:
        raise ValueError("ladder is empty")
    fams = {c.family: c for c in methods.families()}
    rows = (
        ("cost_ms", "diff_nbo", "error − NBO's (m)", "planning ms per step (budget's count)"),
        ("work_per_step", "diff_nbo", "error − NBO's (m)", "model steps per planning step"),
        ("budget_ms", "p_improve", "P(improvement over Monte Carlo)", "budget (ms per step)"),
    )
    fig, axes = plt.subplots(
        len(rows), len(models), figsize=(4.8 * len(models), 9.6), squeeze=False
    )
    for j, model in enumerate(models):
        g = lad[lad["model"] == model]
        for i, (xcol, ycol, ylabel, xlabel) in enumerate(rows):
            ax = axes[i, j]
            ref = 0.5 if ycol == "p_improve" else 0.0
            ax.axhline(ref, color=method_colour("nbo"), lw=1.0, ls="--")
            for fam, f in g.groupby("family", sort=False):
                f = f.sort_values("budget_ms")
                y = f[ycol].to_numpy(float)
                lo = np.nan_to_num(y - f[f"{ycol}_low"].to_numpy(float))
                hi = np.nan_to_num(f[f"{ycol}_high"].to_numpy(float) - y)
                ax.errorbar(
                    f[xcol],
                    y,
                    yerr=np.vstack([lo, hi]),
                    color=METHOD_COLOURS[fams[fam].colour_key] if fam in fams else "0.5",
                    marker="o",
                    ms=4,
                    capsize=2,
                    lw=1.3,
                    label=fams[fam].family_label if fam in fams else fam,
                )
                if xcol == "cost_ms":  # hollow where the closed loop's time is the one counted
                    loop = (f["loop_ms"] > f["plan_ms"]).to_numpy()
                    edge = METHOD_COLOURS[fams[fam].colour_key] if fam in fams else "0.5"
                    ax.scatter(f[xcol][loop], y[loop], s=30, facecolor="white", zorder=3,
                               edgecolor=edge)  # fmt: skip
            ax.set_xscale("log")
            if xcol == "budget_ms":  # the preregistered budgets themselves
                ax.xaxis.set_major_locator(FixedLocator(sorted(set(g["budget_ms"]))))
            elif xcol == "work_per_step":  # decades only: the counts span 3 to 4 of them
                ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0,)))
            else:
                ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
            ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
            ax.xaxis.set_minor_formatter(NullFormatter())
            ax.set_xlabel(xlabel)
            if i == 0:
                ax.set_title(model)
            if j == 0:
                ax.set_ylabel(ylabel)
    axes[0, -1].legend(fontsize="small", loc="best")
    fig.tight_layout()
    return fig
