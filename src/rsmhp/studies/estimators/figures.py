r"""Estimator-study figures: RMSE and bias vs n, tree variance, weighted vs uniform, pruning,
CPU frontier.

Every method has the colour of :func:`rsmhp.report.palette.method_colour` (the same in every figure
and recording); likeliness-weighted variants are drawn with ``LINESTYLES["weighted"]`` (dotted),
derived (closed-form) curves and values with ``LINESTYLES["derived"]`` (dashed). Value ranges
are set by the point estimates, not by the confidence bars, so one wide interval cannot squash
a panel; bars that leave the range are cut at the axis and their number is given in the panel title.
Costs have no physical unit ("cost units"); CPU times are per estimate, from this run.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import seaborn as sns

from rsmhp.models.lqg.linear_quadratic import LinearQuadratic
from rsmhp.pipeline.parallel import parallel_map
from rsmhp.report.figures import save_figure, theme
from rsmhp.report.palette import LINESTYLES, method_colour, method_label

__all__ = [
    "FIGURES",
    "bias_figure",
    "frontier_figure",
    "pruning_heatmap",
    "rmse_figure",
    "save_all",
    "style",
    "tree_variance_figure",
    "weighted_vs_uniform_figure",
]

#: stochastic schemes drawn against n, in legend order
SCHEMES = ("mc", "antithetic", "sobol", "tree", "tree_pernode", "pruned")
#: colour of the exact value J (palette's ``exact``)
EXACT = method_colour("exact")


def style(scheme: str, weighting: str = "uniform") -> dict:
    """Matplotlib keywords of a (scheme, weighting) line: the palette colour of ``scheme``,
    a solid line (dotted when likeliness-weighted) and a legend label."""
    weighted = weighting == "weighted"
    return {
        "color": method_colour(scheme),
        "ls": LINESTYLES["weighted" if weighted else "measured"],
        "label": method_label(scheme) + (", weighted" if weighted else ""),
    }


def _facets(
    n: int, ncols: int = 3, size: tuple[float, float] = (4.2, 3.4), layout: str | None = None
):
    """A grid of ``n`` panels; spare panels are hidden (the first spare one holds the legend)."""
    nrows = int(np.ceil(n / ncols))
    fig, axes = plt.subplots(
        nrows, ncols, figsize=(size[0] * ncols, size[1] * nrows), squeeze=False, layout=layout
    )
    for ax in axes.ravel()[n:]:
        ax.set_axis_off()
    return fig, axes.ravel()


def _legend(fig: plt.Figure, axes: np.ndarray, n: int) -> None:
    """One legend for the figure (unique labels over all panels), in the first spare panel if
    there is one, else below the panels."""
    seen: dict[str, object] = {}
    for ax in axes[:n]:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            seen.setdefault(lab, h)
    if not seen:
        return
    if len(axes) > n:
        axes[n].legend(list(seen.values()), list(seen), loc="center", fontsize=8, frameon=False)
    else:
        fig.legend(
            list(seen.values()),
            list(seen),
            loc="upper center",
            bbox_to_anchor=(0.5, 0.0),
            ncols=3,
            fontsize=8,
        )


def _robust_ylim(
    ax: plt.Axes,
    values: Iterable[float],
    lows: Iterable[float] = (),
    highs: Iterable[float] = (),
    log: bool = False,
    include: Iterable[float] = (),
) -> int:
    """Set the y range from the point estimates ``values`` (and reference values ``include``)
    with a small margin; CI ends (``lows``, ``highs``) outside it are cut at the axis. The
    number of cut bars is appended to the panel title (call after setting it) and returned."""
    v = np.asarray([*values, *include], dtype=float)
    v = v[np.isfinite(v) & ((v > 0) if log else True)]
    if v.size == 0:
        return 0
    lo, hi = float(v.min()), float(v.max())
    if log:
        pad = max((hi / lo) ** 0.06, 1.3)
        a, b = lo / pad, hi * pad
    else:
        span = hi - lo or abs(hi) or 1.0
        a, b = lo - 0.08 * span, hi + 0.08 * span
    lows, highs = np.asarray(list(lows), dtype=float), np.asarray(list(highs), dtype=float)
    cut = int(np.sum(lows < a)) + int(np.sum(highs > b))
    ax.set_ylim(a, b)
    if cut:
        ax.set_title(f"{ax.get_title()}; {cut} CI bar{'s' if cut > 1 else ''} cut")
    return cut


def _main_schemes(s: pd.DataFrame) -> pd.DataFrame:
    """Stochastic cells on a common n axis; the pruned tree at its largest N only."""
    keep = s[s["scheme"].isin(SCHEMES) & s["weighting"].isin(["uniform", "weighted"])]
    pr = keep["scheme"] == "pruned"
    max_n = keep[pr].groupby("problem")["N"].transform("max")
    return keep[~pr | (keep["N"] == max_n.reindex(keep.index))]


def _title(s: pd.DataFrame, problem: str) -> str:
    h = s.loc[s["problem"] == problem, "H"]
    return f"{problem} (H = {int(h.iloc[0])})" if len(h) else problem


def _lines(
    ax: plt.Axes,
    sub: pd.DataFrame,
    x: str,
    col: str,
    ci: bool = True,
    order: str | None = None,
) -> tuple[list, list, list]:
    """One line per (scheme, weighting) of ``sub``: ``col`` against ``x``, CI bars from
    ``col_low``/``col_high`` when ``ci``; points joined in ``order`` (default ``x``).
    Returns the plotted values, CI lows and CI highs."""
    vals, lows, highs = [], [], []
    for scheme in SCHEMES:
        for weighting in ("uniform", "weighted"):
            g = sub[(sub["scheme"] == scheme) & (sub["weighting"] == weighting)]
            if g.empty:
                continue
            g = g.sort_values(order or x)
            st = style(scheme, weighting)
            if scheme == "pruned":
                st["label"] += f" (N = {int(g['N'].max())}, n = M)"
            yerr = None
            if ci:
                yerr = [g[col] - g[f"{col}_low"], g[f"{col}_high"] - g[col]]
                lows += list(g[f"{col}_low"])
                highs += list(g[f"{col}_high"])
            ax.errorbar(g[x], g[col], yerr=yerr, marker="o", ms=3, lw=1.2, capsize=2, **st)
            vals += list(g[col])
    return vals, lows, highs


def rmse_figure(s: pd.DataFrame) -> plt.Figure:
    """RMSE (bootstrap 95% CI as bars) against the number of trajectories, one panel per
    problem, one line per estimator (pruned tree: its largest N, n = M)."""
    theme()
    data = _main_schemes(s)
    problems = list(dict.fromkeys(data["problem"]))
    fig, axes = _facets(len(problems))
    for ax, problem in zip(axes, problems, strict=False):
        vals, lows, highs = _lines(ax, data[data["problem"] == problem], "n_trajectories", "rmse")
        ax.set(
            xscale="log",
            yscale="log",
            title=_title(s, problem),
            xlabel="trajectories n (trees: $N^H$ leaves)",
            ylabel="RMSE (cost units)",
        )
        _robust_ylim(ax, vals, lows, highs, log=True)
    _legend(fig, axes, len(problems))
    fig.suptitle(
        "RMSE against the number of trajectories (95% bootstrap CI); cubature and "
        "Gauss-Hermite are exact here and not shown"
    )
    fig.tight_layout()
    return fig


def bias_figure(s: pd.DataFrame) -> plt.Figure:
    """Bias (bootstrap 95% CI) in units of the NBO error, (mean - J)/(J_NBO - J), against n:
    0 is unbiased, 1 the NBO cost; J(Σ/2), the limit of weighted estimators, sits at 0.5
    (J(Σ/2) - J = -tr(KS)/2 and J_NBO - J = -tr(KS))."""
    theme()
    data = _main_schemes(s)
    data = data.assign(bias_fraction=data["bias_fraction_of_nbo"])
    problems = list(dict.fromkeys(data["problem"]))
    fig, axes = _facets(len(problems))
    for ax, problem in zip(axes, problems, strict=False):
        vals, lows, highs = _lines(
            ax, data[data["problem"] == problem], "n_trajectories", "bias_fraction"
        )
        for y, text, colour in (
            (0.0, "J", EXACT),
            (0.5, "J(Σ/2)", EXACT),
            (1.0, "NBO cost", method_colour("nbo")),
        ):
            ax.axhline(y, color=colour, ls=LINESTYLES["derived"], lw=0.9)
            ax.annotate(
                text,
                (1.0, y),
                xycoords=("axes fraction", "data"),
                xytext=(2, 0),
                textcoords="offset points",
                va="center",
                fontsize=7,
                color=colour,
            )
        ax.set(
            xscale="log",
            title=_title(s, problem),
            xlabel="trajectories n (trees: $N^H$ leaves)",
            ylabel="bias / (J_NBO - J)",
        )
        _robust_ylim(ax, vals, lows, highs, include=(0.0, 1.0))
    _legend(fig, axes, len(problems))
    fig.suptitle(
        "Bias in units of the NBO error (95% bootstrap CI): 0 = unbiased, 0.5 = J(Σ/2), "
        "1 = NBO cost (dashed: derived)"
    )
    fig.tight_layout()
    return fig


def tree_variance_figure(s: pd.DataFrame, problems: Mapping[str, LinearQuadratic]) -> plt.Figure:
    """Variance (bootstrap 95% CI) of the uniform shared tree, per-node tree and independent
    sampling against leaves / trajectories, with the derived variances as dashed lines."""
    theme()
    data = s[(s["weighting"] == "uniform") & s["scheme"].isin(["mc", "tree", "tree_pernode"])]
    names = [p for p in problems if p in set(data["problem"])]
    fig, axes = _facets(len(names))
    derived = LINESTYLES["derived"]
    for ax, problem in zip(axes, names, strict=False):
        qf = problems[problem].quadratic_form
        H = problems[problem].H
        sub = data[data["problem"] == problem]
        vals, lows, highs = [], [], []
        for scheme in ("mc", "tree", "tree_pernode"):
            g = sub[sub["scheme"] == scheme].sort_values("n_trajectories")
            if g.empty:
                continue
            ax.errorbar(
                g["n_trajectories"],
                g["var"],
                yerr=[g["var"] - g["var_low"], g["var_high"] - g["var"]],
                fmt="o",
                ms=3,
                capsize=2,
                color=method_colour(scheme),
                label=f"{method_label(scheme)}: measured",
            )
            vals += list(g["var"])
            lows += list(g["var_low"])
            highs += list(g["var_high"])
        n = np.geomspace(sub["n_trajectories"].min(), sub["n_trajectories"].max(), 50)
        ax.plot(
            n,
            qf.variance() / n,
            color=method_colour("mc"),
            ls=derived,
            lw=1,
            label=f"{method_label('mc')}: derived Var(g)/n",
        )
        Ns = np.unique(np.round(n ** (1 / H)).astype(int))
        Ns = Ns[Ns >= 2]
        for scheme, var in (("tree", qf.tree_variance), ("tree_pernode", qf.pernode_tree_variance)):
            ax.plot(
                Ns**H,
                [var(int(N)) for N in Ns],
                color=method_colour(scheme),
                ls=derived,
                lw=1,
                label=f"{method_label(scheme)}: derived",
            )
        ax.set(
            xscale="log",
            yscale="log",
            title=f"{problem} (H = {H})",
            xlabel="leaves $N^H$ (trees) or trajectories n (MC)",
            ylabel="variance of the estimate (cost units²)",
        )
        _robust_ylim(ax, vals, lows, highs, log=True)
    _legend(fig, axes, len(names))
    fig.suptitle(
        "Variance at equal leaf counts: shared draws (tree) vs fresh draws per node vs "
        "independent trajectories (95% bootstrap CI; dashed: derived)"
    )
    fig.tight_layout()
    return fig


def weighted_vs_uniform_figure(s: pd.DataFrame) -> plt.Figure:
    """Mean estimate (95% CI) against n of uniform and likeliness-weighted (dotted) averages
    (MC, shared tree, per-node tree), with the exact J and the derived large-N limit of the
    weighted averages, J(Σ/2), as dashed horizontal lines. The NBO cost (far below) is left
    out so the panels resolve J and J(Σ/2)."""
    theme()
    keep = s["scheme"].isin(["mc", "tree", "tree_pernode"])
    data = s[keep & s["weighting"].isin(["uniform", "weighted"])]
    data = data.assign(mean_low=data["J_exact"] + data["bias_low"])
    data = data.assign(mean_high=data["J_exact"] + data["bias_high"])
    problems = list(dict.fromkeys(data["problem"]))
    fig, axes = _facets(len(problems))
    for ax, problem in zip(axes, problems, strict=False):
        sub = data[data["problem"] == problem]
        vals, lows, highs = _lines(ax, sub, "n_trajectories", "mean")
        j = float(sub["J_exact"].iloc[0])
        lim = sub.loc[sub["weighting"] == "weighted", "limit"]
        refs = [(j, "J")] + ([(float(lim.iloc[0]), "J(Σ/2)")] if len(lim) else [])
        for y, text in refs:
            ax.axhline(y, color=EXACT, ls=LINESTYLES["derived"], lw=0.9)
            ax.annotate(
                text,
                (1.0, y),
                xycoords=("axes fraction", "data"),
                xytext=(2, 0),
                textcoords="offset points",
                va="center",
                fontsize=7,
            )
        ax.set(
            xscale="log",
            title=_title(s, problem),
            xlabel="trajectories n (trees: $N^H$ leaves)",
            ylabel="mean estimate (cost units)",
        )
        _robust_ylim(ax, vals, lows, highs, include=[y for y, _ in refs])
    _legend(fig, axes, len(problems))
    fig.suptitle(
        "Uniform averages sit on J; likeliness-weighted ones (dotted) lie below J and approach "
        "J(Σ/2) as n grows (95% bootstrap CI; dashed: derived)"
    )
    fig.tight_layout()
    return fig


def pruning_heatmap(s: pd.DataFrame) -> plt.Figure:
    """Pruned tree (uniform): bias / (J_NBO - J) over (N, M), one heat map per problem, one
    colour bar; the colour scale is clipped to [0, 1] (the annotations give the values)."""
    theme()
    data = s[(s["scheme"] == "pruned") & (s["weighting"] == "uniform")]
    problems = list(dict.fromkeys(data["problem"]))
    fig, axes = _facets(len(problems), size=(4.4, 3.4), layout="constrained")
    above = int((data["bias_fraction_of_nbo"] > 1).sum())
    below = int((data["bias_fraction_of_nbo"] < 0).sum())
    mappable = None
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
            cbar=False,
        )
        mappable = ax.collections[0]
        ax.grid(False)
        ax.invert_yaxis()
        ax.set(
            title=_title(s, problem),
            xlabel="draws per level N",
            ylabel="trajectories kept M",
        )
    if mappable is not None:
        fig.colorbar(
            mappable,
            ax=list(axes[: len(problems)]),
            shrink=0.8,
            label="bias / (J_NBO - J): 0 = J, 1 = NBO cost",
        )
    clipped = (
        f"\ncolour scale clipped to [0, 1]: {above} cell(s) above 1 and {below} below 0 drawn "
        "at the limit (annotations give the values)"
        if above or below
        else ""
    )
    fig.suptitle(
        "Pruned tree (uniform weights): bias as a fraction of the NBO error; blank: M > N, "
        f"not run{clipped}"
    )
    return fig


def frontier_figure(s: pd.DataFrame) -> plt.Figure:
    """RMSE against median CPU milliseconds per estimate (log-log), every stochastic scheme,
    points joined in order of n. CPU times are this run's measurements and vary per run."""
    theme()
    data = _main_schemes(s).assign(cpu_ms=lambda d: d["cpu_median"] * 1e3)
    problems = list(dict.fromkeys(data["problem"]))
    fig, axes = _facets(len(problems))
    for ax, problem in zip(axes, problems, strict=False):
        sub = data[data["problem"] == problem]
        vals, _, _ = _lines(ax, sub, "cpu_ms", "rmse", ci=False, order="n_trajectories")
        ax.set(
            xscale="log",
            yscale="log",
            title=_title(s, problem),
            xlabel="median CPU time per estimate (ms, this run)",
            ylabel="RMSE (cost units)",
        )
        _robust_ylim(ax, vals, log=True)
    _legend(fig, axes, len(problems))
    fig.suptitle(
        "RMSE against CPU time (points joined in order of n; timings vary between runs; "
        "exact quadrature not shown)"
    )
    fig.tight_layout()
    return fig


# file stem -> figure function of (summary, problems)
FIGURES = {
    "estimators_rmse_vs_n": lambda s, p: rmse_figure(s),
    "estimators_bias_vs_n": lambda s, p: bias_figure(s),
    "estimators_tree_variance": tree_variance_figure,
    "estimators_weighted_vs_uniform": lambda s, p: weighted_vs_uniform_figure(s),
    "estimators_pruning_heatmap": lambda s, p: pruning_heatmap(s),
    "estimators_frontier": lambda s, p: frontier_figure(s),
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
