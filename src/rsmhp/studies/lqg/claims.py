r"""LQG study, claims LQG-1..LQG-4: each a key number and a verdict rule
(:mod:`rsmhp.report.verdicts`) evaluated on the numbers of :mod:`rsmhp.studies.lqg.summarise`; the
rule's printed text and its evaluation come from the same :class:`~rsmhp.report.verdicts.Rule`.

* **LQG-1, NBO error formula.** For every (a, H) cell of the grid the mean simulated NBO error
  over ``R`` replicates of ``P`` trajectories has the exact standard error
  :math:`\sqrt{\mathrm{Var}(g)/(PR)}`; the paper's own setting adds one more test, pooling
  every trajectory of the convergence run. With :math:`z = (\text{simulated} -
  \text{closed form})/\mathrm{SE}` for these :math:`m` tests, key number :math:`\max|z|`:
  *supported* if :math:`\max|z| \le \Phi^{-1}(1 - 0.025/m)` (two-sided, familywise 95%,
  Bonferroni), *not supported* otherwise (:func:`nbo_error_rule`).
* **LQG-2, Fig. 3 message** (MHP approaches J, NBO stays biased). Key number: the slope of
  the OLS fit :math:`\log \mathrm{RMSE} = c + s \log P` with its 95% CI (null 0).
  *supported* if the CI of :math:`s` lies below 0, at the largest P the upper 95% limit of
  the RMSE is below :math:`|J - J_{NBO}|` and the 95% CI of the mean :math:`J_P` contains
  :math:`J`; *not supported* if the CI of :math:`s` lies at or above 0, or at the largest P
  the CI of the mean excludes J (a bias that does not vanish) or the RMSE's lower limit is at
  least :math:`|J - J_{NBO}|`; *inconclusive* otherwise (:data:`FIG3_RULE`).
* **LQG-3, Prop. 3** (:math:`P(|J_P - J| \ge \epsilon) \le \mathrm{Var}(g)/(P\epsilon^2)`).
  :math:`J_P` is the mean of P copies of the quadratic trajectory cost, so the probability of
  :math:`|J_P - J| \ge \epsilon` is known exactly (a generalised chi-square). Per (P, ε)
  cell the exceedance count is tested against that exact probability (two-sided exact
  binomial test, familywise 95%), which has power (the appendix states the spread error it
  detects), and against Chebyshev's bound (familywise Clopper-Pearson lower limit). *not
  supported* if some cell lies significantly above the bound; *supported* if no cell departs
  from the exact probability and the exact probability is below the bound everywhere;
  *inconclusive* otherwise (:func:`exceedance_rule`). Key number: the smallest
  Bonferroni-adjusted p-value.
* **LQG-4, Prop. 2 for non-overlapping samples** (the likeliness-weighted average converges
  to J). Key number: the weighted estimate at the largest P with its 95% CI. For Gaussian
  noise the weights tilt :math:`N(0, \sigma^2)` to :math:`N(0, \sigma^2/2)`, so the derived
  limit is :math:`J(\sigma^2/2) = J - r v_H/2` (:func:`rsmhp.models.lqg.oven.weighted_limit`).
  *supported*
  if the CI contains J and excludes :math:`J(\sigma^2/2)`; *not supported* if it excludes J;
  *inconclusive* otherwise (:data:`WEIGHTED_RULE`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pandas as pd

from rsmhp.report.ledger import Claim, KeyNumber
from rsmhp.report.markdown import fmt, fmt_ci
from rsmhp.report.verdicts import Case, Facts, Rule, at_most, exceedance_facts, exceedance_rule
from rsmhp.studies.lqg.summarise import (
    ChebyshevCheck,
    Fig3Check,
    LinearCostCheck,
    NboErrorCheck,
    WeightedCheck,
    chebyshev_check,
    eps_label,
    fig3_check,
    nbo_error_check,
    weighted_check,
)

__all__ = [
    "CHEBYSHEV_RULE",
    "FIG3_RULE",
    "PAPER_FIG3",
    "WEIGHTED_RULE",
    "chebyshev_claim",
    "chebyshev_facts",
    "ci_digits",
    "convergence_claims",
    "fig3_claim",
    "fig3_facts",
    "fmt_exact",
    "lqg_claims",
    "nbo_error_claim",
    "nbo_error_rule",
    "weighted_claim",
    "weighted_facts",
]

#: Sec. and figure of the paper this study replicates
PAPER_FIG3 = "Sec. III-A, Fig. 3"

#: the setup of LQG-1..4: the paper's oven model (Sec. III-A)
SETUP = "oven LQG (Sec. III-A)"


def fmt_exact(x: float, digits: int = 4) -> str:
    """An exact (closed-form) value with at most ``digits`` significant digits: whole numbers
    without decimals, trailing zeros dropped (an exact 12.5 is ``12.5``, not ``12.50``)."""
    xf = float(x)
    if xf.is_integer() and abs(xf) < 1e15:
        return str(int(xf))
    out = fmt(xf, digits)
    if "e" not in out and "." in out:
        out = out.rstrip("0").rstrip(".")
    return out


def ci_digits(lo: float, hi: float, minimum: int = 3, maximum: int = 7) -> int:
    r"""Significant digits that show a CI ``[lo, hi]`` with two digits of its width:
    :math:`\lfloor\log_{10}\max(|lo|,|hi|)\rfloor - \lfloor\log_{10}(hi - lo)\rfloor + 2`,
    clipped to [``minimum``, ``maximum``]."""
    ref = max(abs(lo), abs(hi))
    width = hi - lo
    if ref == 0 or width <= 0:
        return minimum
    d = math.floor(math.log10(ref)) - math.floor(math.log10(width)) + 2
    return int(min(max(d, minimum), maximum))


# ------------------------------------------------------------------------------- LQG-1


def nbo_error_rule(z_limit: float, n_tests: int) -> Rule:
    """LQG-1: ``max |z|`` at most the Bonferroni limit ``z_limit`` of ``n_tests`` tests."""
    return at_most(
        "max |z|",
        z_limit,
        limit_text=f"{fmt(z_limit, 3)} (two-sided 95% familywise, Bonferroni over {n_tests} tests)",
        basis="z = (simulated - closed form) / exact SE, SE = √(Var(g)/(P·R)), for each (a, H) "
        "cell and for the paper's setting (all convergence trajectories pooled)",
    )


def _nbo_error_measured(check: NboErrorCheck) -> str:
    paper = check.paper
    half = 1.96 * paper.se
    return (
        f"paper's setting (a = {eps_label(paper.a)}, H = {paper.H}, {paper.n_trajectories} "
        f"trajectories pooled): simulated {fmt(paper.simulated, 6)} "
        f"{fmt_ci(paper.simulated - half, paper.simulated + half, 6)} vs closed form "
        f"{fmt_exact(paper.closed, 6)}, z = {fmt(paper.z, 2, signed=True)}; grid of "
        f"{check.n_cells} (a, H) cells ({check.replicates} replicates of P = {check.P}): "
        f"largest |z| = {fmt(check.grid_max_abs_z, 3)} at a = {eps_label(check.worst_a)}, "
        f"H = {check.worst_H}, largest |relative deviation| "
        f"{fmt(100 * check.max_abs_rel_dev, 2)}%; any cell deviating from the closed "
        f"form by more than {fmt(100 * check.resolution, 2)}% would cross the limit "
        f"({fmt(check.z_limit, 3)} SE)"
    )


def nbo_error_claim(nbo: pd.DataFrame, conv: pd.DataFrame) -> Claim:
    """Claim LQG-1: the NBO error formula, from the (a, H) grid and the paper's own setting."""
    check = nbo_error_check(nbo, conv)
    rule = nbo_error_rule(check.z_limit, check.n_tests)
    return Claim(
        id="LQG-1",
        claim="In the oven LQG, NBO's error is J - J_NBO = r σ² Σ_{n<H} (1-a)^{2n} for every a "
        "and H run",
        paper="Sec. III-A: |J_NBO - J| = r σ² Σ_{n=0}^{H-1} (1-a)^{2n} (derived for H = 2, "
        "stated for any H)",
        key=KeyNumber(f"max |z| over {check.n_tests} tests", check.max_abs_z, digits=3),
        verdict=rule.verdict({"max |z|": check.max_abs_z}),
        rule=rule.text(),
        measured=_nbo_error_measured(check),
        setup=SETUP,
        check=True,
    )


# ------------------------------------------------------------------------------- LQG-2

FIG3_RULE = Rule(
    cases=(
        Case(
            "supported",
            "the slope's 95% CI lies below 0, and at the largest P the RMSE's upper 95% limit "
            "is below |J - J_NBO| and the 95% CI of the mean J_P contains J",
            lambda f: (
                f["slope_high"] < 0
                and f["mean_low"] <= f["J"] <= f["mean_high"]
                and f["rmse_high"] < f["nbo_error"]
            ),
        ),
        Case(
            "not supported",
            "the slope CI lies at/above 0, or at the largest P the CI of the mean J_P excludes "
            "J (a bias that does not vanish) or the RMSE's lower limit reaches |J - J_NBO|",
            lambda f: (
                f["slope_low"] >= 0
                or not f["mean_low"] <= f["J"] <= f["mean_high"]
                or f["nbo_error"] <= f["rmse_low"]
            ),
        ),
    ),
    otherwise="inconclusive",
)


def fig3_facts(check: Fig3Check) -> Facts:
    """The numbers :data:`FIG3_RULE` is evaluated on."""
    return {
        "slope_low": check.fit.low,
        "slope_high": check.fit.high,
        "mean_low": check.ci_low,
        "mean_high": check.ci_high,
        "J": check.J,
        "rmse_low": check.rmse_low,
        "rmse_high": check.rmse_high,
        "nbo_error": check.nbo_error,
    }


def _fig3_measured(check: Fig3Check) -> str:
    dm = ci_digits(check.ci_low, check.ci_high)
    return (
        f"slope {'contains' if check.fit.contains(-0.5) else 'excludes'} the theoretical -1/2 "
        f"(theory: RMSE = √(Var(g)/P)); at P = {check.P}: mean J_P {fmt(check.mean, dm)} "
        f"{fmt_ci(check.ci_low, check.ci_high, dm)} vs J = {fmt_exact(check.J, dm)}, "
        f"RMSE {fmt(check.rmse, 3)} {fmt_ci(check.rmse_low, check.rmse_high, 3)} vs "
        f"|J - J_NBO| = {fmt_exact(check.nbo_error, 4)} "
        f"({fmt(check.nbo_error / check.rmse, 2)} times the RMSE); "
        f"{check.n_P} values of P from {check.P_first} to {check.P}, "
        f"{check.replicates} replicates each"
    )


def fig3_claim(summary: pd.DataFrame) -> Claim:
    """Claim LQG-2 (Fig. 3 message): the RMSE of J_P falls with P, and at the largest P it is
    below NBO's error and the mean shows no bias."""
    check = fig3_check(summary)
    fit = check.fit
    return Claim(
        id="LQG-2",
        claim="In the oven LQG at the paper's setting, the Monte-Carlo estimate J_P approaches "
        "J as P grows while NBO's stays biased (Fig. 3)",
        paper=f"{PAPER_FIG3}: MHP estimate close to J for P = 100..10000; NBO error high",
        key=KeyNumber(
            "slope of log RMSE vs log P",
            fit.slope,
            fit.low,
            fit.high,
            digits=ci_digits(fit.low, fit.high),
            null=0.0,
        ),
        verdict=FIG3_RULE.verdict(fig3_facts(check)),
        rule=FIG3_RULE.text(),
        measured=_fig3_measured(check),
        setup=SETUP,
    )


# ------------------------------------------------------------------------------- LQG-3


CHEBYSHEV_RULE = exceedance_rule(
    "per (P, ε) cell, the count of |J_P − J| ≥ ε over the replicates against its exact "
    "probability (J_P: mean of P copies of the quadratic trajectory cost, a generalised "
    "chi-square) and against Chebyshev's bound Var(g)/(P ε²)"
)


def chebyshev_facts(check: ChebyshevCheck) -> Facts:
    """The numbers :data:`CHEBYSHEV_RULE` is evaluated on."""
    return exceedance_facts(check.test, check.detectable)


def _chebyshev_measured(check: ChebyshevCheck, eps_values: Sequence[float]) -> str:
    eps_text = ", ".join(eps_label(e) for e in eps_values)
    t = check.test
    power = (
        f"the test detects a spread of J_P − J off by {fmt(100 * check.detectable, 2)}% "
        "with 80% power in its most sensitive cell"
        if np.isfinite(check.detectable)
        else "no cell detects a spread error below 50% with 80% power"
    )
    return (
        f"{t.cells} (P, ε) cells, ε ∈ {{{eps_text}}}, {check.replicates} replicates per P; "
        f"{t.departing} cells depart from the exact probability, {t.above_bound} lie "
        f"significantly above the bound; smallest adjusted p = {fmt(t.min_p, 3)} at "
        f"P = {check.worst_P}, ε = {eps_label(check.worst_eps)} (frequency "
        f"{fmt(check.worst_freq, 3)} vs exact {fmt(check.worst_exact, 3)}); "
        + (
            f"exact probability at most {fmt(t.max_exact_ratio, 2)} × the bound in the "
            f"{check.n_informative} cells where the bound is below 1 (the old Chebyshev-only "
            f"test could fail only if the variance were about "
            f"{fmt(1 / t.max_exact_ratio, 2)}× too small); "
            if np.isfinite(t.max_exact_ratio)
            else "no cell has a bound below 1; "
        )
        + power
    )


def chebyshev_claim(summary: pd.DataFrame, eps_values: Sequence[float]) -> Claim:
    """Claim LQG-3 (Prop. 3 on the oven's quadratic cost): exceedances against the exact tail
    probability and against Chebyshev's bound."""
    check = chebyshev_check(summary, eps_values)
    return Claim(
        id="LQG-3",
        claim="In the oven LQG at the paper's setting, the Monte-Carlo estimate's error obeys "
        "P(|J_P - J| ≥ ε) ≤ Var(g)/(P ε²), and its exceedances match the exact probability",
        paper="Sec. II-A, Prop. 3: P(|J_N - J| ≥ ε) ≤ Var(p)/(N ε²) (Chebyshev; stated for a "
        "linear cost, the bound holds for any finite variance)",
        key=KeyNumber(
            f"smallest adjusted p, exceedances vs exact probability ({check.n_cells} cells)",
            check.test.min_p,
            digits=3,
        ),
        verdict=CHEBYSHEV_RULE.verdict(chebyshev_facts(check)),
        rule=CHEBYSHEV_RULE.text(),
        measured=_chebyshev_measured(check, eps_values),
        part="beyond",
        setup=f"{SETUP}, quadratic cost (outside Prop. 3's linear premise)",
        check=True,
    )


# ------------------------------------------------------------------------------- LQG-4

WEIGHTED_RULE = Rule(
    basis="at the largest P",
    cases=(
        Case(
            "supported",
            "the weighted estimate's 95% CI contains J and excludes the derived limit J(σ²/2) "
            "(Gaussian likeliness weights tilt N(0, σ²) to N(0, σ²/2))",
            lambda f: (
                f["ci_low"] <= f["J"] <= f["ci_high"]
                and not f["ci_low"] <= f["limit"] <= f["ci_high"]
            ),
        ),
        Case(
            "not supported",
            "it excludes J",
            lambda f: not f["ci_low"] <= f["J"] <= f["ci_high"],
        ),
    ),
    otherwise="inconclusive",
)


def weighted_facts(check: WeightedCheck) -> Facts:
    """The numbers :data:`WEIGHTED_RULE` is evaluated on."""
    return {"ci_low": check.ci_low, "ci_high": check.ci_high, "J": check.J, "limit": check.limit}


def weighted_claim(summary: pd.DataFrame) -> Claim:
    """Claim LQG-4 (Prop. 2, non-overlapping form): the weighted estimate at the largest P
    against J and against the derived limit J(σ²/2)."""
    check = weighted_check(summary)
    d = ci_digits(check.ci_low, check.ci_high)
    return Claim(
        id="LQG-4",
        claim="In the oven LQG at the paper's setting, the likeliness-weighted average of "
        "independent trajectories converges to J (Prop. 2, non-overlapping form)",
        paper="Sec. II and II-A, Prop. 2: weighted average J~_N → J in probability",
        key=KeyNumber(
            f"weighted estimate at P = {check.P} (J = {fmt_exact(check.J, 4)})",
            check.mean,
            check.ci_low,
            check.ci_high,
            digits=d,
        ),
        verdict=WEIGHTED_RULE.verdict(weighted_facts(check)),
        rule=WEIGHTED_RULE.text(),
        measured=(
            f"derived limit J(σ²/2) = J - r·Var(x_H)/2 = {fmt_exact(check.limit, d)} "
            f"({'inside' if check.contains_limit else 'outside'} the CI); J = "
            f"{fmt_exact(check.J, d)} ({'inside' if check.contains_j else 'outside'}); "
            f"{check.replicates} replicates"
        ),
        setup=SETUP,
    )


# ------------------------------------------------------------------------------- LIN-1

LINEAR_RULE = Rule(
    basis="Prop. 3's own setting (linear dynamics, linear cost): z of the sample variance of "
    "J_n against the paper's formula C[Σ_k 𝒜_k Σ 𝒜_kᵀ]Cᵀ/n (chi-square, exact for Gaussian "
    "J_n) per n and pooled, z of the mean against J per n; per (n, k) cell the count of "
    "|J_n − J| ≥ k sd_n against its exact probability 2Φ(−k) and Chebyshev's 1/k²",
    cases=(
        Case(
            "not supported",
            "some |z| exceeds its Bonferroni limit (familywise 95%) or some cell's "
            "exceedance frequency lies significantly above 1/k²",
            lambda f: f["max |z|"] > f["z limit"] or f["above bound"] >= 1,
        ),
        Case(
            "supported",
            "every |z| is within the limit, no cell's count departs from the exact "
            "probability and the exact probability is below 1/k² in every cell",
            lambda f: f["cells"] >= 1 and f["departing"] == 0 and f["exact above bound"] == 0,
        ),
    ),
    otherwise="inconclusive",
)


def linear_facts(check: LinearCostCheck) -> Facts:
    """The numbers :data:`LINEAR_RULE` is evaluated on."""
    return {
        "max |z|": check.max_abs_z,
        "z limit": check.z_limit,
        **exceedance_facts(check.exceedance),
    }


def linear_claim(check: LinearCostCheck) -> Claim:
    """Claim LIN-1: Prop. 3's variance formula and bound on a linear-cost system."""
    zs = ", ".join(
        f"n = {n}: {fmt(v, 2, True)} / {fmt(m, 2, True)}"
        for n, v, m in zip(check.n, check.var_z, check.mean_z, strict=True)
    )
    t = check.exceedance
    return Claim(
        id="LIN-1",
        claim="On a linear-cost system (Prop. 3's premise), the Monte-Carlo estimate's "
        "variance is C[Σ_k 𝒜_k Σ 𝒜_kᵀ]Cᵀ/N and its error obeys Chebyshev's bound, with "
        "exceedances matching the exact probability",
        paper="Sec. II-A, Prop. 3: Var(p) = C[Σ_k 𝒜_k Σ 𝒜_kᵀ]Cᵀ and "
        "P(|J_N - J| ≥ ε) ≤ Var(p)/(N ε²) for linear dynamics and a linear cost",
        key=KeyNumber(
            f"max |z| over {2 * len(check.n) + 1} variance and mean tests", check.max_abs_z
        ),
        verdict=LINEAR_RULE.verdict(linear_facts(check)),
        rule=LINEAR_RULE.text(),
        measured=f"H = {check.H}, {check.replicates} replicates per n; Var(p) = "
        f"{fmt(check.var_prop3, 6)} by the paper's formula and {fmt(check.var_form, 6)} from "
        f"the cost's quadratic form; z of the variance / of the mean: {zs}; pooled variance "
        f"z = {fmt(check.pooled_z, 2, True)} (Bonferroni limit {fmt(check.z_limit, 3)}); "
        f"{t.cells} (n, k) cells: {t.departing} depart from 2Φ(−k), {t.above_bound} lie "
        f"significantly above 1/k²"
        + (
            f"; 2Φ(−k) is at most {fmt(t.max_exact_ratio, 2)} × 1/k²"
            if np.isfinite(t.max_exact_ratio)
            else ""
        ),
        setup=f"linear-cost 2-D system (LinearCost.example, H = {check.H})",
        check=True,
    )


def convergence_claims(summary: pd.DataFrame, eps_values: Sequence[float]) -> list[Claim]:
    """Claims LQG-2 (Fig. 3 message), LQG-3 (Prop. 3) and LQG-4 (Prop. 2, non-overlapping)."""
    return [fig3_claim(summary), chebyshev_claim(summary, eps_values), weighted_claim(summary)]


def lqg_claims(
    summary: pd.DataFrame,
    nbo: pd.DataFrame,
    conv: pd.DataFrame,
    eps_values: Sequence[float],
    linear: LinearCostCheck,
) -> list[Claim]:
    """Claims LQG-1..LQG-4 and LIN-1 from the per-P summary, the NBO-error summary, the
    convergence table and the linear-cost check (:mod:`rsmhp.studies.lqg.summarise`)."""
    return [
        nbo_error_claim(nbo, conv),
        *convergence_claims(summary, eps_values),
        linear_claim(linear),
    ]
