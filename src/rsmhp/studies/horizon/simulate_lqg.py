r"""The oven LQG at long horizons (``horizon.lqg``): cost estimators and decision regret as the
horizon H grows, where every number has an exact oracle.

Problems. For each ``a`` of ``sim_a`` and H of ``sim_H``: the oven model (``lqg.model`` with
that a) and the H-step open-loop optimum :math:`u^*(H)`
(:func:`rsmhp.models.lqg.oven.optimal_controls`)
as the control sequence, the plan a planner would settle on. Named ``hz_a<a>_h<H>``.

**Estimators** (:func:`run_lqg_estimators`, the estimator study's sampling and rows,
:func:`rsmhp.models.lqg.ablation.ablation_rows`): at every problem, pruned shared-draw trees
(``estimators.pruned_N`` draws per level, the M most likely partial trajectories kept, M in
``estimators.n``; only cells with :math:`N^H > M`, i.e. trees that are pruned: at H = 24 and
N = 4 the full tree would have :math:`4^{24} \approx 2.8 \cdot 10^{14}` leaves, so pruning is
the only way a tree runs there), Monte Carlo and scrambled Sobol' (RQMC) with n = M
trajectories (equal trajectory counts), NBO and the 2H cubature sigma points (exact for this
quadratic cost). One row per replicate (:data:`rsmhp.models.lqg.ablation.ABLATION_COLUMNS`:
estimate, exact J, NBO's J); ``replicates`` replicates per random cell.

**Regret** (:func:`run_lqg_regret`): the decision study's methods and exact sample-average
argmins (:func:`rsmhp.models.lqg.regret.run_lqg_regret`) on the grid (``sim_a``,
``sim_H``, ``regret.P``, ``regret.methods``, pruned trees with ``regret.pruned_N`` draws per
level); the closed forms of :mod:`rsmhp.models.lqg.regret_summary` apply unchanged.

Streams: estimator rows are keyed like the estimator study's (experiment ``estimators``,
problem name and spec, scheme, N, M, n, replicate), under this study's own problem names;
regret rows use the decision study's keys (``decisions_lqg``: method, N, M, P, replicate) with
draws made for this study's longest horizon. Neither depends on worker order or on the other
cells.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Mapping
from typing import Any

import pandas as pd

from rsmhp.models.lqg import oven as lqg
from rsmhp.models.lqg import regret as decisions_lqg
from rsmhp.models.lqg.ablation import (
    ABLATION_COLUMNS,
    GridPoint,
    _weightings,
    build_problem,
    n_trajectories,
    run_points,
)
from rsmhp.models.lqg.linear_quadratic import LinearQuadratic
from rsmhp.pipeline.contracts import Contract

__all__ = [
    "estimator_contract",
    "estimator_points",
    "problem_name",
    "problem_specs",
    "pruned_from",
    "regret_config",
    "regret_contract",
    "run_lqg_estimators",
    "run_lqg_regret",
]

log = logging.getLogger(__name__)

#: the estimator schemes of the study, in table order
SCHEMES = ("nbo", "cubature", "mc", "sobol", "pruned")


def problem_name(a: float, H: int) -> str:
    """``hz_a<a>_h<H>``, e.g. ``hz_a0.5_h24``."""
    return f"hz_a{float(a):g}_h{int(H)}"


def problem_specs(cfg: Mapping[str, Any], model: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """The estimator-study specs (``kind: scalar_lqg``, ``a``, ``u`` = the H-step optimum) of
    every (a, H) of ``cfg`` (``horizon.lqg``), keyed by :func:`problem_name`; ``model`` is
    ``lqg.model``."""
    kw = {k: float(model[k]) for k in ("x0", "r", "target")}
    out = {}
    for a in cfg["sim_a"]:
        for H in cfg["sim_H"]:
            u = lqg.optimal_controls(int(H), a=float(a), **kw)
            out[problem_name(a, H)] = {"kind": "scalar_lqg", "a": float(a), "u": u.tolist()}
    return out


def _problems(cfg: Mapping[str, Any], model: Mapping[str, Any]) -> dict[str, LinearQuadratic]:
    return {n: build_problem(s, model) for n, s in problem_specs(cfg, model).items()}


def estimator_points(
    cfg: Mapping[str, Any], problems: Mapping[str, LinearQuadratic]
) -> list[GridPoint]:
    """Every estimator cell (module docstring), per problem in :data:`SCHEMES` order."""
    est = cfg["estimators"]
    ns = [int(n) for n in est["n"]]
    pts: list[GridPoint] = []
    for name, prob in problems.items():
        pts += [GridPoint(name, "nbo"), GridPoint(name, "cubature")]
        pts += [GridPoint(name, s, n=n) for s in ("mc", "sobol") for n in ns]
        pts += [
            GridPoint(name, "pruned", N=int(N), M=m)
            for N in est["pruned_N"]
            for m in ns
            if int(N) ** prob.H > m
        ]
    return pts


def estimator_contract(cfg: Mapping[str, Any], model: Mapping[str, Any]) -> Contract:
    """What ``results/horizon/lqg_estimators.csv`` must hold: one row per (cell, weighting,
    replicate) of :func:`estimator_points`, one replicate for the deterministic schemes."""
    problems = _problems(cfg, model)
    reps = int(cfg["replicates"])
    names = ["problem", "scheme", "weighting", "N", "M", "n_trajectories", "replicate"]
    keys = [
        (p.problem, p.scheme, w, p.N, p.M, n_trajectories(p, problems[p.problem]), r)
        for p in estimator_points(cfg, problems)
        for w in _weightings(p.scheme)
        for r in range(1 if p.deterministic else reps)
    ]
    return Contract(
        rule="horizon_lqg_estimators",
        columns=ABLATION_COLUMNS,
        text=("problem", "scheme", "weighting"),
        integer=("N", "M", "H", "n_trajectories", "n_nodes", "replicate"),
        keys=names,
        expected=pd.DataFrame(keys, columns=names),
    )


def run_lqg_estimators(
    cfg: Mapping[str, Any], model: Mapping[str, Any], seed: int, n_jobs: int = 1
) -> pd.DataFrame:
    """Every estimator cell of ``cfg`` (``horizon.lqg``) with its replicates, one row per
    estimate (:data:`rsmhp.models.lqg.ablation.ABLATION_COLUMNS`), in contract order."""
    specs = problem_specs(cfg, model)
    problems = {n: build_problem(s, model) for n, s in specs.items()}
    points = estimator_points(cfg, problems)
    df = run_points(
        points, specs, model, seed, int(cfg["replicates"]), n_jobs, "horizon_lqg_estimators"
    )
    order = {(p.problem, p.scheme, p.N, p.M, p.n): i for i, p in enumerate(points)}
    pos = [
        order[(pr, s, n, m, t if s in ("mc", "sobol") else 0)]
        for pr, s, n, m, t in zip(
            df["problem"], df["scheme"], df["N"], df["M"], df["n_trajectories"], strict=True
        )
    ]
    df = df.assign(_o=pos).sort_values(["_o", "weighting", "replicate"], kind="stable")
    return df.drop(columns="_o").reset_index(drop=True)


def regret_config(cfg: Mapping[str, Any]) -> dict[str, Any]:
    """The ``decisions.lqg``-shaped grid of the study's regret part (no full trees: at the
    long horizons they would need N^H leaves)."""
    reg = cfg["regret"]
    return {
        "a_values": [float(a) for a in cfg["sim_a"]],
        "H_values": [int(h) for h in cfg["sim_H"]],
        "P": [int(p) for p in reg["P"]],
        "tree_N": [],
        "pruned_N": int(reg["pruned_N"]),
        "max_leaves": 1,
        "replicates": int(cfg["replicates"]),
        "methods": list(reg["methods"]),
    }


def regret_contract(cfg: Mapping[str, Any]) -> Contract:
    """What ``results/horizon/lqg_regret.csv`` must hold (the decision study's contract on
    :func:`regret_config`, written by rule ``horizon_lqg_regret``)."""
    c = decisions_lqg.regret_contract(regret_config(cfg))
    return dataclasses.replace(c, rule="horizon_lqg_regret")


def run_lqg_regret(
    cfg: Mapping[str, Any], model: Mapping[str, Any], seed: int, n_jobs: int = 1
) -> pd.DataFrame:
    """The regret rows of :func:`regret_config` (``model``: ``lqg.model``)."""
    return decisions_lqg.run_lqg_regret(regret_config(cfg), model, seed, n_jobs)


def pruned_from(N: int, M: int, hs: list[int]) -> int | None:
    """The smallest horizon of ``hs`` at which a tree with N draws per level has more than M
    leaves (:math:`N^H > M`: pruned, M trajectories kept), or None."""
    found = [h for h in sorted(hs) if int(N) ** int(h) > int(M)]
    return found[0] if found else None
