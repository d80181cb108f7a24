"""Decision-study figures: LQG regret against sample size."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import seaborn as sns

from rsmhp.figures import theme

__all__ = ["lqg_regret_figure", "uav_map_figure", "uav_regret_figure"]


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


def _uav_label(method: str) -> str:
    if method == "nbo":
        return "NBO"
    if method.startswith("rsmhp_nt"):
        return f"RS-MHP N_T={method[len('rsmhp_nt') :]}"
    return method.replace("tree_n", "pruned tree N=").replace("_m", " M=")


def uav_regret_figure(regret: pd.DataFrame) -> plt.Figure:
    """Relative regret (percent of the best plan's cost, log scale) of every method's plan at
    every belief state, one column per model variant; top row against the best plan found
    (methods and multi-start), bottom row against the best of the methods' plans only (the
    part due to the cost approximation). Values below 1e-4 % are drawn at 1e-4 %."""
    theme()
    floor = 1e-4
    df = regret.assign(
        label=regret["method"].map(_uav_label),
        total=(100 * regret["regret_rel"]).clip(lower=floor),
        approx=(100 * regret["regret_methods"] / regret["best_cost"]).clip(lower=floor),
    )
    order = list(dict.fromkeys(df["label"]))
    models = list(dict.fromkeys(df["model"]))
    fig, axes = plt.subplots(
        2, len(models), figsize=(5.4 * len(models), 7.6), squeeze=False, sharex=True
    )
    for j, model in enumerate(models):
        sub = df[df["model"] == model]
        n_states = sub[["run", "step"]].drop_duplicates().shape[0]
        for i, (col, what) in enumerate(
            (("total", "vs best plan found"), ("approx", "vs best method's plan"))
        ):
            ax = axes[i, j]
            sns.boxplot(data=sub, x="label", y=col, order=order, ax=ax, color="0.85", fliersize=0)
            sns.stripplot(
                data=sub, x="label", y=col, order=order, ax=ax, size=2.5, alpha=0.5, jitter=0.25
            )
            ax.set_yscale("log")
            ax.set_title(f"'{model}' ({n_states} states): {what}")
            ax.set_xlabel("")
            ax.set_ylabel("relative regret (%)")
            ax.tick_params(axis="x", rotation=30)
    fig.suptitle(
        "UAV open loop: regret of each method's plan on an independent evaluation set "
        f"(< {floor:g} % drawn at {floor:g} %)"
    )
    fig.tight_layout()
    return fig


def uav_map_figure(map_df: pd.DataFrame) -> plt.Figure:
    """Heat map per comparison (RS-MHP − NBO): mean paired difference of the closed-loop
    average location error (m) per cell, diverging colours centred at 0, '*' where the 95%
    bootstrap CI excludes 0; track-loss rates (NBO / RS-MHP) under each value."""
    theme()
    comps = list(dict.fromkeys(map_df["comparison"]))
    fig, axes = plt.subplots(1, len(comps), figsize=(5.6 * len(comps), 4.6), squeeze=False)
    row_key, col_key = map_df["row_key"].iloc[0], map_df["col_key"].iloc[0]
    rows = list(dict.fromkeys(map_df["row_value"].map(lambda v: "∞" if pd.isna(v) else f"{v:g}")))
    cols = list(dict.fromkeys(map_df["col_value"].map(lambda v: "∞" if pd.isna(v) else f"{v:g}")))
    lim = float(np.nanmax(np.abs(map_df["mean_diff"]))) or 1.0
    for ax, comp in zip(axes[0], comps, strict=True):
        sub = map_df[map_df["comparison"] == comp].assign(
            r=lambda d: d["row_value"].map(lambda v: "∞" if pd.isna(v) else f"{v:g}"),
            c=lambda d: d["col_value"].map(lambda v: "∞" if pd.isna(v) else f"{v:g}"),
        )
        grid = sub.pivot(index="r", columns="c", values="mean_diff").loc[rows, cols]
        sig = (sub["ci_high"] < 0) | (sub["ci_low"] > 0)
        text = (
            sub.assign(
                t=[
                    f"{d:+.1f}{'*' if s else ''}\nloss {100 * ln:.0f}/{100 * lm:.0f}%"
                    for d, s, ln, lm in zip(
                        sub["mean_diff"], sig, sub["loss_nbo"], sub["loss_method"], strict=True
                    )
                ]
            )
            .pivot(index="r", columns="c", values="t")
            .loc[rows, cols]
        )
        sns.heatmap(
            grid,
            ax=ax,
            cmap="RdBu_r",
            vmin=-lim,
            vmax=lim,
            annot=text.to_numpy(),
            fmt="",
            annot_kws={"fontsize": 8},
            cbar_kws={"label": "mean paired difference of average error (m)"},
        )
        ax.set_title(f"{comp.replace(' − ', ' minus ')}: closed loop")
        ax.set_ylabel(f"{row_key} (m; ∞ = unlimited)" if "radius" in row_key else row_key)
        ax.set_xlabel(col_key)
        ax.tick_params(axis="y", rotation=0)
    fig.suptitle(
        "Sensitivity map (negative, blue: RS-MHP better; * CI excludes 0; loss NBO/RS-MHP)"
    )
    fig.tight_layout()
    return fig
