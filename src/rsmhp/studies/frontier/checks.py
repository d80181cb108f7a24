"""The equal-compute study's config checks (the ``frontier`` section).

Asked by :func:`rsmhp.pipeline.config.check_config`, as every study's ``checks`` module; no
rule imports it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from rsmhp.models.uav import methods as uav_methods
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.pipeline.config import (
    baseline_problems,
    late_steps,
    member_names,
    model_names,
    run_steps,
)

__all__ = ["config_problems"]

#: why NBO must be among the frontier's methods (as in the decision study it extends)
_BASELINE = "the baseline every comparison of the decision study is made against"


def config_problems(config: Mapping[str, Any]) -> list[str]:
    """Belief-state and timing steps inside a run, at least 2 regret runs for the exploratory
    design, NBO and the families' own checks among the methods, models of ``uav_models``, a
    recorded model that the study runs, and the budget members (:func:`budget_problems`)."""
    fr = config.get("frontier", {}) or {}
    n_steps = run_steps(config)
    problems: list[str] = []
    for path, steps in (
        ("frontier.regret_steps", fr.get("regret_steps", [])),
        ("frontier.timing.steps", (fr.get("timing", {}) or {}).get("steps", [])),
        (
            "frontier.tuning.timing.steps",
            ((fr.get("tuning", {}) or {}).get("timing", {}) or {}).get("steps", [0, 7, 20]),
        ),
        (
            "frontier.confirm.timing.steps",
            ((fr.get("confirm", {}) or {}).get("timing", {}) or {}).get("steps", [0, 7, 20]),
        ),
    ):
        problems += late_steps(path, steps, n_steps)
    rr = fr.get("regret_runs", 10)
    if fr.get("exploratory") and isinstance(rr, int) and rr < 2:
        problems.append(
            f"frontier.regret_runs: {rr} (allowed: at least 2 with "
            "frontier.exploratory: true: its open-loop CIs are over runs)"
        )
    methods = fr.get("methods")
    if isinstance(methods, Mapping) and methods:
        problems += baseline_problems("frontier.methods", methods, _BASELINE)
        if uav_methods.count(methods) < 1:
            problems.append("frontier.methods: no method (allowed: at least 1)")
        problems += uav_methods.config_problems(
            methods, "frontier.methods", config.get("uav", {}) or {}
        )
    names = model_names(config)
    unknown = [m for m in fr.get("models", []) or [] if names and m not in names]
    if unknown:
        problems.append(
            f"frontier.models: {unknown} not model(s) of uav_models "
            f"(allowed: {', '.join(map(str, names))})"
        )
    fr_models = [m for m in fr.get("models", []) or [] if isinstance(m, str)]
    rec = (fr.get("recording", {}) or {}).get("model")
    if rec is not None and fr_models and rec not in fr_models:
        problems.append(
            f"frontier.recording.model: {rec!r} is not a model of frontier.models "
            f"(allowed: {', '.join(fr_models)}; the recording replays one of its runs)"
        )
    if fr_models:
        problems += budget_problems(config.get("decisions", {}) or {}, fr)
    return problems


def budget_problems(dec: Mapping[str, Any], fr: Mapping[str, Any]) -> list[str]:
    """``frontier.budget.members``: methods of the frontier, one per non-baseline family
    and one for each such family of the frontier, all run by the sensitivity map (so that
    the map shows each family at the budget); ``frontier.claims.sigma_reference``: a
    Monte-Carlo member of the frontier."""
    problems: list[str] = []
    path = "frontier.budget.members"
    members = list(((fr.get("budget", {}) or {}).get("members", [])) or [])
    run = member_names(fr.get("methods"))
    if not run:
        return problems
    unknown = [m for m in members if m not in run]
    if unknown:
        problems.append(
            f"{path}: {unknown} not method(s) of frontier.methods "
            f"(allowed: {', '.join(n for n, m in run.items() if not m.baseline)})"
        )
    fams: dict[str, list[str]] = {}
    for name in members:
        if name in run:
            fams.setdefault(run[name].family, []).append(name)
    base = [n for n in members if n in run and run[n].baseline]
    if base:
        problems.append(f"{path}: {base} is the baseline (allowed: one member per other family)")
    twice = {f: n for f, n in fams.items() if len(n) > 1}
    if twice:
        problems.append(f"{path}: several members of one family {twice} (allowed: one each)")
    missing = sorted({m.family for m in run.values() if not m.baseline} - set(fams))
    if missing:
        problems.append(
            f"{path}: no member of the frontier's famil(ies) {missing} (allowed: one member "
            "of every family frontier.methods runs)"
        )
    map_run = member_names((dec.get("map", {}) or {}).get("methods"))
    absent = [m for m in members if m in run and map_run and m not in map_run]
    if absent:
        problems.append(
            f"decisions.map.methods: lacks the budget member(s) {absent} of {path} (allowed: "
            "a map that runs every budget member, so that it shows each family at the budget)"
        )
    ref = (fr.get("claims", {}) or {}).get("sigma_reference")
    mc = [n for n, m in run.items() if isinstance(m, MonteCarlo)]
    if ref is not None and mc and ref not in mc:
        problems.append(
            f"frontier.claims.sigma_reference: {ref!r} is not a Monte-Carlo member "
            f"of frontier.methods (allowed: {', '.join(mc)})"
        )
    return problems
