r"""UAV decision study: open-loop regret of each method's plan at belief states, and paired
closed-loop runs of the methods on model variants (the sensitivity map).

Belief states
-------------
Closed-loop NBO runs of a model (runs ``0..n-1``, the main study's scenarios and noise,
:mod:`rsmhp.models.uav.simulation`) are stopped at the configured steps; the belief state "at step
k" is what the planner sees before planning step k+1: UAV state, tracker mean
:math:`\hat x_k` and covariance :math:`\hat P_k`, and the warm start (NBO's shifted plan;
zeros at k = 0, where :math:`\hat P_0 = P_0`, the most uncertain state).

Open-loop regret at one belief state
------------------------------------
Every method plans once, exactly as in the closed loop (its own hypotheses from
``job_rng(seed, "decisions_uav_plan", model=, run=, step=, method=, N_T=, N=, M=)``, same
warm start, same optimiser budget). Every plan is then scored on an independent evaluation
set of ``n_eval`` hypotheses drawn from the belief (``job_rng(seed, "decisions_uav_eval",
model=, run=, step=)``): :math:`\hat J_{ev}(x) = \frac1{T}\sum_i c_i(x)`, with
:math:`c_i(x) = \sum_j \mathrm{tr} P^i_j(x)` the planner's cost for hypothesis i. The
reference plan is the best of every method's plan and of a multi-start optimisation (the
planner's optimiser, ``uav.planner.optimiser``) of :math:`\hat J_{ev}` itself (starts: the
``polish`` best plans so far and ``random_starts`` uniform points of the box,
``eval_maxiter`` iterations). Regret of a plan :math:`x`:
:math:`\hat J_{ev}(x) - \hat J_{ev}(x_{best}) \ge 0`, with Monte-Carlo standard error
:math:`\mathrm{sd}_i(c_i(x) - c_i(x_{best}))/\sqrt T` (paired over the same hypotheses).
Because :math:`x_{best}` is optimised on the evaluation set, the regret is biased upwards by
at most that optimisation's overfit, :math:`O(1/T)`.

``regret_methods`` is the same difference against the best of the methods' plans only, at the
methods' common optimiser budget. It mixes approximation and optimisation error (a method's
plan can lose to another's because its cost is a worse approximation or because the optimiser
stopped at a poorer local minimum): nothing here separates the two.

Rank agreement: ``n_random`` plans uniform in the box (and ``n_random`` local perturbations
of the best plan, :math:`x_{best} + \mathcal N(0, 0.1^2)` clipped to the box) are costed by
every method's own objective and by :math:`\hat J_{ev}`; Spearman's rank correlation
between the two.

Shared by the studies ``rsmhp.studies.decisions``, ``rsmhp.studies.frontier`` and
``rsmhp.studies.horizon`` (so it lives below them).
"""

from __future__ import annotations

import copy
import dataclasses
import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from threadpoolctl import threadpool_limits

from rsmhp.core.seeding import job_rng
from rsmhp.models.uav import fused, methods, target
from rsmhp.models.uav.methods import Method
from rsmhp.models.uav.planner import Belief, PlanningProblem, polish
from rsmhp.models.uav.runs import simulate_runs
from rsmhp.models.uav.simulation import StepInfo, UAVSetup, draw_scenario, simulate_run
from rsmhp.pipeline.contracts import Contract
from rsmhp.pipeline.parallel import parallel_map
from rsmhp.pipeline.runstore import RunStore

__all__ = [
    "MAP_RUN_COLUMNS",
    "REGRET_COLUMNS",
    "BeliefState",
    "MapCell",
    "belief_states",
    "map_cells",
    "merge_variant",
    "run_map_cell",
    "run_uav_regret",
    "score_state",
]

log = logging.getLogger(__name__)

REGRET_COLUMNS = [
    "model",
    "run",
    "step",
    "trace_P",
    "method",
    "family",
    "N_T",
    "N",
    "M",
    "plan_cost",
    "eval_cost",
    "eval_se",
    "best_cost",
    "regret",
    "regret_se",
    "regret_rel",
    "regret_methods",
    "spearman_random",
    "spearman_local",
    "n_eval",
]
MAP_RUN_COLUMNS = [
    "cell",
    "row_value",
    "col_value",
    "method",
    "run",
    "mean_error",
    "final_error",
    "detect_rate",
    "lost",
    "plan_depth",
]


_REGRET_INTEGERS = ("run", "step", "N_T", "N", "M", "n_eval")
# Spearman correlations are undefined (empty) where a method's cost is constant over the plans
_REGRET_NULLABLE = ("spearman_random", "spearman_local")


def _regret_contract(rule: str, models: Sequence[str], runs: int, steps, method_cfg) -> Contract:
    names = ["model", "run", "step", "method"]
    keys = [
        (m, r, k, name)
        for m in models
        for r in range(int(runs))
        for k in sorted({int(s) for s in steps})
        for name in methods.from_config(method_cfg)
    ]
    return Contract(
        rule=rule,
        columns=REGRET_COLUMNS,
        text=("model", "method", "family"),
        integer=_REGRET_INTEGERS,
        nullable=_REGRET_NULLABLE,
        keys=names,
        expected=pd.DataFrame(keys, columns=names),
        min_rows=0,
    )


def regret_contract(cfg: Mapping[str, Any]) -> Contract:
    """What ``results/decisions/uav_regret.csv`` must hold for the ``decisions.uav`` config
    section: one row per (model, run, step, method)."""
    models = [m["name"] for m in cfg["models"]]
    return _regret_contract("decisions_uav", models, cfg["runs"], cfg["steps"], cfg["methods"])


def map_contracts(cfg: Mapping[str, Any], cell: str) -> tuple[Contract, Contract]:
    """What one map cell's runs CSV and regret CSV (rule ``decisions_map_cell``) must hold
    for the ``decisions.map`` config section: every (method, run) and every open-loop
    (run, step, method) of the cell. ``row_value``/``col_value`` are empty for an unlimited
    footprint (``null``)."""
    names = {c.name: c for c in map_cells(cfg)}
    if cell not in names:
        raise ValueError(f"unknown map cell {cell!r}; cells: {', '.join(names)}")
    keys = [(m, r) for m in methods.from_config(cfg["methods"]) for r in range(cfg["runs"])]
    runs = Contract(
        rule="decisions_map_cell",
        columns=MAP_RUN_COLUMNS,
        text=("cell", "method"),
        boolean=("lost",),
        integer=("run",),
        nullable=("row_value", "col_value", "plan_depth"),
        keys=("method", "run"),
        expected=pd.DataFrame(keys, columns=["method", "run"]),
        values={"cell": cell},
    )
    regret = _regret_contract(
        "decisions_map_cell", [cell], cfg["regret_runs"], cfg["regret_steps"], cfg["methods"]
    )
    return runs, regret


def merge_variant(uav: Mapping[str, Any], variant: Mapping[str, Any]) -> dict[str, Any]:
    """The ``uav`` config section with a model variant's overrides (``sensor``, ``target``,
    ``tracker`` sub-keys) merged in; ``name`` is ignored."""
    out = copy.deepcopy(dict(uav))
    for section, values in variant.items():
        if section == "name":
            continue
        if section not in ("sensor", "target", "tracker"):
            raise ValueError(
                f"decisions model variant: unknown section {section!r} "
                "(allowed: sensor, target, tracker)"
            )
        out[section] = {**out.get(section, {}), **dict(values)}
    return out


@dataclass(frozen=True)
class BeliefState:
    """The planner's input at one step of one closed-loop run."""

    model: str
    run: int
    step: int
    uav: np.ndarray
    x_hat: np.ndarray
    P_hat: np.ndarray
    warm: np.ndarray


def belief_states(
    setup: UAVSetup, model: str, seed: int, runs: Sequence[int], steps: Sequence[int]
) -> list[BeliefState]:
    """Belief states of closed-loop runs of the baseline method (NBO) ``runs`` at ``steps``
    (0 = the initial belief)."""
    H = setup.planner.horizon
    wanted = sorted(set(int(s) for s in steps))
    if wanted and wanted[-1] >= setup.steps:
        raise ValueError(
            f"belief-state step {wanted[-1]} (decisions.uav.steps / decisions.map.regret_steps) "
            f"is not before the run's last step (uav.scenario.steps = {setup.steps})"
        )
    base = methods.baseline()()
    out: list[BeliefState] = []
    for run in runs:
        got: dict[int, BeliefState] = {}
        if 0 in wanted:
            sc = draw_scenario(setup, seed, run)
            got[0] = BeliefState(model, run, 0, sc.uav, sc.estimate, setup.P0, np.zeros((H, 2)))
        later = [k for k in wanted if k > 0]
        if later:

            def observe(info: StepInfo, run=run, got=got, later=later) -> None:
                if info.step in later:
                    got[info.step] = BeliefState(
                        model,
                        run,
                        info.step,
                        info.uav.copy(),
                        info.estimate.copy(),
                        info.covariance.copy(),
                        info.warm_start.copy(),
                    )

            short = dataclasses.replace(setup, steps=max(later))
            simulate_run(short, base, seed, run, observer=observe)
        out.extend(got[k] for k in wanted)
    return out


def _positions(x: np.ndarray, problem: PlanningProblem) -> np.ndarray:
    return np.stack([problem.path(xi)[:, :2] for xi in np.atleast_2d(x)])


def score_state(
    state: BeliefState,
    setup: UAVSetup,
    planners: Mapping[str, Method],
    cfg: Mapping[str, Any],
    seed: int,
) -> list[dict[str, Any]]:
    """One row per method of ``planners`` (see the module docstring)."""
    H = setup.planner.horizon
    ident = {"model": state.model, "run": state.run, "step": state.step}
    eval_rng = job_rng(seed, "decisions_uav_eval", **ident)
    n_eval = int(cfg["n_eval"])
    eval_xy = target.sample_independent(
        state.x_hat, state.P_hat, H, n_eval, setup.target, eval_rng
    )[..., :2]
    args = (setup.uav, setup.target, setup.sensor, setup.planner)
    ev = PlanningProblem(state.uav, state.P_hat, eval_xy, *args)
    plans: dict[str, tuple[np.ndarray, float, PlanningProblem | None]] = {}
    belief = Belief(state.uav, state.x_hat, state.P_hat)
    scale = np.tile(setup.uav.control_scale, H)
    for name, method in planners.items():
        rng = job_rng(seed, "decisions_uav_plan", **ident, **method.job_key())
        res = method.planner(setup).plan(belief, state.warm, rng)
        # the method's own cost of any plan (rank agreement); a planner without hypotheses
        # (a tree search) has no cost of an arbitrary plan: its rank columns are NaN
        hyp = res.hypotheses
        prob = (
            None
            if hyp is None
            else PlanningProblem(
                state.uav, state.P_hat, hyp.states[..., :2], *args, weights=hyp.weights
            )
        )
        plans[name] = (res.controls.ravel() / scale, res.cost, prob)
    # reference: multi-start optimisation of the evaluation cost
    aux = job_rng(seed, "decisions_uav_aux", **ident)
    cands = np.array([p[0] for p in plans.values()])
    cand_cost = ev.costs(cands)
    starts = [cands[i] for i in np.argsort(cand_cost, kind="stable")[: int(cfg["polish"])]]
    starts += list(aux.uniform(-1.0, 1.0, (int(cfg["random_starts"]), 2 * H)))
    best_x, best_f = cands[int(np.argmin(cand_cost))], float(cand_cost.min())
    for x0 in starts:
        x, f = polish(ev, x0, int(cfg["eval_maxiter"]))
        if f < best_f:
            best_x, best_f = x, f
    # per-hypothesis costs c_i of every plan and of the best, on the evaluation set
    all_x = np.vstack([cands, best_x[None, :]])
    per_hyp = fused.covariance_traces(
        state.P_hat, _positions(all_x, ev), eval_xy, setup.target.dt, setup.target.Q, setup.sensor
    ).sum(axis=2)  # (C+1, T)
    best_c = per_hyp[-1]
    best_cost = float(best_c.mean())
    best_method_cost = float(per_hyp[:-1].mean(axis=1).min())
    # rank agreement on random and on local plans
    n_rand = int(cfg["n_random"])
    rand = aux.uniform(-1.0, 1.0, (n_rand, 2 * H))
    local = np.clip(best_x + aux.normal(0.0, 0.1, (n_rand, 2 * H)), -1.0, 1.0)
    ev_rand, ev_local = ev.costs(rand), ev.costs(local)
    rows = []
    for k, (name, (_, own, prob)) in enumerate(plans.items()):
        method = planners[name]
        diff = per_hyp[k] - best_c
        rows.append(
            {
                **ident,
                "trace_P": float(np.trace(state.P_hat)),
                "method": name,
                "family": method.family,
                **method.columns(),
                "plan_cost": own,
                "eval_cost": float(per_hyp[k].mean()),
                "eval_se": float(per_hyp[k].std(ddof=1) / np.sqrt(n_eval)),
                "best_cost": best_cost,
                "regret": float(diff.mean()),
                "regret_se": float(diff.std(ddof=1) / np.sqrt(n_eval)),
                "regret_rel": float(diff.mean() / best_cost),
                "regret_methods": float(per_hyp[k].mean() - best_method_cost),
                "spearman_random": _spearman(prob.costs(rand), ev_rand) if prob else NAN,
                "spearman_local": _spearman(prob.costs(local), ev_local) if prob else NAN,
                "n_eval": n_eval,
            }
        )
    return rows


NAN = float("nan")


def _spearman(a: np.ndarray, b: np.ndarray) -> float:
    """Spearman's rho; NaN when either side is constant (e.g. NBO's cost when its single
    hypothesis is out of every plan's footprint: the cost cannot rank the plans)."""
    if np.ptp(a) == 0.0 or np.ptp(b) == 0.0:
        return float("nan")
    from scipy import stats  # on first use: scipy.stats costs every importing job ~0.4 s

    return float(stats.spearmanr(a, b).statistic)


def _score_task(job) -> list[dict[str, Any]]:
    states, uav_cfg, methods_cfg, cfg, seed = job
    setup = UAVSetup.from_config(uav_cfg)
    planners = methods.from_config(methods_cfg)
    with threadpool_limits(limits=1):
        return [row for st in states for row in score_state(st, setup, planners, cfg, seed)]


def run_uav_regret(
    uav: Mapping[str, Any], cfg: Mapping[str, Any], seed: int, n_jobs: int = 1
) -> pd.DataFrame:
    """The open-loop study of the ``decisions.uav`` section for every model variant in
    ``cfg["models"]``; ``uav`` is the (validated) ``uav`` config section."""
    jobs = []
    n_states = 0
    for variant in cfg["models"]:
        uav_cfg = merge_variant(uav, variant)
        setup = UAVSetup.from_config(uav_cfg)
        with threadpool_limits(limits=1):
            states = belief_states(
                setup, variant["name"], seed, range(int(cfg["runs"])), cfg["steps"]
            )
        n_states += len(states)
        # one task per run's states (a task's rows never depend on the task split)
        by_run: dict[int, list[BeliefState]] = {}
        for st in states:
            by_run.setdefault(st.run, []).append(st)
        jobs += [(sts, uav_cfg, cfg["methods"], cfg, seed) for sts in by_run.values()]
    log.info(
        "decisions_uav: %d belief states x %d methods in %d tasks on %d workers",
        n_states,
        len(methods.from_config(cfg["methods"])),
        len(jobs),
        n_jobs,
    )
    rows = [r for part in parallel_map(_score_task, jobs, n_jobs, desc="states") for r in part]
    return pd.DataFrame(rows, columns=REGRET_COLUMNS)


# ------------------------------------------------------------------------ sensitivity map


@dataclass(frozen=True)
class MapCell:
    """One cell of the map: its name (``r<i>c<j>``, the rule wildcard) and model variant."""

    name: str
    row: int
    col: int
    row_value: Any
    col_value: Any
    variant: dict


def _set(variant: dict, key: str, value: Any) -> None:
    section, field = key.split(".")
    variant.setdefault(section, {})[field] = value


def map_cells(cfg: Mapping[str, Any]) -> list[MapCell]:
    """The cells of the ``decisions.map`` section: rows x cols, each axis a dotted key
    (``sensor.footprint_radius``, ``target.q``, ...) and its values (``null`` for a
    footprint radius means unlimited)."""
    cells = []
    rows, cols = cfg["rows"], cfg["cols"]
    for i, rv in enumerate(rows["values"]):
        for j, cv in enumerate(cols["values"]):
            variant: dict = {}
            _set(variant, rows["key"], rv)
            _set(variant, cols["key"], cv)
            cells.append(MapCell(f"r{i}c{j}", i, j, rv, cv, variant))
    return cells


def run_map_cell(
    uav: Mapping[str, Any],
    cfg: Mapping[str, Any],
    scoring: Mapping[str, Any],
    cell_name: str,
    seed: int,
    n_jobs: int = 1,
    store: RunStore | None = None,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Paired closed-loop runs of every map method in one cell (runs ``0..runs-1``, the same
    scenarios and noise for every method and every cell), and the open-loop regret at the
    belief states of NBO runs ``0..regret_runs-1`` at ``regret_steps``, scored as in
    :func:`score_state` with the settings ``scoring`` (n_eval, polish, random_starts,
    eval_maxiter, n_random).

    A run *loses the track* when its final location error exceeds ``track_loss_error`` m.
    With a ``store``, closed-loop runs it holds are read, not simulated
    (:mod:`rsmhp.models.uav.runs`). Returns (one row per (method, run):
    :data:`MAP_RUN_COLUMNS`; open-loop regret rows: :data:`REGRET_COLUMNS` with ``model`` =
    the cell name)."""
    cells = {c.name: c for c in map_cells(cfg)}
    if cell_name not in cells:
        raise ValueError(f"unknown map cell {cell_name!r}; cells: {', '.join(cells)}")
    cell = cells[cell_name]
    uav_cfg = merge_variant(uav, cell.variant)
    setup = UAVSetup.from_config(uav_cfg)
    planners = methods.from_config(cfg["methods"])
    runs = list(range(int(cfg["runs"])))
    jobs = [(setup, planners[m], seed, r) for m in planners for r in runs]
    log.info("map cell %s (%s): %d closed-loop runs", cell.name, cell.variant, len(jobs))
    out = simulate_runs(jobs, store, n_jobs, desc=f"cell {cell.name} runs")
    summaries = [summary for summary, _ in out]
    loss = float(cfg["track_loss_error"])
    run_rows = [
        {
            "cell": cell.name,
            "row_value": cell.row_value,
            "col_value": cell.col_value,
            "method": s["method"],
            "run": s["run"],
            "mean_error": s["mean_error"],
            "final_error": s["final_error"],
            "detect_rate": s.get("detect_rate", 1.0),
            "lost": bool(s["final_error"] > loss),
            # a tree search's mean plan depth over the run's steps (empty for the others)
            "plan_depth": s.get("diagnostics", {}).get("plan_depth", float("nan")),
        }
        for s in summaries
    ]
    with threadpool_limits(limits=1):
        states = belief_states(
            setup, cell.name, seed, range(int(cfg["regret_runs"])), cfg["regret_steps"]
        )
    jobs2 = [([st], uav_cfg, cfg["methods"], dict(scoring), seed) for st in states]
    regret = [r for part in parallel_map(_score_task, jobs2, n_jobs, desc="states") for r in part]
    return (
        pd.DataFrame(run_rows, columns=MAP_RUN_COLUMNS),
        pd.DataFrame(regret, columns=REGRET_COLUMNS),
    )


# ------------------------------------------------- model variants


def variant(models: list[Mapping[str, Any]], name: str) -> Mapping[str, Any]:
    """The model variant called ``name`` of ``uav_models``."""
    found = {m["name"]: m for m in models}
    if name not in found:
        raise ValueError(
            f"frontier.models: {name!r} is not a model of uav_models (allowed: {', '.join(found)})"
        )
    return found[name]
