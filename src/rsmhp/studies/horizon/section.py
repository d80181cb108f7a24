"""UAV horizon study, report section (order 33, "Long horizons"): the Markdown tables of the
cost approximation and of regret and time by horizon, a short body (setting, findings,
figures) and the appendix, from :mod:`rsmhp.studies.horizon.summarise_uav` and the claims of
:mod:`rsmhp.studies.horizon.claims`. Every number is read from the tables or the claims. The
prose is in the Markdown templates beside this module (``section.md``, the main text;
``section_appendix.md``; ``lqg_limits.md``); this module computes the values they are filled
with (:mod:`rsmhp.report.templates`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.report.ledger import Claim, Section
from rsmhp.report.markdown import ci_cells, fmt, markdown_table, range_text
from rsmhp.report.palette import method_label
from rsmhp.report.templates import render
from rsmhp.studies.horizon import TABLES
from rsmhp.studies.horizon.claims import (
    PrimaryTest,
    budget_text,
    horizon_evidence,
    lqg_horizon_claims,
)
from rsmhp.studies.horizon.figures import FIGURES
from rsmhp.studies.horizon.section_optimiser import TITLE as SPLIT_TITLE
from rsmhp.studies.horizon.section_optimiser import horizon_note

__all__ = ["FIGURES", "TABLES", "HorizonInputs", "horizon_section", "horizon_tables"]


_PACKAGE = "rsmhp.studies.horizon"


def horizon_tables(
    approx_summary: pd.DataFrame,
    regret_summary: pd.DataFrame,
    lqg_table: pd.DataFrame,
    closed_summary: pd.DataFrame,
    lqg_estimators: pd.DataFrame,
    lqg_regret: pd.DataFrame,
) -> dict[str, str]:
    """Markdown tables ``horizon_uav_approx`` (per model, H and method: relative bias and RMSE of
    the cost estimate in percent with cluster-t CIs over runs, the reference's relative SE,
    rank correlation), ``horizon_uav_regret`` (relative regret against the best plan found and
    against the best of the methods' own plans, planning ms), ``horizon_uav_closed`` (closed-loop
    error and its paired difference with NBO with a t CI over runs, the runs a confirmatory
    comparison needs for 80% power at the observed difference), ``horizon_lqg``
    (:func:`rsmhp.studies.horizon.summarise_uav.lqg_horizon_table`), ``horizon_lqg_estimators``
    (oven LQG: relative bias and RMSE of each estimator against the exact J by a and H,
    :func:`rsmhp.studies.horizon.summarise_lqg.summarize_lqg_estimators`) and ``horizon_lqg_regret``
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
        "horizon_uav_approx": markdown_table(t1, digits=3, missing="undefined", signed=("bias %",)),
        "horizon_uav_regret": markdown_table(t2, digits=3),
        "horizon_uav_closed": markdown_table(t4, digits=3, missing="–", signed=("− NBO (m)",)),
        "horizon_lqg": markdown_table(t3, digits=4),
        "horizon_lqg_estimators": markdown_table(t5, digits=3, missing="–", signed=("bias %",)),
        "horizon_lqg_regret": markdown_table(t6, digits=3, missing="–"),
    }


def _render(template: str, **values: Any) -> str:
    """The template ``template`` beside this module (:func:`rsmhp.report.templates.render`)
    filled with ``values``, without the newline that ends the file: a paragraph or a section
    text, not a file."""
    return render(_PACKAGE, template, **values).removesuffix("\n")


@dataclass(frozen=True, eq=False)
class HorizonInputs:
    """What the long-horizon section is made from (rule ``horizon_summary``).

    ``approx``: the approximation rows of :mod:`rsmhp.studies.horizon.simulate_uav`;
    ``approx_summary``, ``regret_summary``, ``closed_summary``: their summaries
    (:mod:`rsmhp.studies.horizon.summarise_uav`); ``tables``: :func:`horizon_tables`; ``cfg``:
    ``horizon.uav``; ``seed``: the study's seed; ``lqg_table``:
    :func:`rsmhp.studies.horizon.summarise_uav.lqg_horizon_table`; ``lqg_cfg``:
    ``horizon.lqg``; ``a_model``: the oven model's a (``lqg.model.a``); ``closed``: the
    closed-loop rows (omitted: no HZ-3); ``lqg_est``, ``lqg_est_summary``,
    ``lqg_regret_summary``: the LQG simulation rows and summaries of
    :mod:`rsmhp.studies.horizon.summarise_lqg` (omitted: no HZ-4/5); ``planner``:
    ``uav.planner`` (the optimiser budget every planner runs at); ``optimiser``: the optimiser
    split's summary (:func:`rsmhp.studies.horizon.section_optimiser.optimiser_summary`;
    omitted: the text points to its section without its numbers)."""

    approx: pd.DataFrame
    approx_summary: pd.DataFrame
    regret_summary: pd.DataFrame
    tables: Mapping[str, str]
    cfg: Mapping[str, Any]
    seed: int
    lqg_table: pd.DataFrame
    lqg_cfg: Mapping[str, Any]
    a_model: float
    closed: pd.DataFrame | None = None
    closed_summary: pd.DataFrame | None = None
    lqg_est: pd.DataFrame | None = None
    lqg_est_summary: pd.DataFrame | None = None
    lqg_regret_summary: pd.DataFrame | None = None
    planner: Mapping[str, Any] | None = None
    optimiser: pd.DataFrame | None = None


def _lqg_text(q: pd.DataFrame, a_model: float, eps: float) -> str:
    """The oven LQG at long horizons for the model's a (closed forms, table horizon_lqg;
    ``lqg_limits.md``)."""
    row = q.iloc[int(np.argmin(np.abs(q["a"].to_numpy(float) - a_model)))]
    shares = [c for c in q.columns if c.startswith("nbo_share_H")]
    return _render(
        "lqg_limits.md",
        a=fmt(float(row["a"]), 2),
        shares=[
            {"share": fmt(float(row[c]), 4), "H": c.removeprefix("nbo_share_H")} for c in shares
        ],
        limit=fmt(float(row["nbo_limit"]), 4),
        eps=fmt(100 * eps, 2),
        vanishing=int(row["vanishing_H"]),
        vanishing_min=int(q["vanishing_H"].min()),
        vanishing_max=int(q["vanishing_H"].max()),
        a_min=fmt(float(q["a"].min()), 2),
        a_max=fmt(float(q["a"].max()), 2),
        stationary=int(row["stationary_H"]),
        stationary_min=int(q["stationary_H"].min()),
        stationary_max=int(q["stationary_H"].max()),
    )


def _lqg_sim_values(est: pd.DataFrame, reg: pd.DataFrame, a_model: float) -> dict | None:
    """The simulated oven LQG at long horizons (tables horizon_lqg_estimators, horizon_lqg_regret),
    at the model's a (or the nearest simulated a); None without simulation rows. ``trees``: the
    pruned trees per N; ``decisions``: uniform Monte Carlo's regret (None without it);
    ``weighted``: the likeliness-weighted cell farthest from its first-order form (None
    unless some |z| > 3)."""
    if est.empty:
        return None
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
    values: dict[str, Any] = {
        "a": fmt(a, 2),
        "n": n_max,
        "h_lo": h_lo,
        "h_hi": h_hi,
        "mc_lo": rmse("mc", h_lo, n_max),
        "mc_hi": rmse("mc", h_hi, n_max),
        "rqmc_lo": rmse("sobol", h_lo, n_max),
        "rqmc_hi": rmse("sobol", h_hi, n_max),
        "nbo_lo": fmt(100 * float(nbo.loc[h_lo]), 3),
        "nbo_hi": fmt(100 * float(nbo.loc[h_hi]), 3),
        "trees": [],
        "decisions": None,
        "weighted": None,
    }
    for N in sorted(int(x) for x in trees["N"].unique()):
        t = trees[trees["N"] == N].set_index("H")["rel_rmse"].sort_index()
        values["trees"].append(
            {
                "N": N,
                "first": fmt(100 * float(t.iloc[0]), 3),
                "h_first": int(t.index[0]),
                "last": fmt(100 * float(t.iloc[-1]), 3),
                "h_last": int(t.index[-1]),
            }
        )
    g = reg[(reg["a"] == a)]
    mc = g[(g["method"] == "mc") & (g["weighting"] == "uniform")]
    w = g[(g["method"] == "mc") & (g["weighting"] == "likeliness")]
    if not mc.empty:
        p_max = int(mc["P"].max())
        m1 = mc[mc["P"] == p_max].set_index("H")
        values["decisions"] = {
            "P": p_max,
            "mean_lo": fmt(float(m1.loc[h_lo, "mean"]), 3),
            "mean_hi": fmt(float(m1.loc[h_hi, "mean"]), 3),
            "closed_lo": fmt(float(m1.loc[h_lo, "closed_form"]), 3),
            "closed_hi": fmt(float(m1.loc[h_hi, "closed_form"]), 3),
            "limit": fmt(float(m1.loc[h_hi, "limit"]), 3),
        }
    if not w.empty:
        bad = w[w["z"].abs() > 3.0]
        if len(bad):
            worst = bad.loc[bad["z"].abs().idxmax()]
            values["weighted"] = {
                "cells_off": len(bad),
                "cells": len(w),
                "z": fmt(float(worst["z"]), 3, True),
                "H": int(worst["H"]),
                "P": int(worst["P"]),
                "mean": fmt(float(worst["mean"]), 3),
                "closed": fmt(float(worst["closed_form"]), 3),
            }
    return values


def _runs_values(closed_summary: pd.DataFrame | None) -> list[dict[str, Any]] | None:
    """Per model, how many runs the closed-loop comparisons used and would need (column
    'runs for 80% power' of horizon_uav_closed): ``need`` the finite counts of the unresolved
    comparisons (None if none is finite), ``beyond`` how many need more than 10⁶ runs; None
    without closed-loop counts."""
    if closed_summary is None:
        return None
    c = closed_summary[closed_summary["runs_to_resolve"].notna()]
    if c.empty:
        return None
    out = []
    for model, g in c.groupby("model", sort=False):
        half = (g["error_diff_high"] - g["error_diff_low"]) / 2
        resolved = (g["error_diff_low"] > 0) | (g["error_diff_high"] < 0)
        need = g.loc[~resolved, "runs_to_resolve"]
        finite = need[np.isfinite(need)]
        out.append(
            {
                "model": model,
                "runs": int(g["runs"].min()),
                "half_min": fmt(float(half.min()), 2),
                "half_max": fmt(float(half.max()), 2),
                "resolved": int(resolved.sum()),
                "cells": len(g),
                "need": (
                    {
                        "min": int(finite.min()),
                        "max": int(finite.max()),
                        "median": int(finite.median()),
                    }
                    if len(finite)
                    else None
                ),
                "beyond": int(len(need) - len(finite)),
            }
        )
    return out


def _interval_values(evidence: Sequence[PrimaryTest]) -> dict[str, Any] | None:
    """How the change from the percentile bootstrap over runs to the cluster-t CI changed
    the intervals of HZ-1..HZ-3 (``ratio``: the range of their width ratios, None if none is
    finite) and which verdicts it moved; None without claims."""
    if not evidence:
        return None
    ratio = [_width_ratio(e) for e in evidence]
    ratio = [r for r in ratio if np.isfinite(r)]
    return {
        "claims": ", ".join(e.claim.id for e in evidence),
        "ratio": range_text(ratio, 3) if ratio else None,
        "moved": [
            {"claim": e.claim.id, "bootstrap": e.boot_verdict, "verdict": e.claim.verdict}
            for e in evidence
            if e.boot_verdict != e.claim.verdict
        ],
    }


def _width_ratio(e: PrimaryTest) -> float:
    k = e.claim.key
    boot = e.boot_high - e.boot_low
    return (k.ci_high - k.ci_low) / boot if boot > 0 else float("nan")


def _interval_table(evidence: Sequence[PrimaryTest]) -> str:
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


def _setting_values(cfg: Mapping[str, Any]) -> dict[str, Any]:
    hs = sorted(int(h) for h in cfg["H"])
    return {
        "horizons": "{" + ", ".join(str(h) for h in hs) + "}",
        "models": ", ".join(repr(m) for m in cfg["models"]),
        "runs": int(cfg["runs"]),
        "plans": int(cfg["plans"]),
        "n_ref": int(cfg["n_ref"]),
        "replicates": int(cfg["replicates"]),
        "closed_runs": int(cfg["closed_runs"]),
    }


def _findings_values(claims: Sequence[Claim], a: pd.DataFrame, r: pd.DataFrame) -> dict:
    """The claims' ids and, per model at the largest H, the methods of lowest and highest
    relative RMSE (in %, None where it is below the reference's noise) and the range of
    planning ms per step."""
    h_hi = max(int(h) for h in a["H"].unique())

    def pct(v: float) -> str | None:
        return fmt(100 * v, 2) if v > 0 else None

    extremes = []
    for model, s in a[a["H"] == h_hi].groupby("model", sort=False):
        ranked = s.sort_values("rel_rmse")
        t = r[(r["H"] == h_hi) & (r["model"] == model)]
        lo, hi = ranked.iloc[0], ranked.iloc[-1]
        extremes.append(
            {
                "model": model,
                "lowest": method_label(lo["method"]),
                "lowest_rmse": pct(float(lo["rel_rmse"])),
                "highest": method_label(hi["method"]),
                "highest_rmse": pct(float(hi["rel_rmse"])),
                "plan_min": fmt(t["plan_ms"].min(), 2),
                "plan_max": fmt(t["plan_ms"].max(), 2),
            }
        )
    return {"claim_ids": ", ".join(c.id for c in claims), "h_hi": h_hi, "extremes": extremes}


def horizon_section(inputs: HorizonInputs) -> Section:
    """The horizon study's report section (order 33) from ``inputs``
    (:class:`HorizonInputs`): its claims (:mod:`rsmhp.studies.horizon.claims`), the main text
    ``section.md`` and the appendix ``section_appendix.md``."""
    i = inputs
    evidence = horizon_evidence(i.approx, i.approx_summary, i.cfg, i.seed, i.closed, i.planner)
    claims = [e.claim for e in evidence]
    empty = pd.DataFrame()
    est = i.lqg_est if i.lqg_est is not None else empty
    est_s = i.lqg_est_summary if i.lqg_est_summary is not None else empty
    reg_s = i.lqg_regret_summary if i.lqg_regret_summary is not None else empty
    lqg_claims = lqg_horizon_claims(est, reg_s, i.lqg_cfg, i.a_model, i.seed)
    body = _render(
        "section.md",
        **_setting_values(i.cfg),
        **_findings_values(claims, i.approx_summary, i.regret_summary),
        budget=budget_text(i.planner),
        optimiser_note=horizon_note(i.optimiser),
        intervals=_interval_values(evidence),
        lqg_limits=_lqg_text(i.lqg_table, i.a_model, float(i.lqg_cfg["eps"])),
        lqg_figure=not est_s.empty,
    )
    # the appendix holds what the main text's size budget leaves out: the runs needed, the
    # simulated oven LQG, every table
    appendix = _render(
        "section_appendix.md",
        runs=_runs_values(i.closed_summary),
        lqg_sim=_lqg_sim_values(est_s, reg_s, i.a_model),
        tables=i.tables,
        split_title=SPLIT_TITLE,
        intervals=_interval_table(evidence) if evidence else None,
        eps=fmt(float(i.lqg_cfg["eps"]), 2),
    )
    return Section(
        key="horizon",
        title="Long horizons: UAV cost approximation, decisions and time",
        order=33,
        body=body,
        claims=[*claims, *lqg_claims],
        figures=list(FIGURES),
        appendix=appendix,
    )
