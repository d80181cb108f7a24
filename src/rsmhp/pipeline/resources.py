"""Memory each simulation rule will need, estimated from the config before any job runs.

The LQG and estimator rules hold, per worker, the sampled noise, states and costs of the
largest cell they simulate. For ``P`` trajectories of ``H`` steps of an ``n``-dimensional state
the working set is at most

.. math:: W(P, H, n) = 8\\,P\\,\\bigl(H\\,(4n + 3) + 8\\bigr) + 2^{24}\\ \\text{bytes},

(the constant covers fixed tables such as scipy's Sobol' direction numbers): an upper bound
of the peak of numpy allocations measured with :mod:`tracemalloc` for every scheme
(``tests/pipeline/test_resources.py`` checks that the peak is at most ``W`` and ``W`` at most 3-4
times the peak plus the constant).
A rule with ``w`` workers then needs ``BASE_MB + w (WORKER_MB + W / 2^20)`` MB, where
``BASE_MB`` is the interpreter with numpy, scipy and pandas loaded and ``WORKER_MB`` one joblib
worker process (measured resident sizes, rounded up).

:func:`memory_problems` compares these estimates with the rules' declared ``mem_mb`` and names
the config keys that drive each estimate. The UAV rules are not estimated: their arrays grow
with the hypothesis counts (at most 10^6 by the schema, a few tens of MB).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

__all__ = ["BASE_MB", "WORKER_MB", "estimate_mb", "memory_problems", "working_set_bytes"]

BASE_MB = 300
FIXED_BYTES = 1 << 24
WORKER_MB = 200


def working_set_bytes(P: int, H: int, n: int = 1) -> int:
    """Upper bound of the bytes one worker holds to simulate ``P`` trajectories of ``H``
    steps with state dimension ``n`` (see the module docstring)."""
    return 8 * int(P) * (int(H) * (4 * int(n) + 3) + 8) + FIXED_BYTES


def _rule_mb(work: int, workers: int) -> int:
    workers = max(1, int(workers))
    extra = WORKER_MB if workers > 1 else 0
    return int(BASE_MB + workers * (extra + work / 2**20))


def _lqg_cells(config: Mapping[str, Any]) -> dict[str, tuple[int, str]]:
    """Largest working set (bytes) of each LQG-type rule and the keys that drive it."""
    from rsmhp.models.lqg import ablation as estimators
    from rsmhp.models.lqg import regret as decisions_lqg
    from rsmhp.studies.lqg import simulate as lqg

    out: dict[str, tuple[int, str]] = {}
    conv = config["lqg"]["convergence"]
    out["lqg_convergence"] = (
        working_set_bytes(max(lqg.p_grid(conv["P"])), len(conv["u"])),
        "lqg.convergence.P.stop, lqg.convergence.u (its length H), threads",
    )
    ne = config["lqg"]["nbo_error"]
    out["lqg_nbo_error"] = (
        working_set_bytes(ne["P"], max(ne["H_values"])),
        "lqg.nbo_error.P, lqg.nbo_error.H_values, threads",
    )
    dec = config.get("decisions", {}).get("lqg")
    if dec:
        cells = decisions_lqg.regret_cells(dec)
        out["decisions_lqg"] = (
            max((working_set_bytes(c.P, c.H) for c in cells), default=0),
            "decisions.lqg.P, decisions.lqg.tree_N / max_leaves, decisions.lqg.H_values, threads",
        )
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
    out["estimators_ablation"] = (
        biggest,
        "estimators.budgets, estimators.max_leaves, estimators.tree_N, estimators.pruning, threads",
    )
    return out


def estimate_mb(config: Mapping[str, Any]) -> dict[str, tuple[int, str]]:
    """Estimated peak memory (MB) of each estimated rule with ``config["threads"]`` workers,
    and the config keys that drive it."""
    threads = int(config.get("threads", 1))
    return {rule: (_rule_mb(w, threads), keys) for rule, (w, keys) in _lqg_cells(config).items()}


def memory_problems(config: Mapping[str, Any], declared_mb: Mapping[str, Any]) -> list[str]:
    """One message per rule whose estimate exceeds its declared ``mem_mb`` (rules whose
    ``mem_mb`` is not a plain number are skipped)."""
    problems = []
    for rule, (need, keys) in estimate_mb(config).items():
        have = declared_mb.get(rule)
        if isinstance(have, int | float) and need > have:
            problems.append(
                f"{rule}: needs about {need} MB for this config but declares mem_mb = "
                f"{int(have)} (allowed: at most mem_mb; reduce {keys}, or raise the rule's "
                "mem_mb with --set-resources "
                f"{rule}:mem_mb={need} if the machine has the memory)"
            )
    return problems
