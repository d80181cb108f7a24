r"""Runs needed at 80% power: how many independent units (runs, belief states) a claim's
rule would need to reach a decisive verdict, if the true difference were the one measured.

A CI rule (:func:`rsmhp.report.verdicts.ci_side`, :func:`~rsmhp.report.verdicts.non_inferior`)
gives a decisive verdict when the 95% CI of the key number lies strictly beyond a boundary
b: the null (0 for a difference; the margin for non-inferiority, where ``null`` is the
margin) for ``supported``/``not supported``, or both ±Δ around the null for ``equivalent``.
With n units, standard error se (taken from the CI: se = (high − low) / (2 z_{0.975}), the
normal approximation of a t or bootstrap interval) and a true value θ at distance
δ > 0 from the boundary the rule needs, the CI clears that boundary with probability
1 − β when

.. math:: n_{80} = n \left(\frac{(z_{0.975} + z_{0.80})\,\mathrm{se}}{\delta}\right)^2,

since se shrinks like 1/√n. The boundary is the one the estimate points to: with a margin Δ
and |θ̂ − null| < Δ, equivalence (δ = Δ − |θ̂ − null|, the nearer of ±Δ, which understates
the runs slightly when θ̂ is near the null, where both sides must clear); otherwise the null
(δ = |θ̂ − null|). θ = θ̂ is the plug-in assumption (the "observed power" caveat: it says
how many runs this effect size would need, not that the effect is real). δ = 0 gives
``None`` (no number of runs decides it).
"""

from __future__ import annotations

import math

from scipy import stats as _st

from rsmhp.report.ledger import KeyNumber

__all__ = ["POWER", "runs_needed", "runs_text"]

#: the power the runs are computed for
POWER = 0.80
_Z_CI = float(_st.norm.ppf(0.975))


def runs_needed(key: KeyNumber, power: float = POWER) -> int | None:
    """The runs (units) at which the key number's rule reaches its decisive verdict with
    probability ``power`` if the truth is the estimate (module docstring); ``None`` without
    ``n``, CI or ``null``, or when the estimate sits on the boundary."""
    if not 0.5 <= power < 1:
        raise ValueError(f"power must be in [0.5, 1), got {power!r}")
    if key.n is None or not key.has_ci or key.null is None:
        return None
    se = (key.ci_high - key.ci_low) / (2 * _Z_CI)
    if se == 0:
        return key.n
    off = abs(key.value - key.null)
    delta = key.margin - off if key.margin is not None and off < key.margin else off
    if delta <= 0:
        return None
    z = _Z_CI + float(_st.norm.ppf(power))
    return max(2, math.ceil(key.n * (z * se / delta) ** 2))


def runs_text(key: KeyNumber, power: float = POWER) -> str:
    """``"80 (320 at 80% power)"``: the units this run had and the units needed, or ``–``."""
    need = runs_needed(key, power)
    if key.n is None:
        return "–"
    if need is None:
        return f"{key.n} (no number of runs decides it)"
    return f"{key.n} ({need} at {power:.0%} power)"
