r"""Optimiser split of the UAV open-loop regret: how much of a plan's regret is the cost
approximation and how much is the optimiser stopping short, per horizon and optimiser budget.

Belief states
-------------
As in the horizon study (:mod:`rsmhp.studies.horizon.simulate_uav`): closed-loop NBO runs
``0..runs-1`` of the model variant at the base horizon ``uav.planner.horizon`` are stopped at
``steps`` (:func:`rsmhp.models.uav.scoring.belief_states`), so every H sees the same
states; the warm start at H is :func:`rsmhp.studies.horizon.simulate_uav._warm` (the base-horizon
warm start cut to H, or extended by holding its last control).

Costs at one state s and horizon H
----------------------------------
With :math:`c_i(x) = \sum_{j=1}^H \mathrm{tr}\,P^i_j(x)` the planning cost of hypothesis i for
normalised controls :math:`x \in [-1, 1]^{2H}`:

* the method's own cost :math:`J_m(x) = \sum_i \omega_i c_i(x)` over the hypotheses it draws
  *once* at s, exactly as the decision study draws them
  (:func:`rsmhp.models.uav.scoring.score_state`:
  ``job_rng(seed, "decisions_uav_plan", model=, run=, step=, **method.job_key())``; NBO and the
  sigma points ignore the stream). :math:`J_m` is the same function for every budget and for
  the polish below, so everything that differs between them is optimisation;
* the evaluation cost :math:`J_{ev}(x) = \frac1n \sum_{i=1}^n c_i(x)` over ``n = n_eval``
  independent hypotheses, drawn as the decision study draws them
  (``job_rng(seed, "decisions_uav_eval", model=, run=, step=)``): keyed on the state only,
  shared by every method and budget (a paired design), and equal to the horizon study's
  evaluation set at the same (model, run, step, H, n_eval).

Budgets and plans
-----------------
A budget b is ``(maxiter, restarts)`` with ``maxfun = 2 maxiter + 1`` unless given. The plan
:math:`x_{m,b}` minimises :math:`J_m` with the configured optimiser (``uav.planner.optimiser``)
from the warm start, at most ``maxiter`` iterations and ``maxfun`` evaluations, plus
``restarts`` optimisations from :func:`rsmhp.models.uav.planner.restart_starts` (the lowest
:math:`J_m` wins), exactly as :class:`rsmhp.models.uav.planner.SampledCostPlanner` plans in the
closed loop. Recorded: iterations ``nit`` (summed over the restarts), ``converged`` (the
winning optimisation stopped on a tolerance, not on a budget), ``work`` (model steps of all
of them), :math:`J_m(x_{m,b})` and :math:`J_{ev}(x_{m,b})`.

The near-global minimiser of the method's own cost,

.. math:: x^*_m = \arg\min \{ J_m(x) : x \in \{x_{m,b}\}_b \cup \{\mathrm{polish}_{J_m}(z)\} \},

where the polish (:func:`rsmhp.models.uav.planner.polish`, ``polish_maxiter`` iterations, 15000
evaluations) starts from ``polish_starts`` uniform points of the box (keyed on the state and
H, ``job_rng(seed, "optimiser_split_starts", model=, run=, step=, H=)``: the same starts for
every method) and from every distinct budget plan. Ties go to the budget plans;
``star_source`` says which kind won.

The reference :math:`J_{ref}` is the lowest :math:`J_{ev}` of every point evaluated at the
state: every method's budget plans and polish end points (so every :math:`x^*_m`), and a
multi-start polish of :math:`J_{ev}` itself as the decision study does it (starts: the
``scoring["polish"]`` candidates lowest on :math:`J_{ev}` and ``scoring["random_starts"]``
uniform points, ``job_rng(seed, "optimiser_split_aux", model=, run=, step=, H=)``), but with
``polish_maxiter`` iterations (not the decision study's ``eval_maxiter``) so that the
reference is optimised at least as hard as :math:`x^*_m`. Every :math:`J_{ev}` value of the
state comes from one batched evaluation, so :math:`J_{ref} \le J_{ev}(x)` holds exactly for
every row.

Regret split
------------
For method m and budget b (relative to the reference, dimensionless):

.. math::
    R_{m,b} = \frac{J_{ev}(x_{m,b}) - J_{ref}}{J_{ref}} \ge 0, \qquad
    A_m = \frac{J_{ev}(x^*_m) - J_{ref}}{J_{ref}} \ge 0, \qquad
    O_{m,b} = R_{m,b} - A_m .

:math:`A_m` (``approx_regret``) is what even a perfect optimiser of the method's own cost
loses because :math:`J_m \ne J_{ev}`; :math:`O_{m,b}` (``optim_regret``) is the rest, due to
the optimiser stopping at a poorer point than :math:`x^*_m`. :math:`O` can be negative (a
local minimiser of :math:`J_m` may be better on :math:`J_{ev}` than :math:`x^*_m` by luck);
it is reported as it is, not clipped. :math:`R = A + O` up to rounding (one subtraction).

NBO and the sigma points (deterministic hypotheses) follow the same definitions. Methods
without a cost of an arbitrary plan (``estimates_cost`` False: the tree searches, e.g. dpw)
have no :math:`J_m` to optimise and are skipped (no rows).

Everything runs on one BLAS thread. A method's budget plans, own costs, :math:`x^*_m` and
evaluation costs never depend on the other methods or budgets configured; the reference, and
so the regrets, can only go down when methods or budgets are added.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd
from threadpoolctl import threadpool_limits

from rsmhp.core import guards
from rsmhp.core.seeding import job_rng
from rsmhp.models.uav import methods, target
from rsmhp.models.uav.methods import Method
from rsmhp.models.uav.planner import Belief, PlanningProblem, SampledCostPlanner, polish
from rsmhp.models.uav.scoring import BeliefState, belief_states
from rsmhp.models.uav.simulation import UAVSetup
from rsmhp.pipeline.contracts import Contract
from rsmhp.studies.horizon.simulate_uav import _warm, horizon_setup

__all__ = [
    "RULE",
    "SPLIT_COLUMNS",
    "budgets",
    "run_optimiser_split",
    "split_contract",
    "split_methods",
    "split_state",
]

log = logging.getLogger(__name__)

SPLIT_COLUMNS = [
    "model",
    "H",
    "run",
    "step",
    "method",
    "family",
    "maxiter",
    "maxfun",
    "restarts",
    "nit",
    "converged",
    "work",
    "own_cost",
    "eval_cost",
    "ref_cost",
    "regret",
    "approx_regret",
    "optim_regret",
    "star_own_cost",
    "star_source",
]

#: the workflow rule that writes the split table of one (model, H)
RULE = "horizon_optimiser"

#: ``star_source`` values: x*_m is a budget plan, or a polish end point
STAR_SOURCES = ("budget", "polish")


def budgets(cfg: Mapping[str, Any]) -> list[tuple[int, int, int]]:
    """The ``(maxiter, maxfun, restarts)`` of ``cfg["budgets"]`` (a list of ``{maxiter,
    restarts}``, optional ``maxfun``, default ``2 maxiter + 1``), in config order. Refuses an
    empty list and two budgets with the same (maxiter, restarts)."""
    raw = cfg["budgets"]
    if not isinstance(raw, Sequence) or isinstance(raw, str) or not raw:
        raise ValueError(f"budgets must be a non-empty list of {{maxiter, restarts}}, got {raw!r}")
    out = []
    for i, b in enumerate(raw):
        maxiter = guards.positive_int(f"budgets[{i}].maxiter", b["maxiter"])
        restarts = guards.integer(f"budgets[{i}].restarts", b.get("restarts", 0), minimum=0)
        maxfun = guards.positive_int(f"budgets[{i}].maxfun", b.get("maxfun", 2 * maxiter + 1))
        out.append((int(maxiter), int(maxfun), int(restarts)))
    keys = [(it, r) for it, _, r in out]
    dup = sorted({k for k in keys if keys.count(k) > 1})
    if dup:
        raise ValueError(f"budgets: (maxiter, restarts) {dup} appear twice")
    return out


def split_methods(cfg: Mapping[str, Any]) -> dict[str, Method]:
    """The methods of ``cfg["methods"]`` that have an own cost (``estimates_cost``), in table
    order; tree searches are skipped."""
    allm = methods.from_config(cfg["methods"], "optimiser_split.methods")
    return {name: m for name, m in allm.items() if m.estimates_cost}


def split_contract(cfg: Mapping[str, Any], model: str, H: int) -> Contract:
    """What :func:`run_optimiser_split` returns for (``model``, ``H``): one row per (run, step,
    method with an own cost, budget), keyed on (run, step, method, maxiter, restarts)."""
    names = list(split_methods(cfg))
    steps = sorted({int(s) for s in cfg["steps"]})
    keys = [
        (r, s, name, it, rs)
        for r in range(int(cfg["runs"]))
        for s in steps
        for name in names
        for it, _, rs in budgets(cfg)
    ]
    cols = ["run", "step", "method", "maxiter", "restarts"]
    return Contract(
        rule=RULE,
        columns=SPLIT_COLUMNS,
        text=("model", "method", "family", "star_source"),
        boolean=("converged",),
        integer=("H", "run", "step", "maxiter", "maxfun", "restarts", "nit", "work"),
        keys=cols,
        expected=pd.DataFrame(keys, columns=cols),
        values={"model": model, "H": int(H)},
    )


def _normalised(controls: np.ndarray, setup: UAVSetup) -> np.ndarray:
    H = setup.planner.horizon
    return np.asarray(controls, dtype=float).reshape(-1) / np.tile(setup.uav.control_scale, H)


def _unique_rows(x: np.ndarray) -> np.ndarray:
    """The distinct rows of ``x`` in first-seen order."""
    _, first = np.unique(x, axis=0, return_index=True)
    return x[np.sort(first)]


def split_state(
    state: BeliefState,
    setup: UAVSetup,
    planners: Mapping[str, Method],
    cfg: Mapping[str, Any],
    scoring: Mapping[str, Any],
    seed: int,
) -> list[dict[str, Any]]:
    """The rows of one belief state (``state.warm`` already at the horizon of ``setup``):
    one per (method of ``planners`` with an own cost, budget of ``cfg``), in that order."""
    H = setup.planner.horizon
    n = 2 * H
    ident = {"model": state.model, "run": state.run, "step": state.step}
    args = (setup.uav, setup.target, setup.sensor)
    n_eval = int(scoring["n_eval"])
    eval_xy = target.sample_independent(
        state.x_hat,
        state.P_hat,
        H,
        n_eval,
        setup.target,
        job_rng(seed, "decisions_uav_eval", **ident),
    )[..., :2]
    ev = PlanningProblem(state.uav, state.P_hat, eval_xy, *args, setup.planner)
    polish_maxiter = int(cfg["polish_maxiter"])
    starts = job_rng(seed, "optimiser_split_starts", **ident, H=H).uniform(
        -1.0, 1.0, (int(cfg["polish_starts"]), n)
    )
    belief = Belief(state.uav, state.x_hat, state.P_hat)
    plan_budgets = budgets(cfg)
    per_method: dict[str, dict[str, Any]] = {}
    for name, method in planners.items():
        if not method.estimates_cost:
            continue
        rng = job_rng(seed, "decisions_uav_plan", **ident, **method.job_key())
        hyp = method.hypotheses(belief, setup, rng)
        own = PlanningProblem(
            state.uav, state.P_hat, hyp.states[..., :2], *args, setup.planner, weights=hyp.weights
        )
        results = []
        for maxiter, maxfun, restarts in plan_budgets:
            params = dataclasses.replace(
                setup.planner, maxiter=maxiter, maxfun=maxfun, restarts=restarts
            )
            planner = SampledCostPlanner(lambda b, r, hyp=hyp: hyp, *args, params)
            results.append(planner.plan(belief, state.warm, None))
        plans = np.array([_normalised(r.controls, setup) for r in results])
        ends = np.array(
            [polish(own, x0, polish_maxiter)[0] for x0 in (*starts, *_unique_rows(plans))]
        ).reshape(-1, n)
        own_costs = own.costs(np.vstack([plans, ends]))
        k = int(np.argmin(own_costs))  # first minimum: a budget plan wins ties
        per_method[name] = {
            "method": method,
            "results": results,
            "plans": plans,
            "ends": ends,
            "own": own_costs[: len(plans)],
            "star": k,
            "star_own": float(own_costs[k]),
            "star_source": STAR_SOURCES[int(k >= len(plans))],
        }
    if not per_method:
        return []
    # reference: multi-start polish of J_ev from the best candidates and uniform starts
    cands = np.vstack([np.vstack([p["plans"], p["ends"]]) for p in per_method.values()])
    cand_ev = ev.costs(cands)
    n_best = min(int(scoring["polish"]), len(cands))
    ev_starts = [cands[i] for i in np.argsort(cand_ev, kind="stable")[:n_best]]
    aux = job_rng(seed, "optimiser_split_aux", **ident, H=H)
    ev_starts += list(aux.uniform(-1.0, 1.0, (int(scoring["random_starts"]), n)))
    ev_ends = [polish(ev, x0, polish_maxiter)[0] for x0 in ev_starts]
    # every J_ev of the state from one batched evaluation: J_ref <= each of them exactly
    all_ev = ev.costs(np.vstack([cands, *[x[None, :] for x in ev_ends]]))
    ref = float(all_ev.min())
    rows = []
    offset = 0
    for name, p in per_method.items():
        method = p["method"]
        mine = all_ev[offset : offset + len(p["plans"]) + len(p["ends"])]
        offset += len(mine)
        plan_ev = mine[: len(p["plans"])]
        approx = (float(mine[p["star"]]) - ref) / ref
        for b, (maxiter, maxfun, restarts) in enumerate(plan_budgets):
            res = p["results"][b]
            regret = (float(plan_ev[b]) - ref) / ref
            rows.append(
                {
                    **ident,
                    "H": H,
                    "method": name,
                    "family": method.family,
                    "maxiter": maxiter,
                    "maxfun": maxfun,
                    "restarts": restarts,
                    "nit": int(res.nit),
                    "converged": bool(res.converged),
                    "work": int(res.work),
                    "own_cost": float(p["own"][b]),
                    "eval_cost": float(plan_ev[b]),
                    "ref_cost": ref,
                    "regret": regret,
                    "approx_regret": approx,
                    "optim_regret": regret - approx,
                    "star_own_cost": p["star_own"],
                    "star_source": p["star_source"],
                }
            )
    return rows


def run_optimiser_split(
    uav: Mapping[str, Any],
    model_variant: Mapping[str, Any],
    H: int,
    cfg: Mapping[str, Any],
    scoring: Mapping[str, Any],
    seed: int,
    runs: Sequence[int] | None = None,
) -> pd.DataFrame:
    """The split (module docstring) for one model variant (an entry of
    ``uav_models``: ``name`` and overrides) at horizon ``H``: one row per (run,
    step, method with an own cost, budget), :data:`SPLIT_COLUMNS`. ``uav`` is the validated
    ``uav`` section; ``cfg`` has ``runs``, ``steps``, ``methods``, ``budgets``,
    ``polish_starts``, ``polish_maxiter``; ``scoring`` has ``n_eval``, ``polish`` and
    ``random_starts`` (the decision study's). Runs on one BLAS thread. ``runs``: the belief
    states of these runs only (default ``0..runs-1``; a chunk job's rows are the unsplit
    job's rows of its runs, :mod:`rsmhp.studies.horizon.chunks`)."""
    model = str(model_variant["name"])
    H = guards.positive_int("H", H)
    base = horizon_setup(uav, model_variant, int(uav["planner"]["horizon"]))
    setup = horizon_setup(uav, model_variant, H)
    planners = split_methods(cfg)
    budgets(cfg)  # refuse a bad budget list before any work
    rows: list[dict[str, Any]] = []
    with threadpool_limits(limits=1):
        runs = range(int(cfg["runs"])) if runs is None else [int(r) for r in runs]
        states = belief_states(base, model, seed, runs, cfg["steps"])
        log.info("optimiser split %s H=%d: %d states x %d methods x %d budgets", model, H,
                 len(states), len(planners), len(cfg["budgets"]))  # fmt: skip
        for i, st in enumerate(states):
            h_state = dataclasses.replace(st, warm=_warm(st, H))
            rows += split_state(h_state, setup, planners, cfg, scoring, seed)
            log.info("optimiser split %s H=%d: state %d/%d done", model, H, i + 1, len(states))
    return pd.DataFrame(rows, columns=SPLIT_COLUMNS)
