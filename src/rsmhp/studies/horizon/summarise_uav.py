r"""UAV horizon study: statistics of the cost approximation, the regret and the planning time
against the horizon H (tables -> numbers, no prose).

Cost approximation, per (model, H, method), from the rows of
:data:`rsmhp.studies.horizon.simulate_uav.APPROX_COLUMNS`: with the relative error
:math:`e = (\hat J_m - \hat J_{ref}) / \hat J_{ref}` of a plan's estimate and the relative
standard error :math:`s` of its reference,

* per belief state: the bias :math:`b = \overline{e}` and the noise-corrected mean square
  :math:`q = \overline{e^2} - \overline{s^2}` (the reference is independent of the estimate,
  so :math:`E[e^2] = \mathrm{MSE} + \mathrm{Var}(\hat J_{ref})/J^2`: subtracting the
  reference's variance leaves the method's own error), both over plans and replicates;
* ``rel_bias`` = mean of b over states, ``rel_rmse`` = :math:`\sqrt{\max(\overline q, 0)}`,
  each with a 95% cluster-t CI over *runs* (clusters: the belief states of one run share its
  scenario, so they are not independent): the jackknife that leaves out one run with all its
  states at a time, t with runs − 1 df (:func:`rsmhp.core.stats.cluster_t_ci`; it holds with
  few runs, where a percentile bootstrap over them is too narrow). The RMSE's CI is that of
  the mean square :math:`\overline q` mapped through :math:`\sqrt{\max(\cdot, 0)}` (monotone,
  so the coverage carries over; 0 where the mean square's CI reaches below 0);
  ``ref_noise`` = :math:`\sqrt{\overline{s^2}}`, the reference's own relative SE; ``spearman``
  = mean over (state, replicate) of the rank correlation of estimate and reference over the
  plans (undefined where the estimate is constant over them, e.g. NBO's single hypothesis
  outside every plan's footprint: counted in ``spearman_undefined``).

:func:`rmse_growth` is the paired change of ``rel_rmse`` between two horizons over the same
runs (with their belief states) at both, with the cluster-t CI (jackknife over runs) and, beside
it, the percentile-bootstrap CI over runs it replaces (``boot_low``, ``boot_high``), so that a
report can show how the interval and the verdicts it gives changed. :func:`advantage_growth`
(closed loop, HZ-3) likewise; for its mean of per-run values the jackknife interval is the
Student-t interval. Regret and time per (model, H, method): mean relative regret against the
best plan found and against the best of the methods' own plans (which mixes the cost
approximation's error with the optimiser's), and the median planning milliseconds.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pandas as pd
from scipy import stats as sps

from rsmhp.core.seeding import job_rng
from rsmhp.core.stats import ClusterInterval, cluster_t_ci, runs_for_power
from rsmhp.models.lqg import oven as lqg
from rsmhp.studies.horizon import closed_forms as lqg_horizon

__all__ = [
    "APPROX_SUMMARY_COLUMNS",
    "CLOSED_SUMMARY_COLUMNS",
    "LEVEL",
    "POWER",
    "REGRET_SUMMARY_COLUMNS",
    "Advantage",
    "Growth",
    "advantage_growth",
    "lqg_horizon_table",
    "rmse_growth",
    "runs_to_resolve",
    "state_errors",
    "summarize_approx",
    "summarize_closed",
    "summarize_horizon_regret",
]

APPROX_SUMMARY_COLUMNS = [
    "model",
    "H",
    "method",
    "family",
    "states",
    "rel_bias",
    "rel_bias_low",
    "rel_bias_high",
    "rel_rmse",
    "rel_rmse_low",
    "rel_rmse_high",
    "ref_noise",
    "spearman",
    "spearman_undefined",
]

REGRET_SUMMARY_COLUMNS = [
    "model",
    "H",
    "method",
    "family",
    "states",
    "regret_pct",
    "regret_methods_pct",
    "plan_ms",
]

_STATE = ["run", "step"]

#: confidence level of every CI of this module
LEVEL = 0.95
#: power of the paired t-test at which :func:`runs_to_resolve` counts the runs a confirmatory
#: comparison needs
POWER = 0.8
#: the largest run count :func:`runs_to_resolve` searches (beyond it: inf)
_MAX_RUNS = 10**6


def state_errors(approx: pd.DataFrame) -> pd.DataFrame:
    """Per (model, H, method, run, step): ``b`` (mean relative error), ``q`` (noise-corrected
    mean square relative error) and ``s2`` (mean squared relative SE of the reference)."""
    e = (approx["estimate"] - approx["reference"]) / approx["reference"]
    s = approx["reference_se"] / approx["reference"]
    df = approx[["model", "H", "method", "family", *_STATE]].assign(e=e, e2=e * e, s2=s * s)
    g = df.groupby(["model", "H", "method", "family", *_STATE], sort=False)
    out = g[["e", "e2", "s2"]].mean().reset_index()
    return out.assign(b=out["e"], q=out["e2"] - out["s2"])[
        ["model", "H", "method", "family", *_STATE, "b", "q", "s2"]
    ]


def _cluster_mean_ci(x: np.ndarray, runs: np.ndarray) -> ClusterInterval:
    """Cluster-t CI (jackknife over runs) of the mean of per-state values ``x`` over all
    states: sum(x over the kept runs) / (states of the kept runs)."""
    ids, inv = np.unique(runs, return_inverse=True)
    sums = np.bincount(inv, weights=x, minlength=ids.size)
    counts = np.bincount(inv, minlength=ids.size).astype(float)
    return cluster_t_ci(lambda idx: float(sums[idx].sum() / counts[idx].sum()), ids.size, LEVEL)


def _spearman(g: pd.DataFrame) -> float:
    est, ref = g["estimate"].to_numpy(float), g["reference"].to_numpy(float)
    if np.ptp(est) == 0.0 or np.ptp(ref) == 0.0:
        return float("nan")
    return float(sps.spearmanr(est, ref).statistic)


def summarize_approx(
    approx: pd.DataFrame, seed: int | None = None, n_boot: int | None = None
) -> pd.DataFrame:
    """One row per (model, H, method) of ``approx`` (module docstring), in table order; CIs
    cluster-t over runs (NaN with fewer than 2 runs). ``seed`` and ``n_boot`` are unused
    (the CIs no longer resample) and kept for the callers."""
    per_state = state_errors(approx)
    rho = (
        approx.groupby(["model", "H", "method", *_STATE, "replicate"], sort=False)
        .apply(_spearman, include_groups=False)
        .rename("rho")
        .reset_index()
    )
    rows = []
    for (model, H, method, family), g in per_state.groupby(
        ["model", "H", "method", "family"], sort=False
    ):
        key = {"model": model, "H": int(H), "method": method}
        b, q = g["b"].to_numpy(float), g["q"].to_numpy(float)
        runs = g["run"].to_numpy()
        r = rho[(rho["model"] == model) & (rho["H"] == H) & (rho["method"] == method)]["rho"]
        if np.unique(runs).size >= 2:
            cb, cq = _cluster_mean_ci(b, runs), _cluster_mean_ci(q, runs)
            b_lo, b_hi = cb.low, cb.high
            q_lo, q_hi = (float(np.sqrt(max(v, 0.0))) for v in (cq.low, cq.high))
        else:
            b_lo = b_hi = q_lo = q_hi = float("nan")
        rows.append(
            {
                **key,
                "family": family,
                "states": int(b.size),
                "rel_bias": float(b.mean()),
                "rel_bias_low": b_lo,
                "rel_bias_high": b_hi,
                "rel_rmse": float(np.sqrt(max(q.mean(), 0.0))),
                "rel_rmse_low": q_lo,
                "rel_rmse_high": q_hi,
                "ref_noise": float(np.sqrt(g["s2"].mean())),
                "spearman": float(r.mean()) if r.notna().any() else float("nan"),
                "spearman_undefined": int(r.isna().sum()),
            }
        )
    return pd.DataFrame(rows, columns=APPROX_SUMMARY_COLUMNS)


class Growth(NamedTuple):
    """Change of the relative RMSE between two horizons (``h_lo`` -> ``h_hi``), paired over
    ``n`` belief states of ``runs`` runs, with its 95% cluster-t CI ``[low, high]``
    (jackknife over runs: standard error ``se``, t with ``df`` = runs − 1 degrees of freedom)
    and ``p_value``, the two-sided t-test p-value of g = 0; ``lo_value`` and ``hi_value`` the
    RMSEs; ``[boot_low, boot_high]`` the 95% percentile-bootstrap CI over runs (the former
    published interval, kept for comparison)."""

    mean: float
    low: float
    high: float
    n: int
    lo_value: float
    hi_value: float
    h_lo: int
    h_hi: int
    runs: int
    se: float
    df: int
    p_value: float
    boot_low: float
    boot_high: float


def _q_wide(per: pd.DataFrame, model: str, method: str, hs: tuple[int, int]) -> pd.DataFrame:
    sel = per[(per["model"] == model) & (per["method"] == method)]
    wide = sel.pivot_table(index=_STATE, columns="H", values="q")
    for h in hs:
        if h not in wide.columns:
            raise ValueError(
                f"H = {h} has no cost-approximation rows of {method!r} on {model!r} "
                f"(horizons: {sorted(int(c) for c in wide.columns)})"
            )
    return wide[list(hs)]


def _rmse(x: np.ndarray) -> np.ndarray:
    return np.sqrt(np.maximum(x.mean(axis=-1), 0.0))


def rmse_growth(
    approx: pd.DataFrame,
    model: str,
    method: str,
    h_lo: int,
    h_hi: int,
    seed: int,
    n_boot: int,
    minus: str | None = None,
) -> Growth:
    r""":math:`g = \mathrm{RMSE}_{rel}(H_{hi}) - \mathrm{RMSE}_{rel}(H_{lo})` of ``method``
    on ``model`` over the belief states both horizons share; with ``minus`` another method,
    :math:`g_{method} - g_{minus}` on the same states (``lo_value``/``hi_value`` are then
    ``method``'s RMSEs).

    The CI is the cluster-t interval (:func:`rsmhp.core.stats.cluster_t_ci`): g is recomputed
    leaving out one run at a time with all its belief states, at both horizons (and for both
    methods) together, and :math:`g \pm t_{R-1}\,\mathrm{se}_{jack}` over the R runs; the
    percentile-bootstrap CI resamples the same runs jointly (``n_boot`` draws, stream keyed on
    model, method, minus, h_lo, h_hi). ValueError if a horizon lacks a method, fewer than 2
    states are shared or they come from fewer than 2 runs."""
    per = state_errors(approx)
    hs = (int(h_lo), int(h_hi))
    parts = [_q_wide(per, model, method, hs)]
    if minus is not None:
        parts.append(_q_wide(per, model, minus, hs))
    wide = pd.concat(parts, axis=1, keys=range(len(parts))).dropna()
    if len(wide) < 2:
        raise ValueError(f"{method!r} on {model!r}: {len(wide)} shared belief state(s)")
    q = [
        (wide[(i, hs[0])].to_numpy(float), wide[(i, hs[1])].to_numpy(float))
        for i in range(len(parts))
    ]

    runs = wide.index.get_level_values("run").to_numpy()
    ids, inv = np.unique(runs, return_inverse=True)
    if ids.size < 2:
        raise ValueError(f"{method!r} on {model!r}: {ids.size} run(s) (allowed: at least 2)")
    counts = np.bincount(inv, minlength=ids.size).astype(float)
    sums = [
        (np.bincount(inv, weights=lo, minlength=ids.size),
         np.bincount(inv, weights=hi, minlength=ids.size))
        for lo, hi in q
    ]  # fmt: skip

    def g(idx: np.ndarray) -> np.ndarray:
        n = counts[idx].sum(axis=-1)

        def rm(sm: np.ndarray) -> np.ndarray:
            return np.sqrt(np.maximum(sm[idx].sum(axis=-1) / n, 0.0))

        out = rm(sums[0][1]) - rm(sums[0][0])
        if minus is not None:
            out = out - (rm(sums[1][1]) - rm(sums[1][0]))
        return out

    ci = cluster_t_ci(lambda idx: float(g(idx)), ids.size, LEVEL)
    key = {"model": model, "method": method, "minus": minus or "", "h_lo": hs[0], "h_hi": hs[1]}
    rng = job_rng(seed, "horizon_growth", **key)
    boots = g(rng.integers(0, ids.size, size=(n_boot, ids.size)))
    c_lo, c_hi = np.quantile(boots, [0.5 - LEVEL / 2, 0.5 + LEVEL / 2])
    a, b = float(_rmse(q[0][0])), float(_rmse(q[0][1]))
    return Growth(
        ci.estimate, ci.low, ci.high, len(wide), a, b, *hs, runs=int(ids.size), se=ci.se,
        df=ci.df, p_value=ci.p_value(0.0), boot_low=float(c_lo), boot_high=float(c_hi),
    )  # fmt: skip


def summarize_horizon_regret(regret: pd.DataFrame) -> pd.DataFrame:
    """One row per (model, H, method): mean relative regret against the best plan found (%),
    mean regret against the best of the methods' plans (% of the best cost) and the median
    planning milliseconds per step."""
    df = regret.assign(
        r=100 * regret["regret_rel"], rm=100 * regret["regret_methods"] / regret["best_cost"]
    )
    g = df.groupby(["model", "H", "method", "family"], sort=False)
    out = g.agg(
        states=("r", "size"), regret_pct=("r", "mean"), regret_methods_pct=("rm", "mean"),
        plan_ms=("plan_ms", "median"),
    ).reset_index()  # fmt: skip
    return out[REGRET_SUMMARY_COLUMNS]


def lqg_horizon_table(a_values, H_values, *, r: float, sigma: float, eps: float) -> pd.DataFrame:
    """Closed forms of the oven LQG at long horizons (:mod:`rsmhp.studies.horizon.closed_forms`),
    one row per a: NBO's error limit :math:`r\\sigma^2/(1-(1-a)^2)` (``nbo_limit``) and its share
    reached at each H of ``H_values`` (``nbo_share_H<H>``, %); the first H at which the
    paper's optimal first control is at most ``eps`` of its one-step value
    (``vanishing_H``); the stage-cost variant's stationary gain (``k_inf``) and the first H
    at which the H-step gain is within ``eps`` of it (``stationary_H``)."""
    rows = []
    for a in a_values:
        lim = lqg_horizon.nbo_error_limit(a=a, r=r, sigma=sigma)
        row = {"a": float(a), "nbo_limit": lim}
        for H in H_values:
            row[f"nbo_share_H{int(H)}"] = 100 * lqg.nbo_error(int(H), a=a, r=r, sigma=sigma) / lim
        row.update(
            vanishing_H=lqg_horizon.vanishing_horizon(a=a, r=r, eps=eps),
            k_inf=lqg_horizon.stationary_gain(a=a, r=r),
            stationary_H=lqg_horizon.stationary_horizon(a=a, r=r, eps=eps),
        )
        rows.append(row)
    return pd.DataFrame(rows)


CLOSED_SUMMARY_COLUMNS = [
    "model",
    "H",
    "method",
    "family",
    "runs",
    "mean_error",
    "error_diff",
    "error_diff_low",
    "error_diff_high",
    "diff_sd",
    "runs_to_resolve",
    "plan_ms",
]


def _paired(model: str, closed: pd.DataFrame) -> pd.DataFrame:
    """mean_error per run (rows) and (H, method) (columns) of ``model``."""
    g = closed[closed["model"] == model]
    return g.pivot_table(index="run", columns=["H", "method"], values="mean_error")


def summarize_closed(
    closed: pd.DataFrame, seed: int | None = None, n_boot: int | None = None
) -> pd.DataFrame:
    """Per (model, H, method), over the runs that pair with NBO's: their number, the mean
    location error (m), the paired difference method − NBO with its 95% cluster-t CI over
    runs (for this mean of per-run differences the jackknife gives the Student-t interval;
    NaN with fewer than 2 pairs), the SD of the paired differences over runs, the runs a
    confirmatory comparison would need to detect a difference of the observed size with 80%
    power (:func:`runs_to_resolve`) and the median planning ms per step. ``seed`` and
    ``n_boot`` are unused (the CI no longer resamples) and kept for the callers."""
    base = _baseline_name()
    rows = []
    for (model, H, method, family), g in closed.groupby(
        ["model", "H", "method", "family"], sort=False
    ):
        w = _paired(model, closed)
        pair = w[list(dict.fromkeys([(H, method), (H, base)]))].dropna()
        d = (pair[(H, method)] - pair[(H, base)]).to_numpy(float)
        key = {"model": model, "H": int(H), "method": method}
        sd = float(d.std(ddof=1)) if d.size >= 2 else float("nan")
        if method == base:
            lo = hi = 0.0
        elif d.size >= 2:
            ci = _mean_ci(d)
            lo, hi = ci.low, ci.high
        else:
            lo = hi = float("nan")
        rows.append(
            {
                **key,
                "family": family,
                "runs": int(d.size),
                "mean_error": float(pair[(H, method)].mean()),
                "error_diff": float(d.mean()) if d.size else float("nan"),
                "error_diff_low": lo,
                "error_diff_high": hi,
                "diff_sd": 0.0 if method == base else sd,
                "runs_to_resolve": float("nan")
                if method == base
                else runs_to_resolve(float(d.mean()) if d.size else float("nan"), sd),
                "plan_ms": float(g["plan_ms"].median()),
            }
        )
    return pd.DataFrame(rows, columns=CLOSED_SUMMARY_COLUMNS)


def runs_to_resolve(mean: float, sd: float) -> float:
    r"""The paired runs a confirmatory comparison needs to detect a mean difference of the
    observed size :math:`\bar d` with 80% power (:data:`POWER`): the smallest n at which the
    two-sided paired t-test at level 5% rejects :math:`\bar d = 0` with probability 0.8 when
    the true mean difference is :math:`\bar d` and the SD over runs is :math:`s`
    (:func:`rsmhp.core.stats.runs_for_power`, noncentral t; at least 2).

    The observed difference is taken as the true effect: where it is inflated (a selected or
    lucky comparison, the winner's curse) the count is optimistic. It replaces
    :math:`(1.96\, s/|\bar d|)^2`, the n at which a normal CI around :math:`\bar d` would
    just exclude 0, which gives only 50% power. NaN for :math:`\bar d = 0` or a NaN input;
    inf if even 10⁶ runs do not give the power."""
    if not (np.isfinite(mean) and np.isfinite(sd)) or mean == 0.0:
        return float("nan")
    try:
        return float(runs_for_power(sd, mean, level=LEVEL, power=POWER, max_n=_MAX_RUNS))
    except ValueError:
        return float("inf")


def _mean_ci(x: np.ndarray) -> ClusterInterval:
    """Cluster-t CI of the mean of per-run values ``x`` (the Student-t interval)."""
    return cluster_t_ci(lambda idx: float(x[idx].mean()), x.size, LEVEL)


class Advantage(NamedTuple):
    """Change of the closed-loop advantage d(H) = error(method) − error(NBO) from ``h_lo``
    to ``h_hi`` (m; negative: the advantage grows), paired over ``n`` runs, with its 95%
    cluster-t CI ``[low, high]`` (jackknife over runs; for this mean of per-run changes the
    Student-t interval, standard error ``se``, ``df`` = n − 1) and ``p_value``, the
    two-sided t-test p-value of D = 0; the two mean advantages ``d_lo``, ``d_hi``; the SD of
    the paired change over runs; ``runs_needed``, the runs a confirmatory comparison needs
    for 80% power at the observed D (:func:`runs_to_resolve`); ``[boot_low, boot_high]``
    the 95% percentile-bootstrap CI over runs (the former published interval)."""

    mean: float
    low: float
    high: float
    n: int
    d_lo: float
    d_hi: float
    sd: float
    se: float
    df: int
    p_value: float
    runs_needed: float
    boot_low: float
    boot_high: float


def advantage_growth(
    closed: pd.DataFrame, model: str, method: str, h_lo: int, h_hi: int, seed: int, n_boot: int
) -> Advantage:
    r""":math:`D = \overline{d_r(H_{hi}) - d_r(H_{lo})}` with :math:`d_r(H)` = mean error of
    ``method`` − NBO's in run r at horizon H (the same scenario at both H); 95% cluster-t CI
    over runs (the Student-t interval of the mean of the per-run changes) with its t-test
    p-value, and the 95% percentile-bootstrap CI over runs beside it (``n_boot`` draws, stream
    keyed on model, method, h_lo, h_hi). ValueError if a horizon or method is missing or
    fewer than 2 runs pair."""
    base = _baseline_name()
    w = _paired(model, closed)
    for h in (h_lo, h_hi):
        for m in (method, base):
            if (h, m) not in w.columns:
                raise ValueError(f"no closed-loop runs of {m!r} at H = {h} on {model!r}")
    both = w[[(h_lo, method), (h_lo, base), (h_hi, method), (h_hi, base)]].dropna()
    d_lo = both[(h_lo, method)] - both[(h_lo, base)]
    d_hi = both[(h_hi, method)] - both[(h_hi, base)]
    D = (d_hi - d_lo).to_numpy(float)
    if D.size < 2:
        raise ValueError(f"{method!r} on {model!r}: {D.size} paired run(s)")
    ci = _mean_ci(D)
    rng = job_rng(seed, "horizon_advantage", model=model, method=method, h_lo=h_lo, h_hi=h_hi)
    idx = rng.integers(0, D.size, size=(n_boot, D.size))
    lo, hi = np.quantile(D[idx].mean(axis=1), [0.5 - LEVEL / 2, 0.5 + LEVEL / 2])
    sd = float(D.std(ddof=1))
    return Advantage(
        ci.estimate, ci.low, ci.high, int(D.size), float(d_lo.mean()), float(d_hi.mean()), sd,
        se=ci.se, df=ci.df, p_value=ci.p_value(0.0), runs_needed=runs_to_resolve(ci.estimate, sd),
        boot_low=float(lo), boot_high=float(hi),
    )  # fmt: skip


def _baseline_name() -> str:
    from rsmhp.models.uav import methods

    return methods.baseline()().name
