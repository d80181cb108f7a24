r"""Estimator ablation: every scheme x weighting x (N, M, budget) on problems with exact J.

Schemes (one row per replicate; ``N``/``M`` are 0 where they do not apply):

============== ============================================== ===================== =========
scheme         sample                                          n_trajectories        weighting
============== ============================================== ===================== =========
``mc``         n independent trajectories (paper Fig. 1b)      n                     uniform,
                                                                                     weighted
``antithetic`` n/2 draws and their negatives                   n                     uniform
``sobol``      scrambled Sobol' (randomized QMC)               n                     uniform
``tree``       shared-draw tree, N per level (paper Fig. 1a)   N^H                   uniform,
                                                                                     weighted
``tree_pernode`` every node draws its own N children           N^H                   uniform,
                                                                                     weighted
``pruned``     shared-draw tree pruned to the M most likely    M                     uniform,
                                                                                     weighted
``cubature``   2D sigma points (deterministic)                 2D                    quadrature
``gauss_hermite`` q^D tensor rule, q = N (deterministic)       q^D                   quadrature
``nbo``        nominal trajectory (deterministic)              1                     nominal
============== ============================================== ===================== =========

Uniform and weighted rows of a replicate are computed from the *same* sample (paired).
``cpu_seconds`` is the process CPU time of drawing the sample and forming the estimate; it is the
only column that is not reproducible bit for bit. Deterministic schemes have one replicate.
Trees of the scalar problems (one-dimensional noise) are sampled for many replicates at once
(:func:`rsmhp.core.sampling.sample_tree_batch`, bit-identical estimates); their ``cpu_seconds`` is
the batch's sampling time divided by its replicates, plus the replicate's own estimate time.

Shared by the studies ``rsmhp.studies.estimators`` and ``rsmhp.studies.horizon`` (so it lives
below them).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.core import designs
from rsmhp.core.cost_estimators import uniform_estimate, weighted_estimate
from rsmhp.core.sampling import rollout, rollout_cost, sample_tree, sample_tree_batch
from rsmhp.core.seeding import job_rng, job_rngs
from rsmhp.models.lqg.linear_quadratic import LinearQuadratic
from rsmhp.pipeline.contracts import Contract
from rsmhp.pipeline.parallel import parallel_map

__all__ = [
    "ABLATION_COLUMNS",
    "BATCH_LEAVES",
    "CELL",
    "SUMMARY_COLUMNS",
    "GridPoint",
    "ablation_contract",
    "build_problem",
    "by_weight",
    "grid_points",
    "n_trajectories",
    "point_weight",
    "run_ablation",
    "run_points",
    "sort_ablation",
    "summarize_ablation",
]

log = logging.getLogger(__name__)

ABLATION_COLUMNS = [
    "problem",
    "scheme",
    "weighting",
    "N",
    "M",
    "H",
    "n_trajectories",
    "n_nodes",
    "replicate",
    "estimate",
    "J_exact",
    "J_nbo",
    "cpu_seconds",
]

WEIGHTED_SCHEMES = ("mc", "tree", "tree_pernode", "pruned")


def build_problem(spec: Mapping[str, Any], lqg_model: Mapping[str, Any]) -> LinearQuadratic:
    """A test problem from its config entry.

    ``kind: scalar_lqg``: the oven model (``lqg.model``, overridable per problem) with control
    sequence ``u``. ``kind: ncv_2d``: a 2-D near-constant-velocity point mass, state (px, py, vx,
    vy), input acceleration (ax, ay), :math:`A = [[I, dt I], [0, I]]`, :math:`B = [[dt^2/2 I],
    [dt I]]`, :math:`\\Sigma = q [[dt^3/3 I, dt^2/2 I], [dt^2/2 I, dt I]]`, stage cost
    :math:`x^\\top \\mathrm{diag}(w_p, w_p, w_v, w_v) x + r_u |u|^2`, terminal cost
    :math:`(x-t)^\\top \\mathrm{diag}(f_p, f_p, f_v, f_v)(x-t)`.
    """
    kind = spec["kind"]
    if kind == "scalar_lqg":
        m = {**lqg_model, **{k: spec[k] for k in ("a", "x0", "r", "target", "sigma") if k in spec}}
        return LinearQuadratic.scalar_lqg(
            spec["u"], x0=m["x0"], a=m["a"], r=m["r"], target=m["target"], sigma=m["sigma"]
        )
    if kind == "ncv_2d":
        dt, q = float(spec["dt"]), float(spec["q"])
        eye, zero = np.eye(2), np.zeros((2, 2))
        return LinearQuadratic(
            A=np.block([[eye, dt * eye], [zero, eye]]),
            B=np.vstack([0.5 * dt**2 * eye, dt * eye]),
            Sigma=q * np.block([[dt**3 / 3 * eye, dt**2 / 2 * eye], [dt**2 / 2 * eye, dt * eye]]),
            Q=np.diag([spec["w_pos"]] * 2 + [spec["w_vel"]] * 2),
            R=spec["r_u"] * eye,
            Qf=np.diag([spec["f_pos"]] * 2 + [spec["f_vel"]] * 2),
            target=spec["target"],
            x0=spec["x0"],
            u=np.asarray(spec["u"], dtype=float),
        )
    raise ValueError(f"unknown problem kind {kind!r} (allowed: scalar_lqg, ncv_2d)")


@dataclass(frozen=True)
class GridPoint:
    """One ablation cell: a problem, a scheme and its size parameters."""

    problem: str
    scheme: str
    N: int = 0
    M: int = 0
    n: int = 0  # budget for mc / antithetic / sobol

    @property
    def deterministic(self) -> bool:
        return self.scheme in ("cubature", "gauss_hermite", "nbo")


def grid_points(cfg: Mapping[str, Any], problems: Mapping[str, LinearQuadratic]) -> list[GridPoint]:
    """Every (problem, scheme, N, M, n) cell of the configured grid (``estimators`` section)."""
    pts: list[GridPoint] = []
    schemes = cfg["schemes"]
    for name, prob in problems.items():
        D = prob.H * prob.d
        for scheme in schemes:
            if scheme in ("mc", "antithetic", "sobol"):
                pts += [GridPoint(name, scheme, n=n) for n in cfg["budgets"]]
            elif scheme in ("tree", "tree_pernode"):
                pts += [
                    GridPoint(name, scheme, N=N)
                    for N in cfg["tree_N"]
                    if N**prob.H <= cfg["max_leaves"]
                ]
            elif scheme == "pruned":
                pts += [
                    GridPoint(name, scheme, N=N, M=M)
                    for N in cfg["pruning"]["N"]
                    for M in cfg["pruning"]["M"]
                    if M <= N
                ]
            elif scheme == "gauss_hermite":
                qs = sorted({designs.gauss_hermite_order(n, D) for n in cfg["budgets"]} - {0})
                pts += [GridPoint(name, scheme, N=q) for q in qs]
            elif scheme in ("cubature", "nbo"):
                pts.append(GridPoint(name, scheme))
            else:
                raise ValueError(f"unknown scheme {scheme!r}")
    return pts


def n_trajectories(point: GridPoint, prob: LinearQuadratic) -> int:
    """Trajectories (leaves, points) behind one estimate of ``point``."""
    s, H, D = point.scheme, prob.H, prob.H * prob.d
    if s in ("mc", "antithetic", "sobol"):
        return point.n
    if s in ("tree", "tree_pernode"):
        return point.N**H
    if s == "pruned":
        keep = 1
        for _ in range(H):
            keep = min(point.M, keep * point.N)
        return keep
    return {"cubature": 2 * D, "gauss_hermite": point.N**D, "nbo": 1}[s]


def _weightings(scheme: str) -> tuple[str, ...]:
    """The ``weighting`` values of a scheme's rows (see :func:`_rows`)."""
    if scheme in designs.DETERMINISTIC:
        return ("quadrature",)
    if scheme == "nbo":
        return ("nominal",)
    return ("uniform", "weighted") if scheme in WEIGHTED_SCHEMES else ("uniform",)


def ablation_contract(cfg: Mapping[str, Any], lqg_model: Mapping[str, Any]) -> Contract:
    """What ``results/estimators/ablation.csv`` must hold for the ``estimators`` config
    section: one row per (grid point, weighting, replicate), one replicate for the
    deterministic schemes, finite estimates."""
    specs = {s["name"]: {k: v for k, v in s.items() if k != "name"} for s in cfg["problems"]}
    problems = {name: build_problem(spec, lqg_model) for name, spec in specs.items()}
    reps = int(cfg["replicates"])
    keys = [
        (p.problem, p.scheme, w, p.N, p.M, n_trajectories(p, problems[p.problem]), r)
        for p in grid_points(cfg, problems)
        for w in _weightings(p.scheme)
        for r in range(1 if p.deterministic else reps)
    ]
    names = ["problem", "scheme", "weighting", "N", "M", "n_trajectories", "replicate"]
    return Contract(
        rule="estimators_ablation",
        columns=ABLATION_COLUMNS,
        text=("problem", "scheme", "weighting"),
        integer=("N", "M", "H", "n_trajectories", "n_nodes", "replicate"),
        keys=names,
        expected=pd.DataFrame(keys, columns=names),
    )


def _sample(point: GridPoint, prob: LinearQuadratic, rng: np.random.Generator | None):
    """Returns (cost, log_likeliness or None, quadrature weights or None, n_nodes)."""
    chol = prob.noise.chol  # factorized once per problem (cached GaussianNoise)
    H = prob.H
    s = point.scheme
    if s == "mc":
        traj = rollout(prob, prob.x0, prob.u, designs.monte_carlo(rng, point.n, H, chol)[0])
        return traj.cost, traj.log_likeliness, None, point.n * H
    if s in ("antithetic", "sobol"):
        w, wt = getattr(designs, s)(rng, point.n, H, chol)
        return rollout_cost(prob, prob.x0, prob.u, w), None, wt, point.n * H
    if s in ("tree", "tree_pernode", "pruned"):
        tree = sample_tree(
            prob,
            prob.x0,
            prob.u,
            point.N,
            rng,
            max_keep=point.M if s == "pruned" else None,
            shared_draws=s != "tree_pernode",
        )
        return tree.leaves.cost, tree.leaves.log_likeliness, None, _tree_nodes(point, H)
    if s == "cubature":
        w, wt = designs.cubature(H, chol)
        return rollout_cost(prob, prob.x0, prob.u, w), None, wt, len(wt) * H
    if s == "gauss_hermite":
        w, wt = designs.gauss_hermite(point.N, H, chol)
        return rollout_cost(prob, prob.x0, prob.u, w), None, wt, len(wt) * H
    if s == "nbo":
        return rollout_cost(prob, prob.x0, prob.u, np.zeros((1, H, prob.d))), None, np.ones(1), H
    raise ValueError(f"unknown scheme {s!r}")


def _tree_nodes(point: GridPoint, H: int) -> int:
    """Nodes drawn by a (pruned) tree: sum over levels of the children created."""
    if point.scheme != "pruned":
        return sum(point.N**k for k in range(1, H + 1))
    nodes, n_keep = 0, 1
    for _ in range(H):
        nodes += n_keep * point.N
        n_keep = min(point.M, n_keep * point.N)
    return nodes


# trees of one cell sampled together (bounded memory: leaves x replicates per batch)
BATCH_LEAVES = 1 << 20


def _batched_tree_samples(point: GridPoint, prob: LinearQuadratic, rngs: list) -> Iterator:
    """(cost, loglik, cpu seconds per replicate) of every replicate of a tree cell, sampled
    with :func:`rsmhp.core.sampling.sample_tree_batch` (bit-identical to one tree at a time for
    these row-wise problems; see its docstring)."""
    leaves = point.M if point.scheme == "pruned" else point.N**prob.H
    per_batch = max(1, BATCH_LEAVES // max(leaves, 1))
    for start in range(0, len(rngs), per_batch):
        chunk = rngs[start : start + per_batch]
        t0 = time.process_time()
        cost, loglik = sample_tree_batch(
            prob,
            prob.x0,
            prob.u,
            point.N,
            chunk,
            max_keep=point.M if point.scheme == "pruned" else None,
            shared_draws=point.scheme != "tree_pernode",
        )
        cpu = (time.process_time() - t0) / len(chunk)
        for r in range(len(chunk)):
            yield cost[r], loglik[r], cpu


def ablation_rows(
    point: GridPoint, prob: LinearQuadratic, spec: Mapping, seed: int, reps: int
) -> Iterator:
    """The ablation rows of one grid point (every replicate), lazily (memory estimates)."""
    j_exact, j_nbo = prob.exact_cost(), prob.nbo_cost()
    n_reps = 1 if point.deterministic else reps
    rngs = job_rngs(
        seed,
        "estimators",
        "replicate",
        range(n_reps),
        problem=point.problem,
        spec=spec,
        scheme=point.scheme,
        N=point.N,
        M=point.M,
        n=point.n,
    )
    batched = None
    if point.scheme in ("tree", "tree_pernode", "pruned") and prob.noise.rowwise:
        batched = _batched_tree_samples(point, prob, list(rngs))
        rngs = range(n_reps)
    for rep, stream in enumerate(rngs):
        rng = None if point.deterministic else stream
        t0 = time.process_time()
        if batched is not None:
            cost, loglik, cpu_sample = next(batched)
            wts, nodes = None, _tree_nodes(point, prob.H)
        else:
            cost, loglik, wts, nodes = _sample(point, prob, rng)
            cpu_sample = 0.0
        if wts is not None:
            estimates = {
                "quadrature"
                if point.scheme in designs.DETERMINISTIC
                else "nominal"
                if point.scheme == "nbo"
                else "uniform": float(wts @ cost)
            }
        else:
            estimates = {"uniform": float(uniform_estimate(cost))}
            if point.scheme in WEIGHTED_SCHEMES:
                estimates["weighted"] = float(weighted_estimate(cost, loglik))
        cpu = time.process_time() - t0 + cpu_sample
        for weighting, est in estimates.items():
            yield {
                "problem": point.problem,
                "scheme": point.scheme,
                "weighting": weighting,
                "N": point.N,
                "M": point.M,
                "H": prob.H,
                "n_trajectories": len(cost),
                "n_nodes": nodes,
                "replicate": rep,
                "estimate": est,
                "J_exact": j_exact,
                "J_nbo": j_nbo,
                "cpu_seconds": cpu,
            }


def _task(job) -> list[dict]:
    points, problem_specs, lqg_model, seed, reps = job
    out = []
    for point in points:
        spec = problem_specs[point.problem]
        prob = build_problem(spec, lqg_model)
        out.extend(ablation_rows(point, prob, spec, seed, reps))
    return out


def point_weight(point: GridPoint, prob: LinearQuadratic) -> int:
    """A rough size of the work of one grid point: trajectories or leaves times H times the
    squared state dimension (the matrix products of a step); what :func:`by_weight` orders
    by. Only the order in which cells are computed depends on it, never a number."""
    size = point.N**prob.H if point.M == 0 else point.N * point.M
    return max(point.n, size, 1) * prob.H * prob.d**2


def by_weight(points: list[GridPoint], problems: Mapping[str, LinearQuadratic]) -> list[GridPoint]:
    """``points``, largest :func:`point_weight` first (ties in grid order)."""
    return sorted(points, key=lambda p: -point_weight(p, problems[p.problem]))


def sort_ablation(df: pd.DataFrame, problem_order: list[str]) -> pd.DataFrame:
    """The ablation rows in table order: problems in ``problem_order`` (the config's), then
    scheme, weighting, N, M, trajectories and replicate (one row per key)."""
    order = {name: i for i, name in enumerate(problem_order)}
    df = df.assign(_p=df["problem"].map(order))
    df = df.sort_values(
        ["_p", "scheme", "weighting", "N", "M", "n_trajectories", "replicate"], kind="stable"
    )
    return df.drop(columns="_p").reset_index(drop=True)


def run_points(
    points: list[GridPoint],
    specs: Mapping[str, Mapping[str, Any]],
    lqg_model: Mapping[str, Any],
    seed: int,
    reps: int,
    n_jobs: int = 1,
    label: str = "estimators",
) -> pd.DataFrame:
    """The rows (:data:`ABLATION_COLUMNS`, in task order) of every grid point of ``points``
    with ``reps`` replicates, on ``n_jobs`` workers; ``specs`` maps problem names to their
    config entries. The largest cells go first, dealt round-robin into ``4 n_jobs`` tasks:
    rows never depend on it (each cell's streams are keyed on the cell)."""
    problems = {name: build_problem(spec, lqg_model) for name, spec in specs.items()}
    ordered = by_weight(points, problems)
    n_tasks = max(1, min(len(points), 4 * n_jobs))
    jobs = [(ordered[i::n_tasks], specs, dict(lqg_model), seed, reps) for i in range(n_tasks)]
    log.info(
        "%s: %d problems, %d grid points, %d replicates, %d tasks on %d workers",
        label,
        len(problems),
        len(points),
        reps,
        len(jobs),
        n_jobs,
    )
    rows = [r for part in parallel_map(_task, jobs, n_jobs, desc=f"{label} tasks") for r in part]
    return pd.DataFrame(rows, columns=ABLATION_COLUMNS)


def run_ablation(
    cfg: Mapping[str, Any], lqg_model: Mapping[str, Any], seed: int, n_jobs: int = 1
) -> pd.DataFrame:
    """Run the whole grid of the ``estimators`` config section; one row per estimate."""
    specs = {
        spec["name"]: {k: v for k, v in spec.items() if k != "name"} for spec in cfg["problems"]
    }
    problems = {name: build_problem(spec, lqg_model) for name, spec in specs.items()}
    points = grid_points(cfg, problems)
    df = run_points(points, specs, lqg_model, seed, int(cfg["replicates"]), n_jobs)
    return sort_ablation(df, list(specs))


# ------------------------------------------------------------------ per-cell summary

CELL = ["problem", "scheme", "weighting", "N", "M", "H", "n_trajectories"]
#: columns of the per-cell summary that the figures and claims read
SUMMARY_COLUMNS = [
    *CELL,
    "n_replicates",
    "J_exact",
    "J_nbo",
    "mean",
    "bias",
    "bias_low",
    "bias_high",
    "var",
    "var_low",
    "var_high",
    "rmse",
    "rmse_low",
    "rmse_high",
    "cpu_median",
    "var_theory",
    "limit",
    "bias_fraction_of_nbo",
    "bias_fraction_low",
    "bias_fraction_high",
]
N_BOOT = 2000


def _theory(row: Mapping[str, Any], prob: LinearQuadratic) -> tuple[float, float]:
    """(derived variance, derived limit) of a cell, NaN where none is derived."""
    qf = prob.quadratic_form
    s, w, n, N = row["scheme"], row["weighting"], int(row["n_trajectories"]), int(row["N"])
    var, limit = np.nan, np.nan
    if w == "uniform" and s in ("mc", "sobol", "antithetic", "tree", "tree_pernode"):
        limit = qf.mean()
    if w == "weighted" and s in ("mc", "tree", "tree_pernode"):
        limit = qf.weighted_limit()
    if w in ("quadrature",):
        limit = qf.mean()
    if s == "nbo":
        limit = qf.nominal()
    if w == "uniform":
        if s == "mc":
            var = qf.independent_variance(n)
        elif s == "antithetic":
            var = qf.antithetic_variance(n)
        elif s == "tree" and N >= 2:
            var = qf.tree_variance(N)
        elif s == "tree_pernode":
            var = qf.pernode_tree_variance(N)
    return var, limit


def _bootstrap(x: np.ndarray, j: float, rng: np.random.Generator) -> dict[str, float]:
    """Percentile-bootstrap 95% intervals of bias, variance and RMSE about ``j``."""
    idx = rng.integers(0, x.size, size=(N_BOOT, x.size))
    xb = x[idx]
    bias_b = xb.mean(axis=1) - j
    var_b = xb.var(axis=1, ddof=1)
    rmse_b = np.sqrt(np.mean((xb - j) ** 2, axis=1))
    q = (2.5, 97.5)
    out = {}
    for name, arr in (("bias", bias_b), ("var", var_b), ("rmse", rmse_b)):
        lo, hi = np.percentile(arr, q)
        out[f"{name}_low"], out[f"{name}_high"] = float(lo), float(hi)
    return out


def summarize_ablation(
    df: pd.DataFrame, problems: Mapping[str, LinearQuadratic], seed: int
) -> pd.DataFrame:
    """One row per grid cell with bias/sd/RMSE (bootstrap CIs), CPU time and derived values."""
    missing = [c for c in ABLATION_COLUMNS if c not in df.columns]
    if missing:
        raise ValueError(f"ablation table lacks columns {missing}")
    unknown = sorted(set(df["problem"]) - set(problems))
    if unknown:
        raise ValueError(f"ablation table has problems {unknown} not in the config")
    rows = []
    for key, grp in df.groupby(CELL, sort=False):
        row = dict(zip(CELL, key, strict=True))
        x = grp["estimate"].to_numpy()
        j = float(grp["J_exact"].iloc[0])
        var_th, lim_th = _theory(row, problems[row["problem"]])
        row.update(
            n_nodes=int(grp["n_nodes"].iloc[0]),
            n_replicates=x.size,
            J_exact=j,
            J_nbo=float(grp["J_nbo"].iloc[0]),
            mean=float(x.mean()),
            bias=float(x.mean() - j),
            var=float(x.var(ddof=1)) if x.size > 1 else 0.0,
            rmse=float(np.sqrt(np.mean((x - j) ** 2))),
            cpu_median=float(grp["cpu_seconds"].median()),
            var_theory=var_th,
            limit=lim_th,
        )
        if x.size > 1:
            rng = job_rng(seed, "estimators_bootstrap", **{k: row[k] for k in CELL})
            row.update(_bootstrap(x, j, rng))
        else:  # deterministic: no sampling error
            row.update(
                {f"{n}_{s}": row[n] for n in ("bias", "var", "rmse") for s in ("low", "high")}
            )
        rows.append(row)
    out = pd.DataFrame(rows)
    out["sd"] = np.sqrt(out["var"])
    nbo_err = out["J_nbo"] - out["J_exact"]
    out["bias_fraction_of_nbo"] = out["bias"] / nbo_err
    # J_NBO - J is negative for convex costs: order the interval ends after dividing
    ends = np.stack([out["bias_low"] / nbo_err, out["bias_high"] / nbo_err])
    out["bias_fraction_low"] = ends.min(axis=0)
    out["bias_fraction_high"] = ends.max(axis=0)
    return out
