r"""The optimiser split of the UAV open-loop regret against the horizon (``horizon_optimiser``).

One panel per model variant; x: the horizon H (log scale); y: regret in percent of the best
plan found (symmetric log scale, linear within :data:`LINTHRESH_PCT` of 0, so that a zero
regret can be drawn; the axis starts at 0: the total and approximation regrets are at least 0
at every state, so a t interval reaching below 0 is cut there). Per method (its palette
colour, dodged slightly along x so that the bars do not overlap): the total regret R at the
default budget (the first configured, solid line), the total regret at the largest budget
(:func:`largest_budget`, dashed) and the approximation part A (dotted), each the mean over
belief states with its 95% cluster-t CI over runs
(:mod:`rsmhp.studies.horizon.summarise_optimiser`).
The optimisation part at a budget is the gap between its total and the approximation part.

The budget helpers (:func:`budget_order`, :func:`largest_budget`, :func:`budget_label`) are
shared with the report section (:mod:`rsmhp.studies.horizon.section_optimiser`).
"""

from __future__ import annotations

from collections.abc import Sequence

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.lines import Line2D
from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter, NullLocator

from rsmhp.models.uav import methods as _registry  # noqa: F401  (UAV method names get their colours)
from rsmhp.report.figures import theme
from rsmhp.report.palette import method_colour, method_label
from rsmhp.studies.horizon import OPTIMISER_FIGURES as FIGURES

__all__ = [
    "FIGURES",
    "LINTHRESH_PCT",
    "budget_label",
    "budget_order",
    "largest_budget",
    "optimiser_figure",
]


#: the symlog axis is linear within ± this many percent
LINTHRESH_PCT = 0.01

Budget = tuple[int, int]


def budget_order(summary: pd.DataFrame) -> list[Budget]:
    """The (maxiter, restarts) of every budget of ``summary``, in the order of their first
    row (the config's order: the first is the default budget)."""
    pairs = zip(summary["maxiter"].astype(int), summary["restarts"].astype(int), strict=True)
    return list(dict.fromkeys(pairs))


def largest_budget(budgets: Sequence[Budget]) -> Budget:
    """The budget with the most iterations over all its optimisations, maxiter (1 +
    restarts); ties go to more restarts."""
    if not budgets:
        raise ValueError("no optimiser budget")
    return max(budgets, key=lambda b: (b[0] * (1 + b[1]), b[1]))


def budget_label(budget: Budget) -> str:
    """``maxiter 30`` or ``maxiter 1000 + 8 restarts``."""
    maxiter, restarts = budget
    if restarts == 0:
        return f"maxiter {maxiter}"
    return f"maxiter {maxiter} + {restarts} restart{'s' if restarts > 1 else ''}"


def _yerr(g: pd.DataFrame, prefix: str) -> tuple[np.ndarray, np.ndarray]:
    y = g[f"{prefix}_pct"].to_numpy(float)
    lo = g[f"{prefix}_lo"].to_numpy(float)
    hi = g[f"{prefix}_hi"].to_numpy(float)
    lo = np.maximum(lo, 0.0)  # both regrets drawn are >= 0 at every state
    err = np.vstack([np.nan_to_num(y - lo, nan=0.0), np.nan_to_num(hi - y, nan=0.0)])
    return y, np.maximum(err, 0.0)


def optimiser_figure(summary: pd.DataFrame) -> plt.Figure:
    """``horizon_optimiser`` from the summary of :func:`rsmhp.studies.horizon.summarise_optimiser.
    summarize_split` (module doc)."""
    theme()
    models = list(dict.fromkeys(summary["model"]))
    if not models:
        raise ValueError("optimiser summary is empty")
    order = budget_order(summary)
    first, big = order[0], largest_budget(order)
    hs = sorted(int(h) for h in summary["H"].unique())
    methods = list(dict.fromkeys(summary["method"]))
    dodge = dict(zip(methods, np.linspace(-0.04, 0.04, len(methods)), strict=True))
    series = [
        (first, "regret", "-", "o", f"total, {budget_label(first)} (default)"),
        (big, "regret", "--", "s", f"total, {budget_label(big)}"),
        (first, "approx", ":", "^", "approximation part"),
    ]
    if big == first:
        series.pop(1)
    fig, axes = plt.subplots(
        1, len(models), figsize=(4.8 * len(models), 3.8), squeeze=False, sharey=True
    )
    for j, model in enumerate(models):
        ax = axes[0, j]
        s = summary[summary["model"] == model]
        for method in methods:
            colour = method_colour(method)
            for (maxiter, restarts), prefix, ls, marker, _ in series:
                g = s[
                    (s["method"] == method)
                    & (s["maxiter"] == maxiter)
                    & (s["restarts"] == restarts)
                ].sort_values("H")
                if g.empty:
                    continue
                y, err = _yerr(g, prefix)
                x = g["H"].to_numpy(float) * np.exp(dodge[method])
                ax.errorbar(x, y, yerr=err, color=colour, ls=ls, marker=marker, ms=3.5, lw=1.2,
                            capsize=2, elinewidth=0.9)  # fmt: skip
        ax.set_yscale("symlog", linthresh=LINTHRESH_PCT)
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(NullFormatter())
        ax.set_xscale("log")
        ax.xaxis.set_major_locator(FixedLocator(hs))
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_locator(NullLocator())
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_title(model)
        ax.set_xlabel("horizon H (steps)")
        if j == 0:
            ax.set_ylabel("open-loop regret (% of the best plan)")
    handles = [Line2D([], [], color=method_colour(m), lw=2, label=method_label(m)) for m in methods]
    handles += [
        Line2D([], [], color="0.3", ls=ls, marker=marker, ms=4, label=label)
        for _, _, ls, marker, label in series
    ]
    # the shared y axis starts at 0 once every panel is drawn (set inside the loop it would
    # freeze the top at the first panel's data and cut the others' lines)
    axes[0, 0].set_ylim(bottom=0.0)
    axes[0, -1].legend(handles=handles, fontsize="x-small", loc="best")
    fig.suptitle("Optimiser error apart from approximation error, by horizon", fontsize=11)
    fig.tight_layout()
    return fig
