"""The estimator study's config checks and memory estimate (the ``estimators`` section).

Asked by :func:`rsmhp.pipeline.config.check_config` (:func:`config_problems`) and
:mod:`rsmhp.pipeline.resources` (:func:`working_sets`), as every study's ``checks`` module; no
rule imports it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from rsmhp.pipeline.resources import working_set_bytes

__all__ = ["NCV_KEYS", "config_problems", "working_sets"]

#: the keys an ``ncv_2d`` problem needs (and a ``scalar_lqg`` problem must not have)
NCV_KEYS = ("dt", "q", "w_pos", "w_vel", "r_u", "f_pos", "f_vel", "target", "x0")


def config_problems(config: Mapping[str, Any]) -> list[str]:
    """Problems of unique names and the right keys per kind, Sobol' budgets that are powers
    of 2, a pruning grid with some ``M <= N``, a recorded tree that keeps ``M <= N``, the
    Monte-Carlo reference among the schemes, and a tree that fits ``max_leaves``."""
    est = config.get("estimators", {}) or {}
    problems = _problem_specs(est.get("problems", []) or [])
    for n in est.get("budgets", []) or []:
        if isinstance(n, int) and n & (n - 1):
            problems.append(
                f"estimators.budgets: {n} is not a power of 2 (allowed: 2, 4, 8, ... for Sobol')"
            )
    pr = est.get("pruning", {}) or {}
    if pr.get("N") and pr.get("M") and min(pr["M"]) > max(pr["N"]):
        problems.append(
            f"estimators.pruning.M: every M ({min(pr['M'])} and up) is greater than every N "
            f"(at most {max(pr['N'])}) (allowed: M <= N for at least one pair)"
        )
    rec = est.get("recording", {}) or {}
    if {"N", "M"} <= rec.keys() and rec["M"] > rec["N"]:
        problems.append(
            f"estimators.recording.M: {rec['M']} is greater than estimators.recording.N = "
            f"{rec['N']} (allowed: 1 <= M <= N; the paper prunes to M <= N trajectories)"
        )
    schemes = est.get("schemes") or []
    if schemes and "mc" not in schemes:
        problems.append(
            f"estimators.schemes: {schemes} has no mc (allowed: any list containing mc, the "
            "reference every estimator is compared with)"
        )
    tree_n, max_leaves = est.get("tree_N") or [], est.get("max_leaves")
    horizons = [
        len(spec["u"]) for spec in est.get("problems") or [] if isinstance(spec.get("u"), list)
    ]
    if {"tree", "tree_pernode"} & set(schemes) and tree_n and max_leaves and horizons:
        if not any(n**h <= max_leaves for n in tree_n for h in horizons):
            problems.append(
                f"estimators.tree_N: no N in {tree_n} gives a tree with N^H <= "
                f"estimators.max_leaves = {max_leaves} for any problem (H in "
                f"{sorted(set(horizons))}) (allowed: at least one such N, or drop tree and "
                "tree_pernode from estimators.schemes)"
            )
    return problems


def _problem_specs(problems: list[Mapping[str, Any]]) -> list[str]:
    """Unique names and per-kind requirements of ``estimators.problems`` entries."""
    out = []
    names = [spec.get("name") for spec in problems]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        out.append(f"estimators.problems: duplicate name(s) {dupes} (allowed: unique names)")
    for i, spec in enumerate(problems):
        path = f"estimators.problems[{i}] ({spec.get('name')})"
        u = spec.get("u", [])
        if spec.get("kind") == "scalar_lqg":
            if any(isinstance(v, list) for v in u):
                out.append(f"{path}.u: {u} must be a list of numbers for kind scalar_lqg")
            for key in ("x0", "target"):
                if isinstance(spec.get(key), list):
                    out.append(f"{path}.{key}: must be a number for kind scalar_lqg")
            extra = sorted(set(spec) & (set(NCV_KEYS) - {"x0", "target"}))
            if extra:
                out.append(f"{path}: {extra} only apply to kind ncv_2d")
        elif spec.get("kind") == "ncv_2d":
            missing = [k for k in NCV_KEYS if k not in spec]
            if missing:
                out.append(f"{path}: kind ncv_2d needs {missing}")
            for key in ("target", "x0"):
                val = spec.get(key)
                if key in spec and (not isinstance(val, list) or len(val) != 4):
                    out.append(
                        f"{path}.{key}: {val!r} must be a list of 4 numbers (px, py, vx, vy)"
                    )
            if not all(isinstance(v, list) for v in u):
                out.append(f"{path}.u: {u} must be a list of [ax, ay] pairs for kind ncv_2d")
            extra = sorted(set(spec) & {"a", "sigma", "r"})
            if extra:
                out.append(f"{path}: {extra} only apply to kind scalar_lqg")
    return out


def working_sets(config: Mapping[str, Any]) -> dict[str, tuple[int, str]]:
    """Largest working set (bytes) of ``estimators_ablation`` over its grid: a replicate
    batch of shared-draw trees of row-wise problems (at most
    :data:`rsmhp.models.lqg.ablation.BATCH_LEAVES` leaves), every kept node's N children of a
    pruned tree, or the trajectories of a sampled scheme."""
    from rsmhp.models.lqg import ablation as estimators

    est = config["estimators"]
    specs = {s["name"]: {k: v for k, v in s.items() if k != "name"} for s in est["problems"]}
    problems = {n: estimators.build_problem(s, config["lqg"]["model"]) for n, s in specs.items()}
    reps = int(est["replicates"])
    biggest = 0
    for pt in estimators.grid_points(est, problems):
        prob = problems[pt.problem]
        leaves = estimators.n_trajectories(pt, prob)
        if pt.scheme in ("tree", "tree_pernode"):
            # replicate trees of row-wise problems are sampled in batches of <= 2^20 leaves
            batch = estimators.BATCH_LEAVES
            per = min(reps, max(1, batch // leaves)) if prob.noise.rowwise else 1
            P = per * leaves
        elif pt.scheme == "pruned":
            P = pt.M * pt.N  # every kept node's N children exist before pruning
        else:
            P = leaves
        biggest = max(biggest, working_set_bytes(P, prob.H, prob.d))
    return {
        "estimators_ablation": (
            biggest,
            "estimators.budgets, estimators.max_leaves, estimators.tree_N, estimators.pruning, "
            "threads",
        )
    }
