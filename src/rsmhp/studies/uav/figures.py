r"""UAV figures: the paper's Figs. 4 and 5 drawn its way (empirical CDFs of the per-run average
target location error :math:`e_r`, one curve per method) and, next to each, our paired view
(per-run differences :math:`d_r = e_r(A) - e_r(B)` and their mean :math:`\bar d` with its 95%
bootstrap CI).

Colours and labels come from :mod:`rsmhp.report.palette` (one colour per method in every figure and
recording). x-ranges come from :func:`rsmhp.studies.uav.summarise.robust_range`; what lies outside
is counted in the figure and in the section's caption (the same functions compute both).
"""

from __future__ import annotations

from collections.abc import Mapping

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from rsmhp.core.seeding import job_rng
from rsmhp.report.figures import theme
from rsmhp.report.palette import LINESTYLES, method_colour, method_label
from rsmhp.studies.uav.claims import key_comparisons
from rsmhp.studies.uav.summarise import (
    cdf_methods,
    cdf_range,
    paired_range,
    paired_view,
    per_run_differences,
)

__all__ = [
    "error_cdf_figure",
    "error_cdf_nbo_figure",
    "error_cdf_nt_figure",
    "paired_diff_figure",
    "paired_diff_nt_figure",
    "paired_figure",
]


def _note(ax: plt.Axes, text: str) -> None:
    """Write the clipping note (what the x-range leaves out) in the lower right of ``ax``."""
    if text:
        ax.text(
            0.99,
            0.02,
            text,
            transform=ax.transAxes,
            ha="right",
            va="bottom",
            fontsize=7.5,
            color="0.2",
            bbox={"fc": "white", "ec": "0.75", "alpha": 0.95, "pad": 2},
        )


def error_cdf_figure(runs: pd.DataFrame, methods: list[str], title: str) -> plt.Figure:
    r"""Empirical CDF :math:`\hat F(x) = \#\{r: e_r \le x\} / R` of ``mean_error`` for each of
    ``methods`` (colour :func:`method_colour`, label :func:`method_label`); the x-range is
    :func:`rsmhp.studies.uav.summarise.cdf_range`, whose note says which runs it leaves out."""
    theme()
    lo, hi, note = cdf_range(runs, methods)
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for m in methods:
        err = runs.loc[runs["method"] == m, "mean_error"].to_numpy()
        ax.ecdf(
            err,
            color=method_colour(m),
            ls=LINESTYLES["measured"],
            lw=1.8,
            label=f"{method_label(m)} ({err.size} runs)",
        )
    ax.set_xlim(lo, hi)
    ax.set_ylim(0.0, 1.02)
    ax.set_xlabel("average target location error per run, $e_r$ (m)")
    ax.set_ylabel("cumulative fraction of runs")
    ax.set_title(title)
    ax.legend(loc="upper left", fontsize=8)
    _note(ax, note)
    return fig


def error_cdf_nt_figure(runs: pd.DataFrame, summary: pd.DataFrame) -> plt.Figure:
    """Paper Fig. 4 drawn its way: CDF of ``mean_error`` for RS-MHP at each N_T."""
    return error_cdf_figure(
        runs,
        cdf_methods(summary)["nt"],
        "Paper Fig. 4 counterpart: RS-MHP for each $N_T$",
    )


def error_cdf_nbo_figure(runs: pd.DataFrame, summary: pd.DataFrame) -> plt.Figure:
    """Paper Fig. 5 drawn its way: CDF of ``mean_error``, NBO vs RS-MHP with the largest N_T."""
    return error_cdf_figure(
        runs, cdf_methods(summary)["nbo"], "Paper Fig. 5 counterpart: NBO vs RS-MHP"
    )


def paired_figure(
    runs: pd.DataFrame,
    rows: pd.DataFrame,
    title: str,
    keys: Mapping[tuple[str, str], str],
    jitter_id: str,
) -> plt.Figure:
    r"""Two panels sharing one row per comparison A − B of ``rows`` (a paired view):

    * left: the per-run :math:`d_r` as points jittered vertically (uniform ±0.25, from
      ``job_rng(0, "figure_jitter", figure=jitter_id)``) in A's colour, the median as a black
      bar, x-range :func:`rsmhp.studies.uav.summarise.paired_range` with its note of what is not
      shown;
    * right: :math:`\bar d` with its 95% bootstrap CI (``ci_low``, ``ci_high``), zoomed to the
      CIs and 0.

    ``keys`` maps (A, B) to the id of the claim whose key number that row is (shown in the
    row's label)."""
    theme()
    rows = rows.reset_index(drop=True)
    n = len(rows)
    lo, hi, note = paired_range(runs, rows)
    diffs = per_run_differences(runs, rows)
    fig, (ax, bx) = plt.subplots(
        1,
        2,
        figsize=(9.5, 1.7 + 0.55 * n),
        sharey=True,
        gridspec_kw={"width_ratios": [1.6, 1.0], "wspace": 0.06},
    )
    rng = job_rng(0, "figure_jitter", figure=jitter_id)
    labels = []
    for i, r in rows.iterrows():
        colour = method_colour(r["method"])
        d = diffs[r["comparison"]]
        ax.scatter(d, i + rng.uniform(-0.25, 0.25, d.size), s=10, color=colour, alpha=0.5, lw=0)
        ax.plot([np.median(d)] * 2, [i - 0.33, i + 0.33], color="k", lw=1.4)
        bx.errorbar(
            r["mean_diff"],
            i,
            xerr=[[r["mean_diff"] - r["ci_low"]], [r["ci_high"] - r["mean_diff"]]],
            fmt="D",
            color=colour,
            mec="k",
            elinewidth=2.2,
            capsize=4,
            ms=6,
        )
        key = keys.get((r["method"], r["baseline"]))
        labels.append(f"{r['comparison']}" + (f"\n(key number of {key})" if key else ""))
    for a in (ax, bx):
        a.axvline(0.0, color="0.3", ls="--", lw=1)
    ax.set_yticks(range(n), labels, fontsize=8)
    # a blank band at the bottom holds the note of what the x-range leaves out
    ax.set_ylim(n - 0.5 + (0.55 if note else 0.0), -0.5)
    ax.set_xlim(lo, hi)
    ax.set_xlabel("per-run difference $d_r$ (m; < 0: A better)")
    ax.set_title("every run (black bar: median)", fontsize=9)
    _note(ax, note)
    ends = np.concatenate([rows["ci_low"], rows["ci_high"], [0.0]])
    span = float(ends.max() - ends.min()) or 1.0
    bx.set_xlim(ends.min() - 0.15 * span, ends.max() + 0.15 * span)
    bx.set_xlabel(r"mean $\bar d$ and 95% bootstrap CI (m)")
    bx.set_title("mean (zoomed x-axis)", fontsize=9)
    n_runs = int(rows["n_runs"].max()) if n else 0
    fig.suptitle(f"{title}: $d_r = e_r(A) - e_r(B)$, {n_runs} paired runs", fontsize=11)
    return fig


def _keys(summary: pd.DataFrame, paired: pd.DataFrame) -> dict[tuple[str, str], str]:
    return {ab: cid for cid, ab in key_comparisons(summary, paired).items()}


def paired_diff_nt_figure(
    runs: pd.DataFrame, summary: pd.DataFrame, paired: pd.DataFrame
) -> plt.Figure:
    """Paired view of Fig. 4: N_T trend pairs (UAV-1) and RS-MHP (N_T = M) − pruned tree
    (UAV-3)."""
    return paired_figure(
        runs,
        paired_view(paired, "nt"),
        "Paired view of Fig. 4",
        _keys(summary, paired),
        "uav_paired_diff_nt",
    )


def paired_diff_figure(
    runs: pd.DataFrame, summary: pd.DataFrame, paired: pd.DataFrame
) -> plt.Figure:
    """Paired view of Fig. 5: every method − NBO (UAV-2)."""
    return paired_figure(
        runs,
        paired_view(paired, "nbo"),
        "Paired view of Fig. 5",
        _keys(summary, paired),
        "uav_paired_diff",
    )
