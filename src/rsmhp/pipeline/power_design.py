r"""Prospective power of a preregistered design, under each claim's own verdict rule.

A preregistration (version 3) states, per claim and model, the rule that decides it, the
per-unit sd of the paired difference (and where that sd comes from), the effect the design
is meant to detect, the units (runs or belief states) and the power. :func:`entry_power`
recomputes the power from the others (:func:`rsmhp.core.stats.rule_power`, exact for normal
units), :func:`power_problems` compares every stated power with it, so a preregistration
cannot state a power its own inputs do not give. The rules:

==================  =================================================================
``equivalence``     P(95% t interval inside ±margin) at the effect (TOST, 2.5% a side)
``non-inferiority`` P(interval below +margin)
``superiority``     P(interval below 0 and not inside ±margin) ("supported" of the FR rules)
``above-zero``      P(interval above 0) (the HZ claims' "supported": no margin)
==================  =================================================================

:func:`sd_from_ci` turns a published 95% interval over n units back into the per-unit sd
(:math:`\mathrm{sd} = h \sqrt n / t_{n-1,0.975}`, h the half-width): exact for a t interval,
an approximation for a percentile-bootstrap one (the published UAV and DEC claims).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import scipy.stats

from rsmhp.core.stats import ci_within, rule_power

__all__ = ["POWER_TOLERANCE", "entry_power", "power_problems", "sd_from_ci"]

#: how far a stated power may be from the recomputed one (it is stated to two decimals)
POWER_TOLERANCE = 0.006


def sd_from_ci(low: float, high: float, n: int, level: float = 0.95) -> float:
    """Per-unit sd behind a ``level`` t interval ``[low, high]`` of a mean over ``n`` units."""
    if not (n >= 2 and high >= low):
        raise ValueError(f"sd_from_ci: need n >= 2 and high >= low, got n={n}, [{low}, {high}]")
    return (high - low) / 2 * math.sqrt(n) / float(scipy.stats.t.ppf(0.5 + level / 2, n - 1))


def entry_power(e: Mapping[str, Any]) -> float:
    """The power of one design entry: ``rule``, ``sd``, ``units``, ``effect`` and (but for
    ``above-zero``) ``margin``; the units' key is ``units``."""
    rule, n, sd, effect = str(e["rule"]), int(e["units"]), float(e["sd"]), float(e["effect"])
    if rule == "above-zero":
        return ci_within(n, sd, effect, 0.0, math.inf)
    return rule_power(rule, n, sd, float(e["margin"]), effect)


def power_problems(power: Mapping[str, Mapping[str, Mapping[str, Any]]]) -> list[str]:
    """Every entry of a preregistration's ``power`` block (claim -> setup -> entry) whose
    stated ``power`` differs from :func:`entry_power` by more than
    :data:`POWER_TOLERANCE`, or that lacks a key, as messages naming claim and setup."""
    out = []
    for cid, setups in power.items():
        for setup, e in setups.items():
            need = {"rule", "sd", "units", "effect", "power"}
            if e.get("rule") != "above-zero":
                need.add("margin")
            missing = sorted(need - set(e))
            if missing:
                out.append(f"power.{cid}.{setup}: missing {', '.join(missing)}")
                continue
            got = entry_power(e)
            if abs(got - float(e["power"])) > POWER_TOLERANCE:
                out.append(
                    f"power.{cid}.{setup}: power {e['power']} is stated, but its rule "
                    f"{e['rule']!r} with sd {e['sd']}, {e['units']} units and effect "
                    f"{e['effect']} gives {got:.3f}"
                )
    return out
