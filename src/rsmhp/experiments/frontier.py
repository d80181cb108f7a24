r"""Equal-compute study of the UAV planners (the ``decisions.frontier`` config section): every
planner family at several sizes, on named model variants of the decision study, with the
compute each one spends measured in the same job.

Per model variant (``decisions.uav.models`` by name) one job computes

* **closed loop**: runs ``0..runs-1`` of every method, paired (the same scenarios, target and
  sensor noise for every method: :mod:`rsmhp.uav.simulation`), with the planner's wall time
  per run; ``plan_ms`` = milliseconds per planning step (wall time of the plan calls, the
  step's stream included, over the run's steps), measured on one thread while the job runs
  alone on its core;
* **open loop**: the regret of every method's plan at the belief states of NBO runs
  ``0..regret_runs-1`` at ``regret_steps``, scored exactly as the decision study scores
  (:func:`rsmhp.experiments.decisions_uav.score_state` with the ``decisions.uav`` scoring
  settings): paired over states and over the evaluation hypotheses.

Random streams are those of the decision study (keyed on model, run, step and the method's
``job_key``): a method's closed-loop runs, its plan at a state and that plan's evaluation cost
never depend on which other methods run (they equal the decision study's for the same model,
run and step). The regret's reference (the best of every plan and of the multi-start) does
depend on the method set: more methods can only lower it.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from typing import Any

import pandas as pd
from threadpoolctl import threadpool_limits

from rsmhp.contracts import Contract
from rsmhp.experiments.decisions_uav import (
    REGRET_COLUMNS,
    _closed_loop_task,
    _regret_contract,
    _score_task,
    belief_states,
    merge_variant,
)
from rsmhp.parallel import parallel_map
from rsmhp.uav import methods
from rsmhp.uav.simulation import UAVSetup

__all__ = [
    "FRONTIER_RUN_COLUMNS",
    "frontier_contracts",
    "recording_setup",
    "run_frontier_model",
    "variant",
]

log = logging.getLogger(__name__)

FRONTIER_RUN_COLUMNS = [
    "model",
    "method",
    "family",
    "N_T",
    "N",
    "M",
    "run",
    "mean_error",
    "final_error",
    "detect_rate",
    "lost",
    "plan_ms",
]


def variant(models: list[Mapping[str, Any]], name: str) -> Mapping[str, Any]:
    """The model variant called ``name`` of ``decisions.uav.models``."""
    found = {m["name"]: m for m in models}
    if name not in found:
        raise ValueError(
            f"decisions.frontier.models: {name!r} is not a model of decisions.uav.models "
            f"(allowed: {', '.join(found)})"
        )
    return found[name]


def frontier_contracts(cfg: Mapping[str, Any], model: str) -> tuple[Contract, Contract]:
    """What the rule ``decisions_frontier`` writes for ``model``: one closed-loop row per
    (method, run) and one open-loop row per (run, step, method)."""
    names = list(methods.from_config(cfg["methods"], "decisions.frontier.methods"))
    keys = [(m, r) for m in names for r in range(int(cfg["runs"]))]
    runs = Contract(
        rule="decisions_frontier",
        columns=FRONTIER_RUN_COLUMNS,
        text=("model", "method", "family"),
        boolean=("lost",),
        integer=("N_T", "N", "M", "run"),
        keys=("method", "run"),
        expected=pd.DataFrame(keys, columns=["method", "run"]),
        values={"model": model},
    )
    regret = _regret_contract(
        "decisions_frontier", [model], cfg["regret_runs"], cfg["regret_steps"], cfg["methods"]
    )
    return runs, regret


def run_frontier_model(
    uav: Mapping[str, Any],
    models: list[Mapping[str, Any]],
    cfg: Mapping[str, Any],
    scoring: Mapping[str, Any],
    model: str,
    seed: int,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The study for one model variant (see the module docstring): ``(closed-loop rows,
    FRONTIER_RUN_COLUMNS; open-loop rows, REGRET_COLUMNS with ``model`` = the variant's
    name)``. ``uav`` is the (validated) ``uav`` section, ``models`` ``decisions.uav.models``,
    ``cfg`` the ``decisions.frontier`` section, ``scoring`` the ``decisions.uav`` section.
    Runs on one thread: the planning times are the study's measure of compute."""
    uav_cfg = merge_variant(uav, variant(models, model))
    planners = methods.from_config(cfg["methods"], "decisions.frontier.methods")
    runs = range(int(cfg["runs"]))
    jobs = [(uav_cfg, planners[m], seed, r) for m in planners for r in runs]
    setup = UAVSetup.from_config(uav_cfg)
    loss = float(cfg["track_loss_error"])
    log.info("frontier %s: %d methods x %d closed-loop runs", model, len(planners), len(runs))
    # one worker: parallel_map runs in this process with BLAS on one thread
    summaries = parallel_map(_closed_loop_task, jobs, 1, desc=f"frontier {model} runs")
    run_rows = [
        {
            "model": model,
            "method": s["method"],
            "family": s["family"],
            "N_T": s["N_T"],
            "N": s["N"],
            "M": s["M"],
            "run": s["run"],
            "mean_error": s["mean_error"],
            "final_error": s["final_error"],
            "detect_rate": s.get("detect_rate", 1.0),
            "lost": bool(s["final_error"] > loss),
            "plan_ms": 1e3 * s["plan_seconds"] / setup.steps,
        }
        for s in summaries
    ]
    with threadpool_limits(limits=1):
        states = belief_states(
            setup, model, seed, range(int(cfg["regret_runs"])), cfg["regret_steps"]
        )
    keys = ("n_eval", "polish", "random_starts", "eval_maxiter", "n_random")
    score_cfg = {k: scoring[k] for k in keys}
    jobs2 = [([st], uav_cfg, cfg["methods"], score_cfg, seed) for st in states]
    regret = [r for part in parallel_map(_score_task, jobs2, 1, desc="states") for r in part]
    return (
        pd.DataFrame(run_rows, columns=FRONTIER_RUN_COLUMNS),
        pd.DataFrame(regret, columns=REGRET_COLUMNS),
    )


def recording_setup(
    uav: Mapping[str, Any],
    models: list[Mapping[str, Any]],
    cfg: Mapping[str, Any],
    model: str,
) -> tuple[UAVSetup, list[methods.Method]]:
    """The setup of the frontier's model variant ``model`` and the methods its recording
    shows: NBO, then the budget member of every family (``decisions.frontier.budget.members``,
    in table order). ``cfg`` is ``decisions.frontier``. A model the frontier does not run, or
    a member it does not run, is refused naming the field."""
    if model not in list(cfg["models"]):
        raise ValueError(
            f"decisions.recording.model: {model!r} is not a model of decisions.frontier.models "
            f"(allowed: {', '.join(map(str, cfg['models'])) or 'none configured'})"
        )
    run = methods.from_config(cfg["methods"], "decisions.frontier.methods")
    members = list(cfg["budget"]["members"])
    unknown = [m for m in members if m not in run]
    if unknown:
        raise ValueError(
            f"decisions.frontier.budget.members: {unknown} not run by decisions.frontier.methods "
            f"(allowed: {', '.join(run)})"
        )
    base = methods.baseline()()
    chosen = sorted((run[m] for m in members), key=lambda m: m.sort_key())
    setup = UAVSetup.from_config(merge_variant(uav, variant(models, model)))
    return setup, [base, *chosen]
