r"""One closed-loop Monte-Carlo run of the UAV tracking problem for one planning method.

Run ``r`` (paired design: identical for every method)
-----------------------------------------------------
* **Scenario** from ``job_rng(seed, "uav_scenario", run=r)``, in this order: target start
  position uniform in :math:`[-b, b]^2`, heading uniform in :math:`[0, 2\pi)`, speed uniform in
  ``[v_min, v_max]``; UAV distance uniform in ``[d_min, d_max]`` at a uniform bearing from the
  target, UAV heading uniform, speed ``uav_speed``; then the initial estimate error
  :math:`\hat x_0 - x_0 \sim \mathcal N(0, P_0)`, :math:`P_0 = \mathrm{diag}(\sigma_p^2,
  \sigma_p^2, \sigma_v^2, \sigma_v^2)`.
* **Truth process noise** :math:`w_1..w_K \sim \mathcal N(0, Q)` from
  ``job_rng(seed, "uav_process_noise", run=r)`` as one (K, 4) standard-normal block times
  :math:`\mathrm{chol}(Q)^T`.
* **Detections** (only with a sensor footprint, :mod:`rsmhp.models.uav.sensor`): uniforms
  :math:`u_1..u_K` from ``job_rng(seed, "uav_detection", run=r)``; step k measures if the
  true horizontal distance is within the footprint (``hard``) or if :math:`u_k < p_d`
  (``logistic``); otherwise the tracker only predicts. Without a footprint nothing is drawn
  and every step measures (the paper's model).
* **Measurement noise**: standard normals :math:`\zeta_1..\zeta_K` (K, 2) from
  ``job_rng(seed, "uav_measurement_noise", run=r)``; the noise at step k is
  :math:`v_k = G_k \mathrm{diag}(\sigma_r, \sigma_c)_k \zeta_k` with the *true* geometry of the
  method's own UAV (:func:`rsmhp.models.uav.sensor.measurement_noise`). Every method therefore sees
  the same scenario, target path and :math:`\zeta`; only geometry-dependent scaling differs.

Planner hypotheses (method-specific)
------------------------------------
At step k the planner's hypotheses come from
``job_rng(seed, "uav_plan", run=r, step=k, **method.job_key())`` (the method's name and its
N_T, N, M): drawn once per planning step and held fixed during the optimisation. The loop only
calls the method's planner (:meth:`rsmhp.models.uav.methods.Method.planner`), so any registered
method runs in it unchanged.

Step k = 1..K
-------------
plan from (UAV state, :math:`\hat x_{k-1}, \hat P_{k-1}`) -> apply :math:`u_0` -> target moves
:math:`x_k = F x_{k-1} + w_k` -> tracker predicts -> :math:`z_k = H x_k + v_k` -> tracker
updates with R at the predicted estimate -> error :math:`e_k = \|\hat p_k - p_k\|`. Everything
after the plan is one compiled call (:class:`rsmhp.models.uav.stepper.Stepper`, tested step by step
against the numpy kinematics and sensor and filterpy's Kalman filter); a method that declares
``uses_rng = False`` (NBO) gets no planning stream.
Metric of the run: ``mean_error`` :math:`= \frac1K \sum_k e_k` (paper's average target location
error), ``rmse`` :math:`= (\frac1K\sum_k e_k^2)^{1/2}`, ``mean_trace`` = mean of
:math:`\mathrm{tr}\,\hat P_k`. ``plan_seconds`` is planner wall time (the only
non-deterministic output). ``work_per_step`` is the mean machine-independent compute per
planning step in model steps (:attr:`rsmhp.models.uav.planner.PlanResult.work`: covariance-recursion
steps, a gradient evaluation counting its forward and adjoint pass; generative-model calls of
a tree search), ``converged_rate`` the fraction of plans whose optimiser stopped on a
tolerance rather than on its iteration or evaluation budget (NaN for a planner without one).

Shared by the studies ``rsmhp.studies.decisions``, ``rsmhp.studies.frontier``,
``rsmhp.studies.horizon`` and ``rsmhp.studies.uav`` (so it lives below them).
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from threadpoolctl import ThreadpoolController

from rsmhp.core import guards
from rsmhp.core.seeding import job_rng
from rsmhp.models.uav import loop
from rsmhp.models.uav.kinematics import UAVParams
from rsmhp.models.uav.methods import Method
from rsmhp.models.uav.planner import CONVERGED, Belief, PlannerParams, shift_plan
from rsmhp.models.uav.sensor import SensorModel
from rsmhp.models.uav.stepper import Stepper
from rsmhp.models.uav.target import TargetModel

__all__ = [
    "MODEL_KEYS",
    "STEP_VALUES",
    "Scenario",
    "StepInfo",
    "UAVSetup",
    "draw_scenario",
    "simulate_run",
]


#: the keys of the config's ``uav`` section that define the model a UAV simulation runs
#: (:meth:`UAVSetup.from_config`); besides them a job depends on its method and the seed. Every
#: UAV study's rules pass these keys as a param (``workflow/rules/common.smk``)
MODEL_KEYS = ("dt", "g", "aircraft", "target", "sensor", "tracker", "scenario", "planner")


@dataclass(frozen=True)
class UAVSetup:
    """Every model constant of the case study (built from the ``uav`` config section)."""

    uav: UAVParams
    target: TargetModel
    sensor: SensorModel
    planner: PlannerParams
    P0: np.ndarray
    steps: int
    scenario: Mapping[str, float]

    def __post_init__(self) -> None:
        guards.instance_of("UAVSetup.uav", self.uav, UAVParams)
        guards.instance_of("UAVSetup.target", self.target, TargetModel)
        guards.instance_of("UAVSetup.sensor", self.sensor, SensorModel)
        guards.instance_of("UAVSetup.planner", self.planner, PlannerParams)
        # positive definite: the scenario's initial estimate error uses its Cholesky factor
        guards.spd_matrix("UAVSetup.P0", self.P0, size=4)
        object.__setattr__(self, "steps", guards.positive_int("UAVSetup.steps", self.steps))
        _check_scenario(self.scenario)

    @classmethod
    def from_config(cls, uav: Mapping[str, Any]) -> UAVSetup:
        tr = uav["tracker"]
        P0 = np.diag([tr["p0_pos_sd"] ** 2] * 2 + [tr["p0_vel_sd"] ** 2] * 2).astype(float)
        return cls(
            uav=UAVParams.from_config(uav),
            target=TargetModel.from_config(uav),
            sensor=SensorModel.from_config(uav),
            planner=PlannerParams.from_config(uav),
            P0=P0,
            steps=uav["scenario"]["steps"],  # checked (not truncated) by the constructor
            scenario=dict(uav["scenario"]),
        )


SCENARIO_KEYS = (
    "target_box",
    "target_speed_min",
    "target_speed_max",
    "uav_distance_min",
    "uav_distance_max",
    "uav_speed",
)


def _check_scenario(sc: Mapping[str, Any]) -> None:
    """The scenario ranges :func:`draw_scenario` draws from: every key present and finite,
    ``target_box``, speeds and distances >= 0, ``uav_speed`` > 0, each min <= its max."""
    guards.instance_of("UAVSetup.scenario", sc, Mapping)
    missing = [k for k in SCENARIO_KEYS if k not in sc]
    if missing:
        raise ValueError(f"UAVSetup.scenario is missing {missing} (needs {list(SCENARIO_KEYS)})")
    for key in SCENARIO_KEYS:
        if key == "uav_speed":
            guards.real(f"scenario.{key}", sc[key], lo=0.0, lo_open=True)
        else:
            guards.real(f"scenario.{key}", sc[key], lo=0.0)
    for lo, hi in (
        ("target_speed_min", "target_speed_max"),
        ("uav_distance_min", "uav_distance_max"),
    ):
        guards.ordered(f"scenario.{lo}", sc[lo], f"scenario.{hi}", sc[hi], strict=False)


@dataclass(frozen=True)
class Scenario:
    """Initial truth (target (4,), UAV (4,)) and the tracker's initial estimate (4,)."""

    target: np.ndarray
    uav: np.ndarray
    estimate: np.ndarray


def draw_scenario(setup: UAVSetup, seed: int, run: int) -> Scenario:
    """The run's scenario (see the module docstring for the draw order)."""
    guards.instance_of("setup", setup, UAVSetup)
    seed = guards.nonneg_int("seed", seed)
    run = guards.nonneg_int("run", run)
    sc = setup.scenario
    rng = job_rng(seed, "uav_scenario", run=run)
    pos = rng.uniform(-sc["target_box"], sc["target_box"], 2)
    heading = rng.uniform(0.0, 2 * math.pi)
    speed = rng.uniform(sc["target_speed_min"], sc["target_speed_max"])
    dist = rng.uniform(sc["uav_distance_min"], sc["uav_distance_max"])
    bearing = rng.uniform(0.0, 2 * math.pi)
    uav_heading = rng.uniform(0.0, 2 * math.pi)
    tgt = np.array([*pos, speed * math.cos(heading), speed * math.sin(heading)])
    uav_xy = pos + dist * np.array([math.cos(bearing), math.sin(bearing)])
    uav = np.array([*uav_xy, float(sc["uav_speed"]), uav_heading])
    est = tgt + rng.standard_normal(4) @ np.linalg.cholesky(setup.P0).T
    return Scenario(target=tgt, uav=uav, estimate=est)


@dataclass
class StepInfo:
    """What happened at step k (for recordings): states after the step, the plan made before it
    (planned UAV states (H, 4), hypotheses (T, H, 4)), error and tr P."""

    step: int
    uav: np.ndarray
    target: np.ndarray
    estimate: np.ndarray
    covariance: np.ndarray
    plan_path: np.ndarray
    hypotheses: np.ndarray
    error: float
    trace: float
    warm_start: np.ndarray | None = None  # (H, 2) the next step's warm start (shifted plan)
    detected: bool = True  # whether the step measured (False only outside a footprint)


def simulate_run(
    setup: UAVSetup,
    method: Method,
    seed: int,
    run: int,
    observer: Callable[[StepInfo], None] | None = None,
    *,
    path: str = "auto",
) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """Simulate run ``run`` with ``method`` (any registered
    :class:`rsmhp.models.uav.methods.Method`;
    the loop only calls its :meth:`~rsmhp.models.uav.methods.Method.planner`): (summary row,
    per-step rows).

    BLAS is limited to one thread for the run: small dense algebra (the hypothesis draws; with
    ``optimiser: scipy``, L-BFGS-B on 2H variables) is many times slower with a
    multi-threaded BLAS pool.

    The arguments are checked here, once per run (``setup`` and ``method`` were checked when
    they were built); the steps of the run then call the planner, the hypothesis generators
    and the tracker with ``check=False``.

    ``path``: ``"auto"`` runs the compiled closed loop where the family has one
    (:func:`rsmhp.models.uav.loop.path`), else the Python loop; ``"python"`` always the Python
    loop (the compiled loop's test oracle: the same rows bit for bit); ``"compiled"`` the
    compiled loop or a ``ValueError`` saying why not.
    """
    guards.instance_of("setup", setup, UAVSetup)
    guards.instance_of("method", method, Method)
    seed = guards.nonneg_int("seed", seed)
    run = guards.nonneg_int("run", run)
    if observer is not None and not callable(observer):
        raise TypeError(f"observer must be callable or None, got {type(observer).__name__}")
    if path not in ("auto", "python", "compiled"):
        raise ValueError(f"path must be 'auto', 'python' or 'compiled', got {path!r}")
    compiled = False
    if path != "python":
        which, why = loop.path(method, setup, observer=observer is not None)
        compiled = which == "compiled"
        if path == "compiled" and not compiled:
            raise ValueError(f"no compiled closed loop for {method.name}: {why}")
    with _blas().limit(limits=1):
        return _simulate_run(setup, method, seed, run, observer, compiled)


@functools.cache
def _blas() -> ThreadpoolController:
    """The process's BLAS/OpenMP pools, found once (``threadpool_limits`` searches the loaded
    libraries on every call: 1 ms, a fifth of an NBO run)."""
    return ThreadpoolController()


#: the float columns of a step row, in table order (``rsmhp.studies.uav.simulate.STEP_COLUMNS``)
STEP_VALUES = (
    "error",
    "trace",
    "uav_x",
    "uav_y",
    "uav_speed",
    "uav_heading",
    "target_x",
    "target_y",
    "est_x",
    "est_y",
    "accel",
    "bank",
    "plan_cost",
    "plan_cost_warm",
)


def _simulate_run(setup, method, seed, run, observer, compiled):
    sc = draw_scenario(setup, seed, run)
    K, H = setup.steps, setup.planner.horizon
    w = job_rng(seed, "uav_process_noise", run=run).standard_normal((K, 4))
    w = w @ np.linalg.cholesky(setup.target.Q).T
    zeta = job_rng(seed, "uav_measurement_noise", run=run).standard_normal((K, 2))
    limited = setup.sensor.limited
    det_u = job_rng(seed, "uav_detection", run=run).random(K) if limited else np.zeros(K)
    if compiled:
        out = loop.run(setup, method, seed, run, sc, w, zeta, det_u)
        # contiguous copies: the Python loop's array layouts, so numpy's reductions below
        # take the same inner loops
        status = out.vals[:, 14].copy()
        diagnostics = {"status": status}
        if setup.planner.restarts:
            diagnostics["restart"] = out.vals[:, 15].copy()
        return _collect(
            setup, method, seed, run, np.ascontiguousarray(out.vals[:, :14]),
            np.ascontiguousarray(out.ints[:, :2]), out.ints[:, 2].copy(), diagnostics,
            np.isin(status, CONVERGED).astype(float), out.ints[:, 3].astype(bool),
            out.plan_seconds,
        )  # fmt: skip
    x_true, uav_state = sc.target.copy(), sc.uav.copy()
    x_est, P_est = sc.estimate.astype(float), np.array(setup.P0, dtype=float)
    stepper = Stepper(setup.uav, setup.target, setup.sensor)
    warm = np.zeros((H, 2))
    vals = np.empty((K, len(STEP_VALUES)))  # one row of floats per step, dicts built at the end
    counts = np.empty((K, 2), dtype=np.int64)  # nit, kernel calls
    work = np.empty(K, dtype=np.int64)  # model steps (PlanResult.work)
    diagnostics: dict[str, list[float]] = {}  # PlanResult.diagnostics per step
    converged = np.full(K, np.nan)  # 1.0 / 0.0 per plan; NaN: no optimiser
    seen_k = np.ones(K, dtype=bool)
    plan_seconds = 0.0
    planner = method.planner(setup)
    uses_rng = method.uses_rng
    for k in range(1, K + 1):
        t0 = time.perf_counter()
        rng = job_rng(seed, "uav_plan", run=run, step=k, **method.job_key()) if uses_rng else None
        res = planner.plan(Belief(uav_state.copy(), x_est.copy(), P_est.copy()), warm, rng)
        plan_seconds += time.perf_counter() - t0
        warm = shift_plan(res.controls)
        u0 = res.controls[0]
        seen, err, tr = stepper.advance(
            uav_state, x_true, x_est, P_est, u0, w[k - 1], zeta[k - 1], det_u[k - 1]
        )
        seen_k[k - 1] = seen
        vals[k - 1] = (
            err, tr, *uav_state, x_true[0], x_true[1], x_est[0], x_est[1], u0[0], u0[1],
            res.cost, res.cost_warm,
        )  # fmt: skip
        counts[k - 1] = (res.nit, res.n_kernel_calls)
        work[k - 1] = res.work
        for key, value in res.diagnostics.items():
            diagnostics.setdefault(key, []).append(float(value))
        if res.converged is not None:
            converged[k - 1] = float(res.converged)
        if observer is not None:
            hyp = res.hypotheses.states if res.hypotheses is not None else np.zeros((0, H, 4))
            observer(
                StepInfo(
                    k, uav_state.copy(), x_true.copy(), x_est.copy(), P_est.copy(),
                    res.uav_path, hyp, err, tr, warm, bool(seen),
                )
            )  # fmt: skip
    return _collect(
        setup, method, seed, run, vals, counts, work, diagnostics, converged, seen_k, plan_seconds
    )


def _collect(setup, method, seed, run, vals, counts, work, diagnostics, converged, seen_k,
             plan_seconds):  # fmt: skip
    """The run's (summary row, step rows) from its per-step arrays (either loop): ``vals``
    (K, 14) :data:`STEP_VALUES`, ``counts`` (K, 2) iterations and kernel calls, ``work`` (K,),
    ``diagnostics`` (key -> K values), ``converged`` (K,), ``seen_k`` (K,) detected."""
    K = setup.steps
    limited = setup.sensor.limited
    rows: list[dict[str, Any]] = []
    for k in range(K):
        row = {"step": k + 1, **dict(zip(STEP_VALUES, vals[k].tolist(), strict=True))}
        row["nit"], row["kernel_calls"] = int(counts[k, 0]), int(counts[k, 1])
        if limited:  # variant-only column: the paper's model's outputs stay as they were
            row["detected"] = bool(seen_k[k])
        rows.append(row)
    errors = vals[:, 0]
    summary = {
        "method": method.name,
        "family": method.family,
        **method.columns(),
        "run": run,
        "seed": seed,
        "mean_error": float(errors.mean()),
        "rmse": float(np.sqrt(np.mean(errors**2))),
        "final_error": float(errors[-1]),
        "mean_trace": float(np.mean(vals[:, 1])),
        "mean_nit": float(np.mean(counts[:, 0])),
        "plan_seconds": plan_seconds,
        "work_per_step": float(np.mean(work)),
        "converged_rate": float(np.mean(converged)),
        # the planner's own diagnostics averaged over the steps that report them (e.g. a
        # tree search's depth statistics)
        "diagnostics": {key: float(np.mean(v)) for key, v in diagnostics.items()},
    }
    if limited:
        summary["detect_rate"] = int(seen_k.sum()) / K
    return summary, rows
