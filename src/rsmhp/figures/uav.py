"""UAV figures: CDFs of the per-run average error (paper Figs. 4 and 5) and paired differences."""

from __future__ import annotations

import matplotlib.pyplot as plt
import pandas as pd
import seaborn as sns

from rsmhp.analysis.uav import method_label
from rsmhp.figures import seeded_legacy_random, theme

__all__ = ["error_cdf_nbo_figure", "error_cdf_nt_figure", "paired_diff_figure"]


def _labelled(runs: pd.DataFrame, summary: pd.DataFrame) -> tuple[pd.DataFrame, list[str]]:
    labels = {r["method"]: r["label"] for _, r in summary.iterrows()}
    return runs.assign(label=runs["method"].map(labels)), list(summary["label"])


def error_cdf_nt_figure(runs: pd.DataFrame, summary: pd.DataFrame) -> plt.Figure:
    """ECDF of ``mean_error`` for RS-MHP at each N_T (Fig. 4 analogue)."""
    theme()
    rs = summary[summary["family"] == "rsmhp"]
    df, _ = _labelled(runs[runs["family"] == "rsmhp"], rs)
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    sns.ecdfplot(data=df, x="mean_error", hue="label", hue_order=list(rs["label"]), ax=ax)
    ax.set_xlabel("average target location error per run (m)")
    ax.set_ylabel("fraction of runs")
    ax.set_title(f"RS-MHP, H = 6: effect of N_T ({int(rs['n_runs'].max())} runs each)")
    ax.get_legend().set_title(None)
    return fig


def error_cdf_nbo_figure(runs: pd.DataFrame, summary: pd.DataFrame) -> plt.Figure:
    """ECDF of ``mean_error`` for NBO and every RS-MHP / tree method (Fig. 5 analogue)."""
    theme()
    df, order = _labelled(runs, summary)
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    sns.ecdfplot(data=df, x="mean_error", hue="label", hue_order=order, ax=ax)
    ax.set_xlabel("average target location error per run (m)")
    ax.set_ylabel("fraction of runs")
    ax.set_title("NBO vs RS-MHP")
    ax.get_legend().set_title(None)
    return fig


def paired_diff_figure(
    runs: pd.DataFrame, summary: pd.DataFrame, paired: pd.DataFrame
) -> plt.Figure:
    """Per-run differences ``e(method) - e(NBO)`` (points) with mean and bootstrap CI (bars)."""
    theme()
    vs = paired[paired["baseline"] == "nbo"]
    wide = runs.pivot(index="run", columns="method", values="mean_error")
    labels = {r["method"]: method_label(r) for _, r in summary.iterrows()}
    long = pd.concat(
        [
            pd.DataFrame({"label": labels[m], "diff": (wide[m] - wide["nbo"]).dropna()})
            for m in vs["method"]
        ],
        ignore_index=True,
    )
    order = [labels[m] for m in vs["method"]]
    fig, ax = plt.subplots(figsize=(6.5, 0.9 + 0.8 * len(order)))
    with seeded_legacy_random("uav_paired_diff"):  # seaborn's jitter uses np.random
        sns.stripplot(data=long, x="diff", y="label", order=order, ax=ax, alpha=0.35, size=3)
    for i, (_, r) in enumerate(vs.iterrows()):
        ax.errorbar(
            r["mean_diff"],
            i,
            xerr=[[r["mean_diff"] - r["ci_low"]], [r["ci_high"] - r["mean_diff"]]],
            fmt="D",
            color="k",
            capsize=4,
            ms=5,
            label="mean, 95% bootstrap CI" if i == 0 else None,
        )
    ax.axvline(0.0, color="C3", ls="--", lw=1)
    ax.set_xlabel("paired difference of average error to NBO per run (m; < 0: better)")
    ax.set_ylabel("")
    ax.legend(loc="best", fontsize=8)
    return fig
