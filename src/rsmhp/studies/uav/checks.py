"""The UAV study's config checks (the ``uav`` section: the model every UAV study builds on,
and the UAV study's own runs and methods).

Asked by :func:`rsmhp.pipeline.config.check_config`, as every study's ``checks`` module; no
rule imports it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from rsmhp.models.uav import methods as uav_methods

__all__ = ["config_problems"]


def config_problems(config: Mapping[str, Any]) -> list[str]:
    """UAV bounds (lo <= hi), initial speed inside the speed range, the family checks of
    ``uav.methods`` (e.g. a tree able to keep M) and at least two methods to compare."""
    uav = config.get("uav", {}) or {}
    problems = []
    for section, lo, hi, strict in (
        ("aircraft", "speed_min", "speed_max", True),
        ("scenario", "target_speed_min", "target_speed_max", False),
        ("scenario", "uav_distance_min", "uav_distance_max", False),
    ):
        node = uav.get(section, {}) or {}
        if {lo, hi} <= node.keys() and (node[lo] >= node[hi] if strict else node[lo] > node[hi]):
            rel = "<" if strict else "<="
            problems.append(
                f"uav.{section}.{lo}: {node[lo]} is not {rel} uav.{section}.{hi} = {node[hi]} "
                f"(allowed: {lo} {rel} {hi})"
            )
    ac, sc = uav.get("aircraft", {}) or {}, uav.get("scenario", {}) or {}
    if {"speed_min", "speed_max"} <= ac.keys() and "uav_speed" in sc:
        if not ac["speed_min"] <= sc["uav_speed"] <= ac["speed_max"]:
            problems.append(
                f"uav.scenario.uav_speed: {sc['uav_speed']} is outside the aircraft's speed range "
                f"(allowed: {ac['speed_min']} <= uav_speed <= {ac['speed_max']})"
            )
    problems += uav_methods.config_problems(uav.get("methods"), "uav.methods", uav)
    methods = uav.get("methods")
    if isinstance(methods, Mapping):
        n = uav_methods.count(methods)
        if n < 2:
            problems.append(
                f"uav.methods: {n} method(s) (allowed: at least 2, e.g. nbo and one rsmhp_nt, "
                "so that there is a comparison)"
            )
    return problems
