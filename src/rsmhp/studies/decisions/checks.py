"""The decision study's config checks and memory estimate (the ``decisions`` section).

Asked by :func:`rsmhp.pipeline.config.check_config` (:func:`config_problems`) and
:mod:`rsmhp.pipeline.resources` (:func:`working_sets`), as every study's ``checks`` module; no
rule imports it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from rsmhp.models.uav import methods as uav_methods
from rsmhp.pipeline.config import baseline_problems, late_steps, run_steps
from rsmhp.pipeline.resources import working_set_bytes

__all__ = ["config_problems", "working_sets"]

#: why NBO must be in every methods block of the study
_BASELINE = "the baseline every comparison of the decision study is made against"


def config_problems(config: Mapping[str, Any]) -> list[str]:
    """Belief-state steps inside a run, NBO and the families' own checks in both methods
    blocks, at least two methods on the map, a DEC-8 method that the map runs, map axes
    with values their key allows."""
    dec = config.get("decisions", {}) or {}
    n_steps = run_steps(config)
    problems = late_steps(
        "decisions.uav.steps", (dec.get("uav", {}) or {}).get("steps", []), n_steps
    )
    mp = dec.get("map", {}) or {}
    problems += late_steps("decisions.map.regret_steps", mp.get("regret_steps", []), n_steps)
    for path, block in (("decisions.uav", dec.get("uav")), ("decisions.map", mp)):
        methods = (block or {}).get("methods")
        if isinstance(methods, Mapping) and methods:
            problems += baseline_problems(f"{path}.methods", methods, _BASELINE)
            if path == "decisions.map" and uav_methods.count(methods) < 2:
                problems.append(
                    "decisions.map.methods: fewer than 2 methods (allowed: NBO and at least "
                    "one RS-MHP N_T or tree, to compare)"
                )
            if uav_methods.count(methods) < 1:
                problems.append(f"{path}.methods: no method (allowed: at least 1)")
            problems += uav_methods.config_problems(
                methods, f"{path}.methods", config.get("uav", {}) or {}
            )
    claim_method = (dec.get("claims", {}) or {}).get("map_method") or ""
    map_methods = mp.get("methods")
    if claim_method and isinstance(map_methods, Mapping):
        try:
            run = [n for n, m in uav_methods.from_config(map_methods).items() if not m.baseline]
        except (ValueError, TypeError):
            run = []  # reported above by the families' own checks
        if run and claim_method not in run:
            problems.append(
                f"decisions.claims.map_method: {claim_method!r} is not a method of "
                f"decisions.map.methods (allowed: {', '.join(run)}, or '' for the first "
                "RS-MHP member)"
            )
    keys = []
    for axis in ("rows", "cols"):
        ax = mp.get(axis) or {}
        key = ax.get("key")
        keys.append(key)
        for v in ax.get("values", []) or []:
            if v is None and key != "sensor.footprint_radius":
                problems.append(
                    f"decisions.map.{axis}.values: null is only allowed for "
                    f"sensor.footprint_radius (unlimited), not for {key}"
                )
            elif v is not None and not (isinstance(v, int | float) and 0 < v <= 100000):
                problems.append(
                    f"decisions.map.{axis}.values: {v!r} is invalid for {key} "
                    "(allowed: number in (0, 100000])"
                )
    if keys[0] is not None and keys[0] == keys[1]:
        problems.append(
            f"decisions.map.cols.key: {keys[1]} is also the rows' key (allowed: two different keys)"
        )
    return problems


def working_sets(config: Mapping[str, Any]) -> dict[str, tuple[int, str]]:
    """Largest working set (bytes) of ``decisions_lqg``: the largest (P, H) cell of its grid."""
    from rsmhp.models.lqg import regret as decisions_lqg

    dec = (config.get("decisions", {}) or {}).get("lqg")
    if not dec:
        return {}
    cells = decisions_lqg.regret_cells(dec)
    return {
        "decisions_lqg": (
            max((working_set_bytes(c.P, c.H) for c in cells), default=0),
            "decisions.lqg.P, decisions.lqg.tree_N / max_leaves, decisions.lqg.H_values, threads",
        )
    }
