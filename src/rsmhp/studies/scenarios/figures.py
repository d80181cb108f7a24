"""The summary across scenarios (:mod:`rsmhp.studies.scenarios.summarise`): per method, the
probability of beating NBO run by run, one marker per group of scenarios, with its 95% stratified
bootstrap interval; the dashed line is 1/2 (no difference)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from rsmhp.report.figures import theme
from rsmhp.report.palette import method_label

__all__ = ["FIGURES", "improvement_figure"]

#: figure stems (results/figures/<stem>.png)
FIGURES = ["scenarios_improvement"]

_MARKERS = ("o", "s", "D", "^")


def improvement_figure(summary: pd.DataFrame) -> plt.Figure:
    """One row per method (ordered by its probability over all its scenarios), x the
    probability, a marker per group; :data:`rsmhp.studies.scenarios.summarise.SUMMARY_COLUMNS`."""
    if summary.empty:
        raise ValueError("improvement summary is empty")
    theme()
    groups = list(dict.fromkeys(summary["group"]))
    order = (
        summary.sort_values("scenarios").groupby("method", sort=False)["p_improve"].last()
        .sort_values().index.tolist()
    )  # fmt: skip
    fig, ax = plt.subplots(figsize=(6.4, 0.5 * len(order) + 1.4))
    ax.axvline(0.5, color="0.4", ls="--", lw=1.0)
    step = 0.6 / max(1, len(groups))
    for k, group in enumerate(groups):
        g = summary[summary["group"] == group].set_index("method")
        ms = [m for m in order if m in g.index]
        y = np.array([order.index(m) for m in ms]) + (k - (len(groups) - 1) / 2) * step
        p = g.loc[ms, "p_improve"].to_numpy(float)
        err = np.vstack([p - g.loc[ms, "low"].to_numpy(float),
                         g.loc[ms, "high"].to_numpy(float) - p])  # fmt: skip
        ax.errorbar(p, y, xerr=err, fmt=_MARKERS[k % len(_MARKERS)], color="0.25", ms=5,
                    capsize=2, lw=1.0, label=group, mfc="white" if k % 2 else "0.25")  # fmt: skip
    ax.set_yticks(range(len(order)), [method_label(m) for m in order])
    ax.set_xlabel("P(run beats NBO's paired run)")
    ax.legend(fontsize="small", loc="lower right")
    fig.tight_layout()
    return fig
