"""The long-horizon study's config checks (the ``horizon`` section: ``horizon.uav``,
``horizon.lqg`` and the optimiser split ``horizon.optimiser``).

Asked by :func:`rsmhp.pipeline.config.check_config`, as every study's ``checks`` module; no
rule imports it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from rsmhp.models.uav import methods as uav_methods
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.models.uav.methods.pruned_tree import PrunedTree
from rsmhp.pipeline.config import (
    baseline_problems,
    late_steps,
    member_names,
    model_names,
    run_steps,
)
from rsmhp.studies.horizon.simulate_optimiser import budgets, split_methods

__all__ = ["config_problems", "lqg_problems", "optimiser_problems", "uav_problems"]


def config_problems(config: Mapping[str, Any]) -> list[str]:
    """The problems of ``horizon.lqg`` (:func:`lqg_problems`), ``horizon.uav``
    (:func:`uav_problems`) and ``horizon.optimiser``
    (:func:`optimiser_problems`)."""
    hz = config.get("horizon", {}) or {}
    return lqg_problems(hz.get("lqg", {}) or {}) + optimiser_problems(config) + uav_problems(config)


def uav_problems(config: Mapping[str, Any]) -> list[str]:
    """``horizon.uav``: models of ``uav_models``, belief-state steps inside a run, NBO among
    the methods, and claim members that the study runs (HZ-2: a pruned tree and a
    Monte-Carlo member)."""
    hz = (config.get("horizon", {}) or {}).get("uav", {}) or {}
    path = "horizon.uav"
    names = model_names(config)
    problems: list[str] = []
    models = [m for m in hz.get("models", []) or [] if isinstance(m, str)]
    unknown = [m for m in models if names and m not in names]
    if unknown:
        problems.append(
            f"{path}.models: {unknown} not model(s) of uav_models "
            f"(allowed: {', '.join(map(str, names))})"
        )
    problems += late_steps(f"{path}.steps", hz.get("steps", []), run_steps(config))
    methods = hz.get("methods")
    if isinstance(methods, Mapping) and methods:
        problems += baseline_problems(f"{path}.methods", methods, "the baseline of the regret")
        problems += uav_methods.config_problems(
            methods, f"{path}.methods", config.get("uav", {}) or {}
        )
    run = member_names(methods)
    claims = hz.get("claims", {}) or {}
    closed = claims.get("closed_model") or ""
    if closed and closed not in models:
        problems.append(
            f"{path}.claims.closed_model: {closed!r} is not a model of {path}.models "
            f"(allowed: {', '.join(models) or 'none configured'}, or '')"
        )
    rec = hz.get("recording", {}) or {}
    if rec.get("model"):
        if rec["model"] not in models:
            problems.append(
                f"{path}.recording.model: {rec['model']!r} is not a model of {path}.models "
                f"(allowed: {', '.join(models) or 'none configured'}, or '')"
            )
        hs = [h for h in hz.get("H", []) or [] if isinstance(h, int)]
        if "H" in rec and rec["H"] not in hs:
            problems.append(
                f"{path}.recording.H: {rec['H']} is not a horizon of {path}.H (allowed: "
                f"{', '.join(map(str, hs))})"
            )
        if not (claims.get("monte_carlo") or ""):
            problems.append(
                f"{path}.recording.model: {rec['model']!r} needs {path}.claims.monte_carlo "
                "(the run is chosen from its paired differences with NBO), got ''"
            )
    for key, family in (("tree", PrunedTree), ("monte_carlo", MonteCarlo)):
        name = claims.get(key) or ""
        ok = [n for n, m in run.items() if isinstance(m, family)]
        if name and run and name not in ok:
            problems.append(
                f"{path}.claims.{key}: {name!r} is not a {family.__name__} member of "
                f"{path}.methods (allowed: {', '.join(ok) or 'none configured'}, or '')"
            )
    return problems


def lqg_problems(hz: Mapping[str, Any]) -> list[str]:
    """``horizon.lqg``: Sobol' sizes are powers of 2, and HZ-4's pruned tree is a cell of
    the estimator grid that is pruned at some configured horizon."""
    path = "horizon.lqg"
    est = hz.get("estimators", {}) or {}
    ns = [n for n in est.get("n", []) or [] if isinstance(n, int)]
    problems = [
        f"{path}.estimators.n: {n} is not a power of 2 (allowed: 2, 4, 8, ... for Sobol')"
        for n in ns
        if n & (n - 1)
    ]
    tree = (hz.get("claims", {}) or {}).get("pruned", {}) or {}
    if not tree:
        return problems
    N, M = tree.get("N"), tree.get("M")
    n_list = [N_ for N_ in est.get("pruned_N", []) or [] if isinstance(N_, int)]
    if N not in n_list:
        problems.append(
            f"{path}.claims.pruned.N: {N!r} is not in {path}.estimators.pruned_N (allowed: "
            f"{', '.join(map(str, n_list)) or 'none configured'})"
        )
    if M not in ns:
        problems.append(
            f"{path}.claims.pruned.M: {M!r} is not in {path}.estimators.n (allowed: "
            f"{', '.join(map(str, ns)) or 'none configured'})"
        )
    hs = sorted(h for h in hz.get("sim_H", []) or [] if isinstance(h, int))
    if isinstance(N, int) and isinstance(M, int) and hs:
        pruned = [h for h in hs if N**h > M]
        if len(pruned) < 2:
            problems.append(
                f"{path}.claims.pruned: N = {N}, M = {M} is pruned (N^H > M) at "
                f"{len(pruned)} of {path}.sim_H = {hs} (allowed: at least 2 such horizons, "
                "HZ-4 compares the first with the last)"
            )
    return problems


def optimiser_problems(config: Mapping[str, Any]) -> list[str]:
    """Cross-field problems of ``horizon.optimiser`` in a whole (schema-valid) config, each
    naming its field and what is allowed: models of ``uav_models``, belief-state
    steps before the run's last step, the methods' own checks and at least one method with
    an own cost (a tree search alone has nothing to optimise), budgets that differ in
    (maxiter, restarts). Empty when the section is absent."""
    hz = config.get("horizon", {}) or {}
    cfg = hz.get("optimiser")
    if not isinstance(cfg, Mapping):
        return []
    path = "horizon.optimiser"
    uav = config.get("uav", {}) or {}
    problems: list[str] = []
    names = model_names(config)
    models = cfg.get("models")
    if models is None:  # default: the horizon study's models
        models = (hz.get("uav", {}) or {}).get("models", []) or []
    unknown = [m for m in models if names and m not in names]
    if unknown:
        problems.append(
            f"{path}.models: {unknown} not model(s) of uav_models "
            f"(allowed: {', '.join(map(str, names))})"
        )
    problems += late_steps(f"{path}.steps", cfg.get("steps", []), run_steps(config))
    meth = cfg.get("methods")
    if isinstance(meth, Mapping):
        own = uav_methods.config_problems(meth, f"{path}.methods", uav)
        problems += own
        if not own:
            try:
                found = split_methods(cfg)
            except (ValueError, TypeError) as exc:
                problems.append(f"{path}.methods: {exc}")
            else:
                if not found:
                    problems.append(
                        f"{path}.methods: no method with an own cost (allowed: at least one "
                        "of NBO, the sigma points or a sampled-cost member; a tree search "
                        "has no cost of a given plan to optimise)"
                    )
    if isinstance(cfg.get("budgets"), Sequence) and cfg["budgets"]:
        try:
            budgets(cfg)
        except (ValueError, TypeError) as exc:  # the messages start with "budgets"
            problems.append(f"{path}.{exc} (allowed: budgets that differ in maxiter or restarts)")
    return problems
