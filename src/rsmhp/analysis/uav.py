r"""Aggregation of the UAV Monte-Carlo study: per-method summaries, paired differences, claims.

Metric: for run :math:`r` and method :math:`A`, the paper's average target location error
:math:`e_r(A) = \frac1K \sum_{k=1}^K \|\hat p_k - p_k\|` (metres; ``mean_error``, estimate
:math:`\hat p_k` of the tracker, true position :math:`p_k`, K steps).

Statistics:

* per method: mean and median of :math:`e_r` with 95% percentile-bootstrap CIs (``B``
  resamples of the runs);
* paired differences :math:`d_r = e_r(A) - e_r(B)` over the runs both methods share (same
  scenario and noise, :mod:`rsmhp.uav.simulation`): the mean :math:`\bar d` with a 95%
  percentile-bootstrap CI, the median, the number of runs with :math:`d_r < 0` (A better) and
  the two-sided Wilcoxon signed-rank p-value (``scipy.stats.wilcoxon``; undefined when every
  :math:`d_r = 0`).

Bootstrap resamples come from ``job_rng(seed, "uav_bootstrap", statistic=..., method=...,
baseline=...)``: the same inputs give the same intervals.

Verdict rule (stated once, applied mechanically by :func:`verdict`)
-------------------------------------------------------------------
For a claim "A has lower error than B" with :math:`d_r = e_r(A) - e_r(B)` and the 95%
bootstrap CI :math:`[l, h]` of :math:`\bar d`: *supported* if :math:`h < 0` (the CI lies
entirely below 0), *not supported* if :math:`l > 0` (entirely above 0), *inconclusive*
otherwise, i.e. when the CI contains or touches 0 (no detectable difference at this number of
runs; the CI says how large a difference is still compatible with the data).

* **UAV-1** (Fig. 4: error falls as N_T grows): A = RS-MHP with the largest N_T, B = RS-MHP
  with the smallest N_T (consecutive N_T pairs are reported alongside, not used in the verdict).
* **UAV-2** (Fig. 5: RS-MHP beats NBO): A = RS-MHP with the largest N_T, B = NBO (the other
  N_T and the pruned tree are reported alongside).
* **UAV-3** (Sec. III-B remark: pruning degrades RS-MHP): A = RS-MHP with N_T = M
  (non-overlapping), B = the pruned tree keeping M trajectories; only if both were run.

Figure ranges (:func:`robust_range`): an axis showing n pooled values ends 10% (of the
distance between them) beyond their 1st and 99th percentiles taken as order statistics
(:math:`x_{(k)}` and :math:`x_{(n-1-k)}`, :math:`k = \lfloor n/100 \rfloor`), never beyond the
data: at most k values at each end are left out, none when n < 100. The figures and captions
count the values left out.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd
from scipy import stats as sps

from rsmhp.ledger import Claim, KeyNumber, Section
from rsmhp.markdown import fmt, fmt_ci, markdown_table
from rsmhp.palette import method_label
from rsmhp.seeding import job_rng
from rsmhp.stats import bootstrap_ci

__all__ = [
    "FIGURES",
    "cdf_methods",
    "cdf_range",
    "clip_note",
    "comparison_pairs",
    "figure_notes",
    "key_comparisons",
    "paired_differences",
    "paired_range",
    "paired_view",
    "per_run_differences",
    "robust_range",
    "summarize_methods",
    "uav_claims",
    "uav_section",
    "uav_tables",
    "verdict",
]

#: figure stems written by the figure rule and referenced by the report section, in the order
#: of the section: each paper-style CDF is followed by its paired view
FIGURES = ("uav_error_cdf_nt", "uav_paired_diff_nt", "uav_error_cdf_nbo", "uav_paired_diff")


def verdict(ci_low: float, ci_high: float) -> str:
    """The module's rule for "A has lower error than B" from the CI ``[l, h]`` of the mean of
    ``d = e(A) - e(B)``: ``h < 0`` supported, ``l > 0`` not supported, else (CI contains or
    touches 0) inconclusive."""
    if ci_high < 0.0:
        return "supported"
    if ci_low > 0.0:
        return "not supported"
    return "inconclusive"


def _methods(runs: pd.DataFrame) -> pd.DataFrame:
    """One row per method (method, family, N_T, N, M), NBO first, then RS-MHP by N_T, trees."""
    meta = runs[["method", "family", "N_T", "N", "M"]].drop_duplicates("method")
    order = {"nbo": 0, "rsmhp": 1, "tree": 2}
    meta = meta.assign(_o=meta["family"].map(order))
    return meta.sort_values(["_o", "N_T", "N", "M"]).drop(columns="_o").reset_index(drop=True)


def summarize_methods(
    runs: pd.DataFrame, seed: int, n_boot: int, level: float = 0.95
) -> pd.DataFrame:
    """Per method: runs, mean, median and SD of ``mean_error`` (with bootstrap CIs of mean and
    median), mean RMSE and tr P, planner wall time per run (seconds; not deterministic)."""
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
                "label": method_label(meta["method"]),
                "n_runs": len(grp),
                "mean": float(err.mean()),
                "ci_low": lo,
                "ci_high": hi,
                "median": float(np.median(err)),
                "median_low": mlo,
                "median_high": mhi,
                "sd": float(err.std(ddof=1)) if err.size > 1 else 0.0,
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
    """Paired differences ``d_r = e_r(method) - e_r(baseline)`` of ``mean_error`` over the runs
    both methods have (see the module doc): mean with bootstrap CI, median, SD, runs with
    ``d_r < 0`` (``frac_better`` as a fraction), Wilcoxon p (NaN if every ``d_r = 0``)."""
    wide = runs.pivot(index="run", columns="method", values="mean_error")
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
                "comparison": f"{method_label(method)} − {method_label(base)}",
                "purpose": purpose,
                "n_runs": d.size,
                "n_missing": int(len(wide) - d.size),
                "mean_diff": float(d.mean()),
                "ci_low": lo,
                "ci_high": hi,
                "median_diff": float(np.median(d)),
                "sd_diff": float(d.std(ddof=1)) if d.size > 1 else 0.0,
                "n_better": int(np.sum(d < 0)),
                "frac_better": float(np.mean(d < 0)),
                "wilcoxon_p": p,
            }
        )
    return pd.DataFrame(rows)


# ---------------------------------------------------------------------------- figure ranges


def robust_range(values: Sequence[float] | np.ndarray, q: float = 0.01, widen: float = 0.1):
    """Plot range ``(lo, hi)`` robust to a few outliers. With the n finite values sorted,
    ``x_(0) <= ... <= x_(n-1)``, and ``k = floor(q n)``: ``a = x_(k)``, ``b = x_(n-1-k)`` (the
    pooled ``q`` and ``1 - q`` quantiles as order statistics), widened to
    ``(a - widen (b - a), b + widen (b - a))`` and intersected with ``[x_(0), x_(n-1)]``.
    At most ``k`` values at each end fall outside; none when ``n < 1/q``."""
    x = np.sort(np.asarray(values, dtype=float))
    x = x[np.isfinite(x)]
    if x.size == 0:
        raise ValueError("robust_range needs at least one finite value")
    k = int(np.floor(q * x.size))
    a, b = x[k], x[x.size - 1 - k]
    pad = widen * (b - a)
    return float(max(x[0], a - pad)), float(min(x[-1], b + pad))


def clip_note(groups: Mapping[str, np.ndarray], lo: float, hi: float, what: str = "runs") -> str:
    """Sentence saying which values of ``groups`` (label -> values, metres) lie outside
    ``[lo, hi]`` and so are not shown; empty when none. Equal counts beyond ``hi`` in every
    group give ``"1 run per curve beyond 19.3 m not shown (up to 29.9 m)"``."""
    allv = np.concatenate([np.asarray(v, dtype=float) for v in groups.values()])
    below = {k: int(np.sum(np.asarray(v) < lo)) for k, v in groups.items()}
    above = {k: int(np.sum(np.asarray(v) > hi)) for k, v in groups.items()}
    n_out = sum(below.values()) + sum(above.values())
    if n_out == 0:
        return ""
    counts = set(above.values())
    if not any(below.values()) and len(counts) == 1 and len(groups) > 1:
        k = counts.pop()
        one = what[:-1] if k == 1 and what.endswith("s") else what
        return f"{k} {one} per curve beyond {fmt(hi)} m not shown (up to {fmt(allv.max())} m)"
    return (
        f"{n_out} of {allv.size} {what} outside [{fmt(lo)}, {fmt(hi)}] m not shown "
        f"(range {fmt(allv.min())} to {fmt(allv.max())} m)"
    )


def cdf_methods(summary: pd.DataFrame) -> dict[str, list[str]]:
    """Methods of the paper-style CDFs: ``"nt"`` (Fig. 4) every RS-MHP by N_T; ``"nbo"``
    (Fig. 5) NBO and RS-MHP with the largest N_T (the comparison of UAV-2)."""
    rs = summary[summary["family"] == "rsmhp"].sort_values("N_T")["method"].tolist()
    nbo = ["nbo"] if "nbo" in set(summary["method"]) else []
    return {"nt": rs, "nbo": nbo + rs[-1:]}


def paired_view(paired: pd.DataFrame, view: str) -> pd.DataFrame:
    """Rows of ``paired`` drawn in a paired figure: ``"nt"`` the N_T trend and pruning pairs
    (Fig. 4 side, UAV-1 and UAV-3), ``"nbo"`` every method minus NBO (Fig. 5 side, UAV-2)."""
    purposes = {"nt": ("N_T trend", "pruning"), "nbo": ("vs NBO",)}[view]
    return paired[paired["purpose"].isin(purposes)].reset_index(drop=True)


def per_run_differences(runs: pd.DataFrame, rows: pd.DataFrame) -> dict[str, np.ndarray]:
    """Per-run differences ``d_r = e_r(A) - e_r(B)`` of each row (A = ``method``, B =
    ``baseline``) of a paired view, keyed by its ``comparison`` label."""
    wide = runs.pivot(index="run", columns="method", values="mean_error")
    return {
        r["comparison"]: (wide[r["method"]] - wide[r["baseline"]]).dropna().to_numpy()
        for _, r in rows.iterrows()
    }


def cdf_range(runs: pd.DataFrame, methods: Sequence[str]) -> tuple[float, float, str]:
    """x-range ``(lo, hi)`` of a CDF of ``mean_error`` over ``methods`` (pooled,
    :func:`robust_range`) and the note of the runs it leaves out (:func:`clip_note`)."""
    groups = {
        method_label(m): runs.loc[runs["method"] == m, "mean_error"].to_numpy() for m in methods
    }
    lo, hi = robust_range(np.concatenate(list(groups.values())))
    return lo, hi, clip_note(groups, lo, hi)


def paired_range(runs: pd.DataFrame, rows: pd.DataFrame) -> tuple[float, float, str]:
    """x-range of the per-run differences of the ``rows`` of a paired view (pooled with 0,
    :func:`robust_range`, always containing 0) and the note of the differences left out."""
    groups = per_run_differences(runs, rows)
    lo, hi = robust_range(np.concatenate([*groups.values(), [0.0]]))
    lo, hi = min(lo, 0.0), max(hi, 0.0)
    return lo, hi, clip_note(groups, lo, hi, "differences")


def figure_notes(
    runs: pd.DataFrame, summary: pd.DataFrame, paired: pd.DataFrame
) -> dict[str, tuple[float, float, str]]:
    """Per figure stem: its x-range ``(lo, hi)`` and clipping note (empty if nothing is left
    out), shared by the figures and the section's captions."""
    out = {}
    for key, methods in cdf_methods(summary).items():
        if methods:
            out[f"uav_error_cdf_{key}"] = cdf_range(runs, methods)
    for key, stem in (("nt", "uav_paired_diff_nt"), ("nbo", "uav_paired_diff")):
        rows = paired_view(paired, key)
        if len(rows):
            out[stem] = paired_range(runs, rows)
    return out


def key_comparisons(summary: pd.DataFrame, paired: pd.DataFrame) -> dict[str, tuple[str, str]]:
    """Claim id -> (A, B), the comparison whose mean paired difference is the claim's key
    number (module doc); claims whose methods were not run are absent."""
    rs = summary[summary["family"] == "rsmhp"].sort_values("N_T")["method"].tolist()
    have = set(zip(paired["method"], paired["baseline"], strict=True))
    out = {}
    if len(rs) >= 2 and (rs[-1], rs[0]) in have:
        out["UAV-1"] = (rs[-1], rs[0])
    if rs and (rs[-1], "nbo") in have:
        out["UAV-2"] = (rs[-1], "nbo")
    prune = paired[paired["purpose"] == "pruning"]
    if len(prune):
        out["UAV-3"] = (prune["method"].iloc[0], prune["baseline"].iloc[0])
    return out


# ---------------------------------------------------------------------------- claims


_RULE = (
    "d_r = e_r({a}) − e_r({b}), e_r = run r's average target location error (m); supported if "
    "the 95% bootstrap CI of mean d lies entirely below 0, not supported if entirely above 0, "
    "inconclusive if it contains or touches 0"
)


def _short(method: str) -> str:
    """``N_T=250``, ``NBO``, ``tree N=8 M=100``: short names for key-number labels."""
    return method_label(method).replace("RS-MHP ", "").replace("pruned tree", "tree")


def _stats(row: pd.Series) -> str:
    """Secondary numbers of one paired comparison (measured text)."""
    p = row["wilcoxon_p"]
    ptxt = f"Wilcoxon p = {fmt(p, 2)}" if np.isfinite(p) else "Wilcoxon p undefined (all d = 0)"
    return (
        f"{row['comparison']}: mean d {fmt(row['mean_diff'], 2, True)} "
        f"{fmt_ci(row['ci_low'], row['ci_high'], 2, True)} m, median d "
        f"{fmt(row['median_diff'], 2, True)} m, d < 0 in {int(row['n_better'])} of "
        f"{int(row['n_runs'])} runs, {ptxt}"
    )


def _alongside(rows: pd.DataFrame) -> str:
    return "; ".join(
        f"{r['comparison']}: {fmt(r['mean_diff'], 2, True)} "
        f"{fmt_ci(r['ci_low'], r['ci_high'], 2, True)} m"
        for _, r in rows.iterrows()
    )


def _dropped(row: pd.Series) -> str:
    """Runs left out of a paired comparison (a method without a result for them)."""
    n = int(row.get("n_missing", 0))
    return f"{n} run(s) without a result for both methods" if n else ""


def _claim(
    cid: str, claim: str, paper: str, row: pd.Series, measured: str, dropped: str = ""
) -> Claim:
    a, b = _short(row["method"]), _short(row["baseline"])
    key = KeyNumber(
        name=f"mean d, e({a}) − e({b})",
        value=float(row["mean_diff"]),
        ci_low=float(row["ci_low"]),
        ci_high=float(row["ci_high"]),
        unit="m",
        reproducible="statistical",
        digits=2,
        null=0.0,
    )
    drop = "; ".join(x for x in (dropped, _dropped(row)) if x)
    return Claim(
        id=cid,
        claim=claim,
        paper=paper,
        key=key,
        verdict=verdict(row["ci_low"], row["ci_high"]),
        rule=_RULE.format(a=a, b=b),
        measured=measured,
        dropped=drop,
    )


def uav_claims(summary: pd.DataFrame, paired: pd.DataFrame) -> list[Claim]:
    """Claims UAV-1..3 by the module's verdict rule (those whose methods were run)."""
    claims = []
    keys = key_comparisons(summary, paired)

    def pick(cid: str) -> tuple[pd.Series, pd.Series]:
        a, b = keys[cid]
        is_key = (paired["method"] == a) & (paired["baseline"] == b)
        return paired[is_key].iloc[0], is_key

    rs = summary[summary["family"] == "rsmhp"].sort_values("N_T")
    if "UAV-1" in keys:
        main, is_key = pick("UAV-1")
        trend = (paired["purpose"] == "N_T trend") & ~is_key
        means = ", ".join(f"{r['label']} {fmt(r['mean'], 4)} m" for _, r in rs.iterrows())
        measured = f"{_stats(main)}; mean e: {means}"
        if trend.any():
            measured += f"; consecutive N_T (mean d, CI): {_alongside(paired[trend])}"
        nts = ", ".join(str(int(n)) for n in rs["N_T"])
        claims.append(
            _claim(
                "UAV-1",
                f"Average target location error falls as N_T grows (N_T = {nts})",
                "Sec. III-B, Fig. 4: CDFs of the average location error improve gradually with "
                "N_T = 50, 100, 250 (H = 6)",
                main,
                measured,
            )
        )
    if "UAV-2" in keys:
        main, is_key = pick("UAV-2")
        others = (paired["purpose"] == "vs NBO") & ~is_key
        measured = _stats(main)
        if others.any():
            measured += f"; other methods − NBO (mean d, CI): {_alongside(paired[others])}"
        claims.append(
            _claim(
                "UAV-2",
                f"RS-MHP ({_short(main['method'])}) gives lower target location error than NBO",
                "Sec. III-B, Fig. 5: CDF of the average location error, RS-MHP better than NBO",
                main,
                measured,
            )
        )
    if "UAV-3" in keys:
        main, is_key = pick("UAV-3")
        others = paired[(paired["purpose"] == "pruning") & ~is_key]
        claims.append(
            _claim(
                "UAV-3",
                "Pruning degrades RS-MHP: non-overlapping N_T = M beats the pruned tree keeping "
                "M trajectories",
                "Sec. III-B, text after Fig. 4: the N_T trend suggests pruning would degrade "
                "RS-MHP (no experiment shown)",
                main,
                _stats(main),
                dropped=(
                    "further pruned trees, reported but not the key number (the first one is): "
                    + _alongside(others)
                    if len(others)
                    else ""
                ),
            )
        )
    return claims


# ---------------------------------------------------------------------------- tables, section


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


def uav_section(
    summary: pd.DataFrame,
    paired: pd.DataFrame,
    tables: Mapping[str, str],
    setting: Mapping[str, Any],
    n_boot: int,
    runs: pd.DataFrame,
) -> Section:
    """The UAV report section (order 20): a short body (what was run, symbols, findings, the
    paper-style CDFs each followed by its paired view) and an appendix (model, tables)."""
    claims = uav_claims(summary, paired)
    ac, sc, pl = setting["aircraft"], setting["scenario"], setting["planner"]
    n_runs = int(summary["n_runs"].max())
    rs = summary[summary["family"] == "rsmhp"].sort_values("N_T")
    trees = summary[summary["family"] == "tree"]
    nts = ", ".join(str(int(n)) for n in rs["N_T"])
    notes = figure_notes(runs, summary, paired)
    big = method_label(rs["method"].iloc[-1]) if len(rs) else "RS-MHP"

    methods = ["NBO (one nominal, noise-free target hypothesis)"]
    if len(rs):
        methods.append(f"RS-MHP with N_T ∈ {{{nts}}} independently sampled target trajectories")
    methods += [
        f"a pruned tree ({int(t['N'])} draws per level, the {int(t['M'])} most likely kept)"
        for _, t in trees.iterrows()
    ]
    n_incl = sum(c.verdict == "inconclusive" for c in claims)
    verdicts = "; ".join(
        f"{c.id} {fmt(c.key.value, 2, True)} {fmt_ci(c.key.ci_low, c.key.ci_high, 2, True)} m "
        f"({c.verdict})"
        for c in claims
    )
    spread = (
        f"Mean e of every method lies in [{fmt(summary['mean'].min(), 4)}, "
        f"{fmt(summary['mean'].max(), 4)}] m, while e varies between runs with SD "
        f"{fmt(summary['sd'].median(), 2)} m. "
    )
    half = float(np.median([(c.key.ci_high - c.key.ci_low) / 2 for c in claims] or [0.0]))
    pct = 100 * half / float(summary["mean"].mean())
    why = (
        f"Every CI contains 0: any effect of the method on e is below what {n_runs} paired "
        f"runs resolve (CI half-width about {fmt(half, 2)} m, {fmt(pct, 2)}% of mean e). "
        if claims and n_incl == len(claims)
        else f"{n_incl} of {len(claims)} CIs contain or touch 0. "
    ) + "The decision study compares the plans themselves (DEC-6, DEC-8)."
    body = "\n".join(
        [
            f"**Run.** {n_runs} closed-loop runs × {sc['steps']} steps (Δt = "
            f"{_num(setting['dt'])} s) per method: a UAV tracks a ground target with a noisy "
            "position sensor and a Kalman filter; at every step it plans H = "
            f"{pl['horizon']} controls minimising Σ_{{k=1..H}} tr P_k (P_k: tracker covariance "
            "predicted k steps ahead along a target hypothesis) averaged over the method's "
            f"hypotheses: {', '.join(methods)}. The paper fixes only H = 6 and N_T; the rest is "
            "our reconstruction (appendix). All methods face the "
            "same scenario and noise in a run (paired design)." + _variant_note(setting["sensor"]),
            "",
            "**Symbols.** e_r = (1/K) Σ_k ‖p̂_k − p_k‖ (m): average target location error of "
            "run r over its K steps (p̂_k estimate, p_k true position). Paired difference d_r = "
            "e_r(A) − e_r(B) (< 0: A better), mean d̄ over runs; CI: 95% percentile bootstrap "
            f"of d̄ ({n_boot} resamples of runs); p: Wilcoxon signed-rank p-value of d.",
            "",
            f"**Found.** {spread}Key numbers d̄ (CI): {verdicts}. {why}",
            "",
            "![Fig. 4 counterpart](figures/uav_error_cdf_nt.png)",
            "",
            _caption(
                f"Paper Fig. 4 drawn the paper's way: CDF of e_r, RS-MHP N_T = {nts}",
                notes.get("uav_error_cdf_nt", (0, 0, ""))[2],
            ),
            "",
            "![paired differences, N_T and pruning](figures/uav_paired_diff_nt.png)",
            "",
            _caption(
                "Paired view of Fig. 4: d_r for larger − smaller N_T (UAV-1) and RS-MHP − "
                "pruned tree (UAV-3), with d̄ and CI",
                notes.get("uav_paired_diff_nt", (0, 0, ""))[2],
            ),
            "",
            "![Fig. 5 counterpart](figures/uav_error_cdf_nbo.png)",
            "",
            _caption(
                f"Paper Fig. 5 drawn the paper's way: CDF of e_r, NBO vs {big}",
                notes.get("uav_error_cdf_nbo", (0, 0, ""))[2],
            ),
            "",
            "![paired differences to NBO](figures/uav_paired_diff.png)",
            "",
            _caption(
                "Paired view of Fig. 5: d_r = e_r(method) − e_r(NBO) with d̄ and CI (UAV-2)",
                notes.get("uav_paired_diff", (0, 0, ""))[2],
            ),
        ]
    )
    sp, sv = _num(setting["tracker"]["p0_pos_sd"]), _num(setting["tracker"]["p0_vel_sd"])
    appendix = "\n".join(
        [
            "The paper gives only H = 6 and N_T ∈ {50, 100, 250}; every other number is this "
            "project's reconstruction (`config/config.yaml`, section `uav`; model in "
            "`rsmhp.uav`).",
            "",
            f"Model: Δt = {_num(setting['dt'])} s; UAV at {_num(ac['altitude'])} m altitude, "
            f"controls |a| ≤ {_num(ac['accel_max'])} m/s², |φ| ≤ {_num(ac['bank_max_deg'])}°, "
            f"speed in [{_num(ac['speed_min'])}, {_num(ac['speed_max'])}] m/s; target: nearly "
            f"constant velocity (NCV), q = {_num(setting['target']['q'])} m²/s³; position sensor "
            f"with range SD σ_r = {_num(setting['sensor']['sigma_r_per_m'])} d and cross-range "
            f"SD σ_c = {_num(setting['sensor']['sigma_c_per_m'])} d (d: 3-D UAV–target "
            f"distance); Kalman filter with P0 = diag({sp}², {sp}², {sv}², {sv}²). Planner: "
            f"horizon H = {pl['horizon']}, cost Σ_{{k=1..H}} tr P_k (P_k: 4×4 covariance "
            "predicted along a target hypothesis) averaged over the hypotheses, L-BFGS-B on "
            f"the control box with at most {pl['maxiter']} iterations / {pl['maxfun']} "
            "evaluations, exact gradient, warm start from the shifted previous plan; identical "
            "for every method." + _variant_note(setting["sensor"]),
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
    return Section(
        key="uav",
        title="Case study 2: UAV target tracking (paper Sec. III-B, Figs. 4-5)",
        order=20,
        body=body,
        claims=claims,
        figures=[f"{f}.png" for f in FIGURES],
        appendix=appendix,
    )
