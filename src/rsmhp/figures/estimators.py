"""Estimator-study figures: RMSE vs n, tree variance, weighted vs uniform, pruning, frontier."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import seaborn as sns

from rsmhp.figures import save_figure, theme
from rsmhp.linear_quadratic import LinearQuadratic
from rsmhp.parallel import parallel_map

__all__ = [
    "bias_figure",
    "frontier_figure",
    "pruning_heatmap",
    "rmse_figure",
    "save_all",
    "tree_variance_figure",
    "weighted_vs_uniform_figure",
]


def _label(s: pd.DataFrame) -> pd.Series:
    return s["scheme"] + np.where(s["weighting"] == "weighted", " (weighted)", "")


def _main_schemes(s: pd.DataFrame) -> pd.DataFrame:
    """Stochastic cells on a common n axis; the pruned tree at its largest N only."""
    keep = s[s["scheme"].isin(["mc", "antithetic", "sobol", "tree", "tree_pernode", "pruned"])]
    pr = keep["scheme"] == "pruned"
    max_n = keep[pr].groupby("problem")["N"].transform("max")
    keep = keep[~pr | (keep["N"] == max_n.reindex(keep.index))]
    return keep.assign(label=_label(keep))


def _facets(n: int, ncols: int = 3, size: tuple[float, float] = (4.2, 3.4)):
    nrows = int(np.ceil(n / ncols))
    fig, axes = plt.subplots(
        nrows, ncols, figsize=(size[0] * ncols, size[1] * nrows), squeeze=False
    )
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    return fig, axes.ravel()


def rmse_figure(s: pd.DataFrame) -> plt.Figure:
    """RMSE (bootstrap 95% CI as bars) vs number of trajectories, per problem and scheme."""
    title = "RMSE of every estimator against the number of trajectories (pruned: largest N)"
    return _metric_figure(s, "n_trajectories", "rmse", "RMSE", log_y=True, title=title)


def bias_figure(s: pd.DataFrame) -> plt.Figure:
    """Bias (bootstrap 95% CI) relative to the NBO error, vs number of trajectories: 0 is
    unbiased, 1 means the estimator returns the NBO cost."""
    scaled = s.assign(
        rel_bias=s["bias_fraction_of_nbo"],
        rel_bias_low=s["bias_fraction_low"],
        rel_bias_high=s["bias_fraction_high"],
    )
    title = "Bias of every estimator, in units of the NBO error (pruned: largest N)"
    ylabel = "bias / (J_NBO - J)"
    return _metric_figure(scaled, "n_trajectories", "rel_bias", ylabel, log_y=False, title=title)


def _metric_figure(
    s: pd.DataFrame, x: str, col: str, ylabel: str, log_y: bool, title: str, ci: bool = True
) -> plt.Figure:
    """One panel per problem, one line per scheme: ``col`` against ``x`` (log axis), with the
    ``col_low``/``col_high`` CI as error bars when ``ci``."""
    theme()
    data = _main_schemes(s)
    problems = list(dict.fromkeys(data["problem"]))
    labels = sorted(data["label"].unique())
    palette = dict(zip(labels, sns.color_palette("colorblind", len(labels)), strict=True))
    fig, axes = _facets(len(problems))
    for ax, problem in zip(axes, problems, strict=False):
        sub = data[data["problem"] == problem]
        for label, g in sub.groupby("label"):
            g = g.sort_values(x)
            yerr = [g[col] - g[f"{col}_low"], g[f"{col}_high"] - g[col]] if ci else None
            ax.errorbar(
                g[x],
                g[col],
                yerr=yerr,
                marker="o",
                ms=3,
                lw=1.2,
                capsize=2,
                color=palette[label],
                label=label,
            )
        xlabel = "trajectories n" if x == "n_trajectories" else "CPU seconds per estimate"
        ax.set(xscale="log", title=problem, xlabel=xlabel, ylabel=ylabel)
        if log_y:
            ax.set_yscale("log")
        else:
            ax.axhline(0.0, color="k", lw=0.8)
    handles, names = axes[0].get_legend_handles_labels()
    fig.legend(handles, names, loc="lower right", fontsize=8, ncols=2)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def tree_variance_figure(s: pd.DataFrame, problems: Mapping[str, LinearQuadratic]) -> plt.Figure:
    """Variance of the uniform shared tree, per-node tree and independent sampling vs leaves,
    with the derived variances as lines."""
    theme()
    data = s[(s["weighting"] == "uniform") & s["scheme"].isin(["mc", "tree", "tree_pernode"])]
    names = [p for p in problems if p in set(data["problem"])]
    fig, axes = _facets(len(names))
    colors = dict(
        zip(["mc", "tree", "tree_pernode"], sns.color_palette("colorblind", 3), strict=True)
    )
    for ax, problem in zip(axes, names, strict=False):
        qf = problems[problem].quadratic_form
        sub = data[data["problem"] == problem]
        for scheme, g in sub.groupby("scheme"):
            g = g.sort_values("n_trajectories")
            ax.errorbar(
                g["n_trajectories"],
                g["var"],
                yerr=[g["var"] - g["var_low"], g["var_high"] - g["var"]],
                fmt="o",
                ms=3,
                capsize=2,
                color=colors[scheme],
                label=f"{scheme} (measured)",
            )
        n = np.geomspace(sub["n_trajectories"].min(), sub["n_trajectories"].max(), 50)
        ax.plot(n, qf.variance() / n, color=colors["mc"], lw=1, label="mc: Var(g)/n")
        H = problems[problem].H
        Ns = np.unique(np.round(n ** (1 / H)).astype(int))
        Ns = Ns[Ns >= 2]
        ax.plot(
            Ns**H,
            [qf.tree_variance(int(N)) for N in Ns],
            color=colors["tree"],
            lw=1,
            label="tree: derived",
        )
        ax.plot(
            Ns**H,
            [qf.pernode_tree_variance(int(N)) for N in Ns],
            color=colors["tree_pernode"],
            lw=1,
            ls="--",
            label="per-node tree: derived",
        )
        ax.set(
            xscale="log",
            yscale="log",
            title=f"{problem} (H={H})",
            xlabel="leaves / trajectories",
            ylabel="variance of the estimate",
        )
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower right", fontsize=8)
    fig.suptitle("Shared draws cost variance: tree vs independent sampling at equal leaf counts")
    fig.tight_layout()
    return fig


def weighted_vs_uniform_figure(s: pd.DataFrame) -> plt.Figure:
    """Mean estimate (95% CI) vs n for uniform and weighted averages (mc and shared tree), with
    J, the derived weighted limit J(Σ/2) and the NBO cost as horizontal lines."""
    theme()
    data = s[s["scheme"].isin(["mc", "tree"]) & s["weighting"].isin(["uniform", "weighted"])]
    data = data.assign(label=_label(data))
    problems = list(dict.fromkeys(data["problem"]))
    fig, axes = _facets(len(problems))
    labels = sorted(data["label"].unique())
    palette = dict(zip(labels, sns.color_palette("colorblind", len(labels)), strict=True))
    for ax, problem in zip(axes, problems, strict=False):
        sub = data[data["problem"] == problem]
        for label, g in sub.groupby("label"):
            g = g.sort_values("n_trajectories")
            lo, hi = g["J_exact"] + g["bias_low"], g["J_exact"] + g["bias_high"]
            ax.errorbar(
                g["n_trajectories"],
                g["mean"],
                yerr=[g["mean"] - lo, hi - g["mean"]],
                marker="o",
                ms=3,
                capsize=2,
                color=palette[label],
                label=label,
            )
        first = sub.iloc[0]
        w_lim = sub.loc[sub["weighting"] == "weighted", "limit"].iloc[0]
        ax.axhline(first["J_exact"], color="k", ls="--", lw=1, label="exact J")
        ax.axhline(w_lim, color="C4", ls=":", lw=1.2, label="derived weighted limit J(Σ/2)")
        ax.axhline(first["J_nbo"], color="C3", ls="-.", lw=1, label="NBO")
        ax.set(xscale="log", title=problem, xlabel="trajectories n", ylabel="mean estimate")
    handles, names = axes[0].get_legend_handles_labels()
    fig.legend(handles, names, loc="lower right", fontsize=8)
    fig.suptitle("Likeliness weighting converges to J(Σ/2), not J")
    fig.tight_layout()
    return fig


def pruning_heatmap(s: pd.DataFrame) -> plt.Figure:
    """Pruned tree (uniform): bias / (J_NBO - J) over (N, M), one heat map per problem."""
    theme()
    data = s[(s["scheme"] == "pruned") & (s["weighting"] == "uniform")]
    problems = list(dict.fromkeys(data["problem"]))
    fig, axes = _facets(len(problems), size=(4.4, 3.4))
    for ax, problem in zip(axes, problems, strict=False):
        grid = data[data["problem"] == problem].pivot(
            index="M", columns="N", values="bias_fraction_of_nbo"
        )
        sns.heatmap(
            grid,
            ax=ax,
            vmin=0,
            vmax=1,
            cmap="rocket_r",
            annot=True,
            fmt=".2f",
            annot_kws={"fontsize": 7},
            cbar=ax is axes[0],
        )
        ax.invert_yaxis()
        ax.set_title(problem)
    fig.suptitle("Pruned tree: bias as a fraction of the NBO error (1 = the NBO cost)")
    fig.tight_layout()
    return fig


def frontier_figure(s: pd.DataFrame) -> plt.Figure:
    """RMSE vs median CPU seconds per estimate (log-log), every stochastic scheme."""
    title = "Error vs CPU time (quadrature rules are exact here and not shown)"
    return _metric_figure(s, "cpu_median", "rmse", "RMSE", log_y=True, title=title, ci=False)


# file stem -> figure function of (summary, problems)
FIGURES = {
    "est_rmse_vs_n": lambda s, p: rmse_figure(s),
    "est_bias_vs_n": lambda s, p: bias_figure(s),
    "est_tree_variance": tree_variance_figure,
    "est_weighted_vs_uniform": lambda s, p: weighted_vs_uniform_figure(s),
    "est_pruning_heatmap": lambda s, p: pruning_heatmap(s),
    "est_frontier": lambda s, p: frontier_figure(s),
}


def _draw_and_save(job: tuple) -> list[Path]:
    name, summary, problems, outdir = job
    return save_figure(FIGURES[name](summary, problems), Path(outdir) / name)


def save_all(
    summary: pd.DataFrame,
    problems: Mapping[str, LinearQuadratic],
    outdir: str | Path,
    n_jobs: int = 1,
) -> list[Path]:
    """Draw and save every figure of :data:`FIGURES` (PNG + PDF) in ``outdir``, one process
    per figure on ``n_jobs`` workers (drawing and rasterising dominate; files do not depend
    on ``n_jobs``)."""
    jobs = [(name, summary, problems, str(outdir)) for name in FIGURES]
    saved = parallel_map(_draw_and_save, jobs, n_jobs, desc="figures")
    return [path for paths in saved for path in paths]
