r"""Statistics of the estimator ablation: per-cell summaries, variance slopes, fractions,
exceedance frequencies and equal-CPU comparisons. Numbers only: the claims and their verdict
rules are in :mod:`rsmhp.studies.estimators.claims`, the report's prose and tables in
:mod:`rsmhp.studies.estimators.section`.

Symbols
-------
H is the horizon (noise draws per trajectory), ``n`` the number of trajectories behind one
estimate (leaves for a tree, kept trajectories for a pruned tree). ``mc`` averages ``n``
independent trajectories; ``tree`` draws ``N`` noise values per level that every node of the
level shares (:math:`N^H` leaves, the paper's Fig. 1a); ``tree_pernode`` draws ``N`` fresh values
at every node; ``pruned`` keeps, at every level, the ``M`` partial trajectories of highest
likeliness (product of the draws' densities). *Weighted* variants average with the normalised
likeliness instead of uniformly. Every trajectory cost is a quadratic form of the stacked noise
:math:`w = (w_0, \dots, w_{H-1}) \sim \mathcal N(0, S)`, :math:`S = I_H \otimes \Sigma`
(:math:`\Sigma` the per-step noise covariance): :math:`g(w) = c + b^\top w + w^\top K w`, so
:math:`J = c + \mathrm{tr}(KS)`, the NBO cost is :math:`c` and :math:`J(\Sigma/2) = c +
\mathrm{tr}(KS)/2` (:class:`rsmhp.models.lqg.linear_quadratic.QuadraticForm`).

Per grid cell (problem, scheme, weighting, N, M, n): bias, standard deviation and RMSE with 95%
percentile-bootstrap intervals (2000 resamples, seeded per cell), median CPU time, and the
derived variance / limit where one exists. Every number below except CPU times is bitwise
reproducible (seeded draws, seeded bootstrap, no optimiser).

Exact rules: cubature and Gauss-Hermite integrate quadratic costs exactly; their error is
floating-point rounding (relative error below ``EXACT_RTOL``), so they are reported as exact and
never as an RMSE gain (a ratio with a rounding error in the denominator means nothing).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.core.stats import DETECTABLE_GRID, SlopeFit, binomial_ci, detectable_scale, loglog_slope
from rsmhp.models.lqg.ablation import (
    CELL,
    SUMMARY_COLUMNS,
    build_problem,
    summarize_ablation,
)
from rsmhp.models.lqg.linear_quadratic import LinearQuadratic

__all__ = [
    "CELL",
    "EXACT_RTOL",
    "MIN_TREE_SIZES",
    "SUMMARY_COLUMNS",
    "antithetic_ratios",
    "best_stochastic_gains",
    "chebyshev_table",
    "equal_cpu_gains",
    "exact_rule_error",
    "largest_cells",
    "largest_leaf_ratios",
    "mc_variance_slopes",
    "problems_from_config",
    "pruning_at_largest_n",
    "pruning_pivot",
    "pruning_weighting_gap",
    "select",
    "sobol_rmse_ratios",
    "summarize_ablation",
    "tree_coverage",
    "tree_slopes",
    "tree_vs_independent",
    "variance_slope",
    "weighted_at_largest",
    "weighted_fractions",
    "weighted_fractions_all",
    "weighted_trend",
]

#: tree sizes (values of N) a problem needs for its log-log slope to count as evidence
MIN_TREE_SIZES = 4
#: relative error below which a deterministic rule counts as exact (floating-point rounding)
EXACT_RTOL = 1e-10
#: the weighted schemes whose fractions f the report tabulates, in table order
WEIGHTED_SCHEMES = ("tree", "tree_pernode", "mc")


def problems_from_config(cfg: Mapping[str, Any], lqg_model: Mapping[str, Any]):
    """name -> :class:`LinearQuadratic` for the ``estimators.problems`` config list."""
    return {spec["name"]: build_problem(spec, lqg_model) for spec in cfg["problems"]}


def select(s: pd.DataFrame, scheme: str, weighting: str = "uniform") -> pd.DataFrame:
    """The summary rows of one ``scheme`` and ``weighting``."""
    return s[(s["scheme"] == scheme) & (s["weighting"] == weighting)]


def tree_vs_independent(s: pd.DataFrame) -> pd.DataFrame:
    """Tree (shared and per-node) vs independent variance at equal leaf counts, measured and
    derived, for every leaf count present in both."""
    mc = select(s, "mc").set_index(["problem", "n_trajectories"])
    rows = []
    for scheme in ("tree", "tree_pernode"):
        for _, r in select(s, scheme).iterrows():
            key = (r["problem"], r["n_trajectories"])
            if key not in mc.index:
                continue
            m = mc.loc[key]
            rows.append(
                {
                    "problem": r["problem"],
                    "tree": scheme,
                    "N": int(r["N"]),
                    "H": int(r["H"]),
                    "leaves": int(r["n_trajectories"]),
                    "var_tree": float(r["var"]),
                    "var_mc": float(m["var"]),
                    "ratio_measured": float(r["var"] / m["var"]),
                    "ratio_derived": float(r["var_theory"] / m["var_theory"]),
                }
            )
    cols = ["problem", "tree", "N", "H", "leaves", "var_tree", "var_mc"]
    return pd.DataFrame(rows, columns=[*cols, "ratio_measured", "ratio_derived"])


def largest_leaf_ratios(s: pd.DataFrame) -> pd.DataFrame:
    """The shared-tree rows of :func:`tree_vs_independent` at each problem's largest leaf
    count."""
    tvi = tree_vs_independent(s)
    shared = tvi[tvi["tree"] == "tree"]
    return shared.loc[shared.groupby("problem", sort=False)["leaves"].idxmax()]


def _is_exact(rmse: float, j: float) -> bool:
    return bool(rmse <= EXACT_RTOL * max(abs(j), 1.0))


def equal_cpu_gains(s: pd.DataFrame) -> pd.DataFrame:
    """Best RMSE each sampler reaches within the median CPU time of plain MC's largest budget
    (its CPU-RMSE Pareto frontier at that time); gain = RMSE_mc / RMSE_sampler.

    A sampler none of whose budgets fits in that time is reported at its cheapest budget, with
    a note. Rules whose error is at rounding level (relative RMSE <= ``EXACT_RTOL``) get
    ``exact = True`` and no gain (NaN): dividing by a rounding error is not a gain. CPU times,
    and so these rows, change from run to run.
    """
    rows = []
    for problem, grp in s.groupby("problem", sort=False):
        mc = select(grp, "mc").sort_values("n_trajectories")
        if mc.empty:
            continue
        t_star, rmse_mc = float(mc["cpu_median"].iloc[-1]), float(mc["rmse"].iloc[-1])
        for scheme in ("mc", "antithetic", "sobol", "tree", "cubature", "gauss_hermite"):
            sub = grp[(grp["scheme"] == scheme) & grp["weighting"].isin(["uniform", "quadrature"])]
            if sub.empty:
                continue
            fits = sub[sub["cpu_median"] <= t_star]
            if scheme == "mc":
                best, note = mc.iloc[-1], "reference (largest budget)"
            elif len(fits):
                best = fits.loc[fits["rmse"].idxmin()]
                note = "best within the time"
            else:
                best = sub.loc[sub["cpu_median"].idxmin()]
                note = "no budget fits the time; cheapest shown"
            rmse = float(best["rmse"])
            exact = _is_exact(rmse, float(best["J_exact"]))
            rows.append(
                {
                    "problem": problem,
                    "scheme": scheme,
                    "cpu_seconds": t_star,
                    "n_trajectories": int(best["n_trajectories"]),
                    "cpu_used": float(best["cpu_median"]),
                    "rmse": rmse,
                    "exact": exact,
                    "gain_vs_mc": np.nan if exact else rmse_mc / rmse,
                    "note": note,
                }
            )
    return pd.DataFrame(rows)


def chebyshev_table(
    df: pd.DataFrame,
    s: pd.DataFrame,
    ks: Sequence[float],
    problems: Mapping[str, LinearQuadratic],
) -> pd.DataFrame:
    r"""Plain MC: frequency of :math:`|J_n - J| \ge k\,\mathrm{sd}_n` (sd from the closed
    form) with its Clopper-Pearson 95% interval, against Chebyshev's bound :math:`1/k^2`
    (``bound``) and the exact probability of that event (``exact``: :math:`J_n` is the mean
    of n copies of the quadratic trajectory cost,
    :meth:`~rsmhp.models.lqg.linear_quadratic.QuadraticForm.mean_error_tail`); ``detectable``: the
    smallest relative spread error the cell's test detects with 80% power
    (:func:`rsmhp.core.stats.detectable_scale`); ``replicates`` per cell."""
    rows = []
    mc = df[(df["scheme"] == "mc") & (df["weighting"] == "uniform")]
    theory = select(s, "mc").set_index(["problem", "n_trajectories"])["var_theory"]
    groups = list(mc.groupby(["problem", "n_trajectories"], sort=False))
    cells = len(groups) * len(ks)
    for (problem, n), grp in groups:
        sd = float(np.sqrt(theory.loc[(problem, n)]))
        form = problems[problem].quadratic_form
        err = np.abs(grp["estimate"].to_numpy() - grp["J_exact"].to_numpy())
        exact = np.atleast_1d(form.mean_error_tail(int(n), sd * np.asarray(ks, dtype=float)))
        for k, p_exact in zip(ks, exact, strict=True):
            hits = int(np.sum(err >= k * sd))
            lo, hi = binomial_ci(hits, err.size)
            rows.append(
                {
                    "problem": problem,
                    "n": int(n),
                    "k": float(k),
                    "replicates": int(err.size),
                    "hits": hits,
                    "bound": min(1.0, 1 / k**2),
                    "exact": float(p_exact),
                    "detectable": detectable_scale(
                        lambda x, n=int(n), form=form: form.mean_error_tail(n, x),
                        float(k * sd),
                        err.size,
                        cells,
                        grid=DETECTABLE_GRID,
                    ),
                    "freq": hits / err.size,
                    "low": lo,
                    "high": hi,
                }
            )
    return pd.DataFrame(rows)


def variance_slope(sub: pd.DataFrame, x: str, y: str = "var") -> SlopeFit | None:
    """Log-log OLS slope of ``y`` against ``x`` over the rows where both are positive; None
    with fewer than 3 such rows."""
    sub = sub[(sub[x] > 0) & (sub[y] > 0)]
    return loglog_slope(sub[x], sub[y]) if len(sub) >= 3 else None


def tree_slopes(s: pd.DataFrame, scheme: str = "tree") -> pd.DataFrame:
    """Per problem (uniform ``scheme``): the tree sizes, the log-log slope of the variance
    against N (NaN with fewer than 3 sizes), whether the problem counts for EST-1 (at least
    ``MIN_TREE_SIZES`` sizes), and whether the variance at the largest N is significantly
    below / above the one at the smallest (disjoint bootstrap CIs)."""
    rows = []
    for problem, grp in select(s, scheme).groupby("problem", sort=False):
        grp = grp.sort_values("N")
        fit = variance_slope(grp, "N")
        first, last = grp.iloc[0], grp.iloc[-1]
        rows.append(
            {
                "problem": problem,
                "H": int(first["H"]),
                "sizes": [int(v) for v in grp["N"]],
                "n_sizes": len(grp),
                "slope": fit.slope if fit else np.nan,
                "slope_low": fit.low if fit else np.nan,
                "slope_high": fit.high if fit else np.nan,
                "counted": len(grp) >= MIN_TREE_SIZES and fit is not None,
                "falls": bool(len(grp) > 1 and last["var_high"] < first["var_low"]),
                "rises": bool(len(grp) > 1 and last["var_low"] > first["var_high"]),
            }
        )
    cols = ["problem", "H", "sizes", "n_sizes", "slope", "slope_low", "slope_high"]
    return pd.DataFrame(rows, columns=[*cols, "counted", "falls", "rises"])


def weighted_fractions(s: pd.DataFrame, scheme: str = "tree") -> pd.DataFrame:
    """Weighted ``scheme`` cells with f = (mean - J)/(J(Σ/2) - J) and its bootstrap CI
    (0: the mean is J; 1: it is the derived large-N limit J(Σ/2))."""
    w = select(s, scheme, "weighted").sort_values(["problem", "n_trajectories"], kind="stable")
    den = w["limit"] - w["J_exact"]
    ends = np.stack([w["bias_low"] / den, w["bias_high"] / den])
    return w.assign(
        f=w["bias"] / den,
        f_low=ends.min(axis=0),
        f_high=ends.max(axis=0),
        ci_low=w["J_exact"] + w["bias_low"],
        ci_high=w["J_exact"] + w["bias_high"],
    )


def tree_coverage(s: pd.DataFrame) -> tuple[int, int]:
    """(cells whose bootstrap variance CI contains the derived tree variance, cells with a
    derived variance) over the uniform shared-tree cells."""
    tree = select(s, "tree").dropna(subset=["var_theory"])
    inside = (tree["var_low"] <= tree["var_theory"]) & (tree["var_theory"] <= tree["var_high"])
    return int(inside.sum()), len(tree)


_TREND_COLUMNS = [
    "problem",
    "n_sizes",
    "N_first",
    "f_first",
    "N",
    "mean",
    "ci_low",
    "ci_high",
    "J_exact",
    "limit",
    "f",
    "f_low",
    "f_high",
    "excludes_j",
    "excludes_limit",
    "not_shrinking",
]


def weighted_trend(s: pd.DataFrame) -> pd.DataFrame:
    """One row per problem of the weighted shared tree (:func:`weighted_fractions`): its cell
    at the largest N, with f at the smallest N (``N_first``, ``f_first``), the number of sizes
    run, whether f's CI at the largest N excludes 0 (J) and 1 (the derived limit), and whether
    |f| did not shrink from the smallest to the largest N."""
    rows = []
    for problem, g in weighted_fractions(s).groupby("problem", sort=False):
        g = g.sort_values("N")
        first, last = g.iloc[0], g.iloc[-1]
        rows.append(
            {
                "problem": problem,
                "n_sizes": len(g),
                "N_first": int(first["N"]),
                "f_first": float(first["f"]),
                **{c: last[c] for c in _TREND_COLUMNS[4:13]},
                "excludes_j": bool(last["f_low"] > 0 or last["f_high"] < 0),
                "excludes_limit": bool(last["f_low"] > 1 or last["f_high"] < 1),
                "not_shrinking": bool(abs(last["f"]) >= abs(first["f"])),
            }
        )
    return pd.DataFrame(rows, columns=_TREND_COLUMNS)


def weighted_fractions_all(s: pd.DataFrame) -> pd.DataFrame:
    """:func:`weighted_fractions` of every weighted scheme, with ``in_unit_interval``: the CI
    of f meets [0, 1]."""
    wf = pd.concat([weighted_fractions(s, sc) for sc in WEIGHTED_SCHEMES])
    return wf.assign(in_unit_interval=(wf["f_low"] <= 1) & (wf["f_high"] >= 0))


def weighted_at_largest(s: pd.DataFrame) -> pd.DataFrame:
    """Each weighted scheme's cell (:func:`weighted_fractions`) at each problem's largest
    n, schemes in the order tree, tree_pernode, mc."""
    lasts = []
    for scheme in WEIGHTED_SCHEMES:
        wf = weighted_fractions(s, scheme)
        if len(wf):
            lasts.append(wf.loc[wf.groupby("problem", sort=False)["n_trajectories"].idxmax()])
    return pd.concat(lasts) if lasts else pd.DataFrame(columns=s.columns)


def mc_variance_slopes(s: pd.DataFrame) -> dict[str, SlopeFit]:
    """problem -> log-log slope of plain MC's variance against n (problems with >= 3 budgets)."""
    fits = {
        p: variance_slope(g, "n_trajectories")
        for p, g in select(s, "mc").groupby("problem", sort=False)
    }
    return {p: f for p, f in fits.items() if f is not None}


def pruning_at_largest_n(s: pd.DataFrame) -> pd.DataFrame:
    """The uniform pruned-tree cells at each problem's largest N (every M)."""
    pr = select(s, "pruned")
    return pr[pr["N"] == pr.groupby("problem")["N"].transform("max")]


def pruning_weighting_gap(s: pd.DataFrame) -> float | None:
    """Largest |uniform - weighted| bias / (J_NBO - J) over the pruned cells run with both
    weightings; None if there is no such cell."""
    key = ["problem", "N", "M"]
    pw = select(s, "pruned", "weighted").set_index(key)["bias_fraction_of_nbo"]
    pu = select(s, "pruned").set_index(key)["bias_fraction_of_nbo"]
    diff = (pu - pw).abs().dropna()
    return float(diff.max()) if len(diff) else None


def pruning_pivot(s: pd.DataFrame) -> pd.DataFrame:
    """Uniform pruned tree: bias / (J_NBO - J) per (problem, M) row and ``N = ...`` column (NaN
    where M > N was not run)."""
    pr = select(s, "pruned")
    pivot = pr.pivot_table(index=["problem", "M"], columns="N", values="bias_fraction_of_nbo")
    pivot.columns = [f"N = {int(c)}" for c in pivot.columns]
    pivot = pivot.reset_index()
    pivot["M"] = pivot["M"].astype(int)
    return pivot


def largest_cells(s: pd.DataFrame) -> pd.DataFrame:
    """Each stochastic (problem, scheme, weighting) at its largest size, problems in the order
    of the summary."""
    sto = s[s["n_replicates"] > 1].sort_values(["n_trajectories", "N", "M"], kind="stable")
    largest = (
        sto.groupby(["problem", "scheme", "weighting"], sort=False)
        .tail(1)
        .sort_values(["problem", "scheme", "weighting"], kind="stable")
    )
    return largest.set_index("problem").loc[list(dict.fromkeys(s["problem"]))].reset_index()


def exact_rule_error(s: pd.DataFrame) -> tuple[int, float] | None:
    """(cells, largest relative error |bias| / max(|J|, 1)) of the quadrature rules (cubature,
    Gauss-Hermite); None if none ran."""
    q = s[s["weighting"] == "quadrature"]
    if q.empty:
        return None
    return len(q), float((q["bias"].abs() / q["J_exact"].abs().clip(lower=1.0)).max())


def antithetic_ratios(s: pd.DataFrame) -> pd.Series:
    """problem -> derived antithetic / MC variance ratio 4 tr((KS)^2) / Var(g) (the same at
    any budget; taken at the first budget both ran)."""
    anti = select(s, "antithetic").set_index(["problem", "n_trajectories"])["var_theory"]
    mcv = select(s, "mc").set_index(["problem", "n_trajectories"])["var_theory"]
    return (anti / mcv).dropna().groupby(level=0, sort=False).first()


def best_stochastic_gains(gains: pd.DataFrame) -> pd.DataFrame:
    """Per problem, the row of :func:`equal_cpu_gains` of the stochastic sampler (antithetic,
    Sobol') with the largest RMSE gain over MC."""
    stoch = gains[gains["scheme"].isin(["antithetic", "sobol"]) & ~gains["exact"]]
    stoch = stoch.dropna(subset=["gain_vs_mc"])
    return stoch.loc[stoch.groupby("problem", sort=False)["gain_vs_mc"].idxmax()]


def sobol_rmse_ratios(s: pd.DataFrame) -> pd.DataFrame:
    """RMSE of plain MC / RMSE of Sobol' per problem at the largest n both ran (columns
    ``problem``, ``n_trajectories``, ``ratio``; empty if they share no budget)."""
    both = select(s, "mc").merge(
        select(s, "sobol"), on=["problem", "n_trajectories"], suffixes=("", "_s")
    )
    big = both[both["n_trajectories"] == both["n_trajectories"].max()]
    return pd.DataFrame(
        {
            "problem": big["problem"],
            "n_trajectories": big["n_trajectories"],
            "ratio": big["rmse"] / big["rmse_s"],
        }
    )
