r"""Verdict rules as small objects: one definition gives both the rule's text (printed next to
the claim in the report) and its evaluation, so the two cannot drift apart.

A :class:`Rule` is an ordered list of :class:`Case` s, each a verdict with a condition on
named *facts* (numbers computed by the study's statistics, e.g. ``{"max_z": 2.1}``), and the
verdict that holds when no case does::

    rule = Rule(
        basis="z = (simulated - closed form) / SE per cell",
        cases=(Case("supported", "max |z| ≤ 3.2", lambda f: f["max_z"] <= 3.2),),
        otherwise="not supported",
    )
    rule.verdict({"max_z": 2.1})  # "supported"
    rule.text()  # "z = ... per cell: supported if max |z| ≤ 3.2, not supported otherwise"

The cases are tried in order; the first whose condition holds gives the verdict. The common
shapes have constructors (:func:`at_most`, :func:`ci_side`, :func:`non_inferior`), whose
boundary behaviour is tested in ``tests/report/test_verdicts.py``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import scipy  # scipy.stats loads on first use (scipy's lazy submodules)

from rsmhp.core.stats import ExceedanceTest, holm
from rsmhp.report.ledger import OVER_BUDGET, STATEMENT_VERDICTS, Claim, Section

__all__ = [
    "HOLM_FAMILY",
    "Case",
    "Facts",
    "Rule",
    "at_most",
    "ci_side",
    "decisive_p",
    "holm_correct",
    "holm_sections",
    "non_inferior",
]

Facts = Mapping[str, float]


@dataclass(frozen=True)
class Case:
    """``verdict`` when ``test(facts)`` is true; ``when`` is the condition in words."""

    verdict: str
    when: str
    test: Callable[[Facts], bool]

    def __post_init__(self) -> None:
        if self.verdict not in (*STATEMENT_VERDICTS, OVER_BUDGET):
            raise ValueError(
                f"Case.verdict must be one of {(*STATEMENT_VERDICTS, OVER_BUDGET)}, "
                f"got {self.verdict!r}"
            )
        if not self.when.strip():
            raise ValueError("Case.when must say the condition in words, got ''")


@dataclass(frozen=True)
class Rule:
    """A verdict rule: ``basis`` (how the key number is obtained, may be empty), the ordered
    ``cases`` and the verdict ``otherwise``."""

    cases: tuple[Case, ...]
    otherwise: str
    basis: str = ""

    def __post_init__(self) -> None:
        if not self.cases:
            raise ValueError("Rule.cases must hold at least one Case")
        if self.otherwise not in STATEMENT_VERDICTS:
            raise ValueError(
                f"Rule.otherwise must be one of {STATEMENT_VERDICTS}, got {self.otherwise!r}"
            )

    @property
    def verdicts(self) -> tuple[str, ...]:
        """Every verdict the rule can give (its cases' and ``otherwise``), in order."""
        out = [c.verdict for c in self.cases] + [self.otherwise]
        return tuple(dict.fromkeys(out))

    def verdict(self, facts: Facts) -> str:
        """The verdict of the first case whose condition holds, else ``otherwise``."""
        for case in self.cases:
            if case.test(facts):
                return case.verdict
        return self.otherwise

    def text(self) -> str:
        """``basis: v1 if c1; v2 if c2; v3 otherwise`` (the rule as the report prints it)."""
        parts = [f"{c.verdict} if {c.when}" for c in self.cases]
        body = "; ".join(parts) + f"; {self.otherwise} otherwise"
        return f"{self.basis}: {body}" if self.basis else body[0].upper() + body[1:]


def at_most(name: str, limit: float, *, limit_text: str, basis: str = "") -> Rule:
    """``supported`` if ``facts[name] <= limit`` (``limit_text`` prints the limit and why),
    ``not supported`` otherwise. The boundary ``facts[name] == limit`` is supported."""
    return Rule(
        basis=basis,
        cases=(Case("supported", f"{name} ≤ {limit_text}", lambda f: f[name] <= limit),),
        otherwise="not supported",
    )


def ci_side(
    name: str,
    null: float,
    *,
    claimed: str,
    null_text: str | None = None,
    basis: str = "",
    margin: float | None = None,
    margin_text: str | None = None,
) -> Rule:
    r"""The CI rule of paired differences: with facts ``<name>_low`` and ``<name>_high`` (the
    95% CI limits of ``name``), ``supported`` if the CI lies entirely on the ``claimed``
    side of ``null`` (``"below"`` or ``"above"``, strictly), ``not supported`` if it lies
    entirely on the other side, ``inconclusive`` if it contains ``null``.

    With an equivalence ``margin`` m > 0 (fixed before the run; ``margin_text`` prints it
    with its unit), a first case gives ``equivalent`` when the CI lies strictly inside
    :math:`(\text{null} - m, \text{null} + m)`: whatever the difference is, it is smaller
    than m, so the claimed effect is absent at that resolution (even when the CI excludes
    ``null``: a significant but negligible difference is not the claimed effect)."""
    if claimed not in ("below", "above"):
        raise ValueError(f"claimed must be 'below' or 'above', got {claimed!r}")
    if margin is not None and not (isinstance(margin, int | float) and margin > 0):
        raise ValueError(f"margin must be a number > 0 (or None), got {margin!r}")
    lo, hi = f"{name}_low", f"{name}_high"
    txt = null_text if null_text is not None else f"{null:g}"

    def is_below(f: Facts) -> bool:
        return f[hi] < null

    def is_above(f: Facts) -> bool:
        return f[lo] > null

    first, second = (is_below, is_above) if claimed == "below" else (is_above, is_below)
    other = "above" if claimed == "below" else "below"
    cases = [
        Case("supported", f"the 95% CI of {name} lies entirely {claimed} {txt}", first),
        Case("not supported", f"it lies entirely {other} {txt}", second),
    ]
    if margin is not None:
        m = float(margin)
        mtxt = margin_text if margin_text is not None else f"{m:g}"

        def inside(f: Facts) -> bool:
            return null - m < f[lo] and f[hi] < null + m

        around = f"{txt} ± {mtxt}" if null else f"±{mtxt}"
        cases.insert(0, Case("equivalent", f"the 95% CI of {name} lies inside {around}", inside))
        cases[1] = Case("supported", f"it lies entirely {claimed} {txt}", first)
    return Rule(basis=basis, cases=tuple(cases), otherwise="inconclusive")


def non_inferior(
    name: str, margin: float, *, margin_text: str, basis: str = "", worse: str = "worse"
) -> Rule:
    r"""The non-inferiority rule of a paired difference d = x(new) − x(reference), where
    larger x is worse: with facts ``<name>_low`` and ``<name>_high`` (the 95% CI of ``name``)
    and a margin m > 0 fixed before the run, ``supported`` (the new method is at most m
    ``worse``) if the CI's upper limit lies strictly below m, ``not supported`` if its lower
    limit lies strictly above m (worse by more than m), ``inconclusive`` otherwise. A CI
    entirely below 0 (the new method better) is supported too: the claim is "no worse than
    m", not "equal"."""
    if not (isinstance(margin, int | float) and margin > 0):
        raise ValueError(f"margin must be a number > 0, got {margin!r}")
    m = float(margin)
    lo, hi = f"{name}_low", f"{name}_high"
    return Rule(
        basis=basis,
        cases=(
            Case(
                "supported",
                f"the 95% CI of {name} lies entirely below +{margin_text} (at most "
                f"{margin_text} {worse})",
                lambda f: f[hi] < m,
            ),
            Case("not supported", f"it lies entirely above +{margin_text}", lambda f: f[lo] > m),
        ),
        otherwise="inconclusive",
    )


def decisive_p(
    verdict: str, estimate: float, se: float, df: float, boundaries: Sequence[tuple[float, str]]
) -> float:
    r"""The p-value behind a CI verdict. Every CI rule here reads "the 95% CI lies strictly
    above (or below) a boundary b" (0, or ±m): with a t interval
    :math:`\hat\theta \pm t_{df}\,\mathrm{se}` that holds exactly when
    :math:`p = \min(1, 2\,(1 - T_{df}((\hat\theta - b)/\mathrm{se})))` ("above"; the mirror
    image for "below") is below 0.05. ``boundaries`` are the (b, side) pairs the verdict's case
    needs; a case that needs several (``equivalent``: above −m and below +m) has the largest
    of their p-values; for ``inconclusive`` give the claimed case's boundary.
    ``se == 0``: 0 when the estimate is strictly on the side, else 1."""
    if not boundaries:
        raise ValueError("boundaries: give at least one (boundary, side) of the verdict's case")
    if not (np.isfinite(se) and se >= 0 and df > 0):
        raise ValueError(f"se must be finite >= 0 and df > 0, got se={se!r}, df={df!r}")
    ps = []
    for b, side in boundaries:
        if side not in ("above", "below"):
            raise ValueError(f"side must be 'above' or 'below', got {side!r}")
        dist = float(estimate) - float(b) if side == "above" else float(b) - float(estimate)
        if se == 0:
            ps.append(0.0 if dist > 0 else 1.0)
        else:
            ps.append(float(min(1.0, 2 * scipy.stats.t.sf(dist / se, df))))
    return max(ps)


#: the claim-id prefixes of the family Holm's correction runs over: the benchmark's own
#: comparisons of planners and horizons (equal compute, long horizons)
HOLM_FAMILY = ("FR-", "HZ-")


def holm_correct(
    claims: Iterable[Claim], family: Sequence[str] = HOLM_FAMILY, alpha: float = 0.05
) -> list[Claim]:
    """Holm's step-down correction over the claims whose id starts with one of ``family``
    and whose key number has a ``p_value`` (:func:`decisive_p`): each gets ``p_holm``, the
    Holm-adjusted p-value over that family (:func:`rsmhp.core.stats.holm`), and a decisive
    verdict (``supported``, ``not supported``, ``equivalent``) whose ``p_holm`` is not below
    ``alpha`` becomes ``inconclusive``, the rule's text saying so. Other claims are returned
    unchanged, in the input order."""
    claims = list(claims)
    idx = [
        i
        for i, c in enumerate(claims)
        if c.id.startswith(tuple(family)) and c.key.p_value is not None
    ]
    if not idx:
        return claims
    adjusted = holm(np.array([claims[i].key.p_value for i in idx], dtype=float))
    out = list(claims)
    for i, p in zip(idx, adjusted, strict=True):
        c = claims[i]
        key = dataclasses.replace(c.key, p_holm=float(p))
        verdict, rule = c.verdict, c.rule
        note = (
            f" Holm over {len(idx)} {'/'.join(f.rstrip('-') for f in family)} claims: p = {p:.3g}"
        )
        if verdict in ("supported", "not supported", "equivalent") and p >= alpha:
            note += f" ≥ {alpha:g}: {verdict} without it, becomes inconclusive"
            verdict = "inconclusive"
        out[i] = dataclasses.replace(c, key=key, verdict=verdict, rule=rule + "." + note)
    return out


def holm_sections(sections: Sequence[Section], alpha: float = 0.05) -> list[Section]:
    """``sections`` with :func:`holm_correct` applied over all their claims at once (the
    report's family spans the equal-compute and long-horizon sections), each section keeping
    its own claims in their order."""
    sections = list(sections)
    flat = [c for s in sections for c in s.claims]
    fixed = iter(holm_correct(flat, alpha=alpha))
    return [dataclasses.replace(s, claims=[next(fixed) for _ in s.claims]) for s in sections]


# ---------------------------------------------- Prop. 3 (LQG-3, EST-3): exceedance counts

#: LQG-3/EST-3 are a test only if some cell would detect a spread of the estimator's error
#: this far (relative) from the exact one with 80% power
POWER_LIMIT = 0.5


def exceedance_rule(basis: str) -> Rule:
    """The rule of Prop. 3's evidence (LQG-3, EST-3): exceedance counts against the exact tail
    probability (power) and against Chebyshev's bound (the statement); ``supported`` needs a
    test with power (some cell detects a spread error of :data:`POWER_LIMIT` with 80%
    power)."""
    return Rule(
        basis=basis,
        cases=(
            Case(
                "not supported",
                "some cell's exceedance frequency lies significantly above Chebyshev's bound "
                "(familywise 95% Clopper-Pearson lower limit above it)",
                lambda f: f["above bound"] >= 1,
            ),
            Case(
                "supported",
                "no cell's count departs from the exact probability (two-sided exact binomial "
                "tests, familywise 95%), the exact probability is below the bound in every "
                f"cell, and some cell would detect a spread error of {100 * POWER_LIMIT:g}% "
                "with 80% power",
                lambda f: (
                    f["cells"] >= 1
                    and f["departing"] == 0
                    and f["exact above bound"] == 0
                    and f["detectable"] <= POWER_LIMIT
                ),
            ),
        ),
        otherwise="inconclusive",
    )


def exceedance_facts(test: ExceedanceTest, detectable: float = np.inf) -> Facts:
    """The facts of :func:`exceedance_rule` from :func:`rsmhp.core.stats.exceedance_test` and the
    smallest detectable relative spread error over the cells
    (:func:`rsmhp.core.stats.detectable_scale`; ``inf``: no power)."""
    return {
        "cells": test.cells,
        "departing": test.departing,
        "above bound": test.above_bound,
        "exact above bound": test.exact_above_bound,
        "detectable": float(detectable),
    }
