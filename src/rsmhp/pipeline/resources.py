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

Each study estimates its own rules (``working_sets`` in its ``checks`` module, with this
module's :func:`working_set_bytes`); :func:`memory_problems` compares these estimates with
the rules' declared ``mem_mb`` and names the config keys that drive each estimate. The UAV
rules are not estimated: their arrays grow with the hypothesis counts (at most 10^6 by the
schema, a few tens of MB).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

__all__ = [
    "BASE_MB",
    "WORKER_MB",
    "estimate_mb",
    "memory_problems",
    "working_set_bytes",
    "working_sets",
]

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


def working_sets(config: Mapping[str, Any]) -> dict[str, tuple[int, str]]:
    """Largest working set (bytes) of each estimated rule and the config keys that drive it:
    every study's own estimates (``rsmhp.studies.<study>.checks.working_sets``, where its
    ``checks`` module has one; :func:`rsmhp.pipeline.config.studies`)."""
    from rsmhp.pipeline.config import studies, study_checks

    out: dict[str, tuple[int, str]] = {}
    for name in studies():
        estimate = getattr(study_checks(name), "working_sets", None)
        if estimate is not None:
            out.update(estimate(config))
    return out


def estimate_mb(config: Mapping[str, Any]) -> dict[str, tuple[int, str]]:
    """Estimated peak memory (MB) of each estimated rule with ``config["threads"]`` workers,
    and the config keys that drive it."""
    threads = int(config.get("threads", 1))
    return {rule: (_rule_mb(w, threads), keys) for rule, (w, keys) in working_sets(config).items()}


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
