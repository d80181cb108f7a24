"""LQG figures: the Fig. 3 analogue, error vs P (log-log) with Chebyshev, and the NBO error."""

from __future__ import annotations

from collections.abc import Sequence

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import seaborn as sns

from rsmhp.analysis.lqg import chebyshev_long
from rsmhp.figures import theme

__all__ = ["convergence_figure", "error_loglog_figure", "nbo_error_figure"]


def convergence_figure(
    conv: pd.DataFrame, summary: pd.DataFrame, realization: int = 0
) -> plt.Figure:
    """J_MHP vs P: one realization (replicate ``realization``), the replicate mean with its 95% CI,
    the central 95% of replicates, and horizontal lines at J (exact) and J_NBO."""
    theme()
    fig, ax = plt.subplots(figsize=(7, 4.2))
    spread = conv.groupby("P")["J_mhp"].quantile([0.025, 0.975]).unstack()
    ax.fill_between(
        spread.index,
        spread[0.025],
        spread[0.975],
        color="C0",
        alpha=0.15,
        lw=0,
        label="central 95% of replicates",
    )
    ax.fill_between(
        summary["P"],
        summary["ci_low"],
        summary["ci_high"],
        color="C0",
        alpha=0.45,
        lw=0,
        label="95% CI of the replicate mean",
    )
    one = conv[conv["replicate"] == realization]
    sns.lineplot(
        data=one,
        x="P",
        y="J_mhp",
        ax=ax,
        color="C1",
        lw=1,
        label=f"MHP, one realization (replicate {realization})",
    )
    sns.lineplot(
        data=summary, x="P", y="mean", ax=ax, color="C0", lw=1.5, label="MHP, mean over replicates"
    )
    j_exact, j_nbo = summary["J_exact"].iloc[0], summary["J_nbo"].iloc[0]
    ax.axhline(j_exact, color="k", ls="--", lw=1.2, label=f"exact J = {j_exact:.3f}")
    ax.axhline(j_nbo, color="C3", ls="-.", lw=1.2, label=f"NBO = {j_nbo:.3f}")
    ax.set_xlabel("number of sampled trajectories P")
    ax.set_ylabel("cost estimate")
    ax.set_title("LQG: MHP vs NBO cost approximation (Fig. 3 analogue)")
    ax.legend(loc="center right", fontsize=8, frameon=True)
    return fig


def error_loglog_figure(summary: pd.DataFrame, eps_values: Sequence[float]) -> plt.Figure:
    """Left: RMSE vs P (log-log) with 95% CI and sqrt(Var(g)/P); right: Chebyshev bound vs observed
    exceedance frequency for each eps (log-log; zero frequencies are drawn at the axis floor)."""
    theme()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    ax1.fill_between(
        summary["P"],
        summary["rmse_low"],
        summary["rmse_high"],
        color="C0",
        alpha=0.3,
        lw=0,
        label="RMSE 95% CI",
    )
    sns.lineplot(data=summary, x="P", y="rmse", ax=ax1, color="C0", label="RMSE over replicates")
    ax1.plot(
        summary["P"],
        summary["sd_theory"],
        "k--",
        lw=1.2,
        label=r"exact $\sqrt{\mathrm{Var}(g)/P}$ (slope $-1/2$)",
    )
    nbo_err = float(summary["J_exact"].iloc[0] - summary["J_nbo"].iloc[0])
    ax1.axhline(nbo_err, color="C3", ls="-.", lw=1.2, label=f"|NBO error| = {nbo_err:.2f}")
    ax1.set(
        xscale="log",
        yscale="log",
        xlabel="P",
        ylabel="|error|",
        title="MHP error vs number of trajectories",
    )
    ax1.legend(fontsize=8)
    cheb = chebyshev_long(summary, eps_values)
    floor = 0.5 / summary["n_replicates"].max()
    cheb = cheb.assign(
        freq_plot=cheb["freq"].clip(lower=floor), eps_label=cheb["eps"].map("ε={:g}".format)
    )
    palette = sns.color_palette("viridis", len(eps_values))
    sns.lineplot(
        data=cheb, x="P", y="bound", hue="eps_label", ax=ax2, palette=palette, ls="--", legend=False
    )
    sns.scatterplot(
        data=cheb,
        x="P",
        y="freq_plot",
        hue="eps_label",
        ax=ax2,
        palette=palette,
        s=12,
        edgecolor="none",
    )
    ax2.set(
        xscale="log",
        yscale="log",
        xlabel="P",
        ylim=(floor * 0.8, 1.2),
        ylabel=r"$P(|J_P - J| \geq \epsilon)$",
        title="Prop. 3: Chebyshev bound (dashed) vs observed (dots)",
    )
    ax2.annotate(
        "frequency 0 drawn at the floor", (0.02, 0.02), xycoords="axes fraction", fontsize=7
    )
    ax2.legend(title=None, fontsize=8)
    fig.tight_layout()
    return fig


def nbo_error_figure(nbo: pd.DataFrame) -> plt.Figure:
    """NBO error vs H per a: simulated mean with 95% CI (points) and closed form (lines)."""
    theme()
    fig, ax = plt.subplots(figsize=(7, 4.2))
    a_vals = sorted(nbo["a"].unique())
    palette = dict(zip(a_vals, sns.color_palette("viridis", len(a_vals)), strict=True))
    data = nbo.assign(a_label=nbo["a"].map("a={:g}".format))
    sns.lineplot(
        data=data,
        x="H",
        y="nbo_error_closed",
        hue="a_label",
        ax=ax,
        palette=[palette[a] for a in a_vals],
        lw=1.2,
    )
    for a, grp in nbo.groupby("a"):
        ax.errorbar(
            grp["H"],
            grp["nbo_error_sim"],
            yerr=1.96 * grp["se"],
            fmt="o",
            ms=3.5,
            color=palette[a],
            capsize=2,
        )
    ax.set_xlabel("horizon H")
    ax.set_ylabel(r"$J - J_{NBO}$")
    ax.set_xticks(np.unique(nbo["H"]))
    ax.set_title(r"NBO error: simulated (points, 95% CI) vs $r\sigma^2\sum_{n<H}(1-a)^{2n}$")
    ax.legend(title=None, fontsize=8, ncols=2)
    return fig
