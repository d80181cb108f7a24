r"""Runs needed at 80% power: how many independent units (runs, belief states) a claim's
rule would need to reach a decisive verdict, if the true difference were the one measured.

A CI rule (:func:`rsmhp.report.verdicts.ci_side`, :func:`~rsmhp.report.verdicts.non_inferior`)
gives a decisive verdict when the 95% CI of the key number lies strictly beyond a boundary
b: the null (0 for a difference; the margin for non-inferiority, where ``null`` is the
margin) for ``supported``/``not supported``, or both ±Δ around the null for ``equivalent``.
With n units, the spread of one unit σ = se·√n (se taken from the CI: se = (high − low) /
(2 t_{0.975, n−1}), exact for a t interval, an approximation for a bootstrap one) and a true
value θ at distance δ > 0 from a boundary, the CI clears that boundary with probability about
1 − β at the smallest n₈₀ with

.. math:: (t_{0.975,\,n_{80}-1} + t_{0.80,\,n_{80}-1})\,\sigma/\sqrt{n_{80}} \le \delta

(the usual central-t approximation of a t-test's power). The boundaries are the null
(δ = |θ̂ − null|, a directional verdict) and, with a margin Δ and |θ̂ − null| < Δ, the nearer
of ±Δ (δ = Δ − |θ̂ − null|, equivalence, which understates the runs slightly when θ̂ is near
the null, where both sides must clear); the runs are those of the nearer to deciding.
Holm's correction is not in it: for a claim of the Holm family (FR and HZ) the runs are at
the unadjusted 5% level and say so ("before Holm"). Claims whose rule needs every cell of a
group carry no n (no single number of runs decides them). θ = θ̂ is the plug-in assumption
(the "observed power" caveat: it says how many runs this effect size would need, not that the
effect is real). δ = 0 gives
``None`` (no number of runs decides it).
"""

from __future__ import annotations

import math

import scipy  # scipy.stats loads on first use (scipy's lazy submodules)

from rsmhp.report.ledger import KeyNumber

__all__ = ["POWER", "runs_needed", "runs_text"]

#: the power the runs are computed for
POWER = 0.80


def _t(q: float, df: float) -> float:
    return float(scipy.stats.t.ppf(q, df))


def _runs_for(sigma: float, delta: float, power: float) -> int:
    """The smallest n >= 2 with (t_{0.975,n-1} + t_{power,n-1}) σ/√n <= δ (the t-test's
    power approximation, central t): bisection over n (the left side falls with n)."""

    def ok(n: int) -> bool:
        return (_t(0.975, n - 1) + _t(power, n - 1)) * sigma / math.sqrt(n) <= delta

    lo, hi = 2, 2
    while not ok(hi):
        lo, hi = hi, hi * 2
        if hi > 10**9:
            return hi
    while lo < hi:
        mid = (lo + hi) // 2
        if ok(mid):
            hi = mid
        else:
            lo = mid + 1
    return hi


def runs_needed(key: KeyNumber, power: float = POWER) -> int | None:
    """The runs (units) at which the key number's rule reaches a decisive verdict with
    probability ``power`` if the truth is the estimate (module docstring), the nearer of the
    boundaries it could clear; ``None`` without ``n``, CI or ``null``, or when the estimate
    sits on every boundary. Holm's correction is not in it (see :func:`runs_text`)."""
    if not 0.5 <= power < 1:
        raise ValueError(f"power must be in [0.5, 1), got {power!r}")
    if key.n is None or not key.has_ci or key.null is None:
        return None
    se = (key.ci_high - key.ci_low) / (2 * _t(0.975, key.n - 1))
    if se == 0:
        return key.n
    sigma = se * math.sqrt(key.n)
    off = abs(key.value - key.null)
    deltas = [off]
    if key.margin is not None and off < key.margin:
        deltas.append(key.margin - off)
    deltas = [d for d in deltas if d > 0]
    if not deltas:
        return None
    return min(_runs_for(sigma, d, power) for d in deltas)


def runs_text(key: KeyNumber, power: float = POWER) -> str:
    """``"80 (post hoc: 320 at 80% power)"``: the units this run had and the units needed
    if the true difference were the estimate (``before Holm`` for a claim of Holm's family),
    or ``–``. Post hoc: computed from the data it describes, not the design's power."""
    need = runs_needed(key, power)
    if key.n is None:
        return "–"
    if need is None:
        return f"{key.n} (no number of runs decides it)"
    holm = ", before Holm" if key.p_holm is not None else ""
    return f"{key.n} (post hoc: {need} at {power:.0%} power{holm})"
