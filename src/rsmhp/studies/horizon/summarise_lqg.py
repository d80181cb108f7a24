r"""The oven LQG at long horizons (:mod:`rsmhp.studies.horizon.simulate_lqg`), statistics. Numbers
only: the claims HZ-4 and HZ-5 are in :mod:`rsmhp.studies.horizon.claims`, prose and tables in
:mod:`rsmhp.studies.horizon.section`.

Estimators: per cell (a, H, scheme, weighting, N, M, n) the estimator study's summary
(:func:`rsmhp.models.lqg.ablation.summarize_ablation`: bias, RMSE with percentile-bootstrap
CIs over replicates) divided by the exact cost J of the cell's problem: relative bias
:math:`(\bar{\hat J} - J)/J` and relative RMSE :math:`\sqrt{\overline{(\hat J - J)^2}}/J`,
and for uniform Monte Carlo its closed form :math:`\sqrt{\mathrm{Var}\,g / n}/J`
(``rel_rmse_theory``, :meth:`rsmhp.models.lqg.linear_quadratic.QuadraticForm.independent_variance`).

Regret: the decision study's summary (:func:`rsmhp.models.lqg.regret_summary.summarize_lqg_regret`:
mean regret with t-CI, closed form, z-score) with the long-horizon limit of each cell's closed
form (``limit``: :func:`rsmhp.studies.horizon.closed_forms.mc_regret_limit` for uniform Monte
Carlo, 0 for the exact methods, NaN where the closed form has no limit or there is none).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from rsmhp.core.seeding import job_rng
from rsmhp.models.lqg.ablation import build_problem, summarize_ablation
from rsmhp.models.lqg.regret_summary import ZERO_REGRET, summarize_lqg_regret
from rsmhp.studies.horizon import closed_forms as lqg_horizon
from rsmhp.studies.horizon.simulate_lqg import problem_name, problem_specs

__all__ = [
    "LQG_ESTIMATOR_COLUMNS",
    "PrunedGrowth",
    "pruned_growth",
    "relative_errors",
    "summarize_lqg_estimators",
    "summarize_lqg_horizon_regret",
]

LQG_ESTIMATOR_COLUMNS = [
    "a",
    "H",
    "scheme",
    "weighting",
    "N",
    "M",
    "n_trajectories",
    "n_replicates",
    "J_exact",
    "rel_bias",
    "rel_bias_low",
    "rel_bias_high",
    "rel_rmse",
    "rel_rmse_low",
    "rel_rmse_high",
    "rel_rmse_theory",
    "nbo_rel_error",
]


def _problems(cfg: Mapping[str, Any], model: Mapping[str, Any]):
    specs = problem_specs(cfg, model)
    return specs, {n: build_problem(s, model) for n, s in specs.items()}


def summarize_lqg_estimators(
    df: pd.DataFrame, cfg: Mapping[str, Any], model: Mapping[str, Any], seed: int
) -> pd.DataFrame:
    """One row per estimator cell (:data:`LQG_ESTIMATOR_COLUMNS`), sorted by a, H, scheme;
    ``cfg`` is ``horizon.lqg``, ``model`` ``lqg.model``. ``nbo_rel_error`` is NBO's relative
    error :math:`(J_{NBO} - J)/J = -r v_H / J` of the cell's problem."""
    specs, problems = _problems(cfg, model)
    s = summarize_ablation(df, problems, seed)
    J = s["J_exact"].to_numpy(float)
    out = pd.DataFrame(
        {
            "a": s["problem"].map(lambda p: float(specs[p]["a"])),
            **{k: s[k] for k in ("H", "scheme", "weighting", "N", "M", "n_trajectories")},
            "n_replicates": s["n_replicates"],
            "J_exact": J,
            "rel_bias": s["bias"] / J,
            "rel_bias_low": s["bias_low"] / J,
            "rel_bias_high": s["bias_high"] / J,
            "rel_rmse": s["rmse"] / J,
            "rel_rmse_low": s["rmse_low"] / J,
            "rel_rmse_high": s["rmse_high"] / J,
            "rel_rmse_theory": np.where(
                (s["scheme"] == "mc") & (s["weighting"] == "uniform"),
                np.sqrt(s["var_theory"].to_numpy(float)) / J,
                np.nan,
            ),
            "nbo_rel_error": (s["J_nbo"] - s["J_exact"]) / J,
        }
    )
    order = {k: i for i, k in enumerate(("nbo", "cubature", "mc", "sobol", "pruned"))}
    out = out.assign(_s=out["scheme"].map(order))
    out = out.sort_values(["a", "H", "_s", "weighting", "N", "M", "n_trajectories"])
    return out.drop(columns="_s").reset_index(drop=True)[LQG_ESTIMATOR_COLUMNS]


def relative_errors(
    df: pd.DataFrame, a: float, H: int, scheme: str, *, N: int = 0, n: int, weighting="uniform"
) -> np.ndarray:
    """The replicates' relative errors :math:`(\\hat J - J)/J` of one cell of the estimator
    rows ``df`` (``n``: trajectories; ``N``: draws per level of a pruned tree)."""
    sel = df[
        (df["problem"] == problem_name(a, H))
        & (df["scheme"] == scheme)
        & (df["weighting"] == weighting)
        & (df["N"] == int(N))
        & (df["n_trajectories"] == int(n))
    ]
    if sel.empty:
        raise ValueError(
            f"no estimator rows for a = {a:g}, H = {H}, {scheme} (N = {N}, n = {n}, {weighting})"
        )
    return ((sel["estimate"] - sel["J_exact"]) / sel["J_exact"]).to_numpy(float)


class PrunedGrowth(NamedTuple):
    """HZ-4's key number: d = growth of the pruned tree's relative RMSE from ``h_lo`` to
    ``h_hi`` − that of Monte Carlo with as many trajectories, with its 95% CI; the four
    RMSEs, Monte Carlo's own growth with its CI and the replicates per cell."""

    mean: float
    low: float
    high: float
    pruned_lo: float
    pruned_hi: float
    mc_lo: float
    mc_hi: float
    mc_growth: float
    mc_growth_low: float
    mc_growth_high: float
    replicates: int
    h_lo: int
    h_hi: int


def pruned_growth(
    df: pd.DataFrame,
    a: float,
    N: int,
    M: int,
    h_lo: int,
    h_hi: int,
    seed: int,
    n_boot: int,
) -> PrunedGrowth:
    r""":math:`d = [R_{tree}(H_{hi}) - R_{tree}(H_{lo})] - [R_{mc}(H_{hi}) - R_{mc}(H_{lo})]`
    with :math:`R` the relative RMSE (uniform weights) of the pruned tree (N, M) and of Monte
    Carlo with n = M. The four cells are independent samples (own problems, own streams), so
    the bootstrap resamples each cell's replicates independently (percentile 95% CI,
    ``n_boot`` resamples, stream keyed on the arguments)."""
    cells = [
        relative_errors(df, a, h, s, N=nn, n=M)
        for s, nn in (("pruned", N), ("mc", 0))
        for h in (h_lo, h_hi)
    ]
    rng = job_rng(seed, "horizon_lqg_growth", a=float(a), N=int(N), M=int(M), h=(h_lo, h_hi))

    def rmse(x: np.ndarray, idx: np.ndarray | None = None) -> np.ndarray | float:
        if idx is None:
            return float(np.sqrt(np.mean(x * x)))
        return np.sqrt(np.mean(x[idx] ** 2, axis=1))

    boot = [rmse(x, rng.integers(0, x.size, size=(n_boot, x.size))) for x in cells]
    point = [rmse(x) for x in cells]
    d_b = (boot[1] - boot[0]) - (boot[3] - boot[2])
    mc_b = boot[3] - boot[2]
    lo, hi = np.percentile(d_b, (2.5, 97.5))
    mlo, mhi = np.percentile(mc_b, (2.5, 97.5))
    return PrunedGrowth(
        mean=(point[1] - point[0]) - (point[3] - point[2]),
        low=float(lo),
        high=float(hi),
        pruned_lo=point[0],
        pruned_hi=point[1],
        mc_lo=point[2],
        mc_hi=point[3],
        mc_growth=point[3] - point[2],
        mc_growth_low=float(mlo),
        mc_growth_high=float(mhi),
        replicates=min(x.size for x in cells),
        h_lo=int(h_lo),
        h_hi=int(h_hi),
    )


def summarize_lqg_horizon_regret(df: pd.DataFrame, model: Mapping[str, Any]) -> pd.DataFrame:
    """:func:`rsmhp.models.lqg.regret_summary.summarize_lqg_regret` of the study's regret rows
    with ``limit`` (module docstring); ``model`` is ``lqg.model``."""
    s = summarize_lqg_regret(df, model)
    r, sigma = float(model["r"]), float(model["sigma"])

    def limit(row: pd.Series) -> float:
        if row["method"] in ZERO_REGRET:
            return 0.0
        if row["method"] == "mc" and row["weighting"] == "uniform":
            return lqg_horizon.mc_regret_limit(int(row["P"]), a=float(row["a"]), r=r, sigma=sigma)
        return float("nan")

    return s.assign(limit=s.apply(limit, axis=1) if len(s) else pd.Series(dtype=float))
