r"""UAV Monte-Carlo study, statistics: per-method summaries, paired differences and the ranges
of the figures. Numbers only: the claims UAV-1..3 are in :mod:`rsmhp.studies.uav.claims`, the prose
and tables in :mod:`rsmhp.studies.uav.section`.

Metric: for run :math:`r` and method :math:`A`, the paper's average target location error
:math:`e_r(A) = \frac1K \sum_{k=1}^K \|\hat p_k - p_k\|` (metres; ``mean_error``, estimate
:math:`\hat p_k` of the tracker, true position :math:`p_k`, K steps).

Statistics:

* per method: mean and median of :math:`e_r` with 95% percentile-bootstrap CIs (``B``
  resamples of the runs);
* paired differences :math:`d_r = e_r(A) - e_r(B)` over the runs both methods share (same
  scenario and noise, :mod:`rsmhp.models.uav.simulation`): the mean :math:`\bar d` with a 95%
  percentile-bootstrap CI, the median, the number of runs with :math:`d_r < 0` (A better) and
  the two-sided Wilcoxon signed-rank p-value (``scipy.stats.wilcoxon``; undefined when every
  :math:`d_r = 0`).

Methods come from the registry (:mod:`rsmhp.models.uav.methods`): tables list them in its order
(:meth:`~rsmhp.models.uav.methods.Method.sort_key`) and every method is compared with the baseline
family's member (purpose :func:`vs_baseline`). Two more kinds of pairs serve the paper's
claims about specific families: the N_T trend of RS-MHP (:class:`MonteCarlo`; consecutive
N_T and largest vs smallest) and each pruned tree (:class:`PrunedTree`) vs RS-MHP with
N_T = M.

Bootstrap resamples come from ``job_rng(seed, "uav_bootstrap", statistic=..., method=...,
baseline=...)``: the same inputs give the same intervals.

Figure ranges (:func:`robust_range`): an axis showing n pooled values ends 10% (of the
distance between them) beyond their 1st and 99th percentiles taken as order statistics
(:math:`x_{(k)}` and :math:`x_{(n-1-k)}`, :math:`k = \lfloor n/100 \rfloor`), never beyond the
data: at most k values at each end are left out, none when n < 100. The figures and captions
count the values left out (:func:`clip_note`).
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from scipy import stats as sps

from rsmhp.core.seeding import job_rng
from rsmhp.core.stats import bootstrap_ci
from rsmhp.models.uav import methods as registry
from rsmhp.models.uav.methods import baseline_name, is_family
from rsmhp.models.uav.methods.base import Method
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.models.uav.methods.pruned_tree import PrunedTree
from rsmhp.report.markdown import fmt
from rsmhp.report.palette import method_label

__all__ = [
    "PRUNING",
    "TREND",
    "baseline_name",
    "cdf_methods",
    "cdf_range",
    "clip_note",
    "comparison_pairs",
    "family_rows",
    "figure_notes",
    "is_family",
    "method_table",
    "paired_differences",
    "paired_range",
    "paired_view",
    "per_run_differences",
    "robust_range",
    "summarize_methods",
    "vs_baseline",
]

#: ``purpose`` of the pairs of RS-MHP's N_T trend (UAV-1) and of the pruning pairs (UAV-3)
TREND = "N_T trend"
PRUNING = "pruning"


def vs_baseline() -> str:
    """``purpose`` of the pairs "every method vs the baseline" (``"vs NBO"``)."""
    return f"vs {registry.baseline().family_label}"


def family_rows(table: pd.DataFrame, family: type[Method]) -> pd.DataFrame:
    """Rows of ``table`` (a ``method`` and an ``N_T`` column) of ``family``, by N_T (ties in
    table order)."""
    return table.loc[is_family(table["method"], family)].sort_values("N_T", kind="stable")


def method_table(runs: pd.DataFrame) -> pd.DataFrame:
    """One row per method (method, family, N_T, N, M), in the registry's order."""
    meta = runs[["method", "family", "N_T", "N", "M"]].drop_duplicates("method")
    key = {m: registry.from_name(m).sort_key() for m in meta["method"]}
    order = sorted(meta["method"], key=key.__getitem__)
    return meta.set_index("method").loc[order].reset_index()


def summarize_methods(
    runs: pd.DataFrame, seed: int, n_boot: int, level: float = 0.95
) -> pd.DataFrame:
    """Per method: runs, mean, median and SD of ``mean_error`` (with bootstrap CIs of mean and
    median), mean RMSE and tr P, planner wall time per run (seconds; not deterministic)."""
    rows = []
    for _, meta in method_table(runs).iterrows():
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
    """(method, baseline, purpose) pairs: every method vs the baseline (if it was run), RS-MHP's
    N_T trend (consecutive and largest vs smallest), each pruned tree vs RS-MHP with N_T = M."""
    meta = method_table(runs)
    names = meta["method"].tolist()
    base = baseline_name()
    pairs = [(m, base, vs_baseline()) for m in names if m != base] if base in names else []
    rs = family_rows(meta, MonteCarlo)["method"].tolist()
    pairs += [(b, a, TREND) for a, b in itertools.pairwise(rs)]
    if len(rs) > 2:
        pairs.append((rs[-1], rs[0], TREND))
    mc = meta.loc[is_family(meta["method"], MonteCarlo)]
    for _, t in meta.loc[is_family(meta["method"], PrunedTree)].iterrows():
        twin = mc[mc["N_T"] == t["M"]]
        if len(twin):
            pairs.append((twin["method"].iloc[0], t["method"], PRUNING))
    return pairs


def _paired_row(
    d: np.ndarray, n_missing: int, rng: np.random.Generator, n_boot: int, level: float
) -> dict[str, float | int]:
    """The statistics of one paired comparison's differences ``d`` (columns of
    :func:`paired_differences` after ``purpose``)."""
    lo, hi = bootstrap_ci(d, rng, n_boot, level)
    return {
        "n_runs": d.size,
        "n_missing": n_missing,
        "mean_diff": float(d.mean()),
        "ci_low": lo,
        "ci_high": hi,
        "median_diff": float(np.median(d)),
        "sd_diff": float(d.std(ddof=1)) if d.size > 1 else 0.0,
        "n_better": int(np.sum(d < 0)),
        "frac_better": float(np.mean(d < 0)),
        "wilcoxon_p": float(sps.wilcoxon(d).pvalue) if np.any(d != 0) else float("nan"),
    }


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
        rows.append(
            {
                "method": method,
                "baseline": base,
                "comparison": f"{method_label(method)} − {method_label(base)}",
                "purpose": purpose,
                **_paired_row(d, int(len(wide) - d.size), rng, n_boot, level),
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
    group give ``"1 run per curve beyond 19.3 m not shown (up to 29.9 m)"``. Shared by the
    figures and the section's captions, so both count the same values."""
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
    (Fig. 5) the baseline and RS-MHP with the largest N_T (the comparison of UAV-2)."""
    rs = family_rows(summary, MonteCarlo)["method"].tolist()
    base = [baseline_name()] if baseline_name() in set(summary["method"]) else []
    return {"nt": rs, "nbo": base + rs[-1:]}


def paired_view(paired: pd.DataFrame, view: str) -> pd.DataFrame:
    """Rows of ``paired`` drawn in a paired figure: ``"nt"`` the N_T trend and pruning pairs
    (Fig. 4 side, UAV-1 and UAV-3), ``"nbo"`` every method minus the baseline (Fig. 5 side,
    UAV-2)."""
    purposes = {"nt": (TREND, PRUNING), "nbo": (vs_baseline(),)}[view]
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
