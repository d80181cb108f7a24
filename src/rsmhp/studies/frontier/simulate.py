r"""Equal-compute study of the UAV planners (the ``frontier`` config section): every
planner family at several sizes, on named model variants of the decision study, with the
compute each one spends measured in the same job.

Per model variant (``uav_models`` by name) one job computes

* **closed loop**: runs ``0..runs-1`` of every method, paired (the same scenarios, target and
  sensor noise for every method: :mod:`rsmhp.models.uav.simulation`), with the planner's wall time
  per run; ``plan_ms`` = milliseconds per planning step (wall time of the plan calls, the
  step's stream included, over the run's steps), measured on one thread while the job runs
  alone on its core;
* **open loop**: the regret of every method's plan at the belief states of NBO runs
  ``0..regret_runs-1`` at ``regret_steps``, scored exactly as the decision study scores
  (:func:`rsmhp.models.uav.scoring.score_state` with the ``decisions.uav`` scoring
  settings): paired over states and over the evaluation hypotheses.

Random streams are those of the decision study (keyed on model, run, step and the method's
``job_key``): a method's closed-loop runs, its plan at a state and that plan's evaluation cost
never depend on which other methods run (they equal the decision study's for the same model,
run and step). The regret's reference (the best of every plan and of the multi-start) does
depend on the method set: more methods can only lower it.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping, Sequence
from typing import Any

import pandas as pd
from threadpoolctl import threadpool_limits

from rsmhp.core.seeding import job_rng
from rsmhp.models.uav import methods
from rsmhp.models.uav.planner import Belief
from rsmhp.models.uav.runs import simulate_runs
from rsmhp.models.uav.scoring import (
    REGRET_COLUMNS,
    _regret_contract,
    _score_task,
    belief_states,
    merge_variant,
    variant,
)
from rsmhp.models.uav.simulation import UAVSetup
from rsmhp.pipeline.contracts import Contract
from rsmhp.pipeline.parallel import parallel_map
from rsmhp.pipeline.protocol import Configuration
from rsmhp.pipeline.runstore import RunStore

__all__ = [
    "CONFIG_RUN_COLUMNS",
    "CONFIG_TIMING_COLUMNS",
    "DEPTH_COLUMNS",
    "FRONTIER_RUN_COLUMNS",
    "TIMING_COLUMNS",
    "config_runs_contract",
    "config_timing_contract",
    "frontier_contracts",
    "recording_setup",
    "run_configurations",
    "run_frontier_model",
    "time_configurations",
    "time_planners",
    "timing_contract",
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
    "mean_nit",
    "work_per_step",
    "converged_rate",
    "plan_depth",
    "max_depth",
    "root_actions",
    "frac_depth1",
]

#: the tree search's depth statistics of a run (means over its planning steps; NaN for the
#: other families): :class:`rsmhp.models.uav.methods.tree_search.TreeSearchPlanner` diagnostics
DEPTH_COLUMNS = ("plan_depth", "max_depth", "root_actions", "frac_depth1")

#: one row per (repeat, belief state, method) of the interleaved timing (rule
#: ``frontier_explore_timing``): the wall time of one plan call (ms) and its work
TIMING_COLUMNS = ["model", "method", "repeat", "run", "step", "slot", "ms", "work"]


def frontier_contracts(cfg: Mapping[str, Any], model: str) -> tuple[Contract, Contract]:
    """What the rule ``frontier_explore`` writes for ``model``: one closed-loop row per
    (method, run) and one open-loop row per (run, step, method)."""
    names = list(methods.from_config(cfg["methods"], "frontier.methods"))
    keys = [(m, r) for m in names for r in range(int(cfg["runs"]))]
    runs = Contract(
        rule="frontier_explore",
        columns=FRONTIER_RUN_COLUMNS,
        text=("model", "method", "family"),
        boolean=("lost",),
        integer=("N_T", "N", "M", "run"),
        # NaN for a planner without an optimiser, and for one that is not a tree search
        nullable=("converged_rate", *DEPTH_COLUMNS),
        keys=("method", "run"),
        expected=pd.DataFrame(keys, columns=["method", "run"]),
        values={"model": model},
    )
    regret = _regret_contract(
        "frontier_explore", [model], cfg["regret_runs"], cfg["regret_steps"], cfg["methods"]
    )
    return runs, regret


def run_frontier_model(
    uav: Mapping[str, Any],
    models: list[Mapping[str, Any]],
    cfg: Mapping[str, Any],
    scoring: Mapping[str, Any],
    model: str,
    seed: int,
    store: RunStore | None = None,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The study for one model variant (see the module docstring): ``(closed-loop rows,
    FRONTIER_RUN_COLUMNS; open-loop rows, REGRET_COLUMNS with ``model`` = the variant's
    name)``. ``uav`` is the (validated) ``uav`` section, ``models`` ``uav_models``,
    ``cfg`` the ``frontier`` section, ``scoring`` the ``decisions.uav`` section.
    Runs on one thread: the planning times are the study's measure of compute. With a
    ``store``, closed-loop runs it holds are read, not simulated (:mod:`rsmhp.models.uav.runs`),
    and their ``plan_ms`` is the time measured by the job that computed them."""
    uav_cfg = merge_variant(uav, variant(models, model))
    planners = methods.from_config(cfg["methods"], "frontier.methods")
    runs = range(int(cfg["runs"]))
    setup = UAVSetup.from_config(uav_cfg)
    jobs = [(setup, planners[m], seed, r) for m in planners for r in runs]
    loss = float(cfg["track_loss_error"])
    log.info("frontier %s: %d methods x %d closed-loop runs", model, len(planners), len(runs))
    # one worker: the runs are simulated in this process with BLAS on one thread
    out = simulate_runs(jobs, store, 1, desc=f"frontier {model} runs")
    summaries = [summary for summary, _ in out]
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
            "mean_nit": s["mean_nit"],
            "work_per_step": s["work_per_step"],
            "converged_rate": s["converged_rate"],
            **{c: s["diagnostics"].get(c, float("nan")) for c in DEPTH_COLUMNS},
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
    shows: NBO, then the budget member of every family (``frontier.budget.members``,
    in table order). ``cfg`` is ``frontier``. A model the frontier does not run, or
    a member it does not run, is refused naming the field."""
    if model not in list(cfg["models"]):
        raise ValueError(
            f"frontier.recording.model: {model!r} is not a model of frontier.models "
            f"(allowed: {', '.join(map(str, cfg['models'])) or 'none configured'})"
        )
    run = methods.from_config(cfg["methods"], "frontier.methods")
    members = list(cfg["budget"]["members"])
    unknown = [m for m in members if m not in run]
    if unknown:
        raise ValueError(
            f"frontier.budget.members: {unknown} not run by frontier.methods "
            f"(allowed: {', '.join(run)})"
        )
    base = methods.baseline()()
    chosen = sorted((run[m] for m in members), key=lambda m: m.sort_key())
    setup = UAVSetup.from_config(merge_variant(uav, variant(models, model)))
    return setup, [base, *chosen]


def timing_contract(cfg: Mapping[str, Any], model: str) -> Contract:
    """What the rule ``frontier_explore_timing`` writes for ``model``: one row per (repeat,
    belief state, method) of ``cfg["timing"]`` (``frontier``)."""
    names = list(methods.from_config(cfg["methods"], "frontier.methods"))
    t = cfg["timing"]
    keys = [
        (m, rep, run, step)
        for rep in range(int(t["repeats"]))
        for run in range(int(t["runs"]))
        for step in sorted(set(int(k) for k in t["steps"]))
        for m in names
    ]
    return Contract(
        rule="frontier_explore_timing",
        columns=TIMING_COLUMNS,
        text=("model", "method"),
        integer=("repeat", "run", "step", "slot", "work"),
        keys=("method", "repeat", "run", "step"),
        expected=pd.DataFrame(keys, columns=["method", "repeat", "run", "step"]),
        values={"model": model},
    )


def time_planners(
    uav: Mapping[str, Any],
    models: list[Mapping[str, Any]],
    cfg: Mapping[str, Any],
    model: str,
    seed: int,
) -> pd.DataFrame:
    """Interleaved timing (:func:`time_configurations`) of every method of ``cfg["methods"]``
    at its default optimiser budget, at ``cfg["timing"]``'s belief states
    (:data:`TIMING_COLUMNS`: ``method`` names the method)."""
    planners = methods.from_config(cfg["methods"], "frontier.methods")
    configs = [Configuration(m) for m in planners]
    t = time_configurations(uav, models, model, configs, cfg["timing"], seed)
    return t.rename(columns={"config": "method"})[TIMING_COLUMNS]


#: one row per (repeat, belief state, configuration) of :func:`time_configurations`
CONFIG_TIMING_COLUMNS = ["model", "config", "repeat", "run", "step", "slot", "ms", "work"]


def time_configurations(
    uav: Mapping[str, Any],
    models: list[Mapping[str, Any]],
    model: str,
    configs: Sequence[Configuration],
    timing: Mapping[str, Any],
    seed: int,
) -> pd.DataFrame:
    r"""Interleaved wall-clock timing of every configuration's plan call
    (:data:`CONFIG_TIMING_COLUMNS`).

    At the belief states of NBO runs ``timing["runs"]`` at ``timing["steps"]`` (the open-loop
    study's states, :func:`rsmhp.models.uav.scoring.belief_states`, drawn from
    ``seed``), every configuration plans once per state and repeat, **round robin**: at state
    s of repeat r the configurations are called in order rotated by
    :math:`(r \cdot S + s) \bmod M` (M configurations, S states), so every configuration
    takes every slot equally often and a slow drift of the machine (frequency, cache, another
    process) is spread over all of them rather than loaded on the ones that run last. Each
    call is timed alone with ``time.perf_counter`` on one BLAS thread, with the step's own
    stream (the closed loop's key, so the plan is the one the closed loop makes at that
    belief). The rules that call this hold the machine's cores while it runs, so nothing runs
    beside it on the reference machine (2 cores). Repeats measure the spread of the time from
    one pass to the next; the plan and its ``work`` (model steps) are the same in every
    repeat."""
    base = UAVSetup.from_config(merge_variant(uav, variant(models, model)))
    with threadpool_limits(limits=1):
        states = belief_states(base, model, seed, range(int(timing["runs"])), timing["steps"])
        built = [(c, c.method, c.method.planner(c.setup(base))) for c in configs]
        n_m, n_s = len(built), len(states)
        rows = []
        for rep in range(int(timing["repeats"])):
            log.info("timing %s: repeat %d of %d", model, rep + 1, timing["repeats"])
            for si, st in enumerate(states):
                belief = Belief(st.uav, st.x_hat, st.P_hat)
                shift = (rep * n_s + si) % n_m
                for slot in range(n_m):
                    config, method, planner = built[(slot + shift) % n_m]
                    rng = (
                        job_rng(seed, "uav_plan", run=st.run, step=st.step + 1, **method.job_key())
                        if method.uses_rng
                        else None
                    )
                    t0 = time.perf_counter()
                    res = planner.plan(belief, st.warm, rng)
                    ms = 1e3 * (time.perf_counter() - t0)
                    rows.append(
                        {
                            "model": model,
                            "config": config.name,
                            "repeat": rep,
                            "run": st.run,
                            "step": st.step,
                            "slot": slot,
                            "ms": ms,
                            "work": int(res.work),
                        }
                    )
    return pd.DataFrame(rows, columns=CONFIG_TIMING_COLUMNS)


def config_timing_contract(
    rule: str, configs: Sequence[Configuration], timing: Mapping[str, Any], model: str
) -> Contract:
    """What a timing rule of the protocol writes: one row per (configuration, repeat,
    belief state) of ``timing``."""
    keys = [
        (c.name, rep, run, step)
        for rep in range(int(timing["repeats"]))
        for run in range(int(timing["runs"]))
        for step in sorted(set(int(k) for k in timing["steps"]))
        for c in configs
    ]
    return Contract(
        rule=rule,
        columns=CONFIG_TIMING_COLUMNS,
        text=("model", "config"),
        integer=("repeat", "run", "step", "slot", "work"),
        keys=("config", "repeat", "run", "step"),
        expected=pd.DataFrame(keys, columns=["config", "repeat", "run", "step"]),
        values={"model": model},
    )


#: one row per (configuration, run) of :func:`run_configurations`
CONFIG_RUN_COLUMNS = [
    "model",
    "config",
    "member",
    "family",
    "maxiter",
    "restarts",
    "run",
    "mean_error",
    "final_error",
    "detect_rate",
    "lost",
    "plan_ms",
    "mean_nit",
    "work_per_step",
    "converged_rate",
    *DEPTH_COLUMNS,
]


def run_configurations(
    uav: Mapping[str, Any],
    models: list[Mapping[str, Any]],
    model: str,
    configs: Sequence[Configuration],
    runs: Sequence[int],
    seed: int,
    track_loss_error: float,
    store: RunStore | None = None,
) -> pd.DataFrame:
    """Paired closed-loop runs ``runs`` of every configuration on ``model`` with root seed
    ``seed`` (:data:`CONFIG_RUN_COLUMNS`; ``plan_ms`` is the run's planning wall time per
    step, measured beside whatever else ran: the protocol's times come from
    :func:`time_configurations`). One thread; runs in configuration-major order. With a
    ``store``, runs it holds are read, not simulated (:mod:`rsmhp.models.uav.runs`; their
    ``plan_ms`` is then the computing job's)."""
    uav_cfg = merge_variant(uav, variant(models, model))
    setup = UAVSetup.from_config(uav_cfg)
    jobs = [(c, int(r)) for c in configs for r in runs]
    log.info("%s: %d configurations x %d closed-loop runs", model, len(configs), len(runs))
    out = simulate_runs(
        [(c.setup(setup), c.method, seed, r) for c, r in jobs], store, 1, desc=f"{model} runs"
    )
    rows = []
    for (c, r), (s, _) in zip(jobs, out, strict=True):
        rows.append(
            {
                "model": model,
                "config": c.name,
                "member": c.member,
                "family": c.family,
                "maxiter": setup.planner.maxiter if c.maxiter is None else c.maxiter,
                "restarts": c.restarts,
                "run": r,
                "mean_error": s["mean_error"],
                "final_error": s["final_error"],
                "detect_rate": s.get("detect_rate", 1.0),
                "lost": bool(s["final_error"] > float(track_loss_error)),
                "plan_ms": 1e3 * s["plan_seconds"] / setup.steps,
                "mean_nit": s["mean_nit"],
                "work_per_step": s["work_per_step"],
                "converged_rate": s["converged_rate"],
                **{k: s["diagnostics"].get(k, float("nan")) for k in DEPTH_COLUMNS},
            }
        )
    return pd.DataFrame(rows, columns=CONFIG_RUN_COLUMNS)


def config_runs_contract(
    rule: str, configs: Sequence[Configuration], runs: Sequence[int], model: str
) -> Contract:
    """What a closed-loop rule of the protocol writes: one row per (configuration, run)."""
    keys = [(c.name, int(r)) for c in configs for r in runs]
    return Contract(
        rule=rule,
        columns=CONFIG_RUN_COLUMNS,
        text=("model", "config", "member", "family"),
        boolean=("lost",),
        integer=("maxiter", "restarts", "run"),
        nullable=("converged_rate", *DEPTH_COLUMNS),
        keys=("config", "run"),
        expected=pd.DataFrame(keys, columns=["config", "run"]),
        values={"model": model},
    )
