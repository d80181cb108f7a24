"""Decision-study figures: LQG regret against sample size."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import seaborn as sns

from rsmhp.figures import theme

__all__ = ["lqg_regret_figure"]


def _label(row: pd.Series) -> str:
    if row["method"] == "pruned":
        name = f"pruned (N={int(row['N'])})"
    elif row["method"] == "tree":
        name = "tree (shared draws)"
    else:
        name = str(row["method"])
    return name if row["weighting"] == "uniform" else f"{name}, likeliness-weighted"


def lqg_regret_figure(summary: pd.DataFrame) -> plt.Figure:
    """Mean regret (log) vs P, the number of trajectories an estimate averages (log), one
    panel per (a, H), one line per method and weighting; dashed lines are the closed forms
    of the methods that have one (uniform mc: kappa v_H / P; tree: kappa v_H / N). Cells with
    zero regret (nbo, antithetic, cubature) are left out (log scale)."""
    theme()
    s = summary[(summary["mean"] > 0) & ~summary["method"].isin(["nbo", "antithetic", "cubature"])]
    s = s.assign(label=s.apply(_label, axis=1))
    order = sorted(s["label"].unique())
    grid = sns.relplot(
        data=s,
        x="P",
        y="mean",
        hue="label",
        hue_order=order,
        style="label",
        style_order=order,
        markers=True,
        dashes=False,
        col="H",
        row="a",
        kind="line",
        height=2.6,
        aspect=1.2,
        facet_kws={"sharey": False, "margin_titles": True},
    )
    palette = dict(zip(order, sns.color_palette("colorblind", len(order)), strict=False))
    for (a, H), ax in grid.axes_dict.items():
        cell = summary[(summary["a"] == a) & (summary["H"] == H)]
        for method, key in (("mc", "mc"), ("tree", "tree (shared draws)")):
            c = cell[
                (cell["method"] == method)
                & (cell["weighting"] == "uniform")
                & (cell["closed_kind"] == "exact")
            ].sort_values("P")
            if not c.empty and key in palette:
                ax.plot(c["P"], c["closed_form"], ls="--", lw=1, color=palette[key])
        ax.set_xscale("log")
        ax.set_yscale("log")
    grid.set_axis_labels("P, trajectories averaged", "mean regret J(û) − J(u*)")
    if grid.legend is not None:
        grid.legend.set_title("method (tree: P = N^H leaves)")
    grid.figure.suptitle(
        "LQG: regret of each method's argmin (dashed: closed forms; NBO, antithetic, cubature: 0)",
        y=1.02,
    )
    if not np.isfinite(s["mean"]).all():
        raise ValueError("regret summary holds non-finite means")
    return grid.figure
