r"""The UAV horizon study: cost-approximation error, planning time and regret against H.

``horizon_uav_error``: columns are model variants; top row the relative RMSE of each method's cost
estimate (%, log scale, noise-corrected; 95% cluster-t CIs over runs; an RMSE the
reference's noise hides, corrected to 0, is drawn at :data:`RMSE_FLOOR_PCT`), bottom row its
relative bias (%). ``horizon_uav_time``: top row the median planning milliseconds per step
(log scale), bottom row the open-loop regret against the best of the methods' own plans (% of
the best cost; it mixes approximation and optimisation error, which the optimiser-split study
separates). x: the horizon H (log scale). ``horizon_uav_closed``: the closed-loop mean location
error minus NBO's on the same runs (m, 95% Student-t CIs over runs). One line per method in
its palette colour.

``horizon_lqg`` (oven LQG, exact oracle; one row per simulated a): left, the relative RMSE (%,
log scale) of each cost estimator with n trajectories (the largest n of the study: Monte
Carlo, RQMC, the pruned trees keeping M = n, one shade per N) and NBO, 95% bootstrap CIs over
replicates; right, the mean regret of uniform Monte Carlo per P with its 95% t-CI, the closed
form κ_H v_H / P (dashed) and its limit κ_∞ v_∞ / P (dotted), log scale.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter, NullLocator

from rsmhp.models.uav import methods as _registry  # noqa: F401  (UAV method names get their colours)
from rsmhp.report.figures import theme
from rsmhp.report.palette import METHOD_COLOURS, method_colour, method_label, size_shade
from rsmhp.studies.horizon import FIGURES

__all__ = [
    "FIGURES",
    "horizon_closed_figure",
    "horizon_error_figure",
    "horizon_lqg_figure",
    "horizon_time_figure",
]


#: relative RMSEs below this (%) are drawn at it (the log axis has no 0)
RMSE_FLOOR_PCT = 1e-3


def _h_axis(ax, hs) -> None:
    ax.set_xscale("log")
    ax.xaxis.set_major_locator(FixedLocator(sorted(hs)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_locator(NullLocator())
    ax.xaxis.set_minor_formatter(NullFormatter())


def _grid(summary: pd.DataFrame, rows, title: str) -> plt.Figure:
    theme()
    models = list(dict.fromkeys(summary["model"]))
    if not models:
        raise ValueError("horizon summary is empty")
    hs = sorted(int(h) for h in summary["H"].unique())
    fig, axes = plt.subplots(
        len(rows), len(models), figsize=(4.8 * len(models), 3.4 * len(rows)), squeeze=False,
        sharex=True,
    )  # fmt: skip
    for j, model in enumerate(models):
        s = summary[summary["model"] == model]
        for i, (col, label, log, floor) in enumerate(rows):
            ax = axes[i, j]
            for method, g in s.groupby("method", sort=False):
                g = g.sort_values("H")
                y = g[col].to_numpy(float)
                if floor is not None:
                    y = np.maximum(y, floor)
                kw = {"color": method_colour(method), "marker": "o", "ms": 3.5, "lw": 1.3}
                if f"{col}_low" in g:
                    lo = np.maximum(g[f"{col}_low"].to_numpy(float), floor or -np.inf)
                    hi = np.maximum(g[f"{col}_high"].to_numpy(float), floor or -np.inf)
                    ax.errorbar(g["H"], y, yerr=np.vstack([np.maximum(y - lo, 0),
                                np.maximum(hi - y, 0)]), capsize=2, label=method_label(method),
                                **kw)  # fmt: skip
                else:
                    ax.plot(g["H"], y, label=method_label(method), **kw)
            if log:
                ax.set_yscale("log")
                ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
                ax.yaxis.set_minor_formatter(NullFormatter())
            else:
                ax.axhline(0.0, color="0.4", lw=0.8)
            _h_axis(ax, hs)
            if i == 0:
                ax.set_title(model)
            if i == len(rows) - 1:
                ax.set_xlabel("horizon H (steps)")
            if j == 0:
                ax.set_ylabel(label)
    axes[0, -1].legend(fontsize="x-small", loc="best")
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return fig


def horizon_error_figure(approx_summary: pd.DataFrame) -> plt.Figure:
    """``horizon_uav_error`` from :func:`rsmhp.studies.horizon.summarise_uav.summarize_approx`
    (module doc)."""
    s = approx_summary.copy()
    for c in ("rel_rmse", "rel_rmse_low", "rel_rmse_high", "rel_bias", "rel_bias_low",
              "rel_bias_high"):  # fmt: skip
        s[c] = 100 * s[c]
    rows = [
        ("rel_rmse", "relative RMSE of the cost estimate (%)", True, RMSE_FLOOR_PCT),
        ("rel_bias", "relative bias (%)", False, None),
    ]
    return _grid(s, rows, "Cost approximation against the reference, by horizon")


def horizon_time_figure(regret_summary: pd.DataFrame) -> plt.Figure:
    """``horizon_uav_time`` from
    :func:`rsmhp.studies.horizon.summarise_uav.summarize_horizon_regret`."""
    rows = [
        ("plan_ms", "planning ms per step (median)", True, None),
        ("regret_methods_pct", "regret vs the methods' best plan (%)", False, None),
    ]
    return _grid(regret_summary, rows, "Planning time and decisions, by horizon")


def horizon_closed_figure(closed_summary: pd.DataFrame) -> plt.Figure:
    """``horizon_uav_closed`` from :func:`rsmhp.studies.horizon.summarise_uav.summarize_closed`."""
    rows = [("error_diff", "closed-loop mean error − NBO's (m)", False, None)]
    return _grid(closed_summary, rows, "Closed loop against NBO, by horizon")


_LQG_SCHEMES = {"nbo": "NBO", "mc": "Monte Carlo", "sobol": "RQMC (Sobol')"}


def horizon_lqg_figure(est_summary: pd.DataFrame, regret_summary: pd.DataFrame) -> plt.Figure:
    """``horizon_lqg`` from :func:`rsmhp.studies.horizon.summarise_lqg.summarize_lqg_estimators` and
    :func:`rsmhp.studies.horizon.summarise_lqg.summarize_lqg_horizon_regret` (module doc)."""
    theme()
    a_vals = sorted(float(a) for a in est_summary["a"].unique())
    if not a_vals:
        raise ValueError("LQG horizon summary is empty")
    e = est_summary[est_summary["weighting"].isin(["uniform", "nominal"])]
    n = int(e.loc[e["scheme"] == "mc", "n_trajectories"].max())
    hs = sorted(int(h) for h in e["H"].unique())
    fig, axes = plt.subplots(
        len(a_vals), 2, figsize=(9.6, 3.4 * len(a_vals)), squeeze=False, sharex=True
    )
    for i, a in enumerate(a_vals):
        ax = axes[i, 0]
        ea = e[e["a"] == a]
        curves = [(s, 0, _LQG_SCHEMES[s], method_colour(s)) for s in _LQG_SCHEMES]
        curves += [
            (
                "pruned",
                int(N),
                f"pruned tree N = {int(N)}, M = {n}",
                size_shade(METHOD_COLOURS["pruned"], 4 * int(N), edges=(8, 16, 64, 128)),
            )
            for N in sorted(ea.loc[ea["scheme"] == "pruned", "N"].unique())
        ]
        for scheme, N, label, colour in curves:
            g = ea[(ea["scheme"] == scheme) & (ea["N"] == N)]
            if scheme != "nbo":
                g = g[g["n_trajectories"] == n]
            g = g.sort_values("H")
            if g.empty:
                continue
            y = 100 * g["rel_rmse"].to_numpy(float)
            err = np.vstack(
                [
                    np.maximum(y - 100 * g["rel_rmse_low"].to_numpy(float), 0),
                    np.maximum(100 * g["rel_rmse_high"].to_numpy(float) - y, 0),
                ]
            )
            style = {"ls": "--", "zorder": 5, "marker": "s"} if scheme == "nbo" else {}
            ax.errorbar(g["H"], y, yerr=err, color=colour, ms=3.5, lw=1.3, capsize=2,
                        label=label, **{"marker": "o", **style})  # fmt: skip
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(NullFormatter())
        ax.set_ylabel(f"a = {a:g}: relative RMSE of Ĵ (%)")
        _h_axis(ax, hs)
        ax = axes[i, 1]
        r = regret_summary[
            (regret_summary["a"] == a)
            & (regret_summary["method"] == "mc")
            & (regret_summary["weighting"] == "uniform")
        ]
        ps = sorted(int(p) for p in r["P"].unique())
        for P in ps:
            g = r[r["P"] == P].sort_values("H")
            colour = size_shade(METHOD_COLOURS["mc"], P, edges=(16, 32, 64, 128))
            y = g["mean"].to_numpy(float)
            err = np.vstack(
                [
                    np.maximum(y - g["ci_low"].to_numpy(float), 0),
                    np.maximum(g["ci_high"].to_numpy(float) - y, 0),
                ]
            )
            ax.errorbar(g["H"], y, yerr=err, color=colour, marker="o", ms=3.5, lw=0,
                        elinewidth=1.0, capsize=2, label=f"Monte Carlo P = {P}")  # fmt: skip
            ax.plot(g["H"], g["closed_form"], color=colour, ls="--", lw=1.0)
            ax.axhline(float(g["limit"].iloc[-1]), color=colour, ls=":", lw=1.0)
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(NullFormatter())
        ax.set_ylabel("mean regret J(û) − J(u*)")
        _h_axis(ax, hs)
        if i == 0:
            axes[0, 0].set_title(f"cost estimators, n = {n} trajectories")
            axes[0, 1].set_title("decisions: --- κ_H v_H / P, ··· limit H → ∞")
            axes[0, 0].legend(fontsize="x-small", loc="best")
            ax.legend(fontsize="x-small", loc="best")
    for ax in axes[-1]:
        ax.set_xlabel("horizon H (steps)")
    fig.suptitle("Oven LQG at long horizons (exact oracle)", fontsize=11)
    fig.tight_layout()
    return fig
