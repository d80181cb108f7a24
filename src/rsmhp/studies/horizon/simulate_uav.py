r"""UAV horizon study (the ``horizon`` config section): how each planner's cost approximation,
its decisions and its planning time change with the horizon H.

Per model variant (``uav_models`` by name) and horizon H, one job works at the
belief states of closed-loop NBO runs ``0..runs-1`` at ``steps`` (the runs use the base
horizon ``uav.planner.horizon``, so every H sees the same belief states) and computes:

* **cost approximation**: at each state, ``plans`` candidate plans (controls uniform in the
  normalised box [-1, 1]^{2H}, keyed on model, state and H) are scored by the *reference*
  cost :math:`J_{ref}(u) = \frac1{n}\sum_{i=1}^{n} c_i(u)`, the mean over ``n_ref``
  independent hypotheses of the planning cost :math:`c_i(u) = \sum_{j=1}^{H}\mathrm{tr}\,P_j`
  (m²), with its standard error; and by every method's own estimate :math:`\hat J_m(u)`, the
  weighted mean of :math:`c` over the method's hypotheses, drawn ``replicates`` times
  (methods without randomness once). One row per (state, method, replicate, plan): the
  estimate, the reference and its SE. Methods without hypotheses (a tree search) estimate no
  cost of a given plan and have no rows here.
* **decisions and compute**: every method plans once at each state with horizon H and is
  scored exactly as the decision study scores
  (:func:`rsmhp.models.uav.scoring.score_state`); its planning time is measured by a
  second, timed plan call with its own stream after it (milliseconds, one thread).

Random streams are keyed on (model, run, step, H, method, replicate): a cost-approximation
row or a timing never depends on the other methods, horizons or models, so jobs can run in
any order. The regret rows reuse the decision study's scoring and streams (keyed on model,
run, step and the method; the same stream at every H, of which only the initial-state draws
coincide across H); their reference, the best plan found, starts from every method's plan,
so a regret depends on the set of methods.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd
from threadpoolctl import threadpool_limits

from rsmhp.core.seeding import job_rng
from rsmhp.models.uav import fused, methods, target
from rsmhp.models.uav.methods import Method
from rsmhp.models.uav.planner import Belief, PlanningProblem
from rsmhp.models.uav.runs import simulate_runs
from rsmhp.models.uav.scoring import (
    _REGRET_INTEGERS,
    _REGRET_NULLABLE,
    REGRET_COLUMNS,
    BeliefState,
    _positions,
    belief_states,
    merge_variant,
    score_state,
    variant,
)
from rsmhp.models.uav.simulation import UAVSetup
from rsmhp.pipeline.contracts import Contract
from rsmhp.pipeline.runstore import RunStore

__all__ = [
    "APPROX_COLUMNS",
    "CLOSED_COLUMNS",
    "HORIZON_REGRET_COLUMNS",
    "closed_contract",
    "horizon_contracts",
    "horizon_setup",
    "recording_members",
    "run_horizon",
    "run_horizon_closed",
]

log = logging.getLogger(__name__)

APPROX_COLUMNS = [
    "model",
    "H",
    "run",
    "step",
    "method",
    "family",
    "replicate",
    "plan",
    "estimate",
    "reference",
    "reference_se",
]

#: the decision study's regret rows with the horizon and the measured planning time
HORIZON_REGRET_COLUMNS = ["H", *REGRET_COLUMNS, "plan_ms"]

#: one closed-loop run of one method with planning horizon H
#: ``plan_depth``: a tree search's mean plan depth over the run's steps (empty for the others)
CLOSED_COLUMNS = [
    "model", "H", "method", "family", "run", "mean_error", "final_error", "plan_ms", "plan_depth",
]  # fmt: skip


def horizon_setup(uav: Mapping[str, Any], model: Mapping[str, Any], H: int) -> UAVSetup:
    """The setup of model variant ``model`` with planning horizon ``H``."""
    cfg = merge_variant(uav, model)
    cfg["planner"] = {**cfg["planner"], "horizon": int(H)}
    return UAVSetup.from_config(cfg)


def _names(cfg: Mapping[str, Any]) -> dict[str, Method]:
    return methods.from_config(cfg["methods"], "horizon.uav.methods")


def recording_members(cfg: Mapping[str, Any]) -> list[Method]:
    """One member per family of ``horizon.uav.methods``, the last in table order (the
    largest: most hypotheses or simulations), in table order: the recording's methods."""
    last: dict[str, Method] = {}
    for m in _names(cfg).values():
        last[m.family] = m
    return list(last.values())


def horizon_contracts(cfg: Mapping[str, Any], model: str, H: int) -> tuple[Contract, Contract]:
    """What the rule ``horizon`` writes for (``model``, ``H``): the cost-approximation rows
    (every state, method with hypotheses, replicate and plan) and the regret rows (every
    state and method)."""
    planners = _names(cfg)
    states = [
        (r, s) for r in range(int(cfg["runs"])) for s in sorted({int(k) for k in cfg["steps"]})
    ]
    approx_keys = [
        (r, s, name, k, p)
        for r, s in states
        for name, m in planners.items()
        if m.estimates_cost
        for k in range(int(cfg["replicates"]) if m.uses_rng else 1)
        for p in range(int(cfg["plans"]))
    ]
    approx = Contract(
        rule="horizon",
        columns=APPROX_COLUMNS,
        text=("model", "method", "family"),
        integer=("H", "run", "step", "replicate", "plan"),
        keys=("run", "step", "method", "replicate", "plan"),
        expected=pd.DataFrame(approx_keys, columns=["run", "step", "method", "replicate", "plan"]),
        values={"model": model, "H": int(H)},
    )
    regret_keys = [(r, s, name) for r, s in states for name in planners]
    regret = Contract(
        rule="horizon",
        columns=HORIZON_REGRET_COLUMNS,
        text=("model", "method", "family"),
        integer=("H", *_REGRET_INTEGERS),
        nullable=_REGRET_NULLABLE,
        keys=("run", "step", "method"),
        expected=pd.DataFrame(regret_keys, columns=["run", "step", "method"]),
        values={"model": model, "H": int(H)},
    )
    return approx, regret


def _warm(state: BeliefState, H: int) -> np.ndarray:
    """The state's warm start (NBO's shifted previous plan, at the base horizon) cut to H
    steps, or extended to H steps by repeating its last control.

    Repeating the last control is the closed loop's rule for the step a shifted plan gains
    (:func:`rsmhp.models.uav.planner.shift_plan`: hold the last control). Zero controls beyond the
    base horizon would mean straight flight at constant speed, a plan nobody would choose,
    and give the optimiser a poor start at long horizons such as H = 24, where most of the
    plan lies beyond the base horizon. An empty warm start gives zeros."""
    warm = np.asarray(state.warm, dtype=float).reshape(-1, 2)
    if len(warm) == 0:
        return np.zeros((H, 2))
    if len(warm) >= H:
        return warm[:H].copy()
    return np.vstack([warm, np.repeat(warm[-1:], H - len(warm), axis=0)])


def _approx_rows(
    state: BeliefState,
    setup: UAVSetup,
    planners: Mapping[str, Method],
    cfg: Mapping[str, Any],
    seed: int,
) -> list[dict[str, Any]]:
    H = setup.planner.horizon
    ident = {"model": state.model, "run": state.run, "step": state.step, "H": H}
    n_ref, n_plans = int(cfg["n_ref"]), int(cfg["plans"])
    ref_xy = target.sample_independent(
        state.x_hat, state.P_hat, H, n_ref, setup.target, job_rng(seed, "horizon_ref", **ident)
    )[..., :2]
    args = (setup.uav, setup.target, setup.sensor, setup.planner)
    plans = job_rng(seed, "horizon_plans", **ident).uniform(-1.0, 1.0, (n_plans, 2 * H))
    ref = PlanningProblem(state.uav, state.P_hat, ref_xy, *args)
    per_hyp = fused.covariance_traces(
        state.P_hat,
        _positions(plans, ref),
        ref_xy,
        setup.target.dt,
        setup.target.Q,
        setup.sensor,
    ).sum(axis=2)  # (plans, n_ref)
    j_ref = per_hyp.mean(axis=1)
    se_ref = per_hyp.std(axis=1, ddof=1) / np.sqrt(n_ref)
    belief = Belief(state.uav, state.x_hat, state.P_hat)
    rows = []
    for name, m in planners.items():
        if not m.estimates_cost:
            continue
        for k in range(int(cfg["replicates"]) if m.uses_rng else 1):
            rng = job_rng(seed, "horizon_hyp", **ident, **m.job_key(), replicate=k)
            hyp = m.hypotheses(belief, setup, rng)
            est = PlanningProblem(
                state.uav, state.P_hat, hyp.states[..., :2], *args, weights=hyp.weights
            ).costs(plans)
            rows += [
                {
                    "model": state.model,
                    "H": H,
                    "run": state.run,
                    "step": state.step,
                    "method": name,
                    "family": m.family,
                    "replicate": k,
                    "plan": p,
                    "estimate": float(est[p]),
                    "reference": float(j_ref[p]),
                    "reference_se": float(se_ref[p]),
                }
                for p in range(n_plans)
            ]
    return rows


def _timed_plans(
    state: BeliefState, setup: UAVSetup, planners: Mapping[str, Method], seed: int
) -> dict[str, float]:
    """Milliseconds of one plan call per method (its own stream; one thread)."""
    H = setup.planner.horizon
    belief = Belief(state.uav, state.x_hat, state.P_hat)
    out = {}
    for name, m in planners.items():
        planner = m.planner(setup)
        rng = job_rng(
            seed, "horizon_timing", model=state.model, run=state.run, step=state.step, H=H,
            **m.job_key(),
        )  # fmt: skip
        t0 = time.perf_counter()
        planner.plan(belief, _warm(state, H), rng)
        out[name] = 1e3 * (time.perf_counter() - t0)
    return out


def run_horizon(
    uav: Mapping[str, Any],
    models: Sequence[Mapping[str, Any]],
    cfg: Mapping[str, Any],
    scoring: Mapping[str, Any],
    model: str,
    H: int,
    seed: int,
    runs: Sequence[int] | None = None,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The study for (``model``, ``H``) (module docstring): ``(cost-approximation rows,
    APPROX_COLUMNS; regret rows, HORIZON_REGRET_COLUMNS)``. ``uav`` is the validated ``uav``
    section, ``models`` ``uav_models``, ``cfg`` the ``horizon`` section,
    ``scoring`` the decision study's scoring settings. Runs on one thread. ``runs``: the
    belief states of these runs only (default ``0..runs-1``; a chunk job's rows are the
    unsplit job's rows of its runs, :mod:`rsmhp.studies.horizon.chunks`)."""
    var = variant(list(models), model)
    base = horizon_setup(uav, var, int(uav["planner"]["horizon"]))
    setup = horizon_setup(uav, var, H)
    planners = _names(cfg)
    runs = range(int(cfg["runs"])) if runs is None else [int(r) for r in runs]
    with threadpool_limits(limits=1):
        states = belief_states(base, model, seed, runs, cfg["steps"])
        log.info("horizon %s H=%d: %d belief states x %d methods", model, H, len(states),
                 len(planners))  # fmt: skip
        approx, regret = [], []
        for i, st in enumerate(states):
            h_state = BeliefState(st.model, st.run, st.step, st.uav, st.x_hat, st.P_hat,
                                  _warm(st, H))  # fmt: skip
            approx += _approx_rows(h_state, setup, planners, cfg, seed)
            scored = score_state(h_state, setup, planners, scoring, seed)
            # timed after the scored plans: no first-call (compilation, cache) cost is timed
            ms = _timed_plans(h_state, setup, planners, seed)
            for row in scored:
                regret.append({"H": int(H), **row, "plan_ms": ms[row["method"]]})
            log.info("horizon %s H=%d: state %d/%d done", model, H, i + 1, len(states))
    return (
        pd.DataFrame(approx, columns=APPROX_COLUMNS),
        pd.DataFrame(regret, columns=HORIZON_REGRET_COLUMNS),
    )


def closed_contract(cfg: Mapping[str, Any], model: str, H: int) -> Contract:
    """What the rule ``horizon_uav_closed`` writes for (``model``, ``H``): one row per
    (method, run) for runs ``0..closed_runs-1``."""
    keys = [(m, r) for m in _names(cfg) for r in range(int(cfg["closed_runs"]))]
    return Contract(
        rule="horizon_uav_closed",
        columns=CLOSED_COLUMNS,
        text=("model", "method", "family"),
        integer=("H", "run"),
        nullable=("plan_depth",),
        keys=("method", "run"),
        expected=pd.DataFrame(keys, columns=["method", "run"]),
        values={"model": model, "H": int(H)},
    )


def run_horizon_closed(
    uav: Mapping[str, Any],
    models: Sequence[Mapping[str, Any]],
    cfg: Mapping[str, Any],
    model: str,
    H: int,
    seed: int,
    store: RunStore | None = None,
    runs: Sequence[int] | None = None,
) -> pd.DataFrame:
    """Closed-loop runs ``0..closed_runs-1`` (or ``runs``: a chunk job's) of every method of
    ``horizon.uav.methods`` on ``model`` with planning horizon ``H``
    (:func:`rsmhp.models.uav.simulation.simulate_run`: the same scenarios and noise for every
    method and every H, so differences pair by run, also across horizons), method-major.
    ``plan_ms``: planner milliseconds per step of the run (one thread). With a ``store``, runs
    it holds are read, not simulated (:mod:`rsmhp.models.uav.runs`; their ``plan_ms`` is then
    the computing run's)."""
    var = variant(list(models), model)
    setup = horizon_setup(uav, var, H)
    planners = _names(cfg)
    runs = range(int(cfg["closed_runs"])) if runs is None else [int(r) for r in runs]
    jobs = [(setup, m, seed, r) for m in planners.values() for r in runs]
    summaries = simulate_runs(jobs, store, 1, desc=f"horizon {model} H={H} closed loop")
    rows = [
        {
            "model": model,
            "H": int(H),
            "method": m.name,
            "family": m.family,
            "run": r,
            "mean_error": summary["mean_error"],
            "final_error": summary["final_error"],
            "plan_ms": 1e3 * summary["plan_seconds"] / setup.steps,
            "plan_depth": summary.get("diagnostics", {}).get("plan_depth", float("nan")),
        }
        for (_, m, _, r), (summary, _) in zip(jobs, summaries, strict=True)
    ]
    return pd.DataFrame(rows, columns=CLOSED_COLUMNS)
