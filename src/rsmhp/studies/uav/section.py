"""UAV study, report section (paper Sec. III-B, Figs. 4-5): the Markdown tables, a short body
(what was run, symbols, findings, the paper-style CDFs each followed by its paired view) and
the appendix (model, tables), assembled from the statistics of :mod:`rsmhp.studies.uav.summarise`
and the claims of :mod:`rsmhp.studies.uav.claims`."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.models.uav import methods as registry
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.models.uav.methods.pruned_tree import PrunedTree
from rsmhp.report.ledger import VERDICTS, Claim, Section
from rsmhp.report.markdown import fmt, fmt_ci, markdown_table, param_text
from rsmhp.report.palette import method_label
from rsmhp.studies.uav.claims import uav_claims
from rsmhp.studies.uav.summarise import family_rows, figure_notes, is_family

__all__ = ["FIGURES", "uav_section", "uav_tables"]

#: how the appendix names the planner's optimiser (config ``uav.planner.optimiser``)
OPTIMISER_TEXT = {
    "boxqn": "a projected L-BFGS (`rsmhp.core.boxqn`, compiled, scipy's tolerances)",
    "scipy": "scipy's L-BFGS-B",
}

#: figure stems written by the figure rule and referenced by the report section, in the order
#: of the section: each paper-style CDF is followed by its paired view
FIGURES = ("uav_error_cdf_nt", "uav_paired_diff_nt", "uav_error_cdf_nbo", "uav_paired_diff")


def uav_tables(summary: pd.DataFrame, paired: pd.DataFrame) -> dict[str, str]:
    """Markdown tables keyed by file stem (``results/tables/<stem>.md``): per method, and the
    paired comparisons (a Wilcoxon p that is undefined prints as ``n/a``, explained below)."""
    methods = pd.DataFrame(
        {
            "method": summary["label"],
            "runs": summary["n_runs"].astype(int),
            "mean e (m)": summary["mean"],
            "CI low": summary["ci_low"],
            "CI high": summary["ci_high"],
            "median e (m)": summary["median"],
            "median CI low": summary["median_low"],
            "median CI high": summary["median_high"],
            "SD of e (m)": summary["sd"],
            "RMSE (m)": summary["mean_rmse"],
            "mean tr P̂": summary["mean_trace"],
            "planner s/run": summary["plan_seconds_per_run"],
        }
    )
    pairs = pd.DataFrame(
        {
            "comparison A − B": paired["comparison"],
            "purpose": paired["purpose"],
            "runs": paired["n_runs"].astype(int),
            "mean d (m)": paired["mean_diff"],
            "CI low": paired["ci_low"],
            "CI high": paired["ci_high"],
            "median d (m)": paired["median_diff"],
            "SD of d (m)": paired["sd_diff"],
            "runs d < 0": paired["n_better"].astype(int),
            "Wilcoxon p": paired["wilcoxon_p"],
        }
    )
    signed = ("mean d (m)", "CI low", "CI high", "median d (m)")
    ptable = markdown_table(pairs, digits=3, missing="n/a", signed=signed)
    if paired["wilcoxon_p"].isna().any():
        ptable += "\n\nn/a: every paired difference is 0, the signed-rank test is undefined."
    return {"uav_methods": markdown_table(methods, digits=4), "uav_paired": ptable}


def _num(x: float) -> str:
    """A configuration number as given: integer-valued numbers without decimals (``1``, not
    ``1.00``), others with at most 3 significant digits and no trailing zeros."""
    xf = float(x)
    if xf.is_integer():
        return fmt(int(xf))
    out = fmt(xf)
    return out if "e" in out else out.rstrip("0").rstrip(".")


def _variant_note(sensor: Mapping[str, Any]) -> str:
    """A sentence naming the model variant when the sensor is not the reconstruction's."""
    parts = []
    if sensor.get("footprint_radius") is not None:
        parts.append(
            f"a sensor footprint of radius {_num(sensor['footprint_radius'])} m (truth detections "
            f"{sensor.get('detection', 'hard')}, planner width "
            f"{_num(sensor.get('footprint_width', 10))} m)"
        )
    if sensor.get("noise_growth", "linear") != "linear":
        parts.append(
            f"noise growing quadratically with distance (reference "
            f"{_num(sensor.get('reference_distance', 100))} m)"
        )
    if not parts:
        return ""
    return " **Model variant, not the paper's model:** " + "; ".join(parts) + "."


def _caption(text: str, note: str) -> str:
    return f"*{text}{'; ' + note if note else ''}.*"


def _methods_run(summary: pd.DataFrame) -> list[str]:
    """The methods run, in words: NBO, RS-MHP with its N_T values, each pruned tree, then any
    other registered family's members by their labels."""
    rs = family_rows(summary, MonteCarlo)
    nts = ", ".join(str(int(n)) for n in rs["N_T"])
    out = ["NBO (one nominal, noise-free target hypothesis)"]
    if len(rs):
        out.append(f"RS-MHP with N_T ∈ {{{nts}}} independently sampled target trajectories")
    out += [
        f"a pruned tree ({int(t['N'])} draws per level, the {int(t['M'])} most likely kept)"
        for _, t in family_rows(summary, PrunedTree).iterrows()
    ]
    described = (registry.baseline(), MonteCarlo, PrunedTree)
    other = ~np.logical_or.reduce([is_family(summary["method"], c) for c in described])
    return out + [method_label(m) for m in summary.loc[other, "method"]]


def _findings(claims: Sequence[Claim], summary: pd.DataFrame, margin: float) -> str:
    """The body's findings: spread of the method means, key numbers, the equivalence margin
    and its justification, why the numbers are what they are (every number from the summary
    and the claims)."""
    n_runs = int(summary["n_runs"].max())
    counts = {v: sum(c.verdict == v for c in claims) for v in ("equivalent", "inconclusive")}
    verdicts = "; ".join(
        f"{c.id} {fmt(c.key.value, 2, True)} {fmt_ci(c.key.ci_low, c.key.ci_high, 2, True)} m "
        f"({c.verdict})"
        for c in claims
    )
    mean_e, sd_e = float(summary["mean"].mean()), float(summary["sd"].median())
    spread = (
        f"Mean e of every method lies in [{fmt(summary['mean'].min(), 4)}, "
        f"{fmt(summary['mean'].max(), 4)}] m, while e varies between runs with SD "
        f"{fmt(sd_e, 2)} m. "
    )
    half = float(np.median([(c.key.ci_high - c.key.ci_low) / 2 for c in claims] or [0.0]))
    pct = 100 * half / mean_e
    margin_text = (
        f"The equivalence margin Δ = {param_text(margin)} m (fixed in the config before the "
        f"run) is {fmt(100 * margin / mean_e, 2)}% of the mean error and "
        f"{fmt(margin / sd_e, 2)} of its run-to-run SD; a difference below Δ is treated as "
        "none. "
    )
    decided = [f"{c.id} ({c.verdict})" for c in claims if c.verdict in VERDICTS[:2]]
    figures = {"UAV-1": "Fig. 4", "UAV-2": "Fig. 5"}
    absent = [
        f"{figures[c.id]} ({c.id})" for c in claims if c.verdict == "equivalent" and c.id in figures
    ]
    n_inc = counts["inconclusive"]
    why = (
        f"{counts['equivalent']} of {len(claims)} CIs lie inside ±Δ and {n_inc} "
        f"{'contains' if n_inc == 1 else 'contain'} 0 without fitting inside it ({n_runs} "
        f"paired runs, CI half-width about {fmt(half, 2)} m, {fmt(pct, 2)}% of mean e)"
        + (f"; CIs on one side of 0: {', '.join(decided)}" if decided else "")
        + (
            f": on this reconstruction the difference of {' and '.join(absent)} does not "
            "appear at that resolution. "
            if absent
            else ". "
        )
    )
    return (
        f"**Found.** {spread}Key numbers d̄ (CI): {verdicts}. {margin_text}{why}"
        "The decision study compares the plans themselves (DEC-6, DEC-8)."
    )


def _figures(summary: pd.DataFrame, notes: Mapping[str, tuple[float, float, str]]) -> list[str]:
    """The four figures with their captions (each caption counts what its range leaves out)."""
    rs = family_rows(summary, MonteCarlo)
    nts = ", ".join(str(int(n)) for n in rs["N_T"])
    big = method_label(rs["method"].iloc[-1]) if len(rs) else "RS-MHP"

    def note(stem: str) -> str:
        return notes.get(stem, (0, 0, ""))[2]

    return [
        "![Fig. 4 counterpart](figures/uav_error_cdf_nt.png)",
        "",
        _caption(
            f"Paper Fig. 4 drawn the paper's way: CDF of e_r, RS-MHP N_T = {nts}",
            note("uav_error_cdf_nt"),
        ),
        "",
        "![paired differences, N_T and pruning](figures/uav_paired_diff_nt.png)",
        "",
        _caption(
            "Paired view of Fig. 4: d_r for larger − smaller N_T (UAV-1) and RS-MHP − "
            "pruned tree (UAV-3), with d̄ and CI",
            note("uav_paired_diff_nt"),
        ),
        "",
        "![Fig. 5 counterpart](figures/uav_error_cdf_nbo.png)",
        "",
        _caption(
            f"Paper Fig. 5 drawn the paper's way: CDF of e_r, NBO vs {big}",
            note("uav_error_cdf_nbo"),
        ),
        "",
        "![paired differences to NBO](figures/uav_paired_diff.png)",
        "",
        _caption(
            "Paired view of Fig. 5: d_r = e_r(method) − e_r(NBO) with d̄ and CI (UAV-2)",
            note("uav_paired_diff"),
        ),
    ]


def _body(
    margin: float,
    claims: Sequence[Claim],
    summary: pd.DataFrame,
    setting: Mapping[str, Any],
    n_boot: int,
    notes: Mapping[str, tuple[float, float, str]],
) -> str:
    sc, pl = setting["scenario"], setting["planner"]
    n_runs = int(summary["n_runs"].max())
    run = (
        f"**Run.** {n_runs} closed-loop runs × {sc['steps']} steps (Δt = "
        f"{_num(setting['dt'])} s) per method: a UAV tracks a ground target with a noisy "
        "position sensor and a Kalman filter; at every step it plans H = "
        f"{pl['horizon']} controls minimising Σ_{{k=1..H}} tr P_k (P_k: tracker covariance "
        "predicted k steps ahead along a target hypothesis) averaged over the method's "
        f"hypotheses: {', '.join(_methods_run(summary))}. The paper fixes only H = 6 and N_T; "
        "the rest is our reconstruction (appendix). All methods face the "
        "same scenario and noise in a run (paired design)." + _variant_note(setting["sensor"])
    )
    symbols = (
        "**Symbols.** e_r = (1/K) Σ_k ‖p̂_k − p_k‖ (m): average target location error of "
        "run r over its K steps (p̂_k estimate, p_k true position). Paired difference d_r = "
        "e_r(A) − e_r(B) (< 0: A better), mean d̄ over runs; CI: 95% percentile bootstrap "
        f"of d̄ ({n_boot} resamples of runs); p: Wilcoxon signed-rank p-value of d."
    )
    return "\n".join(
        [run, "", symbols, "", _findings(claims, summary, margin), "", *_figures(summary, notes)]
    )


def _appendix(setting: Mapping[str, Any], tables: Mapping[str, str]) -> str:
    ac, sc, pl = setting["aircraft"], setting["scenario"], setting["planner"]
    sp, sv = _num(setting["tracker"]["p0_pos_sd"]), _num(setting["tracker"]["p0_vel_sd"])
    model = (
        f"Model: Δt = {_num(setting['dt'])} s; UAV at {_num(ac['altitude'])} m altitude, "
        f"controls |a| ≤ {_num(ac['accel_max'])} m/s², |φ| ≤ {_num(ac['bank_max_deg'])}°, "
        f"speed in [{_num(ac['speed_min'])}, {_num(ac['speed_max'])}] m/s; target: nearly "
        f"constant velocity (NCV), q = {_num(setting['target']['q'])} m²/s³; position sensor "
        f"with range SD σ_r = {_num(setting['sensor']['sigma_r_per_m'])} d and cross-range "
        f"SD σ_c = {_num(setting['sensor']['sigma_c_per_m'])} d (d: 3-D UAV–target "
        f"distance); Kalman filter with P0 = diag({sp}², {sp}², {sv}², {sv}²). Planner: "
        f"horizon H = {pl['horizon']}, cost Σ_{{k=1..H}} tr P_k (P_k: 4×4 covariance "
        "predicted along a target hypothesis) averaged over the hypotheses, "
        f"{OPTIMISER_TEXT[pl.get('optimiser', 'boxqn')]} on "
        f"the control box with at most {pl['maxiter']} iterations / {pl['maxfun']} "
        "evaluations, exact gradient, warm start from the shifted previous plan; identical "
        "for every method." + _variant_note(setting["sensor"])
    )
    return "\n".join(
        [
            "The paper gives only H = 6 and N_T ∈ {50, 100, 250}; every other number is this "
            "project's reconstruction (`config/config.yaml`, section `uav`; model in "
            "`rsmhp.models.uav`).",
            "",
            model,
            "",
            f"Scenarios: target speed {_num(sc['target_speed_min'])}-"
            f"{_num(sc['target_speed_max'])} m/s, UAV {_num(sc['uav_distance_min'])}-"
            f"{_num(sc['uav_distance_max'])} m away at {_num(sc['uav_speed'])} m/s; scenario, "
            "truth noise and measurement noise of run r come from streams keyed on r only.",
            "",
            "Per method (e in m; CIs: 95% percentile bootstrap over runs; tr P̂: trace of the "
            "tracker's 4×4 covariance, m² + m²/s²; planner s/run: wall time, varies between "
            "executions):",
            "",
            tables["uav_methods"],
            "",
            "Paired differences d = e(A) − e(B) (m; negative: A has the lower error):",
            "",
            tables["uav_paired"],
        ]
    )


def uav_section(
    summary: pd.DataFrame,
    paired: pd.DataFrame,
    tables: Mapping[str, str],
    setting: Mapping[str, Any],
    n_boot: int,
    runs: pd.DataFrame,
    margin: float,
) -> Section:
    """The UAV report section (order 20): a short body (what was run, symbols, findings, the
    paper-style CDFs each followed by its paired view) and an appendix (model, tables);
    ``margin`` is the claims' equivalence margin (m)."""
    claims = uav_claims(summary, paired, margin)
    notes = figure_notes(runs, summary, paired)
    return Section(
        key="uav",
        title="Case study 2: UAV target tracking (paper Sec. III-B, Figs. 4-5)",
        order=20,
        body=_body(margin, claims, summary, setting, n_boot, notes),
        claims=claims,
        figures=[f"{f}.png" for f in FIGURES],
        appendix=_appendix(setting, tables),
    )
