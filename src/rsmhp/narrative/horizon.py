"""UAV horizon study, report section (order 33, "Long horizons"): the Markdown tables of the
cost approximation and of regret and time by horizon, a short body (setting, findings,
figures) and the appendix, from :mod:`rsmhp.analysis.horizon` and the claims of
:mod:`rsmhp.claims.horizon`. Every number is read from the tables or the claims."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.claims.horizon import horizon_claims
from rsmhp.figures.horizon import FIGURES
from rsmhp.ledger import Claim, Section
from rsmhp.markdown import ci_cells, fmt, fmt_ci, markdown_table
from rsmhp.palette import method_label

__all__ = ["FIGURES", "TABLES", "horizon_section", "horizon_tables"]

TABLES = ("hz_uav_approx", "hz_uav_regret", "hz_uav_closed", "hz_lqg")


def horizon_tables(
    approx_summary: pd.DataFrame,
    regret_summary: pd.DataFrame,
    lqg_table: pd.DataFrame,
    closed_summary: pd.DataFrame,
) -> dict[str, str]:
    """Markdown tables ``hz_uav_approx`` (per model, H and method: relative bias and RMSE of
    the cost estimate in percent with CIs, the reference's relative SE, rank correlation),
    ``hz_uav_regret`` (relative regret against the best plan found and against the best of the
    methods' plans, planning ms), ``hz_uav_closed`` (closed-loop error and its paired
    difference with NBO) and ``hz_lqg`` (:func:`rsmhp.analysis.horizon.lqg_horizon_table`)."""
    a = approx_summary
    t1 = pd.DataFrame(
        {
            "model": a["model"],
            "H": a["H"].astype(int),
            "method": a["method"].map(method_label),
            "states": a["states"].astype(int),
            "bias %": 100 * a["rel_bias"],
            "95% CI": ci_cells(a["rel_bias_low"], a["rel_bias_high"], 100),
            "RMSE %": 100 * a["rel_rmse"],
            "95% CI ": ci_cells(a["rel_rmse_low"], a["rel_rmse_high"], 100),
            "reference SE %": 100 * a["ref_noise"],
            "Spearman": a["spearman"],
            "constant": a["spearman_undefined"].astype(int),
        }
    )
    r = regret_summary
    t2 = pd.DataFrame(
        {
            "model": r["model"],
            "H": r["H"].astype(int),
            "method": r["method"].map(method_label),
            "states": r["states"].astype(int),
            "regret %": r["regret_pct"],
            "vs methods' best %": r["regret_methods_pct"],
            "ms/step": r["plan_ms"],
        }
    )
    q = lqg_table
    t3 = pd.DataFrame(
        {
            "a": q["a"],
            "NBO error limit": q["nbo_limit"],
            **{
                f"reached at H = {c.removeprefix('nbo_share_H')} %": q[c]
                for c in q.columns
                if c.startswith("nbo_share_H")
            },
            "first control vanishes at H": q["vanishing_H"].astype(int),
            "stage-cost K∞": q["k_inf"],
            "K_H within eps of K∞ at H": q["stationary_H"].astype(int),
        }
    )
    c = closed_summary
    t4 = pd.DataFrame(
        {
            "model": c["model"],
            "H": c["H"].astype(int),
            "method": c["method"].map(method_label),
            "runs": c["runs"].astype(int),
            "error (m)": c["mean_error"],
            "− NBO (m)": c["error_diff"],
            "95% CI (m)": ci_cells(c["error_diff_low"], c["error_diff_high"], signed=True),
            "ms/step": c["plan_ms"],
        }
    )
    return {
        "hz_uav_approx": markdown_table(t1, digits=3, missing="undefined", signed=("bias %",)),
        "hz_uav_regret": markdown_table(t2, digits=3),
        "hz_uav_closed": markdown_table(t4, digits=3, signed=("− NBO (m)",)),
        "hz_lqg": markdown_table(t3, digits=4),
    }


def _lqg_text(q: pd.DataFrame, a_model: float, eps: float) -> str:
    """The oven LQG at long horizons for the model's a (closed forms, table hz_lqg)."""
    row = q.iloc[int(np.argmin(np.abs(q["a"].to_numpy(float) - a_model)))]
    shares = [c for c in q.columns if c.startswith("nbo_share_H")]
    reach = ", ".join(
        f"{fmt(float(row[c]), 4)}% at H = {c.removeprefix('nbo_share_H')}" for c in shares
    )
    return (
        f"Oven LQG (closed forms, a = {fmt(float(row['a']), 2)}): NBO's error r v_H reaches "
        f"{reach} of its limit r σ²/(1 − (1 − a)²) = {fmt(float(row['nbo_limit']), 4)}. The "
        "paper calls a horizon long when the optimal policy is nearly stationary; in its "
        "terminal-cost problem the gain of the optimal first control shrinks like "
        "(1 − a)^(H−1) (the controls gather at the end of the horizon), so its stationary "
        f"limit is zero: it falls below {fmt(100 * eps, 2)}% of its one-step value at H = "
        f"{int(row['vanishing_H'])} (from H = {int(q['vanishing_H'].min())} to "
        f"{int(q['vanishing_H'].max())} over a ∈ [{fmt(float(q['a'].min()), 2)}, "
        f"{fmt(float(q['a'].max()), 2)}]). With a stage cost r(x_k − T)² at every step "
        "(beyond the paper) the first-step gain is within "
        f"{fmt(100 * eps, 2)}% of the stationary Riccati gain from H = "
        f"{int(row['stationary_H'])} ({int(q['stationary_H'].min())} to "
        f"{int(q['stationary_H'].max())} over a)."
    )


def _setting(cfg: Mapping[str, Any], hs: Sequence[int]) -> str:
    return (
        f"H ∈ {{{', '.join(str(h) for h in hs)}}} on "
        f"{', '.join(repr(m) for m in cfg['models'])}, at the belief states of "
        f"{int(cfg['runs'])} NBO runs (the same at every H). **Cost approximation**: each "
        f"method's estimate of the cost (Σ tr P) of {int(cfg['plans'])} random plans per state "
        f"against a reference of {int(cfg['n_ref'])} independent hypotheses (random methods "
        f"drawn {int(cfg['replicates'])} times); relative RMSE noise-corrected (the "
        "reference's variance subtracted), 95% bootstrap CIs over runs (each with its states). "
        "**Decisions and "
        "time**: each method plans once per state, scored as in the decision study, and is "
        "timed on a second plan call (one thread). The tree search estimates no given plan's "
        f"cost: regret and time only. **Closed loop**: {int(cfg['closed_runs'])} paired runs "
        "per method and H (the same scenarios at every H)."
    )


def _findings(claims: Sequence[Claim], a: pd.DataFrame, r: pd.DataFrame) -> str:
    out = []
    for c in claims:
        k = c.key
        out.append(
            f"{c.id} ({c.verdict}): {k.name} {fmt(k.value, k.digits, True)} {k.unit} "
            f"{fmt_ci(k.ci_low, k.ci_high, k.digits, True)}."
        )
    h_hi = max(int(h) for h in a["H"].unique())
    for model, s in a[a["H"] == h_hi].groupby("model", sort=False):
        ranked = s.sort_values("rel_rmse")
        t = r[(r["H"] == h_hi) & (r["model"] == model)]
        out.append(
            f"At H = {h_hi} on '{model}', relative RMSE: "
            + ", ".join(
                f"{method_label(m)} "
                + (f"{fmt(100 * v, 2)}%" if v > 0 else "below the reference's noise")
                for m, v in zip(ranked["method"], ranked["rel_rmse"], strict=True)
            )
            + f"; planning {fmt(t['plan_ms'].min(), 2)} to {fmt(t['plan_ms'].max(), 2)} ms per "
            f"step; regret against the methods' best plan {fmt(t['regret_methods_pct'].min(), 2)}"
            f"% to {fmt(t['regret_methods_pct'].max(), 2)}%, against the best plan found "
            f"(a longer multi-start on the reference cost) {fmt(t['regret_pct'].min(), 2)}% to "
            f"{fmt(t['regret_pct'].max(), 2)}%."
        )
    return " ".join(out)


_FIGURE = [
    "![Closed loop by horizon](figures/hz_uav_closed.png)",
    "",
    "*Closed-loop mean location error − NBO's on the same runs (m), by horizon; bars: 95% "
    "bootstrap CIs over runs.*",
    "",
    "![Cost approximation by horizon](figures/hz_uav_error.png)",
    "",
    "*Relative RMSE (log scale, noise-corrected; below the reference's noise drawn at "
    "0.001%) and bias of each method's cost estimate against the reference, by horizon; "
    "bars: 95% bootstrap CIs over belief states.*",
    "",
    "![Planning time and regret by horizon](figures/hz_uav_time.png)",
    "",
    "*Median planning ms per step (log scale) and the open-loop regret against the best of "
    "the methods' plans (%), by horizon.*",
]


def horizon_section(
    approx: pd.DataFrame,
    approx_summary: pd.DataFrame,
    regret_summary: pd.DataFrame,
    tables: Mapping[str, str],
    cfg: Mapping[str, Any],
    seed: int,
    lqg_table: pd.DataFrame,
    lqg_cfg: Mapping[str, Any],
    a_model: float,
    closed: pd.DataFrame | None = None,
) -> Section:
    """The horizon study's report section (order 33); ``cfg`` is ``horizon.uav``,
    ``lqg_cfg`` ``horizon.lqg``, ``a_model`` the oven model's a (``lqg.model.a``)."""
    claims = horizon_claims(approx, approx_summary, cfg, seed, closed)
    hs = sorted(int(h) for h in cfg["H"])
    body = "\n".join(
        [
            _setting(cfg, hs),
            "",
            _findings(claims, approx_summary, regret_summary),
            "",
            _lqg_text(lqg_table, a_model, float(lqg_cfg["eps"])),
            "",
            *_FIGURE,
        ]
    )
    appendix = "\n".join(
        [
            "Cost approximation per model, horizon and method (relative bias and RMSE of the "
            "cost estimate in percent of the reference cost, 95% bootstrap CIs over runs, each "
            "with its belief states; 'reference SE': the reference's own relative standard "
            "error, already "
            "subtracted from the RMSE; Spearman: rank correlation of estimate and reference "
            "over the plans, mean over states and replicates; 'constant': (state, replicate) "
            "pairs where the estimate does not change over the plans, left out of it):",
            "",
            tables["hz_uav_approx"],
            "",
            "Open-loop regret (percent of the best plan found) and planning time per model, "
            "horizon and method ('vs methods' best': against the best of the methods' plans):",
            "",
            tables["hz_uav_regret"],
            "",
            "Closed loop per model, horizon and method: mean location error over the paired "
            "runs and its paired difference with NBO (95% bootstrap CI over runs), planning "
            "ms per step (median over runs):",
            "",
            tables["hz_uav_closed"],
            "",
            "Oven LQG at long horizons, closed forms (`rsmhp.lqg_horizon`; r, σ of the oven "
            "model): NBO's error limit r σ²/(1 − (1 − a)²) and the share of it reached at H; "
            "the first H at which the gain L_H = r a (1 − a)^(H−1) / (1 + r a² Σ_(n<H) "
            "(1 − a)^(2n)) of the paper's optimal first control L_H (T − (1 − a)^H x_0) is at "
            f"most eps = {fmt(float(lqg_cfg['eps']), 2)} of L_1; the stationary gain K∞ of the "
            "stage-cost "
            "variant (algebraic Riccati equation) and the first H whose first-step gain K_H "
            "is within eps of it:",
            "",
            tables["hz_lqg"],
        ]
    )
    return Section(
        key="horizon_uav",
        title="Long horizons: UAV cost approximation, decisions and time",
        order=33,
        body=body,
        claims=claims,
        figures=list(FIGURES),
        appendix=appendix,
    )
