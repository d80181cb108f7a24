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
* **LIN-1, Prop. 3 on its own premise** (linear dynamics, linear cost): z of the sample variance
  of :math:`J_n` against :math:`C[\sum_k \mathcal{A}_k \Sigma \mathcal{A}_k^T]C^T/n` per n and
  pooled, z of the mean per n, and the exceedances of :math:`|J_n - J| \ge k\,\mathrm{sd}_n`
  against :math:`2\Phi(-k)` and :math:`1/k^2` (:data:`LINEAR_RULE`).

Each claim is data (:class:`rsmhp.report.claimspec.ClaimSpec`: id, setup, rule, evidence
function); its sentences, the rules' words and the key numbers' names are the macros of the
template ``claims.md`` beside this module (:data:`WORDS`), filled with the numbers the evidence
functions format.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pandas as pd

from rsmhp.report.claimspec import ClaimSpec, Evidence
from rsmhp.report.ledger import Claim, KeyNumber
from rsmhp.report.markdown import fmt, fmt_ci
from rsmhp.report.templates import Words
from rsmhp.report.verdicts import Case, Facts, Rule, at_most, exceedance_facts, exceedance_rule
from rsmhp.studies.lqg.summarise import (
    ChebyshevCheck,
    Fig3Check,
    LinearCostCheck,
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
    "LINEAR_RULE",
    "LIN_1",
    "LQG_1",
    "LQG_2",
    "LQG_3",
    "LQG_4",
    "PAPER_FIG3",
    "SETUP",
    "WEIGHTED_RULE",
    "WORDS",
    "chebyshev_claim",
    "chebyshev_evidence",
    "chebyshev_facts",
    "ci_digits",
    "convergence_claims",
    "fig3_claim",
    "fig3_evidence",
    "fig3_facts",
    "fmt_exact",
    "linear_claim",
    "linear_evidence",
    "linear_facts",
    "lqg_claims",
    "nbo_error_claim",
    "nbo_error_evidence",
    "nbo_error_rule",
    "weighted_claim",
    "weighted_evidence",
    "weighted_facts",
]

#: the words of the claims: the macros of ``claims.md`` beside this module
WORDS = Words("rsmhp.studies.lqg", "claims.md")

#: Sec. and figure of the paper this study replicates
PAPER_FIG3 = WORDS("paper_fig3")

#: the setup of LQG-1..4: the paper's oven model (Sec. III-A)
SETUP = WORDS("setup")


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


def _finite(x: float, digits: int, scale: float = 1.0) -> str | None:
    """``scale * x`` with ``digits`` significant digits, None where ``x`` is not finite (the
    template then says so in words)."""
    return fmt(scale * x, digits) if np.isfinite(x) else None


# ------------------------------------------------------------------------------- LQG-1


def nbo_error_rule(z_limit: float, n_tests: int) -> Rule:
    """LQG-1: ``max |z|`` at most the Bonferroni limit ``z_limit`` of ``n_tests`` tests."""
    return at_most(
        "max |z|",
        z_limit,
        limit_text=WORDS("lqg_1_rule_limit", z_limit=fmt(z_limit, 3), tests=n_tests),
        basis=WORDS("lqg_1_rule_basis"),
    )


def nbo_error_evidence(nbo: pd.DataFrame, conv: pd.DataFrame) -> Evidence:
    r"""LQG-1 from the (a, H) grid and the paper's own setting: key number :math:`\max|z|`
    over every test, judged by :func:`nbo_error_rule` of their Bonferroni limit; the paper's
    setting is printed with its 95% interval :math:`\pm 1.96\,\mathrm{SE}`."""
    check = nbo_error_check(nbo, conv)
    paper = check.paper
    half = 1.96 * paper.se
    return Evidence(
        key=KeyNumber(WORDS("lqg_1_key", tests=check.n_tests), check.max_abs_z, digits=3),
        facts={"max |z|": check.max_abs_z},
        rule=nbo_error_rule(check.z_limit, check.n_tests),
        values={
            "a": eps_label(paper.a),
            "H": paper.H,
            "trajectories": paper.n_trajectories,
            "simulated": fmt(paper.simulated, 6),
            "ci": fmt_ci(paper.simulated - half, paper.simulated + half, 6),
            "closed": fmt_exact(paper.closed, 6),
            "z": fmt(paper.z, 2, signed=True),
            "cells": check.n_cells,
            "replicates": check.replicates,
            "P": check.P,
            "max_z": fmt(check.grid_max_abs_z, 3),
            "worst_a": eps_label(check.worst_a),
            "worst_H": check.worst_H,
            "max_rel_dev": fmt(100 * check.max_abs_rel_dev, 2),
            "resolution": fmt(100 * check.resolution, 2),
            "z_limit": fmt(check.z_limit, 3),
        },
    )


LQG_1 = ClaimSpec(id="LQG-1", setup=SETUP, evidence=nbo_error_evidence, words=WORDS, check=True)


def nbo_error_claim(nbo: pd.DataFrame, conv: pd.DataFrame) -> Claim:
    """Claim LQG-1: the NBO error formula, from the (a, H) grid and the paper's own setting."""
    return LQG_1.build(nbo, conv)


# ------------------------------------------------------------------------------- LQG-2

FIG3_RULE = Rule(
    cases=(
        Case(
            "supported",
            WORDS("lqg_2_rule_supported"),
            lambda f: (
                f["slope_high"] < 0
                and f["mean_low"] <= f["J"] <= f["mean_high"]
                and f["rmse_high"] < f["nbo_error"]
            ),
        ),
        Case(
            "not supported",
            WORDS("lqg_2_rule_not_supported"),
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


def fig3_evidence(summary: pd.DataFrame) -> Evidence:
    r"""LQG-2 from the per-P summary: key number the slope :math:`s` of :math:`\log
    \mathrm{RMSE} = c + s \log P` with its 95% CI (null 0, theory -1/2); at the largest P the
    mean :math:`J_P` against J and the RMSE against :math:`|J - J_{NBO}|`."""
    check = fig3_check(summary)
    fit = check.fit
    dm = ci_digits(check.ci_low, check.ci_high)
    return Evidence(
        key=KeyNumber(
            WORDS("lqg_2_key"),
            fit.slope,
            fit.low,
            fit.high,
            digits=ci_digits(fit.low, fit.high),
            null=0.0,
        ),
        facts=fig3_facts(check),
        values={
            "slope_has_theory": fit.contains(-0.5),
            "P": check.P,
            "mean": fmt(check.mean, dm),
            "ci": fmt_ci(check.ci_low, check.ci_high, dm),
            "J": fmt_exact(check.J, dm),
            "rmse": fmt(check.rmse, 3),
            "rmse_ci": fmt_ci(check.rmse_low, check.rmse_high, 3),
            "nbo_error": fmt_exact(check.nbo_error, 4),
            "in_rmse": fmt(check.nbo_error / check.rmse, 2),
            "n_P": check.n_P,
            "P_first": check.P_first,
            "replicates": check.replicates,
        },
    )


LQG_2 = ClaimSpec(id="LQG-2", setup=SETUP, evidence=fig3_evidence, words=WORDS, rule=FIG3_RULE)


def fig3_claim(summary: pd.DataFrame) -> Claim:
    """Claim LQG-2 (Fig. 3 message): the RMSE of J_P falls with P, and at the largest P it is
    below NBO's error and the mean shows no bias."""
    return LQG_2.build(summary)


# ------------------------------------------------------------------------------- LQG-3


CHEBYSHEV_RULE = exceedance_rule(WORDS("lqg_3_rule_basis"))


def chebyshev_facts(check: ChebyshevCheck) -> Facts:
    """The numbers :data:`CHEBYSHEV_RULE` is evaluated on."""
    return exceedance_facts(check.test, check.detectable)


def chebyshev_evidence(summary: pd.DataFrame, eps_values: Sequence[float]) -> Evidence:
    r"""LQG-3 from the per-P summary and the configured ε: key number the smallest
    Bonferroni-adjusted p-value of the exceedance tests; the largest ratio :math:`r` of the
    exact probability to the bound where the bound is below 1 (the variance would have to be
    :math:`1/r` times too small for Chebyshev's bound to fail) and the smallest spread error
    detected with 80% power (both None where not finite)."""
    check = chebyshev_check(summary, eps_values)
    t = check.test
    return Evidence(
        key=KeyNumber(WORDS("lqg_3_key", cells=check.n_cells), t.min_p, digits=3),
        facts=chebyshev_facts(check),
        values={
            "cells": t.cells,
            "eps": ", ".join(eps_label(e) for e in eps_values),
            "replicates": check.replicates,
            "departing": t.departing,
            "above_bound": t.above_bound,
            "min_p": fmt(t.min_p, 3),
            "worst_P": check.worst_P,
            "worst_eps": eps_label(check.worst_eps),
            "worst_freq": fmt(check.worst_freq, 3),
            "worst_exact": fmt(check.worst_exact, 3),
            "ratio": _finite(t.max_exact_ratio, 2),
            "informative": check.n_informative,
            "inverse_ratio": _finite(1 / t.max_exact_ratio, 2),
            "detectable": _finite(check.detectable, 2, scale=100),
        },
    )


LQG_3 = ClaimSpec(
    id="LQG-3",
    setup=WORDS("lqg_3_setup"),
    evidence=chebyshev_evidence,
    words=WORDS,
    rule=CHEBYSHEV_RULE,
    part="beyond",
    check=True,
)


def chebyshev_claim(summary: pd.DataFrame, eps_values: Sequence[float]) -> Claim:
    """Claim LQG-3 (Prop. 3 on the oven's quadratic cost): exceedances against the exact tail
    probability and against Chebyshev's bound."""
    return LQG_3.build(summary, eps_values)


# ------------------------------------------------------------------------------- LQG-4

WEIGHTED_RULE = Rule(
    basis=WORDS("lqg_4_rule_basis"),
    cases=(
        Case(
            "supported",
            WORDS("lqg_4_rule_supported"),
            lambda f: (
                f["ci_low"] <= f["J"] <= f["ci_high"]
                and not f["ci_low"] <= f["limit"] <= f["ci_high"]
            ),
        ),
        Case(
            "not supported",
            WORDS("lqg_4_rule_not_supported"),
            lambda f: not f["ci_low"] <= f["J"] <= f["ci_high"],
        ),
    ),
    otherwise="inconclusive",
)


def weighted_facts(check: WeightedCheck) -> Facts:
    """The numbers :data:`WEIGHTED_RULE` is evaluated on."""
    return {"ci_low": check.ci_low, "ci_high": check.ci_high, "J": check.J, "limit": check.limit}


def weighted_evidence(summary: pd.DataFrame) -> Evidence:
    r"""LQG-4 from the per-P summary: key number the weighted estimate at the largest P with
    its 95% CI, against J and the derived limit :math:`J(\sigma^2/2)`."""
    check = weighted_check(summary)
    d = ci_digits(check.ci_low, check.ci_high)
    return Evidence(
        key=KeyNumber(
            WORDS("lqg_4_key", P=check.P, J=fmt_exact(check.J, 4)),
            check.mean,
            check.ci_low,
            check.ci_high,
            digits=d,
        ),
        facts=weighted_facts(check),
        values={
            "limit": fmt_exact(check.limit, d),
            "limit_inside": check.contains_limit,
            "J": fmt_exact(check.J, d),
            "J_inside": check.contains_j,
            "replicates": check.replicates,
        },
    )


LQG_4 = ClaimSpec(
    id="LQG-4", setup=SETUP, evidence=weighted_evidence, words=WORDS, rule=WEIGHTED_RULE
)


def weighted_claim(summary: pd.DataFrame) -> Claim:
    """Claim LQG-4 (Prop. 2, non-overlapping form): the weighted estimate at the largest P
    against J and against the derived limit J(σ²/2)."""
    return LQG_4.build(summary)


# ------------------------------------------------------------------------------- LIN-1

LINEAR_RULE = Rule(
    basis=WORDS("lin_1_rule_basis"),
    cases=(
        Case(
            "not supported",
            WORDS("lin_1_rule_not_supported"),
            lambda f: f["max |z|"] > f["z limit"] or f["above bound"] >= 1,
        ),
        Case(
            "supported",
            WORDS("lin_1_rule_supported"),
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


def linear_evidence(check: LinearCostCheck) -> Evidence:
    """LIN-1 from the linear-cost check: key number the largest |z| of the ``2 len(n) + 1``
    variance and mean tests; per n the z of the variance and of the mean (signed)."""
    t = check.exceedance
    return Evidence(
        key=KeyNumber(WORDS("lin_1_key", tests=2 * len(check.n) + 1), check.max_abs_z),
        facts=linear_facts(check),
        values={
            "H": check.H,
            "replicates": check.replicates,
            "var_prop3": fmt(check.var_prop3, 6),
            "var_form": fmt(check.var_form, 6),
            "zs": [
                {"n": n, "var": fmt(v, 2, True), "mean": fmt(m, 2, True)}
                for n, v, m in zip(check.n, check.var_z, check.mean_z, strict=True)
            ],
            "pooled_z": fmt(check.pooled_z, 2, True),
            "z_limit": fmt(check.z_limit, 3),
            "cells": t.cells,
            "departing": t.departing,
            "above_bound": t.above_bound,
            "ratio": _finite(t.max_exact_ratio, 2),
        },
    )


LIN_1 = ClaimSpec(
    id="LIN-1",
    # the horizon is filled from the evidence's values
    setup=WORDS("lin_1_setup", H="{H}"),
    evidence=linear_evidence,
    words=WORDS,
    rule=LINEAR_RULE,
    check=True,
)


def linear_claim(check: LinearCostCheck) -> Claim:
    """Claim LIN-1: Prop. 3's variance formula and bound on a linear-cost system."""
    return LIN_1.build(check)


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
