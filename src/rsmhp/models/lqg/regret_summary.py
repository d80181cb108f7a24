r"""Decision-quality study on the scalar LQG (:mod:`rsmhp.models.lqg.regret`),
statistics: regret summaries, closed-form checks (z-scores) and scaling fits. Numbers only:
the claims DEC-1..DEC-5 are in :mod:`rsmhp.studies.decisions.claims_lqg`, the prose and tables in
:mod:`rsmhp.studies.decisions.section_lqg`.

Per cell (a, H, method, weighting, N, M, P): mean regret :math:`\bar\rho` of R replicates
with a t-interval, the closed-form mean :math:`\rho` where one exists
(:func:`closed_form_regret`, from :mod:`rsmhp.models.lqg.oven`) and the z-score of the simulated
mean against it. The regret of a cell with a closed form is :math:`\rho` times a :math:`\chi^2_1`
variable, so the standard error of a mean of R replicates is :math:`\rho\sqrt{2/R}`
(:func:`rsmhp.models.lqg.oven.regret_standard_error`): :math:`z = (\bar\rho -
\rho)/(\rho\sqrt{2/R})`. A
family of m z-scores is checked against the Bonferroni limit :math:`\Phi^{-1}(1 -
0.05/(2m))` (95% family-wise, :func:`bonferroni`).

Closed forms (all derived in :mod:`rsmhp.models.lqg.oven`): nbo, antithetic and cubature 0 (exact);
mc with uniform weights :math:`\kappa v_H / P`; the shared-draw tree with uniform weights
:math:`\kappa v_H / N`; mc with likeliness weights, to first order in 1/P,
:math:`\kappa v_H (4/3)^{H/2}/(3P)`. Here
:math:`\kappa = r^2 a^2 \|\beta\|^2 / (1 + r a^2 \|\beta\|^2)`,
:math:`\beta_k = (1-a)^{H-1-k}` and :math:`v_H = \sigma^2 \|\beta\|^2` is the variance of the
final state.

Slopes: OLS fit :math:`\log \bar\rho = c + s \log x` per (a, H, method, weighting) with
:math:`x = P` (tree: N; pruned: M = P) and a t-interval for :math:`s`
(:func:`rsmhp.core.stats.loglog_slope`).

Shared by the studies ``rsmhp.studies.decisions`` and ``rsmhp.studies.horizon`` (so it lives
below them).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple

import numpy as np
import pandas as pd
import scipy  # scipy.stats loads on first use (scipy's lazy submodules)

from rsmhp.core.stats import loglog_slope, mean_ci
from rsmhp.models.lqg import oven as lqg

__all__ = [
    "CELL",
    "LQG_SUMMARY_COLUMNS",
    "NO_Z_CELLS",
    "SCALING_COLUMNS",
    "WEIGHTED_MIN_P",
    "ZERO_REGRET",
    "ZCheck",
    "bonferroni",
    "cells_without_slope",
    "closed_form_regret",
    "independent_regret",
    "lqg_scaling",
    "max_rel_regret",
    "pruned_shape",
    "slopes",
    "summarize_lqg_regret",
    "z_families",
]

CELL = ["problem", "a", "H", "method", "weighting", "N", "M", "P"]
LQG_SUMMARY_COLUMNS = [
    *CELL,
    "n",
    "mean",
    "ci_low",
    "ci_high",
    "median",
    "J_star",
    "rel_mean",
    "closed_form",
    "closed_kind",
    "z",
]
SCALING_COLUMNS = ["a", "H", "method", "weighting", "x", "n_points", "slope", "low", "high"]

#: methods whose sample has mean final-state noise 0: regret 0 (exact), no slope
ZERO_REGRET = ("nbo", "antithetic", "cubature")

#: likeliness-weighted mc: the closed form is first order in 1/P; cells below are left out
#: of its z-score family
WEIGHTED_MIN_P = 100


def closed_form_regret(
    method: str, weighting: str, N: int, P: int, H: int, model: Mapping[str, float]
) -> tuple[float, str]:
    """(mean regret, kind) of a cell, kind ``exact``, ``asymptotic`` (large P) or ``none``
    (no closed form: NaN); ``model`` holds a, r and sigma. nbo, antithetic, cubature: 0;
    uniform mc: :func:`rsmhp.models.lqg.oven.expected_regret` (P); uniform tree: the same with N;
    likeliness-weighted mc: :func:`rsmhp.models.lqg.oven.weighted_expected_regret`."""
    kw = {"a": model["a"], "r": model["r"], "sigma": model["sigma"]}
    if method in ZERO_REGRET:
        return 0.0, "exact"
    if weighting == "uniform" and method == "mc":
        return lqg.expected_regret(P, H, **kw), "exact"
    if weighting == "uniform" and method == "tree":
        return lqg.expected_regret(N, H, **kw), "exact"
    if weighting == "likeliness" and method == "mc":
        return lqg.weighted_expected_regret(P, H, **kw), "asymptotic"
    return float("nan"), "none"


def _summary_row(cell: dict[str, Any], reg: np.ndarray, model: Mapping[str, Any]) -> dict:
    """One row of :func:`summarize_lqg_regret` from the regrets ``reg`` of ``cell``."""
    a, H = float(cell["a"]), int(cell["H"])
    base = lqg.LQGModel.from_config(model, a=a)
    j_star = lqg.optimal_cost(H, **base.closed_form_args())
    if reg.size >= 2:
        mean, lo, hi = mean_ci(reg)
    else:
        mean, lo, hi = float(reg[0]), float(reg[0]), float(reg[0])
    closed, kind = closed_form_regret(
        cell["method"],
        cell["weighting"],
        int(cell["N"]),
        int(cell["P"]),
        H,
        {"a": a, "r": base.r, "sigma": base.sigma},
    )
    z = (
        (mean - closed) / lqg.regret_standard_error(closed, reg.size)
        if kind != "none" and closed > 0
        else float("nan")
    )
    return {
        **cell,
        "n": int(reg.size),
        "mean": mean,
        "ci_low": lo,
        "ci_high": hi,
        "median": float(np.median(reg)),
        "J_star": j_star,
        "rel_mean": mean / j_star,
        "closed_form": closed,
        "closed_kind": kind,
        "z": z,
    }


def summarize_lqg_regret(df: pd.DataFrame, model: Mapping[str, Any]) -> pd.DataFrame:
    """One row per cell (:data:`LQG_SUMMARY_COLUMNS`); ``model`` is the ``lqg.model`` config
    section (x0, r, target, sigma). ``rel_mean`` is the mean regret over the optimal cost
    :math:`J(u^*)` (:func:`rsmhp.models.lqg.oven.optimal_cost`); ``z`` is NaN where the closed form
    is 0 or absent."""
    rows = []
    for key, g in df.groupby(CELL, sort=False):
        cell = dict(zip(CELL, key, strict=True))
        rows.append(_summary_row(cell, g["regret"].to_numpy(float), model))
    return pd.DataFrame(rows, columns=LQG_SUMMARY_COLUMNS)


def lqg_scaling(summary: pd.DataFrame) -> pd.DataFrame:
    """Log-log slope of mean regret in the sample size for every stochastic (a, H, method,
    weighting) with >= 3 sizes: against P (mc, sobol, pruned: P = M) or against N (tree).
    Methods with zero regret (nbo, antithetic, cubature) have no slope."""
    rows = []
    stochastic = summary[~summary["method"].isin(ZERO_REGRET)]
    for (a, H, method, weighting), g in stochastic.groupby(
        ["a", "H", "method", "weighting"], sort=False
    ):
        x_name = "N" if method == "tree" else "P"
        g = g[g["mean"] > 0]
        if len(g) < 3:
            continue
        fit = loglog_slope(g[x_name].to_numpy(float), g["mean"].to_numpy(float))
        rows.append(
            {
                "a": a,
                "H": H,
                "method": method,
                "weighting": weighting,
                "x": x_name,
                "n_points": len(g),
                "slope": fit.slope,
                "low": fit.low,
                "high": fit.high,
            }
        )
    return pd.DataFrame(rows, columns=SCALING_COLUMNS)


def slopes(scaling: pd.DataFrame, method: str, weighting: str = "uniform") -> pd.DataFrame:
    """The slope fits of ``method`` with ``weighting`` (one row per (a, H) cell)."""
    return scaling[(scaling["method"] == method) & (scaling["weighting"] == weighting)]


def bonferroni(n_tests: int, level: float = 0.95) -> float:
    r"""Two-sided normal limit of ``n_tests`` z-scores at family-wise ``level``:
    :math:`\Phi^{-1}(1 - (1 - \text{level})/(2m))`."""
    return float(scipy.stats.norm.ppf(1.0 - (1.0 - level) / (2 * max(n_tests, 1))))


class ZCheck(NamedTuple):
    """A family of closed-form checks: the largest :math:`|z|` (NaN if no cell), its
    Bonferroni limit and the number of cells with a finite z."""

    max_abs_z: float
    limit: float
    cells: int


def _z_check(rows: pd.DataFrame) -> ZCheck:
    z = rows["z"].abs().to_numpy(float)
    z = z[np.isfinite(z)]
    return ZCheck((float(z.max()) if z.size else float("nan")), bonferroni(z.size), int(z.size))


#: the (max |z|, limit, cells) of a claim whose family has no cell
NO_Z_CELLS = ZCheck(float("nan"), float("nan"), 0)


def z_families(summary: pd.DataFrame) -> dict[str, ZCheck]:
    """The closed-form checks of DEC-2 (uniform mc), DEC-3 (uniform shared-draw tree) and
    DEC-5 (likeliness-weighted mc, P >= :data:`WEIGHTED_MIN_P`); a family without cells is
    left out."""
    m, w = summary["method"], summary["weighting"]
    families = {
        "DEC-2": summary[(m == "mc") & (w == "uniform") & (summary["closed_kind"] == "exact")],
        "DEC-3": summary[(m == "tree") & (w == "uniform") & (summary["closed_kind"] == "exact")],
        "DEC-5": summary[
            (m == "mc")
            & (w == "likeliness")
            & (summary["closed_kind"] == "asymptotic")
            & (summary["P"] >= WEIGHTED_MIN_P)
        ],
    }
    out = {k: _z_check(rows) for k, rows in families.items()}
    return {k: v for k, v in out.items() if v.cells > 0}


def max_rel_regret(summary: pd.DataFrame, methods: Sequence[str]) -> float:
    """The largest mean regret / J(u*) of the cells of ``methods`` (0 if none)."""
    rows = summary[summary["method"].isin(methods)]
    return float(rows["rel_mean"].max()) if not rows.empty else 0.0


def cells_without_slope(
    summary: pd.DataFrame, scaling: pd.DataFrame, method: str, weighting: str
) -> list[tuple[float, int]]:
    """The (a, H) cells of ``method`` with ``weighting`` that have no slope (fewer than 3
    sample sizes with a positive mean regret), sorted."""
    have = {
        (float(a), int(h))
        for a, h in slopes(scaling, method, weighting)[["a", "H"]].itertuples(index=False)
    }
    rows = summary[(summary["method"] == method) & (summary["weighting"] == weighting)]
    return sorted({(float(a), int(h)) for a, h in rows[["a", "H"]].itertuples(index=False)} - have)


def independent_regret(cell: pd.Series, model: Mapping[str, Any]) -> float:
    """The closed-form mean regret :math:`\\kappa v_H / P` of ``cell['P']`` independent
    trajectories in the cell's (a, H) (a tree cell's leaves, had they been independent)."""
    return lqg.expected_regret(
        int(cell["P"]),
        int(cell["H"]),
        a=float(cell["a"]),
        r=float(model["r"]),
        sigma=float(model["sigma"]),
    )


#: columns of :func:`pruned_shape`
SHAPE_COLUMNS = [
    "a", "H", "N", "n_M", "M_first", "mean_first", "low_first", "high_first",
    "M_best", "mean_best", "low_best", "high_best", "M_last", "mean_last", "low_last",
    "high_last", "falls", "rises", "tree_mean",
]  # fmt: skip


def pruned_shape(summary: pd.DataFrame) -> pd.DataFrame:
    r"""The shape of the pruned tree's mean regret in M (N fixed), one row per (a, H) cell
    with at least 3 values of M: the regret (mean, 95% CI) at the smallest M, at the M with
    the lowest mean (``best``) and at the largest M; ``falls`` if the CIs at the largest and
    at the smallest M do not overlap with the largest below, ``rises`` if the CI at the largest
    M lies entirely above the CI at the best M (more kept trajectories decide significantly
    worse than fewer: a U shape); ``tree_mean`` the mean regret of the unpruned shared-draw
    tree with the same N in that cell (NaN if it was not run)."""
    pr = summary[(summary["method"] == "pruned") & (summary["weighting"] == "uniform")]
    tree = summary[(summary["method"] == "tree") & (summary["weighting"] == "uniform")]
    rows = []
    for (a, H), g in pr.groupby(["a", "H"], sort=True):
        g = g.sort_values("M")
        if len(g) < 3:
            continue
        first, last = g.iloc[0], g.iloc[-1]
        best = g.loc[g["mean"].idxmin()]
        n = int(g["N"].iloc[0])
        t = tree[(tree["a"] == a) & (tree["H"] == H) & (tree["N"] == n)]
        rows.append(
            {
                "a": a, "H": int(H), "N": n, "n_M": len(g),
                **{f"{k}_{tag}": r[c] for tag, r in (("first", first), ("best", best),
                   ("last", last)) for k, c in (("M", "M"), ("mean", "mean"),
                   ("low", "ci_low"), ("high", "ci_high"))},
                "falls": bool(last["ci_high"] < first["ci_low"]),
                "rises": bool(last["ci_low"] > best["ci_high"]),
                "tree_mean": float(t["mean"].iloc[0]) if len(t) else float("nan"),
            }
        )  # fmt: skip
    return pd.DataFrame(rows, columns=SHAPE_COLUMNS)
