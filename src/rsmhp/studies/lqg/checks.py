"""The LQG study's config checks and memory estimates (the ``lqg`` section).

:func:`rsmhp.pipeline.config.check_config` asks every study package's ``checks`` module for
:func:`config_problems` once the schema is satisfied, and :mod:`rsmhp.pipeline.resources` asks
it for :func:`working_sets`, as the method registry asks every family for its problems. No
rule imports this module, so its code digest is no rule's.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from rsmhp.pipeline.resources import working_set_bytes

__all__ = ["config_problems", "working_sets"]


def config_problems(config: Mapping[str, Any]) -> list[str]:
    """``P.start <= P.stop`` with at least 3 values of P (the error slope in P), a recorded
    tree that keeps ``M <= N`` trajectories, a finite model."""
    problems = []
    lqg = config.get("lqg", {}) or {}
    grid = (lqg.get("convergence", {}) or {}).get("P", {}) or {}
    if {"start", "stop"} <= grid.keys() and grid["start"] > grid["stop"]:
        problems.append(
            f"lqg.convergence.P.start: {grid['start']} is greater than lqg.convergence.P.stop "
            f"= {grid['stop']} (allowed: start <= stop)"
        )
    rec = lqg.get("recording", {}) or {}
    if {"N", "M"} <= rec.keys() and rec["M"] > rec["N"]:
        problems.append(
            f"lqg.recording.M: {rec['M']} is greater than lqg.recording.N = "
            f"{rec['N']} (allowed: 1 <= M <= N; the paper prunes to M <= N trajectories)"
        )
    for key in ("x0", "r", "target", "sigma", "a"):
        val = (lqg.get("model", {}) or {}).get(key)
        if isinstance(val, float) and not math.isfinite(val):
            problems.append(f"lqg.model.{key}: {val} is not finite")
    if {"start", "stop", "step"} <= grid.keys() and grid["step"] > 0:
        n_p = len(range(int(grid["start"]), int(grid["stop"]) + 1, int(grid["step"])))
        if n_p < 3:
            problems.append(
                f"lqg.convergence.P: {{start: {grid['start']}, stop: {grid['stop']}, step: "
                f"{grid['step']}}} gives {n_p} value(s) (allowed: at least 3, for the error "
                "slope in P)"
            )
    return problems


def working_sets(config: Mapping[str, Any]) -> dict[str, tuple[int, str]]:
    """Largest working set (bytes, :func:`rsmhp.pipeline.resources.working_set_bytes`) of
    ``lqg_convergence`` (the largest P of the grid, H = len(u)) and ``lqg_nbo_error`` (P
    trajectories at the largest H), with the config keys that drive each."""
    from rsmhp.studies.lqg import simulate as lqg

    conv = config["lqg"]["convergence"]
    ne = config["lqg"]["nbo_error"]
    return {
        "lqg_convergence": (
            working_set_bytes(max(lqg.p_grid(conv["P"])), len(conv["u"])),
            "lqg.convergence.P.stop, lqg.convergence.u (its length H), threads",
        ),
        "lqg_nbo_error": (
            working_set_bytes(ne["P"], max(ne["H_values"])),
            "lqg.nbo_error.P, lqg.nbo_error.H_values, threads",
        ),
    }
