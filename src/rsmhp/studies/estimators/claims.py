r"""Claims of the estimator study, EST-1..EST-4: each a key number and a verdict rule
(:class:`rsmhp.report.verdicts.Rule`) evaluated on *facts*, numbers computed from the statistics of
:mod:`rsmhp.studies.estimators.summarise` (symbols in its docstring). The rule objects give both the
verdict and the rule's text printed in the report.

Verdict rules
-------------
* **EST-1, Prop. 1** (the uniform shared-draw tree converges as N grows): per problem, the OLS
  slope of log Var against log N with its 95% t-interval. Only problems whose tree ran at
  ``>= MIN_TREE_SIZES`` (4) values of N count: with 3 points the interval has one degree of
  freedom (t = 12.7) and cannot separate a falling from a flat variance; the others are named in
  ``dropped``. *not supported* if a counted slope CI lies above 0 or some problem's variance at
  its largest N is significantly above the one at its smallest N (disjoint CIs); *supported* if
  every counted slope CI lies below 0 and the derived variance
  (:meth:`~rsmhp.models.lqg.linear_quadratic.QuadraticForm.tree_variance`, ~1/N) lies inside the
  bootstrap CI of at least ``COVERAGE_MIN`` (90%) of all tree cells; else *inconclusive* (e.g. a
  counted slope CI admits 0). Key number: the counted slope whose CI reaches highest (the least
  evidence of a decrease).
* **EST-2, Prop. 2** (the likeliness-weighted tree converges to J): per problem,
  :math:`f = (\bar J_w - J)/(J(\Sigma/2) - J)` of the weighted shared tree's mean
  :math:`\bar J_w` with its bootstrap CI (0: at J; 1: at the derived large-N limit). *not
  supported* if, in a problem with ``>= MIN_TREE_SIZES`` tree sizes, f's CI at the largest N
  excludes 0 and f at the largest N is not below f at the smallest N (the bias does not shrink);
  *supported* if at the largest N of every problem f's CI contains 0 and excludes 1; else
  *inconclusive*. At finite N no closed form exists (self-normalised weights); the derived end
  points are N = 1 (weight 1, mean J, f = 0) and N -> infinity (f = 1).
* **EST-3, Prop. 3** (Chebyshev bound, 1/n rate of plain MC): at :math:`\varepsilon = k\,
  \mathrm{sd}_n` (derived sd) the bound is :math:`1/k^2`; the exact probability of
  :math:`|J_n - J| \ge \varepsilon` is known (a generalised chi-square). The rule is
  :func:`rsmhp.studies.lqg.claims.exceedance_rule` (counts against the exact probability, with
  power, and against the bound) plus the variance-vs-n slopes: *not supported* if some cell
  lies significantly above :math:`1/k^2` or some slope CI excludes -1; *supported* if no cell
  departs from the exact probability, the exact probability is below the bound and every
  slope CI contains -1; else *inconclusive*. Key number: the smallest Bonferroni-adjusted
  p-value of the exceedance tests.
* **EST-4, pruning** (the paper, Sec. III-B: pruning would degrade the performance): the
  bias as a fraction of the NBO error, :math:`f = (\bar J - J)/(J_\mathrm{NBO} - J)` (0: J,
  1: the NBO cost), uniform weighting, at the largest N, per (problem, M). *supported* if
  every CI lies above 0 (every pruned estimate is biased toward the NBO cost); *not
  supported* if every CI contains 0; else *inconclusive*. Key number: the cell whose CI
  reaches nearest to J (the weakest evidence of a degradation).

Each claim is data (:class:`rsmhp.report.claimspec.ClaimSpec`: id, setup, rule, evidence
function); its sentences, the rules' words and the key numbers' names are the macros of the
template ``claims.md`` beside this module (:data:`WORDS`), filled with the numbers the evidence
functions format.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.core.stats import ExceedanceTest, exceedance_test
from rsmhp.report.claimspec import ClaimSpec, Evidence
from rsmhp.report.ledger import Claim, KeyNumber
from rsmhp.report.markdown import fmt, fmt_ci
from rsmhp.report.templates import Words
from rsmhp.report.verdicts import Case, Rule, exceedance_facts, exceedance_rule
from rsmhp.studies.estimators.summarise import (
    MIN_TREE_SIZES,
    largest_leaf_ratios,
    mc_variance_slopes,
    pruning_at_largest_n,
    pruning_weighting_gap,
    tree_coverage,
    tree_slopes,
    weighted_trend,
)

__all__ = [
    "COVERAGE_MIN",
    "EST_1",
    "EST_2",
    "EST_3",
    "EST_4",
    "RULE_EST1",
    "RULE_EST2",
    "RULE_EST4",
    "SETUP",
    "WORDS",
    "claim_est1",
    "claim_est2",
    "claim_est3",
    "claim_est4",
    "claims",
    "evidence_est1",
    "evidence_est2",
    "evidence_est3",
    "evidence_est4",
    "facts_est1",
    "facts_est2",
    "facts_est3",
    "facts_est4",
    "k_text",
    "range_text",
    "rule_est3",
    "sizes_text",
]

#: the words of the claims: the macros of ``claims.md`` beside this module
WORDS = Words("rsmhp.studies.estimators", "claims.md")

#: share of tree cells whose bootstrap CI must contain the derived variance (EST-1)
COVERAGE_MIN = 0.9
#: the setup of EST-1..4: the paper's oven model at the estimator study's horizons
SETUP = WORDS("setup")


# --- text of numbers shared by the claims and the narrative ------------------------------


def range_text(values: Sequence[float], digits: int = 2, unit: str = "") -> str:
    """``lo to hi`` (or one value when both print alike), ``unit`` appended."""
    lo, hi = float(min(values)), float(max(values))
    if fmt(lo, digits) == fmt(hi, digits):
        return fmt(lo, digits) + unit
    return f"{fmt(lo, digits)} to {fmt(hi, digits)}{unit}"


def sizes_text(values: Sequence[Any]) -> str:
    """``2, 3, 4`` from a sequence of integer-valued sizes."""
    return ", ".join(str(int(v)) for v in values)


def k_text(k: float) -> str:
    """A Chebyshev multiplier as written in the config: ``1.5``, ``2``, ``3``."""
    return f"{float(k):g}"


def _slope_row(problem: Any, slope: float, low: float, high: float) -> dict[str, Any]:
    """A fitted slope printed: the problem, the slope (3 digits) and its 95% CI."""
    return {"problem": problem, "slope": fmt(slope, 3), "ci": fmt_ci(low, high)}


# --- the rules ------------------------------------------------------------------------------

RULE_EST1 = Rule(
    basis=WORDS("est_1_rule_basis", sizes=MIN_TREE_SIZES),
    cases=(
        Case(
            "not supported",
            WORDS("est_1_rule_not_supported"),
            lambda f: f["slope_low_max"] > 0 or f["rising"] > 0,
        ),
        Case(
            "supported",
            WORDS("est_1_rule_supported", coverage=f"{COVERAGE_MIN:.0%}"),
            lambda f: (
                f["counted"] > 0
                and f["slope_high_max"] < 0
                and f["cells"] > 0
                and f["covered"] >= COVERAGE_MIN * f["cells"]
            ),
        ),
    ),
    otherwise="inconclusive",
)

RULE_EST2 = Rule(
    basis=WORDS("est_2_rule_basis"),
    cases=(
        Case(
            "not supported",
            WORDS("est_2_rule_not_supported", sizes=MIN_TREE_SIZES),
            lambda f: f["growing"] > 0,
        ),
        Case(
            "supported",
            WORDS("est_2_rule_supported"),
            lambda f: f["problems"] > 0 and f["at_j"] == f["problems"],
        ),
    ),
    otherwise="inconclusive",
)


def rule_est3(ks: Sequence[float]) -> Rule:
    """The EST-3 rule for the Chebyshev multipliers ``ks``: :func:`rsmhp.studies.lqg.claims.
    exceedance_rule` plus the 1/n rate of plain MC's variance."""
    base = exceedance_rule("")
    return Rule(
        basis=WORDS("est_3_rule_basis", ks=", ".join(k_text(k) for k in ks)),
        cases=(
            Case(
                "not supported",
                WORDS("est_3_rule_not_supported", exceedance=base.cases[0].when),
                lambda f: base.cases[0].test(f) or f["slopes_off"] > 0,
            ),
            Case(
                "supported",
                WORDS("est_3_rule_supported", exceedance=base.cases[1].when),
                lambda f: base.cases[1].test(f) and f["slopes"] > 0,
            ),
        ),
        otherwise="inconclusive",
    )


RULE_EST4 = Rule(
    basis=WORDS("est_4_rule_basis"),
    cases=(
        Case(
            "supported",
            WORDS("est_4_rule_supported"),
            lambda f: f["cells"] > 0 and f["above_zero"] == f["cells"],
        ),
        Case(
            "not supported",
            WORDS("est_4_rule_not_supported"),
            lambda f: f["cells"] > 0 and f["contain_zero"] == f["cells"],
        ),
    ),
    otherwise="inconclusive",
)


# --- facts: the numbers each rule reads -----------------------------------------------------


def facts_est1(s: pd.DataFrame) -> dict[str, float]:
    """EST-1: counted problems, the highest lower / upper slope CI limit among them (-inf if
    none), problems whose variance rises significantly, tree cells covering the derived
    variance and tree cells with one."""
    sl = tree_slopes(s)
    counted = sl[sl["counted"]]
    covered, cells = tree_coverage(s)
    return {
        "counted": len(counted),
        "slope_low_max": float(counted["slope_low"].max()) if len(counted) else -np.inf,
        "slope_high_max": float(counted["slope_high"].max()) if len(counted) else -np.inf,
        "rising": int(sl["rises"].sum()),
        "covered": covered,
        "cells": cells,
    }


def facts_est2(s: pd.DataFrame) -> dict[str, float]:
    """EST-2: problems, problems with a weighted-tree bias that does not shrink although their
    CI at the largest N excludes 0 (with >= ``MIN_TREE_SIZES`` sizes), problems at J there."""
    tr = weighted_trend(s)
    return {
        "problems": len(tr),
        "growing": int(_growing(tr).sum()),
        "at_j": int((~tr["excludes_j"] & tr["excludes_limit"]).sum()),
    }


def _growing(tr: pd.DataFrame) -> pd.Series:
    """Rows of :func:`~rsmhp.studies.estimators.summarise.weighted_trend` that contradict Prop.
    2."""
    return (tr["n_sizes"] >= MIN_TREE_SIZES) & tr["excludes_j"] & tr["not_shrinking"]


def facts_est3(cheb: pd.DataFrame, s: pd.DataFrame) -> dict[str, float]:
    """EST-3, from :func:`~rsmhp.studies.estimators.summarise.chebyshev_table` ``cheb``: the facts
    of :func:`rsmhp.studies.lqg.claims.exceedance_facts`, MC variance slopes and those whose CI
    excludes -1."""
    rate = mc_variance_slopes(s)
    empty = {
        "cells": 0,
        "departing": 0,
        "above bound": 0,
        "exact above bound": 0,
        "detectable": np.inf,
    }
    return {
        **(
            exceedance_facts(_exceedance(cheb), float(cheb["detectable"].min()))
            if len(cheb)
            else empty
        ),
        "slopes": len(rate),
        "slopes_off": sum(not f.contains(-1.0) for f in rate.values()),
    }


def _exceedance(cheb: pd.DataFrame) -> ExceedanceTest:
    return exceedance_test(cheb["hits"], cheb["replicates"], cheb["exact"], cheb["bound"])


def facts_est4(top: pd.DataFrame) -> dict[str, float]:
    """EST-4, from the pruned cells at the largest N: cells, cells whose CI lies above 0,
    cells whose CI contains 0."""
    lo, hi = top["bias_fraction_low"], top["bias_fraction_high"]
    return {
        "cells": len(top),
        "above_zero": int((lo > 0).sum()),
        "contain_zero": int(((lo <= 0) & (hi >= 0)).sum()),
    }


# --- EST-1 ------------------------------------------------------------------------------------


def evidence_est1(s: pd.DataFrame) -> Evidence:
    """EST-1 (Prop. 1): key number the counted slope whose CI reaches highest (null 0); the
    counted slopes, the tree cells covering the derived variance, the problems whose variance
    falls significantly, Var(shared tree)/Var(independent) at the largest leaf count, and the
    problems left out of the slope evidence with why."""
    sl = tree_slopes(s)
    counted = sl[sl["counted"]]
    covered, cells = tree_coverage(s)
    return Evidence(
        key=_key_est1(counted),
        facts=facts_est1(s),
        values={
            "slopes": [
                _slope_row(r["problem"], r["slope"], r["slope_low"], r["slope_high"])
                for _, r in counted.iterrows()
            ],
            "covered": covered,
            "cells": cells,
            "falls": int(sl["falls"].sum()),
            "multi": len(sl[sl["n_sizes"] > 1]),
            "leaf_ratios": [
                {
                    "measured": fmt(r["ratio_measured"], 3),
                    "derived": fmt(r["ratio_derived"], 3),
                    "leaves": int(r["leaves"]),
                    "problem": r["problem"],
                    "N": r["N"],
                }
                for _, r in largest_leaf_ratios(s).iterrows()
            ],
            "problems": [_dropped_est1(r) for _, r in sl[~sl["counted"]].iterrows()],
        },
    )


def _key_est1(counted: pd.DataFrame) -> KeyNumber:
    """The counted slope whose CI reaches highest (null 0), or the count 0 of counted
    problems."""
    if not len(counted):
        return KeyNumber(name=WORDS("est_1_key_none", sizes=MIN_TREE_SIZES), value=0.0)
    worst = counted.loc[counted["slope_high"].idxmax()]
    return KeyNumber(
        name=WORDS("est_1_key", problem=worst["problem"]),
        value=float(worst["slope"]),
        ci_low=float(worst["slope_low"]),
        ci_high=float(worst["slope_high"]),
        null=0.0,
    )


def _dropped_est1(r: pd.Series) -> dict[str, Any]:
    """A problem left out of EST-1's slopes (too few tree sizes): its sizes and, where a slope
    could be fitted, the slope with its CI and degrees of freedom (sizes - 2)."""
    fitted = bool(np.isfinite(r["slope"]))
    return {
        "problem": r["problem"],
        "H": r["H"],
        "sizes": sizes_text(r["sizes"]),
        "slope": fmt(r["slope"], 3) if fitted else None,
        "ci": fmt_ci(r["slope_low"], r["slope_high"]) if fitted else None,
        "dof": r["n_sizes"] - 2,
        "admits_zero": bool(r["slope_low"] <= 0 <= r["slope_high"]),
        "falls": bool(r["falls"]),
    }


EST_1 = ClaimSpec(id="EST-1", setup=SETUP, evidence=evidence_est1, words=WORDS, rule=RULE_EST1)


def claim_est1(s: pd.DataFrame) -> Claim:
    """EST-1 (Prop. 1) by :data:`RULE_EST1` (module docstring)."""
    return EST_1.build(s)


# --- EST-2 ------------------------------------------------------------------------------------


def evidence_est2(s: pd.DataFrame) -> Evidence:
    """EST-2 (Prop. 2) from the weighted shared tree's f at each problem's largest N (module
    docstring): per problem the mean against J and J(Σ/2), f with its CI and f at the
    smallest N; the problems with too few sizes to decide 'not supported'."""
    tr = weighted_trend(s)
    return Evidence(
        key=_key_est2(tr),
        facts=facts_est2(s),
        values={
            "problems": [_measured_est2(p) for _, p in tr.iterrows()],
            "few": [
                {"problem": p["problem"], "sizes": int(p["n_sizes"])}
                for _, p in tr[tr["n_sizes"] < MIN_TREE_SIZES].iterrows()
            ],
        },
    )


def _key_est2(tr: pd.DataFrame) -> KeyNumber:
    """f of the deciding problem: among the counterexamples the one at the largest N (then
    most sizes), else the problem whose CI of f reaches highest."""
    rows = [p for _, p in tr.iterrows()]
    deciding = [p for (_, p), g in zip(tr.iterrows(), _growing(tr), strict=True) if g]
    if deciding:
        pick = max(deciding, key=lambda p: (int(p["N"]), int(p["n_sizes"])))
    elif rows:
        pick = max(rows, key=lambda p: float(p["f_high"]))
    else:
        return KeyNumber(name=WORDS("est_2_key_none"), value=0.0)
    return KeyNumber(
        name=WORDS("est_2_key", problem=pick["problem"], N=int(pick["N"])),
        value=float(pick["f"]),
        ci_low=float(pick["f_low"]),
        ci_high=float(pick["f_high"]),
        null=1.0,
    )


def _measured_est2(p: pd.Series) -> dict[str, Any]:
    """One problem of EST-2 printed: mean with its CI against J and J(Σ/2), f with its CI at
    the largest N, f at the smallest N (None if only one size ran)."""
    more = p["n_sizes"] > 1
    return {
        "problem": p["problem"],
        "N": int(p["N"]),
        "mean": fmt(p["mean"], 4),
        "ci": fmt_ci(p["ci_low"], p["ci_high"], 4),
        "J": fmt(p["J_exact"], 4),
        "limit": fmt(p["limit"], 4),
        "f": fmt(p["f"], 3),
        "f_ci": fmt_ci(p["f_low"], p["f_high"]),
        "N_first": int(p["N_first"]) if more else None,
        "f_first": fmt(p["f_first"], 3) if more else None,
    }


EST_2 = ClaimSpec(id="EST-2", setup=SETUP, evidence=evidence_est2, words=WORDS, rule=RULE_EST2)


def claim_est2(s: pd.DataFrame) -> Claim:
    """EST-2 (Prop. 2) by :data:`RULE_EST2` from the weighted shared tree's f at each problem's
    largest N (module docstring)."""
    return EST_2.build(s)


# --- EST-3 ------------------------------------------------------------------------------------


def evidence_est3(s: pd.DataFrame, cheb: pd.DataFrame) -> Evidence:
    """EST-3 (Prop. 3) by :func:`rule_est3` of the multipliers run: key number the smallest
    adjusted p of plain MC's exceedances against the exact probability; the cell of that p,
    the largest ratio of the exact probability to the bound (1 where none is finite), the
    smallest spread error detected with 80% power (None without power) and the variance-vs-n
    slopes."""
    ks = sorted(cheb["k"].unique()) if len(cheb) else []
    rule = rule_est3(ks)
    facts = facts_est3(cheb, s)
    if not len(cheb):
        return Evidence(
            key=KeyNumber(name=WORDS("est_3_key_none"), value=0.0),
            facts=facts,
            rule=rule,
            values={"cells": None},
        )
    test = _exceedance(cheb)
    worst = cheb.iloc[test.worst]
    det = float(cheb["detectable"].min())
    ratio = test.max_exact_ratio
    return Evidence(
        key=KeyNumber(name=WORDS("est_3_key", cells=test.cells), value=test.min_p),
        facts=facts,
        rule=rule,
        values={
            "cells": test.cells,
            "departing": test.departing,
            "above_bound": test.above_bound,
            "problem": worst["problem"],
            "n": int(worst["n"]),
            "k": k_text(worst["k"]),
            "freq": fmt(worst["freq"], 3),
            "exact": fmt(worst["exact"], 3),
            "ratio": fmt(ratio, 2) if np.isfinite(ratio) else 1,
            "detectable": fmt(100 * det, 2) if np.isfinite(det) else None,
            "slopes": [
                _slope_row(p, f.slope, f.low, f.high) for p, f in mc_variance_slopes(s).items()
            ],
        },
    )


EST_3 = ClaimSpec(
    id="EST-3",
    setup=WORDS("est_3_setup"),
    evidence=evidence_est3,
    words=WORDS,
    part="beyond",
    check=True,
)


def claim_est3(s: pd.DataFrame, cheb: pd.DataFrame) -> Claim:
    """EST-3 (Prop. 3) by :func:`rule_est3`: exceedances of plain MC against the exact
    probability and Chebyshev's bound (:func:`~rsmhp.studies.estimators.summarise.chebyshev_table`),
    and its variance-vs-n slopes."""
    return EST_3.build(s, cheb)


# --- EST-4 ------------------------------------------------------------------------------------


def evidence_est4(s: pd.DataFrame) -> Evidence:
    """EST-4 (pruning): bias / (J_NBO - J) of the uniform pruned tree at the largest N, per
    (problem, M); key number the cell whose CI reaches nearest to J (the weakest evidence of a
    degradation, null 0); per problem the range of the fraction, the leaves the full tree
    would have, N^H, against the M kept, and the largest gap to the weighted pruned cells."""
    top = pruning_at_largest_n(s)
    near = top.loc[top["bias_fraction_low"].idxmin()] if len(top) else None
    gap = pruning_weighting_gap(s)
    by_problem = top.groupby("problem", sort=False)
    return Evidence(
        key=_key_est4(near),
        facts=facts_est4(top),
        values={
            "sizes": sizes_text(sorted(top["N"].unique())),
            "ms": sizes_text(sorted(top["M"].unique())),
            "problems": [
                {"problem": p, "range": range_text(g["bias_fraction_of_nbo"], 3)}
                for p, g in by_problem
            ],
            "near": None
            if near is None
            else {
                "problem": near["problem"],
                "M": int(near["M"]),
                "f": fmt(near["bias_fraction_of_nbo"], 3),
                "ci": fmt_ci(near["bias_fraction_low"], near["bias_fraction_high"]),
            },
            "compute": [_compute_est4(p, g) for p, g in by_problem if "H" in top.columns],
            "gap": None if gap is None else fmt(gap, 2),
        },
    )


def _key_est4(near: pd.Series | None) -> KeyNumber:
    """The fraction of the pruned cell ``near`` whose CI reaches nearest to J (null 0, 4
    digits), or the count 0 of pruned cells."""
    if near is None:
        return KeyNumber(name=WORDS("est_4_key_none"), value=0.0)
    return KeyNumber(
        name=WORDS("est_4_key", problem=near["problem"], N=int(near["N"]), M=int(near["M"])),
        value=float(near["bias_fraction_of_nbo"]),
        ci_low=float(near["bias_fraction_low"]),
        ci_high=float(near["bias_fraction_high"]),
        digits=4,
        null=0.0,
    )


def _compute_est4(problem: Any, g: pd.DataFrame) -> dict[str, Any]:
    """A problem's pruned cells at the largest N: the most trajectories kept, M, against the
    full tree's N^H leaves (3 significant digits)."""
    return {
        "problem": problem,
        "N": int(g["N"].iloc[0]),
        "M": int(g["M"].max()),
        "leaves": f"{float(g['N'].iloc[0]) ** int(g['H'].iloc[0]):.3g}",
    }


EST_4 = ClaimSpec(id="EST-4", setup=SETUP, evidence=evidence_est4, words=WORDS, rule=RULE_EST4)


def claim_est4(s: pd.DataFrame) -> Claim:
    """EST-4 (pruning) by :data:`RULE_EST4`: bias / (J_NBO - J) of the uniform pruned tree at
    the largest N, per (problem, M)."""
    return EST_4.build(s)


def claims(s: pd.DataFrame, cheb: pd.DataFrame) -> list[Claim]:
    """Claims EST-1..EST-4 from the ablation ``df``, its summary ``s`` and the Chebyshev
    table ``cheb`` (:func:`~rsmhp.studies.estimators.summarise.chebyshev_table`)."""
    return [claim_est1(s), claim_est2(s), claim_est3(s, cheb), claim_est4(s)]
