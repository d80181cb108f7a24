r"""Aggregation of the UAV Monte-Carlo study: per-method summaries, paired differences, claims.

Statistics (all on the per-run metric ``mean_error``, the paper's average target location
error, in metres):

* per method: mean and median with 95% percentile-bootstrap CIs (``B`` resamples of runs);
* paired differences ``d_r = e_r(method) - e_r(baseline)`` over the runs both share (same
  scenario and noise, :mod:`rsmhp.uav.simulation`): mean with a 95% percentile-bootstrap CI,
  median, fraction of runs where the method is better, and the two-sided Wilcoxon signed-rank
  p-value (``scipy.stats.wilcoxon``).

Bootstrap resamples come from ``job_rng(seed, "uav_bootstrap", statistic=..., method=...,
baseline=...)``: the same inputs give the same intervals.

Verdict rules (stated once, applied mechanically)
-------------------------------------------------
For a claim "A has lower error than B" with paired differences ``d = e(A) - e(B)``:
*supported* if the 95% bootstrap CI of the mean of ``d`` lies entirely below 0, *not
supported* if it lies entirely above 0, *inconclusive* otherwise (no detectable difference
at this number of runs; the CI says how large a difference is still compatible with the data).

* **UAV-1** (Fig. 4: error falls as N_T grows): A = RS-MHP with the largest N_T, B = RS-MHP with
  the smallest N_T (consecutive N_T pairs are reported alongside, not used in the verdict).
* **UAV-2** (Fig. 5: RS-MHP beats NBO): A = RS-MHP with the largest N_T, B = NBO (the other N_T
  are reported alongside).
* **UAV-3** (Sec. III-B remark: pruning degrades RS-MHP): A = RS-MHP with N_T = M
  (non-overlapping), B = the pruned tree keeping M trajectories; only if both were run.
"""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
from scipy import stats as sps

from rsmhp.report import Claim, Section, claims_list
from rsmhp.seeding import job_rng

__all__ = [
    "FIGURES",
    "bootstrap_ci",
    "method_label",
    "paired_differences",
    "summarize_methods",
    "uav_claims",
    "uav_section",
    "uav_tables",
]

#: figure stems written by the figure rule and referenced by the report section
FIGURES = ("uav_error_cdf_nt", "uav_error_cdf_nbo", "uav_paired_diff")


def method_label(row: pd.Series | dict) -> str:
    """Human-readable method name: ``NBO``, ``RS-MHP N_T=50``, ``tree N=8 M=100``."""
    fam = row["family"]
    if fam == "nbo":
        return "NBO"
    if fam == "rsmhp":
        return f"RS-MHP N_T={int(row['N_T'])}"
    return f"pruned tree N={int(row['N'])} M={int(row['M'])}"


def bootstrap_ci(
    x: np.ndarray, rng: np.random.Generator, n_boot: int, level: float, stat=np.mean
) -> tuple[float, float]:
    """Percentile bootstrap CI of ``stat`` over resamples of ``x`` (with replacement)."""
    x = np.asarray(x, dtype=float)
    idx = rng.integers(0, x.size, size=(n_boot, x.size))
    boots = stat(x[idx], axis=1)
    lo, hi = np.quantile(boots, [0.5 - level / 2, 0.5 + level / 2])
    return float(lo), float(hi)


def _methods(runs: pd.DataFrame) -> pd.DataFrame:
    """One row per method (method, family, N_T, N, M), NBO first, then RS-MHP by N_T, trees."""
    meta = runs[["method", "family", "N_T", "N", "M"]].drop_duplicates("method")
    order = {"nbo": 0, "rsmhp": 1, "tree": 2}
    meta = meta.assign(_o=meta["family"].map(order))
    return meta.sort_values(["_o", "N_T", "N", "M"]).drop(columns="_o").reset_index(drop=True)


def summarize_methods(
    runs: pd.DataFrame, seed: int, n_boot: int, level: float = 0.95
) -> pd.DataFrame:
    """Per method: runs, mean and median of ``mean_error`` with bootstrap CIs, mean RMSE and
    tr P, planner wall time per step (seconds; not deterministic)."""
    rows = []
    for _, meta in _methods(runs).iterrows():
        grp = runs[runs["method"] == meta["method"]]
        err = grp["mean_error"].to_numpy()
        rng = job_rng(seed, "uav_bootstrap", statistic="per_method", method=meta["method"])
        lo, hi = bootstrap_ci(err, rng, n_boot, level)
        mlo, mhi = bootstrap_ci(err, rng, n_boot, level, stat=np.median)
        rows.append(
            {
                **meta.to_dict(),
                "label": method_label(meta),
                "n_runs": len(grp),
                "mean": float(err.mean()),
                "ci_low": lo,
                "ci_high": hi,
                "median": float(np.median(err)),
                "median_low": mlo,
                "median_high": mhi,
                "mean_rmse": float(grp["rmse"].mean()),
                "mean_trace": float(grp["mean_trace"].mean()),
                "plan_seconds_per_run": float(grp["plan_seconds"].mean()),
            }
        )
    return pd.DataFrame(rows)


def comparison_pairs(runs: pd.DataFrame) -> list[tuple[str, str, str]]:
    """(method, baseline, purpose) pairs: every method vs NBO, RS-MHP N_T trend (consecutive
    and largest vs smallest), and each pruned tree vs RS-MHP with N_T = M."""
    meta = _methods(runs)
    pairs = []
    names = meta["method"].tolist()
    if "nbo" in names:
        pairs += [(m, "nbo", "vs NBO") for m in names if m != "nbo"]
    rs = meta[meta["family"] == "rsmhp"].sort_values("N_T")["method"].tolist()
    pairs += [(b, a, "N_T trend") for a, b in itertools.pairwise(rs)]
    if len(rs) > 2:
        pairs.append((rs[-1], rs[0], "N_T trend"))
    for _, t in meta[meta["family"] == "tree"].iterrows():
        twin = meta[(meta["family"] == "rsmhp") & (meta["N_T"] == t["M"])]
        if len(twin):
            pairs.append((twin["method"].iloc[0], t["method"], "pruning"))
    return pairs


def paired_differences(
    runs: pd.DataFrame, seed: int, n_boot: int, level: float = 0.95
) -> pd.DataFrame:
    """Paired differences ``method - baseline`` of ``mean_error`` per run (see module doc)."""
    wide = runs.pivot(index="run", columns="method", values="mean_error")
    labels = {m["method"]: method_label(m) for _, m in _methods(runs).iterrows()}
    rows = []
    for method, base, purpose in comparison_pairs(runs):
        pair = wide[[method, base]].dropna()
        d = (pair[method] - pair[base]).to_numpy()
        rng = job_rng(seed, "uav_bootstrap", statistic="paired", method=method, baseline=base)
        lo, hi = bootstrap_ci(d, rng, n_boot, level)
        p = float(sps.wilcoxon(d).pvalue) if np.any(d != 0) else float("nan")
        rows.append(
            {
                "method": method,
                "baseline": base,
                "comparison": f"{labels[method]} − {labels[base]}",
                "purpose": purpose,
                "n_runs": d.size,
                "mean_diff": float(d.mean()),
                "ci_low": lo,
                "ci_high": hi,
                "median_diff": float(np.median(d)),
                "frac_better": float(np.mean(d < 0)),
                "wilcoxon_p": p,
            }
        )
    return pd.DataFrame(rows)


def _verdict(row: pd.Series) -> str:
    """'A better than B' for d = A - B: CI below 0 supported, above 0 not supported."""
    if row["ci_high"] < 0:
        return "supported"
    if row["ci_low"] > 0:
        return "not supported"
    return "inconclusive"


def _fmt(row: pd.Series) -> str:
    return (
        f"{row['comparison']}: mean paired difference {row['mean_diff']:+.3f} m "
        f"(95% CI [{row['ci_low']:+.3f}, {row['ci_high']:+.3f}]), median "
        f"{row['median_diff']:+.3f} m, better in {row['frac_better']:.0%} of "
        f"{int(row['n_runs'])} runs, Wilcoxon p = {row['wilcoxon_p']:.3g}"
    )


def uav_claims(summary: pd.DataFrame, paired: pd.DataFrame) -> list[Claim]:
    """Claims UAV-1..3 by the module's verdict rules (those whose methods were run)."""
    claims = []
    rs = summary[summary["family"] == "rsmhp"].sort_values("N_T")
    trend = paired[paired["purpose"] == "N_T trend"]
    if len(rs) >= 2:
        big, small = rs["method"].iloc[-1], rs["method"].iloc[0]
        main = trend[(trend["method"] == big) & (trend["baseline"] == small)].iloc[0]
        consecutive = trend[~((trend["method"] == big) & (trend["baseline"] == small))]
        steps = "; ".join(
            f"{r['comparison']}: {r['mean_diff']:+.3f} [{r['ci_low']:+.3f}, {r['ci_high']:+.3f}]"
            for _, r in consecutive.iterrows()
        )
        means = ", ".join(f"{r['label']}: {r['mean']:.2f} m" for _, r in rs.iterrows())
        if steps:
            means += f"; consecutive pairs (mean diff, CI): {steps}"
        claims.append(
            Claim(
                id="UAV-1",
                claim="Average target location error falls as N_T grows (50, 100, 250)",
                source="Sec. III-B, Fig. 4",
                experiment="uav_simulate, uav_summary",
                measured=f"{_fmt(main)}; means {means}",
                verdict=_verdict(main),
            )
        )
    vs_nbo = paired[(paired["purpose"] == "vs NBO") & paired["method"].isin(rs["method"])]
    if len(vs_nbo):
        main = vs_nbo[vs_nbo["method"] == rs["method"].iloc[-1]].iloc[0]
        others = "; ".join(
            f"N_T={int(summary.loc[summary['method'] == r['method'], 'N_T'].iloc[0])}: "
            f"{r['mean_diff']:+.3f} [{r['ci_low']:+.3f}, {r['ci_high']:+.3f}]"
            for _, r in vs_nbo.iterrows()
            if r["method"] != main["method"]
        )
        claims.append(
            Claim(
                id="UAV-2",
                claim="RS-MHP gives lower target location error than NBO",
                source="Sec. III-B, Fig. 5",
                experiment="uav_simulate, uav_summary",
                measured=_fmt(main) + (f"; other N_T (mean diff, CI): {others}" if others else ""),
                verdict=_verdict(main),
            )
        )
    prune = paired[paired["purpose"] == "pruning"]
    if len(prune):
        row = prune.iloc[0]
        claims.append(
            Claim(
                id="UAV-3",
                claim="Pruning degrades RS-MHP (non-overlapping beats the pruned tree at equal "
                "trajectory count)",
                source="Sec. III-B (remark after Fig. 4)",
                experiment="uav_simulate (tree ablation), uav_summary",
                measured=_fmt(row),
                verdict=_verdict(row),
            )
        )
    return claims


def _md(df: pd.DataFrame, floatfmt: str = ".3f") -> str:
    fmts = ["d" if pd.api.types.is_integer_dtype(t) else floatfmt for t in df.dtypes]
    return df.to_markdown(index=False, floatfmt=fmts)


def uav_tables(summary: pd.DataFrame, paired: pd.DataFrame) -> dict[str, str]:
    """Markdown tables keyed by file stem (``results/tables/<stem>.md``)."""
    methods = summary[
        [
            "label",
            "n_runs",
            "mean",
            "ci_low",
            "ci_high",
            "median",
            "median_low",
            "median_high",
            "mean_rmse",
            "mean_trace",
            "plan_seconds_per_run",
        ]
    ].rename(columns={"label": "method"})
    pairs = paired[
        [
            "comparison",
            "purpose",
            "n_runs",
            "mean_diff",
            "ci_low",
            "ci_high",
            "median_diff",
            "frac_better",
            "wilcoxon_p",
        ]
    ]
    fmts = [
        "",
        "",
        "d",
        ".3f",
        ".3f",
        ".3f",
        ".3f",
        ".2f",
        ".3g",
    ]
    return {
        "uav_methods": _md(methods),
        "uav_paired": pairs.to_markdown(index=False, floatfmt=fmts),
    }


def _variant_note(sensor: dict) -> str:
    """A sentence naming the model variant when the sensor is not the reconstruction's."""
    parts = []
    if sensor.get("footprint_radius") is not None:
        parts.append(
            f"a sensor footprint of radius {sensor['footprint_radius']:g} m (truth detections "
            f"{sensor.get('detection', 'hard')}, planner width "
            f"{sensor.get('footprint_width', 10):g} m)"
        )
    if sensor.get("noise_growth", "linear") != "linear":
        parts.append(
            f"noise growing quadratically with distance (reference "
            f"{sensor.get('reference_distance', 100):g} m)"
        )
    if not parts:
        return ""
    return (
        " **Model variant, not the paper's model:** " + "; ".join(parts) + " (`rsmhp.uav.sensor`)."
    )


def uav_section(
    summary: pd.DataFrame,
    paired: pd.DataFrame,
    tables: dict[str, str],
    setting: dict,
    n_boot: int,
) -> Section:
    """The UAV report section (order 20)."""
    claims = uav_claims(summary, paired)
    ac, sc, pl = setting["aircraft"], setting["scenario"], setting["planner"]
    n_runs = int(summary["n_runs"].max())
    body = "\n".join(
        [
            "UAV path planning for target tracking (Sec. III-B). The paper gives only H = 6 and "
            "N_T ∈ {50, 100, 250}; every other number is this project's reconstruction "
            "(`config/config.yaml`, section `uav`; model in `rsmhp.uav`).",
            "",
            f"Model: Δt = {setting['dt']:g} s; UAV at {ac['altitude']:g} m altitude, controls "
            f"|a| ≤ {ac['accel_max']:g} m/s², |φ| ≤ {ac['bank_max_deg']:g}°, speed in "
            f"[{ac['speed_min']:g}, {ac['speed_max']:g}] m/s; NCV target, q = "
            f"{setting['target']['q']:g} m²/s³; position sensor with σ_r = "
            f"{setting['sensor']['sigma_r_per_m']:g} d, σ_c = "
            f"{setting['sensor']['sigma_c_per_m']:g} d (d: 3-D distance); Kalman filter with "
            f"P0 = diag({setting['tracker']['p0_pos_sd']:g}², "
            f"{setting['tracker']['p0_pos_sd']:g}², {setting['tracker']['p0_vel_sd']:g}², "
            f"{setting['tracker']['p0_vel_sd']:g}²). Planner: H = {pl['horizon']}, cost "
            "Σ_{k=1..H} tr P_k averaged over the hypotheses, L-BFGS-B on the control box with "
            f"at most {pl['maxiter']} iterations / {pl['maxfun']} evaluations, exact gradient "
            "(adjoint of the covariance recursion and the kinematics, compiled kernel), warm "
            "start from the shifted previous plan; identical for every method."
            + _variant_note(setting["sensor"]),
            "",
            f"Study: {n_runs} runs × {sc['steps']} steps per method. Each run draws its scenario "
            f"(target speed {sc['target_speed_min']:g}-{sc['target_speed_max']:g} m/s, UAV "
            f"{sc['uav_distance_min']:g}-{sc['uav_distance_max']:g} m away at "
            f"{sc['uav_speed']:g} m/s), truth noise and measurement noise from streams keyed on "
            "the run only: all methods face identical scenarios and noise (paired design). "
            "Metric per run: mean over steps of ‖p̂_k − p_k‖.",
            "",
            f"Verdict rules (see `rsmhp.analysis.uav`): for 'A has lower error than B', "
            f"supported if the 95% percentile-bootstrap CI ({n_boot} resamples) of the mean "
            "paired difference A − B lies below 0, not supported if above 0, inconclusive "
            "otherwise. Wilcoxon signed-rank p-values are reported alongside.",
            "",
            "### Claims",
            "",
            *claims_list(claims),
            "",
            "### Figures",
            "",
            "![Fig. 4 analogue](figures/uav_error_cdf_nt.png)",
            "",
            "*Empirical CDF of the per-run average target location error, RS-MHP with each N_T "
            "(paper Fig. 4).*",
            "",
            "![Fig. 5 analogue](figures/uav_error_cdf_nbo.png)",
            "",
            "*Empirical CDF of the per-run average error, NBO vs RS-MHP (paper Fig. 5).*",
            "",
            "![paired differences](figures/uav_paired_diff.png)",
            "",
            "*Per-run paired differences of the average error to NBO (negative: better than "
            "NBO), with the mean and its 95% bootstrap CI.*",
            "",
            "### Tables",
            "",
            "Per method (errors in m; CIs: 95% percentile bootstrap over runs; planner time "
            "per run in s is wall time and varies between executions):",
            "",
            tables["uav_methods"],
            "",
            "Paired differences (m; negative: the first method has the lower error):",
            "",
            tables["uav_paired"],
        ]
    )
    return Section(
        key="uav",
        title="Case study 2: UAV target tracking (paper Sec. III-B, Figs. 4-5)",
        order=20,
        body=body,
        claims=claims,
        figures=[f"{f}.png" for f in FIGURES],
    )
