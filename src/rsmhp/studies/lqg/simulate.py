"""LQG experiments: estimator convergence in P (paper Fig. 3), the NBO error over (a, H), and
Prop. 3 on its own setting (linear dynamics, linear cost: :func:`run_linear_cost`).

Both drivers return one row per (parameters, replicate). Row ``(P, replicate)`` draws
its ``P x H`` noise from ``job_rng(seed, <experiment>, a=..., H=..., ..., P=P, replicate=i)``.
"""

from __future__ import annotations

import itertools
import logging
from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.core.cost_estimators import nbo_estimate, uniform_estimate, weighted_estimate
from rsmhp.core.sampling import sample_independent
from rsmhp.core.seeding import job_rng
from rsmhp.models.lqg import oven as lqg
from rsmhp.models.lqg.linear_quadratic import LinearCost
from rsmhp.pipeline.contracts import Contract
from rsmhp.pipeline.parallel import chunked, parallel_map

__all__ = [
    "CONVERGENCE_COLUMNS",
    "LINEAR_COST_COLUMNS",
    "NBO_ERROR_COLUMNS",
    "convergence_contract",
    "estimate_row",
    "linear_cost_contract",
    "nbo_error_contract",
    "p_grid",
    "run_convergence",
    "run_linear_cost",
    "run_nbo_error",
]

log = logging.getLogger(__name__)

CONVERGENCE_COLUMNS = [
    "a",
    "H",
    "sigma",
    "r",
    "target",
    "x0",
    "u",
    "P",
    "replicate",
    "J_mhp",
    "J_mhp_weighted",
    "J_nbo",
    "J_exact",
]
NBO_ERROR_COLUMNS = [
    "a",
    "H",
    "sigma",
    "r",
    "target",
    "x0",
    "u_value",
    "P",
    "replicate",
    "J_mhp",
    "J_nbo",
    "nbo_error_sim",
    "nbo_error_se",
    "nbo_error_closed",
    "J_exact",
]


def _constants(model: lqg.LQGModel) -> dict[str, float]:
    """The model constants as the CSV columns hold them (column order of the tables)."""
    return {k: getattr(model, k) for k in ("a", "sigma", "r", "target", "x0")}


def convergence_contract(cfg: Mapping[str, Any]) -> Contract:
    """What ``results/lqg/convergence.csv`` must hold for the ``lqg`` config section ``cfg``:
    one row per (P, replicate) of the grid, the model constants of the config, finite
    estimates."""
    conv = cfg["convergence"]
    keys = itertools.product(p_grid(conv["P"]), range(int(conv["replicates"])))
    return Contract(
        rule="lqg_convergence",
        columns=CONVERGENCE_COLUMNS,
        text=("u",),
        integer=("H", "P", "replicate"),
        keys=("P", "replicate"),
        expected=pd.DataFrame(list(keys), columns=["P", "replicate"]),
        values={
            **_constants(lqg.LQGModel.from_config(cfg["model"])),
            "H": len(conv["u"]),
            "u": ";".join(repr(float(v)) for v in conv["u"]),
        },
    )


def nbo_error_contract(cfg: Mapping[str, Any]) -> Contract:
    """What ``results/lqg/nbo_error.csv`` must hold for the ``lqg`` config section ``cfg``:
    one row per (a, H, replicate) of the grid (``nbo_error_se`` is empty when P = 1)."""
    ne = cfg["nbo_error"]
    keys = itertools.product(
        [float(a) for a in ne["a_values"]],
        [int(h) for h in ne["H_values"]],
        range(int(ne["replicates"])),
    )
    params = _constants(lqg.LQGModel.from_config(cfg["model"]))
    del params["a"]
    return Contract(
        rule="lqg_nbo_error",
        columns=NBO_ERROR_COLUMNS,
        integer=("H", "P", "replicate"),
        nullable=("nbo_error_se",),
        keys=("a", "H", "replicate"),
        expected=pd.DataFrame(list(keys), columns=["a", "H", "replicate"]),
        values={**params, "P": int(ne["P"]), "u_value": float(ne["u_value"])},
    )


def p_grid(spec: Mapping[str, int]) -> list[int]:
    """``range(start, stop + 1, step)`` from a ``{start, stop, step}`` mapping (stop inclusive)."""
    return list(range(int(spec["start"]), int(spec["stop"]) + 1, int(spec["step"])))


def estimate_row(
    seed: int, experiment: str, model: lqg.LQGModel, u: np.ndarray, P: int, replicate: int
) -> tuple[float, float, float]:
    """One MHP estimate from P non-overlapping trajectories of ``model`` under controls ``u``
    (from ``model.x0``): (uniform, weighted, std of the P costs; NaN for P = 1). The noise comes
    from ``job_rng(seed, experiment, a=, H=, sigma=, r=, target=, x0=, u=, P=, replicate=)``."""
    rng = job_rng(
        seed,
        experiment,
        a=model.a,
        H=len(u),
        sigma=model.sigma,
        r=model.r,
        target=model.target,
        x0=model.x0,
        u=u,
        P=P,
        replicate=replicate,
    )
    traj = sample_independent(model, [model.x0], u, P, rng)
    return (
        float(uniform_estimate(traj.cost)),
        float(weighted_estimate(traj.cost, traj.log_likeliness)),
        float(np.std(traj.cost, ddof=1)) if P > 1 else float("nan"),
    )


def _convergence_chunk(
    job: tuple[int, lqg.LQGModel, tuple[float, ...], list[int], int],
) -> list[dict]:
    seed, params, u_t, p_values, replicates = job
    u = np.asarray(u_t)
    j_nbo = lqg.nbo_cost(u, **params.closed_form_args(sigma=False))
    j_exact = lqg.exact_cost(u, **params.closed_form_args())
    u_text = ";".join(repr(float(v)) for v in u)
    rows = []
    for P in p_values:
        for rep in range(replicates):
            j_u, j_w, _ = estimate_row(seed, "lqg_convergence", params, u, P, rep)
            rows.append(
                {
                    "a": params.a,
                    "H": len(u),
                    "sigma": params.sigma,
                    "r": params.r,
                    "target": params.target,
                    "x0": params.x0,
                    "u": u_text,
                    "P": P,
                    "replicate": rep,
                    "J_mhp": j_u,
                    "J_mhp_weighted": j_w,
                    "J_nbo": j_nbo,
                    "J_exact": j_exact,
                }
            )
    return rows


def run_convergence(cfg: Mapping[str, Any], seed: int, n_jobs: int = 1) -> pd.DataFrame:
    """Fig. 3 experiment: ``replicates`` MHP estimates (non-overlapping, uniform and weighted)
    for every P in the grid, next to the NBO and exact costs (closed forms).

    ``cfg`` is the ``lqg`` config section (``model`` and ``convergence``).
    """
    params = lqg.LQGModel.from_config(cfg["model"])
    conv = cfg["convergence"]
    u = tuple(float(v) for v in conv["u"])
    ps = p_grid(conv["P"])
    reps = int(conv["replicates"])
    # large P first so the long chunks start early; chunking never changes the numbers
    chunks = chunked(sorted(ps, reverse=True), max(1, 4 * n_jobs))
    jobs = [(seed, params, u, chunk, reps) for chunk in chunks]
    log.info(
        "lqg_convergence: %d P values x %d replicates in %d chunks on %d workers",
        len(ps),
        reps,
        len(jobs),
        n_jobs,
    )
    rows = [
        row
        for part in parallel_map(_convergence_chunk, jobs, n_jobs, desc="chunks")
        for row in part
    ]
    df = pd.DataFrame(rows, columns=CONVERGENCE_COLUMNS)
    return df.sort_values(["P", "replicate"], kind="stable").reset_index(drop=True)


def _nbo_error_chunk(job: tuple[int, Mapping[str, Any], list[tuple[float, int]]]) -> list[dict]:
    seed, cfg, grid = job
    ne = cfg["nbo_error"]
    P, reps, u_value = int(ne["P"]), int(ne["replicates"]), float(ne["u_value"])
    rows = []
    for a, H in grid:
        params = lqg.LQGModel.from_config(cfg["model"], a=a)
        u = np.full(H, u_value)
        j_nbo_sim = nbo_estimate(params, [params.x0], u)
        closed = lqg.nbo_error(H, a=params.a, r=params.r, sigma=params.sigma)
        j_exact = lqg.exact_cost(u, **params.closed_form_args())
        for rep in range(reps):
            j_u, _, sd = estimate_row(seed, "lqg_nbo_error", params, u, P, rep)
            rows.append(
                {
                    "a": params.a,
                    "H": H,
                    "sigma": params.sigma,
                    "r": params.r,
                    "target": params.target,
                    "x0": params.x0,
                    "u_value": u_value,
                    "P": P,
                    "replicate": rep,
                    "J_mhp": j_u,
                    "J_nbo": j_nbo_sim,
                    "nbo_error_sim": j_u - j_nbo_sim,
                    "nbo_error_se": sd / np.sqrt(P),
                    "nbo_error_closed": closed,
                    "J_exact": j_exact,
                }
            )
    return rows


def run_nbo_error(cfg: Mapping[str, Any], seed: int, n_jobs: int = 1) -> pd.DataFrame:
    r"""NBO error over the (a, H) grid: simulated :math:`\hat J_P - J_{NBO}` (the NBO cost from
    the simulated system with zero noise) next to :math:`r\sigma^2\sum_{n<H}(1-a)^{2n}`."""
    ne = cfg["nbo_error"]
    grid = [(float(a), int(H)) for a in ne["a_values"] for H in ne["H_values"]]
    chunks = chunked(grid, max(1, 4 * n_jobs))
    jobs = [(seed, dict(cfg), chunk) for chunk in chunks]
    log.info(
        "lqg_nbo_error: %d (a, H) points x %d replicates, P=%d, %d workers",
        len(grid),
        ne["replicates"],
        ne["P"],
        n_jobs,
    )
    rows = [
        row for part in parallel_map(_nbo_error_chunk, jobs, n_jobs, desc="chunks") for row in part
    ]
    df = pd.DataFrame(rows, columns=NBO_ERROR_COLUMNS)
    return df.sort_values(["a", "H", "replicate"], kind="stable").reset_index(drop=True)


LINEAR_COST_COLUMNS = ["H", "n", "replicate", "estimate", "J_exact", "var_prop3"]


def linear_cost_contract(cfg: Mapping[str, Any]) -> Contract:
    """What ``results/lqg/linear_cost.csv`` must hold for the ``lqg`` config section ``cfg``:
    one row per (n, replicate) of ``lqg.linear_cost``."""
    lc = cfg["linear_cost"]
    keys = itertools.product([int(n) for n in lc["n"]], range(int(lc["replicates"])))
    return Contract(
        rule="lqg_linear_cost",
        columns=LINEAR_COST_COLUMNS,
        integer=("H", "n", "replicate"),
        keys=("n", "replicate"),
        expected=pd.DataFrame(list(keys), columns=["n", "replicate"]),
        values={"H": int(lc["H"])},
    )


def run_linear_cost(cfg: Mapping[str, Any], seed: int) -> pd.DataFrame:
    r"""Prop. 3 on its own premise: the linear-cost system :meth:`LinearCost.example` (H from
    ``cfg["linear_cost"]``), for each n of the grid ``replicates`` Monte-Carlo estimates
    :math:`J_n = \frac1n\sum_i p_i` of n independent trajectories
    (:func:`rsmhp.core.sampling.sample_independent`; replicate ``i`` of size ``n`` draws from
    ``job_rng(seed, "lqg_linear_cost", H=H, n=n, replicate=i)``), next to the exact
    :math:`J = E[p]` and the paper's variance formula :math:`\mathrm{Var}(p) =
    C[\sum_k \mathcal A_k \Sigma \mathcal A_k^\top]C^\top` (``var_prop3``)."""
    lc = cfg["linear_cost"]
    H, reps = int(lc["H"]), int(lc["replicates"])
    system = LinearCost.example(H)
    j_exact, var = system.exact_cost(), system.prop3_variance()
    log.info("lqg_linear_cost: H = %d, n in %s, %d replicates", H, list(lc["n"]), reps)
    rows = []
    for n in (int(v) for v in lc["n"]):
        for rep in range(reps):
            rng = job_rng(seed, "lqg_linear_cost", H=H, n=n, replicate=rep)
            cost = sample_independent(system, system.x0, system.u, n, rng).cost
            rows.append((H, n, rep, float(cost.mean()), j_exact, var))
    return pd.DataFrame(rows, columns=LINEAR_COST_COLUMNS)
