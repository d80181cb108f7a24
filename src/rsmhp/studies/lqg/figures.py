r"""LQG figures (paper Sec. III-A): the paper-style Fig. 3, our statistical view of it, the
error against P (log-log) with the Chebyshev bound of Prop. 3, and the NBO error against H
with its residuals.

Colours come from :mod:`rsmhp.report.palette`: the MHP estimate (independent trajectories) is
``mc``, NBO is ``nbo``, the exact cost is ``exact``; closed-form curves use the method's
colour with the ``derived`` line style. Costs are dimensionless.
"""

from __future__ import annotations

from collections.abc import Sequence

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import seaborn as sns

from rsmhp.report.figures import theme
from rsmhp.report.markdown import fmt
from rsmhp.report.palette import LINESTYLES, method_colour, method_label
from rsmhp.studies.lqg.claims import fmt_exact
from rsmhp.studies.lqg.section import NBO_Z_CLIP
from rsmhp.studies.lqg.summarise import chebyshev_long, eps_label, nbo_z_limit

__all__ = [
    "convergence_figure",
    "error_loglog_figure",
    "fig3_paper_figure",
    "nbo_error_figure",
    "nbo_shades",
]

MHP, NBO, EXACT = "mc", "nbo", "exact"
#: |z| beyond which residuals are drawn at the panel edge (an outlier would hide the others)
Z_CLIP = NBO_Z_CLIP


def _cost(x: float) -> str:
    return fmt_exact(float(x), 4)


def _reference_lines(ax: plt.Axes, j_exact: float, j_nbo: float) -> None:
    """Horizontal lines at the exact J and at J_NBO (closed forms: ``derived`` style)."""
    ax.axhline(
        j_exact,
        color=method_colour(EXACT),
        ls=LINESTYLES["derived"],
        lw=1.3,
        label=f"exact J = {_cost(j_exact)}",
    )
    ax.axhline(
        j_nbo,
        color=method_colour(NBO),
        ls=LINESTYLES["derived"],
        lw=1.3,
        label=f"{method_label(NBO)} J_NBO = {_cost(j_nbo)}",
    )


def fig3_paper_figure(
    conv: pd.DataFrame, summary: pd.DataFrame, realization: int = 0
) -> plt.Figure:
    """The paper's Fig. 3 drawn its way: one realisation (replicate ``realization``) of the MHP
    estimate :math:`J_P` against P, and horizontal lines at NBO's :math:`J_{NBO}` and the exact
    :math:`J`; nothing else."""
    theme()
    fig, ax = plt.subplots(figsize=(7, 4.2))
    one = conv[conv["replicate"] == realization].sort_values("P")
    if one.empty:
        raise ValueError(f"convergence table has no replicate {realization}")
    ax.plot(
        one["P"],
        one["J_mhp"],
        color=method_colour(MHP),
        ls=LINESTYLES["measured"],
        lw=1.2,
        label="MHP J_P (one realisation)",
    )
    _reference_lines(ax, float(summary["J_exact"].iloc[0]), float(summary["J_nbo"].iloc[0]))
    ax.set_xlabel("number of sampled trajectories P")
    ax.set_ylabel("cost (dimensionless)")
    ax.set_title("LQG problem: MHP vs NBO (paper Fig. 3, drawn the paper's way)")
    ax.legend(loc="center right", fontsize=8, frameon=True)
    return fig


def convergence_figure(conv: pd.DataFrame, summary: pd.DataFrame) -> plt.Figure:
    """Our statistical view of Fig. 3. Left: mean of :math:`J_P` over the replicates with its
    95% CI, the central 95% of the replicates, the exact J and :math:`J_{NBO}`. Right: mean
    minus J with its 95% CI and the exact :math:`\\pm 1.96\\sqrt{\\mathrm{Var}(g)/(PR)}` band
    of an unbiased mean (R replicates)."""
    theme()
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.2), width_ratios=(1.25, 1))
    colour = method_colour(MHP)
    spread = conv.groupby("P")["J_mhp"].quantile([0.025, 0.975]).unstack()
    ax.fill_between(
        spread.index,
        spread[0.025],
        spread[0.975],
        color=colour,
        alpha=0.15,
        lw=0,
        label="central 95% of replicates",
    )
    ax.fill_between(
        summary["P"],
        summary["ci_low"],
        summary["ci_high"],
        color=colour,
        alpha=0.5,
        lw=0,
        label="95% CI of the mean",
    )
    ax.plot(summary["P"], summary["mean"], color=colour, lw=1.3, label="MHP J_P, mean")
    j_exact, j_nbo = float(summary["J_exact"].iloc[0]), float(summary["J_nbo"].iloc[0])
    _reference_lines(ax, j_exact, j_nbo)
    reps = int(summary["n_replicates"].max())
    ax.set(
        xlabel="number of sampled trajectories P",
        ylabel="cost (dimensionless)",
        title=f"MHP estimate over {reps} replicates vs NBO",
    )
    ax.legend(loc="center right", fontsize=8, frameon=True)

    half = 1.96 * summary["sd_theory"] / np.sqrt(summary["n_replicates"])
    ax2.fill_between(
        summary["P"],
        -half,
        half,
        color=method_colour(EXACT),
        alpha=0.1,
        lw=0,
        label=r"$\pm 1.96\sqrt{\mathrm{Var}(g)/(PR)}$ (an unbiased mean)",
    )
    bias = summary["mean"] - j_exact
    ax2.fill_between(
        summary["P"],
        summary["ci_low"] - j_exact,
        summary["ci_high"] - j_exact,
        color=colour,
        alpha=0.4,
        lw=0,
        label="95% CI of mean J_P − J",
    )
    ax2.plot(summary["P"], bias, color=colour, lw=1.2, label="mean J_P − J")
    ax2.axhline(0.0, color=method_colour(EXACT), ls=LINESTYLES["derived"], lw=1.0)
    reach = float(
        max(
            half.max(),
            (summary["ci_high"] - j_exact).abs().max(),
            (summary["ci_low"] - j_exact).abs().max(),
        )
    )
    ax2.set(
        ylim=(-1.1 * reach, 1.75 * reach),
        xscale="log",
        xlabel="P (log scale)",
        ylabel="mean J_P − J (cost)",
        title="Bias of the mean (zoom)",
    )
    ax2.legend(loc="upper right", fontsize=7, frameon=True, ncols=2)
    fig.tight_layout()
    return fig


def error_loglog_figure(summary: pd.DataFrame, eps_values: Sequence[float]) -> plt.Figure:
    """Left: RMSE of :math:`J_P` vs P (log-log) with its 95% CI, the exact
    :math:`\\sqrt{\\mathrm{Var}(g)/P}` and NBO's error. Right: the Chebyshev bound of Prop. 3
    against the observed exceedance frequency for each ε (log-log; zero frequencies, which a
    log axis cannot show, are drawn at the floor 0.5/R and said so in the panel)."""
    theme()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    colour = method_colour(MHP)
    ax1.fill_between(
        summary["P"],
        summary["rmse_low"],
        summary["rmse_high"],
        color=colour,
        alpha=0.3,
        lw=0,
        label="95% CI",
    )
    ax1.plot(summary["P"], summary["rmse"], color=colour, lw=1.3, label="MHP: RMSE of J_P")
    ax1.plot(
        summary["P"],
        summary["sd_theory"],
        color=method_colour(EXACT),
        ls=LINESTYLES["derived"],
        lw=1.1,
        label=r"exact $\sqrt{\mathrm{Var}(g)/P}$ (slope $-1/2$)",
    )
    nbo_err = abs(float(summary["J_exact"].iloc[0] - summary["J_nbo"].iloc[0]))
    ax1.axhline(
        nbo_err,
        color=method_colour(NBO),
        ls=LINESTYLES["derived"],
        lw=1.3,
        label=f"NBO: |J − J_NBO| = {_cost(nbo_err)}",
    )
    ax1.set(
        xscale="log",
        yscale="log",
        xlabel="number of sampled trajectories P",
        ylabel="error (cost)",
        title="Error of the MHP estimate vs P",
    )
    ax1.legend(fontsize=8, loc="lower left")

    cheb = chebyshev_long(summary, eps_values)
    floor = 0.5 / summary["n_replicates"].max()
    n_zero = int((cheb["freq"] <= 0).sum())
    cheb = cheb.assign(
        freq_plot=cheb["freq"].clip(lower=floor),
        label=cheb["eps"].map(lambda e: f"ε = {eps_label(e)}"),
    )
    palette = dict(
        zip(
            cheb["label"].unique(),
            sns.color_palette("viridis", len(eps_values)),
            strict=True,
        )
    )
    for label, grp in cheb.groupby("label", sort=False):
        c = palette[label]
        ax2.plot(grp["P"], grp["bound"], color=c, ls=LINESTYLES["derived"], lw=1.1)
        ax2.scatter(grp["P"], grp["freq_plot"], color=c, s=10, edgecolor="none", label=label)
    ax2.plot([], [], color="0.3", ls=LINESTYLES["derived"], label="bound min(1, Var(g)/(Pε²))")
    ax2.set(
        xscale="log",
        yscale="log",
        xlabel="number of sampled trajectories P",
        ylim=(floor * 0.7, 1.3),
        ylabel=r"$\Pr(|J_P - J| \geq \epsilon)$",
        title="Prop. 3: Chebyshev bound (dashed) vs observed (dots)",
    )
    if n_zero:
        ax2.annotate(
            f"{n_zero} cells with frequency 0 drawn at {fmt(floor, 2)}",
            (0.02, 0.11),
            xycoords="axes fraction",
            fontsize=7,
        )
    ax2.legend(title=None, fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    return fig


def nbo_shades(n: int) -> list[tuple[float, float, float]]:
    """``n`` shades of the NBO colour, light to dark (one per value of a)."""
    return sns.blend_palette(["#f0a070", method_colour(NBO), "#401600"], n_colors=n)


def nbo_error_figure(nbo: pd.DataFrame, z_limit: float | None = None) -> plt.Figure:
    """Top: NBO error :math:`J - J_{NBO}` vs H per a, simulated mean with 95% CI (points) and
    the closed form :math:`r\\sigma^2\\sum_{n<H}(1-a)^{2n}` (dashed). Bottom: the residual
    :math:`z = (\\text{simulated} - \\text{closed form})/\\mathrm{SE}` with the Bonferroni limits
    :math:`\\pm z_{lim}` of claim LQG-1 (default :func:`rsmhp.studies.lqg.summarise.nbo_z_limit`);
    residuals beyond :data:`Z_CLIP` are drawn at the edge as triangles and counted."""
    theme()
    z_limit = nbo_z_limit(len(nbo)) if z_limit is None else float(z_limit)
    fig, (ax, axz) = plt.subplots(
        2, 1, figsize=(7, 6.4), sharex=True, height_ratios=(2.2, 1), layout="constrained"
    )
    a_vals = sorted(nbo["a"].unique())
    shades = dict(zip(a_vals, nbo_shades(len(a_vals)), strict=True))
    offsets = dict(zip(a_vals, np.linspace(-0.25, 0.25, len(a_vals)), strict=True))
    for a, grp in nbo.groupby("a"):
        grp = grp.sort_values("H")
        c = shades[a]
        ax.plot(grp["H"], grp["nbo_error_closed"], color=c, ls=LINESTYLES["derived"], lw=1.1)
        ax.errorbar(
            grp["H"],
            grp["nbo_error_sim"],
            yerr=1.96 * grp["se"],
            fmt="o",
            ms=3.5,
            color=c,
            capsize=2,
            label=f"a = {eps_label(a)}",
        )
        z = grp["z"].to_numpy()
        x = grp["H"].to_numpy() + offsets[a]
        inside = np.abs(z) <= Z_CLIP
        axz.scatter(x[inside], z[inside], color=c, s=12, edgecolor="none")
        if (~inside).any():
            axz.scatter(
                x[~inside],
                np.sign(z[~inside]) * Z_CLIP,
                color=c,
                marker="^",
                s=22,
                edgecolor="k",
                linewidth=0.4,
            )
    ax.plot([], [], color="0.3", ls=LINESTYLES["derived"], label="closed form")
    ax.set_ylabel("NBO error J − J_NBO (cost)")
    ax.set_title(
        r"NBO error: simulated (95% CI) vs closed form $r\sigma^2\,\Sigma_{n<H}(1-a)^{2n}$"
    )
    ax.legend(title=None, fontsize=7, ncols=2, loc="upper left")
    n_clip = int((nbo["z"].abs() > Z_CLIP).sum())
    top = max(z_limit * 1.35, min(float(nbo["z"].abs().max()) * 1.15, Z_CLIP * 1.08))
    for s in (-1, 1):
        axz.axhline(s * z_limit, color=method_colour(EXACT), ls=LINESTYLES["derived"], lw=1.0)
    axz.axhline(0.0, color="0.5", lw=0.8)
    axz.annotate(
        f"Bonferroni limit ±{fmt(z_limit, 3)}",
        (0.01, 0.97),
        xycoords="axes fraction",
        va="top",
        fontsize=7,
    )
    if n_clip:
        axz.annotate(
            f"{n_clip} residuals beyond ±{fmt(Z_CLIP, 1)} drawn at the edge (triangles)",
            (0.99, 0.03),
            xycoords="axes fraction",
            ha="right",
            fontsize=7,
        )
    axz.set(
        ylim=(-top, top),
        xlabel="horizon H",
        ylabel="(sim. − closed) / SE",
        title="Residual in standard errors",
    )
    axz.set_xticks(np.unique(nbo["H"]))
    return fig
