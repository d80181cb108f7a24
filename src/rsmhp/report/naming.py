r"""A tree search named by what it did: its measured plan depth beside its name.

A tree search's plan (:class:`rsmhp.models.uav.methods.tree_search.TreeSearchPlanner`) follows
the most visited path of its tree for ``plan_depth`` of its H steps and the rollout policy
after that. At a mean plan depth :math:`\bar D` (over the planning steps of the runs behind a
number) below :data:`ROLLOUT_DEPTH` = 2 the plan is, at most steps, one searched action
followed by the rollout policy: a one-step rollout (one-step lookahead over sampled actions,
the rest of the horizon played by the policy), not a search of the horizon. Such a member is
named that way wherever the report names it (claims, tables, the summary figure's cells);
a deeper one keeps its name with the depth beside it. The threshold is fixed here, before the
tuning of issue 43 measured any depth of the tuned members (the published first and second
confirmatory runs had measured 1.20 on 'paper' and 4.20 on 'footprint150').
"""

from __future__ import annotations

import math
import re

from rsmhp.report.markdown import fmt

__all__ = ["ROLLOUT_DEPTH", "ROLLOUT_POLICIES", "depth_name", "depth_of"]

#: mean plan depth below which a tree search is named a one-step rollout
ROLLOUT_DEPTH = 2.0
#: the rollout policies' names in prose (:data:`rsmhp.models.uav.dpw.ROLLOUTS`)
ROLLOUT_POLICIES = {"pursuit": "the pursuit policy", "warm": "the warm start"}


def depth_name(label: str, plan_depth: float | None, rollout: str = "pursuit",
               short: bool = False) -> str:  # fmt: skip
    """``label`` with the measured mean plan depth :math:`\bar D` beside it:
    ``"tree search 30 sims (plan depth 1.20: a one-step rollout over the pursuit policy)"``
    for :math:`\bar D <` :data:`ROLLOUT_DEPTH`, ``"tree search 100 sims (plan depth 4.20)"``
    otherwise; ``short`` (a figure's cell) gives ``"..., depth 1.20: one-step rollout"``.
    ``plan_depth`` ``None`` or NaN (no depth measured: a method that is no tree search) leaves
    ``label`` as it is. ``rollout`` is one of :data:`ROLLOUT_POLICIES`; a negative depth is
    refused."""
    if plan_depth is None or not math.isfinite(float(plan_depth)):
        return label
    d = float(plan_depth)
    if d < 0:
        raise ValueError(
            f"plan_depth: {d!r} (allowed: >= 0, the mean steps of a plan from the tree)"
        )
    if rollout not in ROLLOUT_POLICIES:
        raise ValueError(f"rollout: {rollout!r} (allowed: {', '.join(ROLLOUT_POLICIES)})")
    depth = fmt(d, 3)
    d = float(depth)  # decide on the depth as printed: 1.999 reads 2.00, not a rollout
    if short:
        return f"{label}, depth {depth}" + (": one-step rollout" if d < ROLLOUT_DEPTH else "")
    if d < ROLLOUT_DEPTH:
        return f"{label} (plan depth {depth}: a one-step rollout over {ROLLOUT_POLICIES[rollout]})"
    return f"{label} (plan depth {depth})"


_DEPTH = re.compile(r"\((plan depth [^()]*)\)")


def depth_of(text: str) -> str:
    """The first ``plan depth …`` phrase :func:`depth_name` put into ``text`` (a claim's
    words), without its parentheses; empty if there is none. The main text's table puts it
    beside a tree-search claim's setup."""
    m = _DEPTH.search(text)
    return m.group(1) if m else ""
