"""UAV horizon study, report section (order 33, "Long horizons"): the Markdown tables of the
cost approximation and of regret and time by horizon, a short body (setting, findings,
figures) and the appendix, from :mod:`rsmhp.studies.horizon.summarise_uav` and the claims of
:mod:`rsmhp.studies.horizon.claims`. Every number is read from the tables or the claims."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.report.ledger import Claim, Section
from rsmhp.report.markdown import ci_cells, fmt, markdown_table, range_text
from rsmhp.report.palette import method_label
from rsmhp.studies.horizon.claims import Evidence, budget_text, horizon_evidence, lqg_horizon_claims
from rsmhp.studies.horizon.figures import FIGURES
from rsmhp.studies.horizon.section_optimiser import TITLE as SPLIT_TITLE
from rsmhp.studies.horizon.section_optimiser import horizon_note

__all__ = ["FIGURES", "TABLES", "horizon_section", "horizon_tables"]

TABLES = (
    "hz_uav_approx",
    "hz_uav_regret",
    "hz_uav_closed",
    "hz_lqg",
    "hz_lqg_estimators",
    "hz_lqg_regret",
)


def horizon_tables(
    approx_summary: pd.DataFrame,
    regret_summary: pd.DataFrame,
    lqg_table: pd.DataFrame,
    closed_summary: pd.DataFrame,
    lqg_estimators: pd.DataFrame,
    lqg_regret: pd.DataFrame,
) -> dict[str, str]:
    """Markdown tables ``hz_uav_approx`` (per model, H and method: relative bias and RMSE of
    the cost estimate in percent with cluster-t CIs over runs, the reference's relative SE,
    rank correlation), ``hz_uav_regret`` (relative regret against the best plan found and
    against the best of the methods' own plans, planning ms), ``hz_uav_closed`` (closed-loop
    error and its paired difference with NBO with a t CI over runs, the runs a confirmatory
    comparison needs for 80% power at the observed difference), ``hz_lqg``
    (:func:`rsmhp.studies.horizon.summarise_uav.lqg_horizon_table`), ``hz_lqg_estimators`` (oven
    LQG: relative bias and RMSE of each estimator against the exact J by a and H,
    :func:`rsmhp.studies.horizon.summarise_lqg.summarize_lqg_estimators`) and ``hz_lqg_regret``
    (mean regret with CI, closed form, its limit and z,
    :func:`rsmhp.studies.horizon.summarise_lqg.summarize_lqg_horizon_regret`)."""
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
            "vs best of methods' plans %": r["regret_methods_pct"],
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
            "SD over runs (m)": c["diff_sd"],
            "runs for 80% power": c["runs_to_resolve"],
            "ms/step": c["plan_ms"],
        }
    )
    e = lqg_estimators
    t5 = pd.DataFrame(
        {
            "a": e["a"],
            "H": e["H"].astype(int),
            "scheme": e["scheme"],
            "weighting": e["weighting"],
            "N": e["N"].astype(int),
            "n": e["n_trajectories"].astype(int),
            "bias %": 100 * e["rel_bias"],
            "RMSE %": 100 * e["rel_rmse"],
            "95% CI": ci_cells(e["rel_rmse_low"], e["rel_rmse_high"], 100),
            "closed form %": 100 * e["rel_rmse_theory"],
        }
    )
    g = lqg_regret
    t6 = pd.DataFrame(
        {
            "a": g["a"],
            "H": g["H"].astype(int),
            "method": g["method"],
            "weighting": g["weighting"],
            "P": g["P"].astype(int),
            "mean regret": g["mean"],
            "95% CI": ci_cells(g["ci_low"], g["ci_high"]),
            "closed form": g["closed_form"],
            "limit H → ∞": g["limit"],
            "z": g["z"],
            "regret / J*": g["rel_mean"],
        }
    )
    return {
        "hz_uav_approx": markdown_table(t1, digits=3, missing="undefined", signed=("bias %",)),
        "hz_uav_regret": markdown_table(t2, digits=3),
        "hz_uav_closed": markdown_table(t4, digits=3, missing="–", signed=("− NBO (m)",)),
        "hz_lqg": markdown_table(t3, digits=4),
        "hz_lqg_estimators": markdown_table(t5, digits=3, missing="–", signed=("bias %",)),
        "hz_lqg_regret": markdown_table(t6, digits=3, missing="–"),
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
        "paper's 'long horizon' is a nearly stationary optimal policy; in its terminal-cost "
        "problem the optimal first control's gain shrinks like (1 − a)^(H−1) (control "
        "gathers at the end), so its stationary "
        f"limit is zero: it falls below {fmt(100 * eps, 2)}% of its one-step value at H = "
        f"{int(row['vanishing_H'])} (from H = {int(q['vanishing_H'].min())} to "
        f"{int(q['vanishing_H'].max())} over a ∈ [{fmt(float(q['a'].min()), 2)}, "
        f"{fmt(float(q['a'].max()), 2)}]). With a stage cost r(x_k − T)² at every step "
        "(beyond the paper) the first-step gain is within "
        f"{fmt(100 * eps, 2)}% of the stationary Riccati gain from H = "
        f"{int(row['stationary_H'])} ({int(q['stationary_H'].min())} to "
        f"{int(q['stationary_H'].max())} over a)."
    )


def _lqg_sim_text(est: pd.DataFrame, reg: pd.DataFrame, a_model: float) -> str:
    """The simulated oven LQG at long horizons (tables hz_lqg_estimators, hz_lqg_regret), at
    the model's a (or the nearest simulated a)."""
    if est.empty:
        return ""
    a_vals = np.unique(est["a"].to_numpy(float))
    a = float(a_vals[np.argmin(np.abs(a_vals - a_model))])
    e = est[(est["a"] == a) & (est["weighting"].isin(["uniform", "nominal"]))]
    hs = sorted(int(h) for h in e["H"].unique())
    h_lo, h_hi = hs[0], hs[-1]

    def rmse(scheme: str, h: int, n: int, N: int = 0) -> str:
        row = e[
            (e["scheme"] == scheme) & (e["H"] == h) & (e["n_trajectories"] == n) & (e["N"] == N)
        ]
        return f"{fmt(100 * float(row['rel_rmse'].iloc[0]), 3)}%" if len(row) else "–"

    n_max = int(e.loc[e["scheme"] == "mc", "n_trajectories"].max())
    trees = e[(e["scheme"] == "pruned") & (e["n_trajectories"] == n_max)]
    nbo = e[e["scheme"] == "nbo"].set_index("H")["rel_rmse"]
    parts = [
        f"Simulated oven LQG (a = {fmt(a, 2)}, controls u*(H), exact J): with n = {n_max} "
        f"trajectories the relative RMSE of Monte Carlo is {rmse('mc', h_lo, n_max)} at H = "
        f"{h_lo} and {rmse('mc', h_hi, n_max)} at H = {h_hi}, of RQMC "
        f"{rmse('sobol', h_lo, n_max)} and {rmse('sobol', h_hi, n_max)} (its advantage shrinks "
        f"as the dimension H grows); NBO's is {fmt(100 * float(nbo.loc[h_lo]), 3)}% and "
        f"{fmt(100 * float(nbo.loc[h_hi]), 3)}%."
    ]
    for N in sorted(int(x) for x in trees["N"].unique()):
        t = trees[trees["N"] == N].set_index("H")["rel_rmse"].sort_index()
        parts.append(
            f"Pruned tree, N = {N} draws per level, M = {n_max} kept: "
            f"{fmt(100 * float(t.iloc[0]), 3)}% at H = {int(t.index[0])}, "
            f"{fmt(100 * float(t.iloc[-1]), 3)}% at H = {int(t.index[-1])}."
        )
    g = reg[(reg["a"] == a)]
    mc = g[(g["method"] == "mc") & (g["weighting"] == "uniform")]
    w = g[(g["method"] == "mc") & (g["weighting"] == "likeliness")]
    if not mc.empty:
        p_max = int(mc["P"].max())
        m1 = mc[mc["P"] == p_max].set_index("H")
        parts.append(
            f"Decisions: uniform Monte Carlo's mean regret at P = {p_max} is "
            + ", ".join(f"{fmt(float(m1.loc[h, 'mean']), 3)}" for h in (h_lo, h_hi))
            + f" at H = {h_lo}, {h_hi} (closed forms "
            + ", ".join(f"{fmt(float(m1.loc[h, 'closed_form']), 3)}" for h in (h_lo, h_hi))
            + f"; limit {fmt(float(m1.loc[h_hi, 'limit']), 3)}); NBO, antithetic pairs and "
            "sigma points have zero regret at every H."
        )
    if not w.empty:
        bad = w[w["z"].abs() > 3.0]
        if len(bad):
            worst = bad.loc[bad["z"].abs().idxmax()]
            parts.append(
                "The likeliness-weighted Monte-Carlo regret leaves its first-order form "
                "κ v_H (4/3)^(H/2)/(3P) at long horizons (the weights' effective sample size "
                f"falls like (3/4)^(H/2) P): |z| > 3 in {len(bad)} of {len(w)} cells, worst "
                f"z = {fmt(float(worst['z']), 3, True)} at H = {int(worst['H'])}, P = "
                f"{int(worst['P'])} (mean {fmt(float(worst['mean']), 3)} vs "
                f"{fmt(float(worst['closed_form']), 3)})."
            )
    return " ".join(parts)


def _runs_text(closed_summary: pd.DataFrame) -> str:
    """How many runs the closed-loop comparisons used and would need (column 'runs for 80%
    power' of hz_uav_closed)."""
    c = closed_summary[closed_summary["runs_to_resolve"].notna()]
    if c.empty:
        return ""
    out = []
    for model, g in c.groupby("model", sort=False):
        half = (g["error_diff_high"] - g["error_diff_low"]) / 2
        resolved = (g["error_diff_low"] > 0) | (g["error_diff_high"] < 0)
        need = g.loc[~resolved, "runs_to_resolve"]
        finite = need[np.isfinite(need)]
        beyond = int(len(need) - len(finite))
        rest = (
            f", the rest would need {int(finite.min())} to {int(finite.max())} runs (median "
            f"{int(finite.median())})"
            if len(finite)
            else ""
        )
        if beyond:
            rest += f"{',' if rest else ', the rest'} {beyond} of them more than 10⁶"
        out.append(
            f"'{model}': {int(g['runs'].min())} runs, half-widths {fmt(float(half.min()), 2)} "
            f"to {fmt(float(half.max()), 2)} m, {int(resolved.sum())} of {len(g)} CIs exclude "
            f"0{rest}"
        )
    return (
        "Runs needed (closed loop; table hz_uav_closed): the paired runs at which a "
        "confirmatory comparison, a paired t-test at 5%, would detect a difference of the "
        "observed size with 80% power. The observed difference is used as the assumed true "
        "effect, so the counts are optimistic where it is inflated by selection (a comparison "
        "singled out for its large difference). " + "; ".join(out) + "."
    )


def _interval_text(evidence: Sequence[Evidence]) -> str:
    """How the change from the percentile bootstrap over runs to the cluster-t CI changed
    the intervals of HZ-1..HZ-3 and which verdicts it moved."""
    if not evidence:
        return ""
    ratio = [_width_ratio(e) for e in evidence]
    ratio = [r for r in ratio if np.isfinite(r)]
    moved = [
        f"{e.claim.id} ({e.boot_verdict} → {e.claim.verdict})"
        for e in evidence
        if e.boot_verdict != e.claim.verdict
    ]
    widths = (
        f"{range_text(ratio, 3)} times as wide as the percentile bootstrap over runs they replace"
        if ratio
        else "beside the percentile bootstrap over runs they replace"
    )
    return (
        f"CIs of {', '.join(e.claim.id for e in evidence)}: cluster-t over runs (jackknife "
        "over runs, t with runs − 1 df; Student-t for HZ-3's mean of per-run changes), which "
        f"holds with few runs, {widths}; the change "
        + (f"moves {', '.join(moved)}" if moved else "moves no verdict")
        + " (table in the appendix, with each claim's t-test p-value)."
    )


def _width_ratio(e: Evidence) -> float:
    k = e.claim.key
    boot = e.boot_high - e.boot_low
    return (k.ci_high - k.ci_low) / boot if boot > 0 else float("nan")


def _interval_table(evidence: Sequence[Evidence]) -> str:
    """HZ-1..HZ-3: key number, cluster-t CI, p-value, percentile-bootstrap CI, their width
    ratio and the verdict of each (Markdown)."""
    rows = pd.DataFrame(
        {
            "claim": [e.claim.id for e in evidence],
            "value": [e.claim.key.value for e in evidence],
            "unit": [e.claim.key.unit for e in evidence],
            "cluster-t 95% CI": ci_cells(
                [e.claim.key.ci_low for e in evidence],
                [e.claim.key.ci_high for e in evidence],
                signed=True,
            ),
            "df": [e.df for e in evidence],
            "p": [e.p_value for e in evidence],
            "bootstrap 95% CI": ci_cells(
                [e.boot_low for e in evidence], [e.boot_high for e in evidence], signed=True
            ),
            "width ratio": [_width_ratio(e) for e in evidence],
            "verdict": [e.claim.verdict for e in evidence],
            "bootstrap verdict": [e.boot_verdict for e in evidence],
        }
    )
    return markdown_table(rows, digits=3, missing="–", signed=("value",))


def _setting(cfg: Mapping[str, Any], hs: Sequence[int]) -> str:
    return (
        f"H ∈ {{{', '.join(str(h) for h in hs)}}} on "
        f"{', '.join(repr(m) for m in cfg['models'])}, belief states of "
        f"{int(cfg['runs'])} NBO runs (the same at every H). **Cost approximation**: each "
        f"method's estimate of Σ tr P for {int(cfg['plans'])} random plans per state against "
        f"{int(cfg['n_ref'])} independent hypotheses ({int(cfg['replicates'])} draws of a "
        "random method); RMSE noise-corrected, CIs over runs. **Decisions and time**: one "
        "plan per state, scored as in the decision study, timed on a second call (one "
        "thread); the tree search has no cost estimate. **Closed loop**: "
        f"{int(cfg['closed_runs'])} paired runs per method and H (the same scenarios at every "
        "H). The HZ rules are in the config, written after pilots that gave the same signs."
    )


def _findings(claims: Sequence[Claim], a: pd.DataFrame, r: pd.DataFrame) -> str:
    out = (
        [f"Claims {', '.join(c.id for c in claims)}: key numbers and verdicts in the ledger."]
        if claims
        else []
    )
    h_hi = max(int(h) for h in a["H"].unique())

    def pct(v: float) -> str:
        return f"{fmt(100 * v, 2)}%" if v > 0 else "below the reference's noise"

    for model, s in a[a["H"] == h_hi].groupby("model", sort=False):
        ranked = s.sort_values("rel_rmse")
        t = r[(r["H"] == h_hi) & (r["model"] == model)]
        lo, hi = ranked.iloc[0], ranked.iloc[-1]
        out.append(
            f"At H = {h_hi} on '{model}' (all methods in table hz_uav_approx): lowest relative "
            f"RMSE {method_label(lo['method'])} {pct(float(lo['rel_rmse']))}, highest "
            f"{method_label(hi['method'])} {pct(float(hi['rel_rmse']))}; planning "
            f"{fmt(t['plan_ms'].min(), 2)} to {fmt(t['plan_ms'].max(), 2)} ms per step."
        )
    return " ".join(out)


def _budget_text(planner: Mapping[str, Any] | None, optimiser: pd.DataFrame | None) -> str:
    """Which regret the study shows: every planner at uav.planner's optimiser budget, and
    the pointer to the optimiser split (with its numbers at the largest H if given)."""
    budget = budget_text(planner)
    return (
        "Optimiser budget: every planner that optimises a plan (all but the tree search), in "
        "the open-loop regret and time and in the closed loop (HZ-3), runs at uav.planner's "
        "budget"
        + (f" ({budget})" if budget else "")
        + ", the same for every method and H, so its regret mixes cost-approximation and "
        "optimisation error. " + horizon_note(optimiser)
    )


_LQG_FIGURE = [
    "![Oven LQG at long horizons](figures/hz_lqg.png)",
    "",
    "*Oven LQG (exact oracle) against H: relative RMSE of each cost estimator (n = M "
    "trajectories each), Monte Carlo's mean regret with κ_H v_H / P (dashed) and its "
    "limit (dotted); bars: 95% CIs.*",
]

_FIGURE = [
    "![Closed loop by horizon](figures/hz_uav_closed.png)",
    "",
    "*Closed-loop mean location error − NBO's on the same runs (m), by horizon; bars: 95% "
    "t CIs over runs.*",
    "",
    "![Cost approximation by horizon](figures/hz_uav_error.png)",
    "",
    "*Relative RMSE (log scale, noise-corrected; below the reference's noise: drawn at "
    "0.001%) and bias of each cost estimate, by horizon; bars: 95% cluster-t CIs over runs.*",
    "",
    "![Planning time and regret by horizon](figures/hz_uav_time.png)",
    "",
    "*Median planning ms per step (log scale) and the open-loop regret against the best of "
    "the methods' own plans (%; it mixes cost-approximation and optimisation error), by "
    "horizon.*",
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
    closed_summary: pd.DataFrame | None = None,
    lqg_est: pd.DataFrame | None = None,
    lqg_est_summary: pd.DataFrame | None = None,
    lqg_regret_summary: pd.DataFrame | None = None,
    planner: Mapping[str, Any] | None = None,
    optimiser: pd.DataFrame | None = None,
) -> Section:
    """The horizon study's report section (order 33); ``cfg`` is ``horizon.uav``,
    ``lqg_cfg`` ``horizon.lqg``, ``a_model`` the oven model's a (``lqg.model.a``); the LQG
    simulation rows and summaries of :mod:`rsmhp.studies.horizon.summarise_lqg` (omitted: no
    HZ-4/5);
    ``planner``: ``uav.planner`` (the optimiser budget every planner runs at); ``optimiser``:
    the optimiser split's summary
    (:func:`rsmhp.studies.horizon.section_optimiser.optimiser_summary`;
    omitted: the text points to its section without its numbers)."""
    evidence = horizon_evidence(approx, approx_summary, cfg, seed, closed, planner)
    claims = [e.claim for e in evidence]
    empty = pd.DataFrame()
    est = lqg_est if lqg_est is not None else empty
    est_s = lqg_est_summary if lqg_est_summary is not None else empty
    reg_s = lqg_regret_summary if lqg_regret_summary is not None else empty
    lqg_claims = lqg_horizon_claims(est, reg_s, lqg_cfg, a_model, seed)
    hs = sorted(int(h) for h in cfg["H"])
    body = "\n".join(
        [
            _setting(cfg, hs),
            "",
            _findings(claims, approx_summary, regret_summary),
            "",
            _budget_text(planner, optimiser),
            "",
            _interval_text(evidence),
            "",
            _lqg_text(lqg_table, a_model, float(lqg_cfg["eps"])),
            "",
            *_FIGURE,
            "",
            *(_LQG_FIGURE if not est_s.empty else []),
        ]
    )
    claims = [*claims, *lqg_claims]
    appendix = "\n".join(
        [
            # moved from the main text (its size budget): runs needed, the simulated oven LQG
            _runs_text(closed_summary) if closed_summary is not None else "",
            "",
            _lqg_sim_text(est_s, reg_s, a_model),
            "",
            "Cost approximation per model, horizon and method (relative bias and RMSE of the "
            "cost estimate in percent of the reference cost, 95% cluster-t CIs over runs: "
            "jackknife leaving out one run with its belief states, t with runs − 1 df; the "
            "RMSE's is that of the mean square, square-rooted and floored at 0; "
            "'reference SE': the reference's own relative standard "
            "error, already "
            "subtracted from the RMSE; Spearman: rank correlation of estimate and reference "
            "over the plans, mean over states and replicates; 'constant': (state, replicate) "
            "pairs where the estimate does not change over the plans, left out of it):",
            "",
            tables["hz_uav_approx"],
            "",
            "Open-loop regret (percent of the best plan found) and planning time per model, "
            "horizon and method ('vs best of methods' plans': regret against the best of the "
            "plans the methods found themselves, at their common optimiser budget; it mixes "
            "each method's cost-approximation error with its optimisation error, split in "
            f"section '{SPLIT_TITLE}'):",
            "",
            tables["hz_uav_regret"],
            "",
            "Closed loop per model, horizon and method: mean location error over the paired "
            "runs and its paired difference with NBO (95% Student-t CI over runs), the SD of "
            "the paired differences over runs, 'runs for 80% power': the paired runs at which "
            "a paired t-test at 5% would detect a difference of the observed size with "
            "probability 0.8 (noncentral t, the observed mean difference and SD taken as the "
            "true ones, so optimistic where the observed difference is inflated by selection; "
            "'–' for NBO itself or beyond 10⁶ runs), planning ms per step (median over runs):",
            "",
            tables["hz_uav_closed"],
            "",
            *(
                [
                    "Intervals of the claims HZ-1..HZ-3: the published 95% cluster-t CI "
                    "(jackknife over runs, t with df = runs − 1) with the p-value of the "
                    "t-test of 0 behind the verdict (two-sided where the CI excludes 0; for an "
                    "inconclusive verdict towards the claimed side; before the ledger's Holm "
                    "correction), and the 95% percentile bootstrap over runs it replaced, with "
                    "the ratio of their widths and the verdict each gives:",
                    "",
                    _interval_table(evidence),
                    "",
                ]
                if evidence
                else []
            ),
            "Oven LQG at long horizons, closed forms (`rsmhp.models.lqg.horizon`; r, σ of the oven "
            "model): NBO's error limit r σ²/(1 − (1 − a)²) and the share of it reached at H; "
            "the first H at which the gain L_H = r a (1 − a)^(H−1) / (1 + r a² Σ_(n<H) "
            "(1 − a)^(2n)) of the paper's optimal first control L_H (T − (1 − a)^H x_0) is at "
            f"most eps = {fmt(float(lqg_cfg['eps']), 2)} of L_1; the stationary gain K∞ of the "
            "stage-cost "
            "variant (algebraic Riccati equation) and the first H whose first-step gain K_H "
            "is within eps of it:",
            "",
            tables["hz_lqg"],
            "",
            "Oven LQG simulated at long horizons (controls u*(H), exact J; "
            "`rsmhp.studies.horizon.simulate_lqg`): relative bias and RMSE of each cost estimator "
            "in percent of J with the RMSE's 95% bootstrap CI over replicates, and uniform "
            "Monte Carlo's closed form √(Var g / n)/J; n = trajectories (M kept for a pruned "
            "tree with N draws per level, run only where N^H > M); '–': no closed form:",
            "",
            tables["hz_lqg_estimators"],
            "",
            "Decision regret J(û) − J(u*) of the sample-average argmin at long horizons (mean "
            "over replicates with t-CI, closed form, its limit as H → ∞, z of the mean against "
            "the closed form; '–': none):",
            "",
            tables["hz_lqg_regret"],
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
