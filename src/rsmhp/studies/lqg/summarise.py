r"""LQG study (paper Sec. III-A, Fig. 3), statistics: per-P summaries, the NBO-error check,
the Chebyshev exceedances and the checks the claims rest on. Numbers only: the claims and
their verdict rules are in :mod:`rsmhp.studies.lqg.claims`, the prose and tables in
:mod:`rsmhp.studies.lqg.section`.

Everything is recomputed from the raw CSVs (which carry the model constants in their
columns) and the closed forms of :mod:`rsmhp.models.lqg.oven`; nothing is copied from a previous
run.

Model: :math:`x_{k+1} = (1-a)x_k + a u_k + w_k`, :math:`w_k \sim N(0, \sigma^2)`, cost
:math:`J = E[r(x_H - T)^2 + \sum_{k<H} u_k^2]`. One trajectory's cost :math:`g` has the
closed-form variance :math:`\mathrm{Var}(g)`; the MHP estimate :math:`J_P` averages
:math:`P` independent trajectories, so :math:`\mathrm{Var}(J_P) = \mathrm{Var}(g)/P`. NBO sets
every :math:`w_k` to 0 and gets :math:`J_{NBO} = J - r\sigma^2\sum_{n<H}(1-a)^{2n}`.

* :func:`summarize_convergence`: per P, mean of :math:`J_P` (t-interval), RMSE about J
  (:math:`\chi^2` interval), the weighted estimate, and per ε the exceedance frequency of
  :math:`|J_P - J| \ge \epsilon` (Clopper-Pearson) next to the Chebyshev bound.
* :func:`summarize_nbo_error`: per (a, H) the simulated NBO error, its exact standard error
  :math:`\sqrt{\mathrm{Var}(g)/(PR)}` and :math:`z = (\text{simulated} - \text{closed})/SE`.
* :func:`nbo_error_check` (LQG-1), :func:`fig3_check` (LQG-2), :func:`chebyshev_check`
  (LQG-3), :func:`weighted_check` (LQG-4): the numbers each claim's rule is evaluated on.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy import stats as sps

from rsmhp.core.stats import (
    DETECTABLE_GRID,
    ExceedanceTest,
    SlopeFit,
    binomial_ci,
    detectable_scale,
    exceedance_test,
    loglog_slope,
    mean_ci,
    rmse_ci,
)
from rsmhp.models.lqg import oven as lqg
from rsmhp.models.lqg.linear_quadratic import LinearCost, LinearQuadratic
from rsmhp.studies.lqg.simulate import CONVERGENCE_COLUMNS, LINEAR_COST_COLUMNS, NBO_ERROR_COLUMNS

__all__ = [
    "ChebyshevCheck",
    "Fig3Check",
    "LinearCostCheck",
    "NboErrorCheck",
    "PaperSettingCheck",
    "WeightedCheck",
    "chebyshev_check",
    "chebyshev_long",
    "eps_label",
    "fig3_check",
    "linear_cost_check",
    "model_from_table",
    "nbo_error_check",
    "nbo_z_limit",
    "paper_setting_nbo_error",
    "summarize_convergence",
    "summarize_nbo_error",
    "weighted_check",
]


def eps_label(eps: float) -> str:
    """A configured ε (or any configured parameter) as written in the config: ``0.25``, ``1``
    (also the suffix of the per-ε summary columns, ``bound_eps0.25``)."""
    return f"{float(eps):g}"


def model_from_table(df: pd.DataFrame) -> tuple[np.ndarray, lqg.LQGModel]:
    """(controls u, model) of a single-model convergence table (columns ``a, sigma, r,
    target, x0`` and ``u`` as ``u_0;u_1;...``); ``ValueError`` if it mixes settings."""
    cols = ["a", "sigma", "r", "target", "x0", "u"]
    uniq = df[cols].drop_duplicates()
    if len(uniq) != 1:
        raise ValueError(f"convergence table mixes {len(uniq)} model settings; expected one")
    row = uniq.iloc[0]
    u = np.array([float(v) for v in str(row["u"]).split(";")])
    return u, lqg.LQGModel.from_config(row)


def _convergence_row(
    P: int, est: np.ndarray, weighted: np.ndarray, u: np.ndarray, model: lqg.LQGModel
) -> dict[str, float]:
    """The eps-independent columns of :func:`summarize_convergence` for one P."""
    kw = model.closed_form_args()
    j_exact = lqg.exact_cost(u, **kw)
    m, lo, hi = mean_ci(est)
    rm, rlo, rhi = rmse_ci(est - j_exact)
    wm, wlo, whi = mean_ci(weighted)
    return {
        "P": int(P),
        "n_replicates": est.size,
        "J_exact": j_exact,
        "J_nbo": lqg.nbo_cost(u, **model.closed_form_args(sigma=False)),
        "mean": m,
        "ci_low": lo,
        "ci_high": hi,
        "std": float(est.std(ddof=1)),
        "sd_theory": float(np.sqrt(lqg.mhp_variance(int(P), u, **kw))),
        "bias": m - j_exact,
        "rmse": rm,
        "rmse_low": rlo,
        "rmse_high": rhi,
        "weighted_mean": wm,
        "weighted_ci_low": wlo,
        "weighted_ci_high": whi,
        "weighted_limit": lqg.weighted_limit(u, **kw),
    }


def summarize_convergence(df: pd.DataFrame, eps_values: Sequence[float]) -> pd.DataFrame:
    r"""Per-P summary of the uniform MHP estimator (and the weighted one) against the closed forms.

    Columns: ``P, n_replicates, J_exact, J_nbo, mean, ci_low, ci_high, std, sd_theory, bias,
    rmse, rmse_low, rmse_high, weighted_mean, weighted_ci_low, weighted_ci_high,
    weighted_limit`` and, per eps, ``bound_eps<e>`` (Chebyshev
    :math:`\min\{1, \mathrm{Var}(g)/(P\epsilon^2)\}`), ``exceed_eps<e>`` (observed frequency
    of :math:`|J_P - J| \ge \epsilon`) and its Clopper-Pearson 95% limits
    ``exceed_low_eps<e>``/``exceed_high_eps<e>``, ``exact_eps<e>`` (the exact probability
    of :math:`|J_P - J| \ge \epsilon`: :math:`J_P` is the mean of P copies of the quadratic
    form g of the noise, a generalised chi-square,
    :meth:`~rsmhp.models.lqg.linear_quadratic.QuadraticForm.mean_error_tail`) and
    ``detectable_eps<e>``
    (the smallest relative error of the spread of :math:`J_P - J` the cell's exceedance test
    detects with 80% power, :func:`rsmhp.core.stats.detectable_scale`). ``sd_theory`` is
    :math:`\sqrt{\mathrm{Var}(g)/P}`.
    """
    missing = [c for c in CONVERGENCE_COLUMNS if c not in df.columns]
    if missing:
        raise ValueError(f"convergence table lacks columns {missing}")
    u, model = model_from_table(df)
    kw = model.closed_form_args()
    form = LinearQuadratic.from_lqg(model, u).quadratic_form
    cells = df["P"].nunique() * len(eps_values)
    rows = []
    for P, grp in df.groupby("P", sort=True):
        est = grp["J_mhp"].to_numpy()
        row = _convergence_row(int(P), est, grp["J_mhp_weighted"].to_numpy(), u, model)
        exact = np.atleast_1d(form.mean_error_tail(int(P), np.asarray(eps_values, dtype=float)))
        for eps, p_exact in zip(eps_values, exact, strict=True):
            k = int(np.sum(np.abs(est - row["J_exact"]) >= eps))
            flo, fhi = binomial_ci(k, est.size)
            e = eps_label(eps)
            row[f"bound_eps{e}"] = lqg.chebyshev_bound(int(P), eps, u, **kw)
            row[f"exact_eps{e}"] = float(p_exact)
            row[f"detectable_eps{e}"] = detectable_scale(
                lambda x, P=int(P): form.mean_error_tail(P, x),
                float(eps),
                est.size,
                cells,
                grid=DETECTABLE_GRID,
            )
            row[f"exceed_eps{e}"] = k / est.size
            row[f"exceed_low_eps{e}"] = flo
            row[f"exceed_high_eps{e}"] = fhi
        rows.append(row)
    return pd.DataFrame(rows)


def chebyshev_long(summary: pd.DataFrame, eps_values: Sequence[float]) -> pd.DataFrame:
    r"""Long format of the Chebyshev columns, one row per (P, ε): ``P, eps, n`` (replicates),
    ``k`` (exceedances), ``bound`` (capped at 1), ``exact`` (exact probability),
    ``detectable`` (see :func:`summarize_convergence`), ``bound_raw``
    (:math:`\mathrm{Var}(g)/(P\epsilon^2)`, uncapped), ``freq = k/n`` and its 95%
    Clopper-Pearson limits ``low``, ``high``."""
    parts = []
    for eps in eps_values:
        e = eps_label(eps)
        n = summary["n_replicates"].astype(int)
        parts.append(
            pd.DataFrame(
                {
                    "P": summary["P"].astype(int),
                    "eps": float(eps),
                    "n": n,
                    "k": np.rint(summary[f"exceed_eps{e}"] * n).astype(int),
                    "bound": summary[f"bound_eps{e}"],
                    "bound_raw": summary["sd_theory"] ** 2 / float(eps) ** 2,
                    "exact": summary[f"exact_eps{e}"],
                    "detectable": summary[f"detectable_eps{e}"],
                    "freq": summary[f"exceed_eps{e}"],
                    "low": summary[f"exceed_low_eps{e}"],
                    "high": summary[f"exceed_high_eps{e}"],
                }
            )
        )
    return pd.concat(parts, ignore_index=True)


def summarize_nbo_error(df: pd.DataFrame) -> pd.DataFrame:
    r"""Per (a, H): mean simulated NBO error over replicates, its exact standard error
    :math:`\sqrt{\mathrm{Var}(g)/(PR)}`, the closed form, z-score and relative deviation
    (columns ``a, H, n_replicates, P, u_value, nbo_error_sim, se, ci_low, ci_high,
    nbo_error_closed, z, rel_dev``)."""
    missing = [c for c in NBO_ERROR_COLUMNS if c not in df.columns]
    if missing:
        raise ValueError(f"NBO-error table lacks columns {missing}")
    rows = []
    for (a, H), grp in df.groupby(["a", "H"], sort=True):
        first = grp.iloc[0]
        kw = {k: float(first[k]) for k in ("x0", "r", "target", "sigma")}
        u = np.full(int(H), float(first["u_value"]))
        n_total = int(grp["P"].sum())
        se = float(np.sqrt(lqg.mhp_variance(n_total, u, a=float(a), **kw)))
        closed = lqg.nbo_error(int(H), a=float(a), r=kw["r"], sigma=kw["sigma"])
        sim = float(np.average(grp["nbo_error_sim"], weights=grp["P"]))
        rows.append(
            {
                "a": float(a),
                "H": int(H),
                "n_replicates": len(grp),
                "P": int(first["P"]),
                "u_value": float(first["u_value"]),
                "nbo_error_sim": sim,
                "se": se,
                "ci_low": sim - 1.96 * se,
                "ci_high": sim + 1.96 * se,
                "nbo_error_closed": closed,
                "z": (sim - closed) / se,
                "rel_dev": (sim - closed) / closed,
            }
        )
    return pd.DataFrame(rows)


@dataclass(frozen=True)
class PaperSettingCheck:
    r"""The NBO error in the paper's setting from every trajectory of the convergence run:
    :math:`\hat e = \sum_{P,i} P (J_{P,i} - J_{NBO}) / \sum P` (independent draws for every
    (P, replicate)), standard error :math:`\sqrt{\mathrm{Var}(g)/\sum P}` (exact)."""

    a: float
    H: int
    n_trajectories: int
    simulated: float
    se: float
    closed: float

    @property
    def z(self) -> float:
        return (self.simulated - self.closed) / self.se


def paper_setting_nbo_error(conv: pd.DataFrame) -> PaperSettingCheck:
    """:class:`PaperSettingCheck` of the convergence table ``conv`` (one model setting)."""
    u, model = model_from_table(conv)
    total = int(conv["P"].sum())
    pooled = float(np.average(conv["J_mhp"] - conv["J_nbo"], weights=conv["P"]))
    se = float(np.sqrt(lqg.mhp_variance(total, u, **model.closed_form_args())))
    closed = lqg.nbo_error(len(u), a=model.a, r=model.r, sigma=model.sigma)
    return PaperSettingCheck(model.a, len(u), total, pooled, se, closed)


def nbo_z_limit(n_grid: int) -> float:
    r"""Bonferroni limit of LQG-1: :math:`\Phi^{-1}(1 - 0.025/m)` for the ``m = n_grid + 1``
    tests (every (a, H) cell and the paper's setting)."""
    return float(sps.norm.ppf(1 - 0.025 / (int(n_grid) + 1)))


@dataclass(frozen=True)
class NboErrorCheck:
    r"""LQG-1's numbers: the z-scores of the (a, H) grid and of the paper's setting against
    the closed form :math:`r\sigma^2\sum_{n<H}(1-a)^{2n}`.

    ``max_abs_z`` is the largest :math:`|z|` of all ``n_tests`` tests, ``z_limit`` their
    Bonferroni limit (:func:`nbo_z_limit`); ``grid_max_abs_z`` and ``worst_a``/``worst_H``
    the largest grid :math:`|z|` and its cell; ``resolution`` the largest relative deviation
    from the closed form a grid cell could have without crossing the limit,
    :math:`\max z_{lim}\,SE/\text{closed}`."""

    paper: PaperSettingCheck
    n_cells: int
    n_tests: int
    z_limit: float
    max_abs_z: float
    grid_max_abs_z: float
    worst_a: float
    worst_H: int
    max_abs_rel_dev: float
    resolution: float
    replicates: int
    P: int


def nbo_error_check(nbo: pd.DataFrame, conv: pd.DataFrame) -> NboErrorCheck:
    """:class:`NboErrorCheck` of the NBO-error summary ``nbo`` (:func:`summarize_nbo_error`)
    and the convergence table ``conv`` (the paper's setting)."""
    paper = paper_setting_nbo_error(conv)
    z_crit = nbo_z_limit(len(nbo))
    abs_z = nbo["z"].abs()
    worst = nbo.loc[abs_z.idxmax()]
    return NboErrorCheck(
        paper=paper,
        n_cells=len(nbo),
        n_tests=len(nbo) + 1,
        z_limit=z_crit,
        max_abs_z=float(max(abs_z.max(), abs(paper.z))),
        grid_max_abs_z=float(abs_z.max()),
        worst_a=float(worst["a"]),
        worst_H=int(worst["H"]),
        max_abs_rel_dev=float(nbo["rel_dev"].abs().max()),
        resolution=float((z_crit * nbo["se"] / nbo["nbo_error_closed"]).max()),
        replicates=int(nbo["n_replicates"].iloc[0]),
        P=int(nbo["P"].iloc[0]),
    )


@dataclass(frozen=True)
class Fig3Check:
    r"""LQG-2's numbers: the OLS fit :math:`\log \mathrm{RMSE} = c + s \log P` over the P grid
    and, at the largest P, the mean :math:`J_P` with its 95% CI, J, :math:`J_{NBO}` and the
    RMSE with its 95% interval."""

    fit: SlopeFit
    P: int
    mean: float
    ci_low: float
    ci_high: float
    J: float
    J_nbo: float
    rmse: float
    rmse_low: float
    rmse_high: float
    n_P: int
    P_first: int
    replicates: int

    @property
    def nbo_error(self) -> float:
        """:math:`|J - J_{NBO}|`."""
        return abs(self.J - self.J_nbo)


def fig3_check(summary: pd.DataFrame) -> Fig3Check:
    """:class:`Fig3Check` of the per-P summary (:func:`summarize_convergence`)."""
    last = summary.iloc[-1]
    return Fig3Check(
        fit=loglog_slope(summary["P"], summary["rmse"]),
        P=int(last["P"]),
        mean=float(last["mean"]),
        ci_low=float(last["ci_low"]),
        ci_high=float(last["ci_high"]),
        J=float(last["J_exact"]),
        J_nbo=float(last["J_nbo"]),
        rmse=float(last["rmse"]),
        rmse_low=float(last["rmse_low"]),
        rmse_high=float(last["rmse_high"]),
        n_P=len(summary),
        P_first=int(summary["P"].iloc[0]),
        replicates=int(last["n_replicates"]),
    )


@dataclass(frozen=True)
class ChebyshevCheck:
    r"""LQG-3's numbers over the (P, ε) cells: ``test`` compares each cell's exceedance count
    with the exact probability of :math:`|J_P - J| \ge \epsilon` and with Chebyshev's bound
    (:func:`rsmhp.core.stats.exceedance_test`, familywise 95% over the cells); ``detectable`` is
    the smallest relative error of the spread of :math:`J_P - J` that the most sensitive cell
    detects with 80% power (``inf`` if none on the grid); ``worst_P``, ``worst_eps`` the cell
    with the smallest adjusted p-value; ``n_informative`` the cells whose bound is below 1."""

    test: ExceedanceTest
    detectable: float
    worst_P: int
    worst_eps: float
    worst_freq: float
    worst_exact: float
    n_informative: int
    replicates: int

    @property
    def n_cells(self) -> int:
        return self.test.cells


def chebyshev_check(summary: pd.DataFrame, eps_values: Sequence[float]) -> ChebyshevCheck:
    """:class:`ChebyshevCheck` of the per-P summary for the configured ``eps_values``."""
    cheb = chebyshev_long(summary, eps_values)
    test = exceedance_test(cheb["k"], cheb["n"], cheb["exact"], cheb["bound"])
    worst = cheb.iloc[test.worst]
    return ChebyshevCheck(
        test=test,
        detectable=float(cheb["detectable"].min()),
        worst_P=int(worst["P"]),
        worst_eps=float(worst["eps"]),
        worst_freq=float(worst["freq"]),
        worst_exact=float(worst["exact"]),
        n_informative=int((cheb["bound_raw"] < 1).sum()),
        replicates=int(summary["n_replicates"].max()),
    )


@dataclass(frozen=True)
class WeightedCheck:
    r"""LQG-4's numbers at the largest P: the likeliness-weighted estimate with its 95% CI,
    J and the derived limit :math:`J(\sigma^2/2) = J - r v_H/2`
    (:func:`rsmhp.models.lqg.oven.weighted_limit`)."""

    P: int
    mean: float
    ci_low: float
    ci_high: float
    J: float
    limit: float
    replicates: int

    @property
    def contains_j(self) -> bool:
        return self.ci_low <= self.J <= self.ci_high

    @property
    def contains_limit(self) -> bool:
        return self.ci_low <= self.limit <= self.ci_high


def weighted_check(summary: pd.DataFrame) -> WeightedCheck:
    """:class:`WeightedCheck` of the per-P summary (its largest P)."""
    last = summary.iloc[-1]
    return WeightedCheck(
        P=int(last["P"]),
        mean=float(last["weighted_mean"]),
        ci_low=float(last["weighted_ci_low"]),
        ci_high=float(last["weighted_ci_high"]),
        J=float(last["J_exact"]),
        limit=float(last["weighted_limit"]),
        replicates=int(last["n_replicates"]),
    )


@dataclass(frozen=True)
class LinearCostCheck:
    r"""Prop. 3 on its own setting (:func:`rsmhp.studies.lqg.simulate.run_linear_cost`). Per n:
    the sample variance :math:`s_n^2` of the R estimates :math:`J_n` against the paper's
    :math:`\mathrm{Var}(p)/n`; :math:`J_n` is exactly Gaussian, so :math:`(R-1)s_n^2 n /
    \mathrm{Var}(p) \sim \chi^2_{R-1}` and :math:`z_n = (s_n^2 n/\mathrm{Var}(p) - 1)/
    \sqrt{2/(R-1)}` is standard normal to within :math:`O(R^{-1/2})`; ``pooled_z`` sums the
    independent chi-squares over n. The means give :math:`z = (\bar J_n - J)/
    \sqrt{\mathrm{Var}(p)/(nR)}`. ``z_limit``: Bonferroni limit (two-sided, familywise 95%)
    over the ``2 len(n) + 1`` z tests. ``exceedance``: counts of :math:`|J_n - J| \ge k\,
    \mathrm{sd}_n` against the exact probability :math:`2\Phi(-k)` and Chebyshev's
    :math:`1/k^2`. ``var_prop3`` the paper's formula, ``var_form`` the same variance derived
    independently from the cost's quadratic form (they agree to rounding)."""

    n: tuple[int, ...]
    var_z: tuple[float, ...]
    mean_z: tuple[float, ...]
    pooled_z: float
    z_limit: float
    exceedance: ExceedanceTest
    var_prop3: float
    var_form: float
    replicates: int
    H: int

    @property
    def max_abs_z(self) -> float:
        return float(max(np.abs([*self.var_z, *self.mean_z, self.pooled_z])))


def linear_cost_check(df: pd.DataFrame, ks: Sequence[float]) -> LinearCostCheck:
    """:class:`LinearCostCheck` of ``results/lqg/linear_cost.csv`` for the multipliers ``ks``."""
    missing = [c for c in LINEAR_COST_COLUMNS if c not in df.columns]
    if missing:
        raise ValueError(f"linear-cost table lacks columns {missing}")
    H = int(df["H"].iloc[0])
    system = LinearCost.example(H)
    var, J = system.prop3_variance(), system.exact_cost()
    form = system.quadratic_form
    ns, var_z, mean_z, cells = [], [], [], []
    chi, dof = 0.0, 0
    for n, g in df.groupby("n", sort=True):
        est = g["estimate"].to_numpy(float)
        R, sd_n = est.size, float(np.sqrt(var / n))
        ratio = float(est.var(ddof=1)) / sd_n**2
        ns.append(int(n))
        var_z.append((ratio - 1.0) / np.sqrt(2.0 / (R - 1)))
        mean_z.append((float(est.mean()) - J) / (sd_n / np.sqrt(R)))
        chi, dof = chi + (R - 1) * ratio, dof + (R - 1)
        exact = np.atleast_1d(form.mean_error_tail(int(n), sd_n * np.asarray(ks, dtype=float)))
        for k, p_exact in zip(ks, exact, strict=True):
            hits = int(np.sum(np.abs(est - J) >= k * sd_n))
            cells.append((hits, R, float(p_exact), min(1.0, 1.0 / float(k) ** 2)))
    k_arr, n_arr, p_arr, b_arr = (np.array(c) for c in zip(*cells, strict=True))
    m = 2 * len(ns) + 1
    return LinearCostCheck(
        n=tuple(ns),
        var_z=tuple(float(z) for z in var_z),
        mean_z=tuple(float(z) for z in mean_z),
        pooled_z=float((chi - dof) / np.sqrt(2.0 * dof)),
        z_limit=float(sps.norm.ppf(1 - 0.025 / m)),
        exceedance=exceedance_test(k_arr, n_arr, p_arr, b_arr),
        var_prop3=var,
        var_form=form.variance(),
        replicates=int(df.groupby("n").size().min()),
        H=H,
    )
