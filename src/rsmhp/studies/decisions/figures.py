r"""Decision-study figures: LQG regret against sample size, UAV open-loop regret per belief
state, and the sensitivity map of the closed-loop difference RS-MHP − NBO.

Colours and labels come from :mod:`rsmhp.report.palette` (one colour per method in every figure);
measured curves are solid, closed forms dashed and likeliness-weighted variants dotted
(:data:`rsmhp.report.palette.LINESTYLES`). Where a value is drawn outside its true position (the
UAV regret floor on a log scale) the figure says how many.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.lines import Line2D

from rsmhp.core.seeding import job_rng
from rsmhp.models.lqg.regret_summary import ZERO_REGRET
from rsmhp.report.figures import theme
from rsmhp.report.markdown import fmt
from rsmhp.report.palette import LINESTYLES, method_colour, method_label
from rsmhp.studies.decisions.summarise_uav import (
    REGRET_FLOOR_PCT,
    REGRET_FLOOR_TEXT,
    axis_label,
    axis_value,
)

__all__ = ["lqg_regret_figure", "uav_map_figure", "uav_regret_figure"]

_MARKERS = {"mc": "o", "sobol": "s", "tree": "^", "pruned": "D"}


def _lqg_label(method: str, weighting: str, pruned_n: int | None = None) -> str:
    name = method_label(method)
    if method == "pruned" and pruned_n is not None:
        name = f"pruned tree N={pruned_n} (x = M)"
    if method == "tree":
        name += " (x = N^H)"
    return name if weighting == "uniform" else f"{name}, likeliness-weighted"


def lqg_regret_figure(summary: pd.DataFrame) -> plt.Figure:
    r"""Mean regret :math:`J(\hat u) - J(u^*)` (log) against P, the number of trajectories an
    estimate averages (log; tree: :math:`N^H` leaves, pruned tree: M), one panel per (a, H)
    (rows a, columns H), one line per method (palette colour; solid uniform, dotted
    likeliness-weighted) with 95% t-interval bars; dashed lines are the closed forms of
    uniform mc (:math:`\kappa v_H / P`) and the shared-draw tree (:math:`\kappa v_H / N`).
    Methods with zero regret (nbo, antithetic, cubature) are left out (log scale); nothing
    else is clipped."""
    theme()
    s = summary[(summary["mean"] > 0) & ~summary["method"].isin(ZERO_REGRET)]
    if not np.isfinite(s["mean"]).all():
        raise ValueError("regret summary holds non-finite means")
    a_values = sorted(s["a"].unique())
    h_values = sorted(s["H"].unique())
    pruned = summary.loc[summary["method"] == "pruned", "N"]
    pruned_n = int(pruned.iloc[0]) if not pruned.empty else None
    fig, axes = plt.subplots(
        len(a_values),
        len(h_values),
        figsize=(3.6 * len(h_values) + 2.6, 2.9 * len(a_values) + 0.8),
        squeeze=False,
        sharex=True,
    )
    series = list(dict.fromkeys(zip(s["method"], s["weighting"], strict=True)))
    series.sort(
        key=lambda mw: (
            list(_MARKERS).index(mw[0]) if mw[0] in _MARKERS else len(_MARKERS),
            mw[1] != "uniform",
        )
    )
    for i, a in enumerate(a_values):
        for j, H in enumerate(h_values):
            ax = axes[i, j]
            cell = s[(s["a"] == a) & (s["H"] == H)]
            for method, weighting in series:
                c = cell[(cell["method"] == method) & (cell["weighting"] == weighting)]
                c = c.sort_values("P")
                if c.empty:
                    continue
                colour = method_colour(method)
                style = LINESTYLES["measured" if weighting == "uniform" else "weighted"]
                lo = np.clip(c["mean"] - c["ci_low"], 0, None)
                hi = np.clip(c["ci_high"] - c["mean"], 0, None)
                bars = ax.errorbar(
                    c["P"],
                    c["mean"],
                    yerr=[lo, hi],
                    color=colour,
                    ls=style,
                    marker=_MARKERS.get(method, "o"),
                    ms=3.5,
                    lw=1.2,
                    elinewidth=0.8,
                    label=_lqg_label(method, weighting, pruned_n),
                )
                bars.lines[0].set_gid(f"{method}/{weighting}")
                if weighting == "uniform" and method in ("mc", "tree"):
                    exact = c[c["closed_kind"] == "exact"]
                    # wide and pale behind the measured line, which it matches closely
                    ax.plot(
                        exact["P"],
                        exact["closed_form"],
                        color=colour,
                        ls=LINESTYLES["derived"],
                        lw=3.0,
                        alpha=0.45,
                        zorder=1,
                        label=f"closed form, {method_label(method)}",
                        gid=f"{method}/closed form",
                    )
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_title(f"a = {a:g}, H = {int(H)}")
            if i == len(a_values) - 1:
                ax.set_xlabel("P, trajectories averaged (count)")
            if j == 0:
                ax.set_ylabel("mean regret (cost units)")
    handles = [
        Line2D(
            [],
            [],
            color=method_colour(m),
            ls=LINESTYLES["measured" if w == "uniform" else "weighted"],
            marker=_MARKERS.get(m, "o"),
            label=_lqg_label(m, w, pruned_n),
        )
        for m, w in series
    ]
    handles += [
        Line2D(
            [],
            [],
            color=method_colour(m),
            ls=LINESTYLES["derived"],
            lw=3.0,
            alpha=0.45,
            label=f"closed form, {t}",
        )
        for m, t in (("mc", "MC: κ v_H / P"), ("tree", "tree: κ v_H / N"))
        if (m, "uniform") in series
    ]
    fig.legend(handles=handles, loc="center left", bbox_to_anchor=(1.0, 0.5), frameon=False)
    fig.suptitle(
        "LQG decision quality: mean regret J(û) − J(u*) of each method's sample-average argmin "
        "(bars: 95% CI)\nNBO, antithetic and cubature have regret 0 up to rounding (not drawn "
        "on the log scale); nothing clipped"
    )
    fig.tight_layout()
    return fig


def _jitter(n: int, key: str) -> np.ndarray:
    """Deterministic horizontal jitter in [-0.25, 0.25] for ``n`` points."""
    return job_rng(0, "figure", figure="decisions_uav_regret", key=key).uniform(-0.25, 0.25, n)


def uav_regret_figure(regret: pd.DataFrame) -> plt.Figure:
    """Relative regret (percent of the best plan's cost, log scale) of every method's plan at
    every belief state, one column per model variant; top row against the best plan found
    (methods and multi-start), bottom row against the best of the methods' plans only (the
    part due to the cost approximation). Points in the method's palette colour, a grey box
    per method (quartiles, whiskers 1.5 IQR); values below
    :data:`rsmhp.studies.decisions.summarise_uav.REGRET_FLOOR_PCT` percent
    (zero included) are drawn at it and counted in each panel."""
    theme()
    floor = REGRET_FLOOR_PCT
    df = regret.assign(
        total=100 * regret["regret_rel"],
        approx=100 * regret["regret_methods"] / regret["best_cost"],
    )
    methods = list(dict.fromkeys(df["method"]))
    models = list(dict.fromkeys(df["model"]))
    fig, axes = plt.subplots(
        2, len(models), figsize=(5.6 * len(models), 8.0), squeeze=False, sharex=True
    )
    for j, model in enumerate(models):
        sub = df[df["model"] == model]
        n_states = sub[["run", "step"]].drop_duplicates().shape[0]
        for i, (col, what) in enumerate(
            (("total", "vs best plan found"), ("approx", "vs best method's plan"))
        ):
            ax = axes[i, j]
            data = [sub.loc[sub["method"] == m, col].to_numpy(float) for m in methods]
            shown = [np.clip(x, floor, None) for x in data]
            ax.boxplot(
                shown,
                positions=range(len(methods)),
                widths=0.6,
                showfliers=False,
                patch_artist=True,
                boxprops={"facecolor": "0.92", "edgecolor": "0.5"},
                medianprops={"color": "0.2"},
                whiskerprops={"color": "0.5"},
                capprops={"color": "0.5"},
            )
            for k, (m, y) in enumerate(zip(methods, shown, strict=True)):
                ax.scatter(
                    k + _jitter(y.size, f"{model}/{col}/{m}"),
                    y,
                    s=6,
                    alpha=0.6,
                    color=method_colour(m),
                    label=method_label(m),
                    gid=m,
                    zorder=3,
                )
            n_floor = int(sum((x < floor).sum() for x in data))
            n_all = int(sum(x.size for x in data))
            ax.set_yscale("log")
            ax.set_title(
                f"'{model}' ({n_states} belief states): {what}\n{n_floor} of {n_all} values "
                f"< {REGRET_FLOOR_TEXT} (zeros included) drawn at {REGRET_FLOOR_TEXT}",
                fontsize=10,
            )
            ax.set_ylabel("relative regret (% of best plan's cost)")
            ax.set_xticks(
                range(len(methods)),
                [method_label(m) for m in methods],
                rotation=30,
                ha="right",
                rotation_mode="anchor",
            )
            ax.set_xlabel("")
    fig.suptitle(
        "UAV open loop: relative regret of each method's plan, scored on independent "
        "hypotheses (log scale; values below the floor drawn at it)"
    )
    fig.tight_layout()
    return fig


#: panels per row of the map figure (more comparisons wrap to further rows)
MAP_PANELS_PER_ROW = 3


def uav_map_figure(map_df: pd.DataFrame) -> plt.Figure:
    """Heat map per comparison (method − NBO; at most :data:`MAP_PANELS_PER_ROW` panels per
    row): mean paired difference of the closed-loop average location error (m) per cell,
    diverging colours centred at 0 over the symmetric range ±max |difference| (nothing
    clipped), '*' where the 95% bootstrap CI excludes 0, track-loss rates (NBO / method)
    under each value; a null footprint radius is labelled "unlimited"."""
    theme()
    comps = list(dict.fromkeys(map_df["comparison"]))
    row_key, col_key = map_df["row_key"].iloc[0], map_df["col_key"].iloc[0]
    rows = list(dict.fromkeys(axis_value(row_key, v) for v in map_df["row_value"]))
    cols = list(dict.fromkeys(axis_value(col_key, v) for v in map_df["col_value"]))
    lim = float(np.abs(map_df["mean_diff"]).max()) or 1.0
    n_c = min(MAP_PANELS_PER_ROW, len(comps))
    n_r = -(-len(comps) // n_c)
    fig, axes = plt.subplots(
        n_r,
        n_c,
        figsize=(1.3 * len(cols) * n_c + 3.2, (1.0 * len(rows) + 1.6) * n_r + 0.8),
        squeeze=False,
        layout="constrained",
    )
    for ax in axes.ravel()[len(comps) :]:
        ax.set_visible(False)
    image = None
    for ax, comp in zip(axes.ravel(), comps, strict=False):
        sub = map_df[map_df["comparison"] == comp]
        grid = np.full((len(rows), len(cols)), np.nan)
        for _, r in sub.iterrows():
            y = rows.index(axis_value(row_key, r["row_value"]))
            x = cols.index(axis_value(col_key, r["col_value"]))
            grid[y, x] = r["mean_diff"]
            sig = r["ci_high"] < 0 or r["ci_low"] > 0
            loss = "/".join(fmt(round(float(100 * r[k]))) for k in ("loss_nbo", "loss_method"))
            ax.text(
                x,
                y,
                f"{fmt(r['mean_diff'], 3, signed=True)}{'*' if sig else ''}\nloss {loss}%",
                ha="center",
                va="center",
                fontsize=8,
                color="white" if abs(r["mean_diff"]) > 0.6 * lim else "black",
            )
        image = ax.imshow(grid, cmap="RdBu_r", vmin=-lim, vmax=lim, aspect="auto")
        ax.set_xticks(range(len(cols)), cols)
        ax.set_yticks(range(len(rows)), rows)
        ax.grid(False)
        ax.set_title(" − ".join(method_label(m) for m in comp.split(" − ")))
        ax.set_xlabel(axis_label(col_key))
        ax.set_ylabel(axis_label(row_key))
    cbar = fig.colorbar(image, ax=axes.ravel().tolist(), shrink=0.9 / n_r**0.5)
    cbar.set_label("mean paired difference of average\nlocation error, method − NBO (m)")
    fig.suptitle(
        "Sensitivity map, closed loop (blue: the method better; *: 95% CI excludes 0; "
        "loss: track-loss rate NBO/method)\ncolour scale ±max |difference| "
        f"= ±{fmt(lim, 3)} m, nothing clipped",
        fontsize=11,
    )
    return fig
