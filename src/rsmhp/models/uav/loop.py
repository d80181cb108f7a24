r"""The compiled closed loop: a whole run of :func:`rsmhp.models.uav.simulation.simulate_run` in
one compiled call, for every family that declares it.

What runs where
---------------
Python sets the run up once (scenario, the truth's process noise, the measurement normals, the
detection uniforms: the same draws from the same keyed streams as the Python loop) and collects
the step rows at the end. The 60 steps run in :func:`rsmhp.models.uav.fused._planner_kernel`: the
step's hypotheses, the planner's cost arguments, the optimisation from the shifted warm start
(and from each restart start), the first control applied, the target moved, the tracker's
prediction and update (:func:`rsmhp.models.uav.stepper._advance`), the row. A family says how its
hypotheses are made by its class attribute ``closed_loop``
(:class:`rsmhp.models.uav.methods.Method`):

* ``"nominal"`` (NBO): the noise-free prediction :math:`x_j = F^j \hat x`, computed in the compiled
  loop by :func:`rsmhp.models.uav.target.nominal`'s own kernel;
* ``"drawn"`` (Monte Carlo, per-step Monte Carlo, RQMC, antithetic, sigma points, pruned tree):
  the family's own :meth:`~rsmhp.models.uav.methods.Method.hypotheses`, called from the compiled
  loop once per step (numba's object mode, about 2 µs per call) with the step's stream
  ``job_rng(seed, "uav_plan", run=r, step=k, **method.job_key())``. The hypotheses therefore
  come from exactly the numpy code and the BLAS and LAPACK calls of the Python loop: a compiled
  replacement of the Cholesky factor and the 4 x 4 products rounds differently from numpy's
  OpenBLAS (and differently again on each OpenBLAS core type), which 60 feedback steps amplify;
* ``"python"`` (the default: the tree search, plugins, any new family): the Python loop.

A run also takes the Python loop when it has an ``observer`` (recordings), when the setup's
optimiser is scipy's L-BFGS-B, or when the method's planner is not the default
:class:`rsmhp.models.uav.planner.SampledCostPlanner` with :class:`~rsmhp.models.uav.planner.BoxQN`.
:func:`path` names the path a run takes and why; ``check_method`` reports it per family.

Every step row is the Python loop's, bit for bit (``tests/models/uav/test_uav_loop.py``: float
hex of every column, every built-in family, both sensor models, restarts). The one
measurement, ``plan_seconds``, is taken with the processor's cycle counter
(:mod:`rsmhp.core.clock`) from the start of each step to the end of its optimisations (as the
Python loop times from the step's stream to the end of the plan), converted to seconds with
the wall time of the whole compiled call; without a cycle counter (not x86-64) it is the
run's wall time.

The arrays of ``loop`` (:func:`rsmhp.models.uav.fused._planner_kernel`)
----------------------------------------------------------------------
``flags`` (3,) int64: hypothesis kind (``fused.NOMINAL`` / ``fused.DRAWN``), generator handle,
cycle counter on; ``F``, ``Q`` (4, 4); the stepper's aircraft and sensor tuples
(:class:`rsmhp.models.uav.stepper.Stepper`); the planner's ``cfg`` (8,) (its weight divisor set
per step); the UAV state, true target and estimate (4,) and covariance (4, 4), updated in
place; ``noise`` (K, 7): the truth's process noise (4), measurement normals (2), detection
uniform; ``scale`` (2H,) the control scale; ``starts`` (R, 2H) the restarts' normalised
starts as the Python loop clips them; outputs ``vals`` (K, 16): the 14 step values of
:data:`rsmhp.models.uav.simulation.STEP_VALUES`, the optimiser status and the winning start;
``ints`` (K, 4): iterations, kernel calls, work, detected.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rsmhp.core import clock
from rsmhp.core.seeding import job_rngs
from rsmhp.models.uav import fused
from rsmhp.models.uav.methods import Method
from rsmhp.models.uav.planner import BoxQN, SampledCostPlanner, restart_starts
from rsmhp.models.uav.stepper import Stepper

__all__ = ["KINDS", "CompiledRun", "path", "run"]

#: the values of ``Method.closed_loop`` and what they mean (see the module docstring)
KINDS = {
    "nominal": "compiled; NBO's nominal hypothesis in compiled code",
    "drawn": "compiled; the family's hypotheses drawn in Python once per step",
    "python": "the Python loop",
}

_handles = itertools.count(1)


def path(method: Method, setup, *, observer: bool = False) -> tuple[str, str]:
    """``("compiled" | "python", reason)``: the loop a run of ``method`` on ``setup`` takes."""
    # declared by the family's own class: a subclass that inherits it may draw otherwise
    kind = vars(type(method)).get("closed_loop", "python")
    if kind not in KINDS:
        return "python", f"closed_loop = {kind!r} is not one of {sorted(KINDS)}"
    if kind == "python":
        return "python", f"family {method.family!r} declares no compiled closed loop"
    if observer:
        return "python", "an observer (recording) sees every step"
    if setup.planner.optimiser != "boxqn":
        return "python", f"optimiser {setup.planner.optimiser!r} (only boxqn is compiled)"
    planner = method.planner(setup)
    if type(planner) is not SampledCostPlanner or not isinstance(planner.optimiser, BoxQN):
        return "python", f"the planner is {type(planner).__name__}, not SampledCostPlanner + BoxQN"
    return "compiled", KINDS[kind]


@dataclass
class CompiledRun:
    """The arrays of one compiled run: ``vals`` (K, 16), ``ints`` (K, 4) (module docstring)
    and the planner's wall time in seconds."""

    vals: np.ndarray
    ints: np.ndarray
    plan_seconds: float


def run(setup, method: Method, seed: int, run: int, scenario, w, zeta, det_u) -> CompiledRun:
    """Run ``run`` of ``method`` in the compiled loop, from the Python loop's set-up
    (``scenario``, process noise ``w`` (K, 4), normals ``zeta`` (K, 2), uniforms ``det_u``
    (K,)); the caller checked the arguments and :func:`path`."""
    K, H = setup.steps, setup.planner.horizon
    planner = method.planner(setup)
    kind = type(method).closed_loop
    step = Stepper(setup.uav, setup.target, setup.sensor)
    scale = np.tile(setup.uav.control_scale, H).astype(float)
    R = setup.planner.restarts
    starts = np.empty((R, 2 * H))
    for i, x0 in enumerate(restart_starts(H, R)):  # as BoxQN.minimise clips problem.controls(x0)
        starts[i] = np.clip((x0 * scale).reshape(H, 2).ravel() / scale, -1.0, 1.0)
    uav = np.array(scenario.uav, dtype=float)
    x_true = np.array(scenario.target, dtype=float)
    x_est = np.array(scenario.estimate, dtype=float)
    P = np.array(setup.P0, dtype=float)
    noise = np.empty((K, 7))
    noise[:, 0:4], noise[:, 4:6], noise[:, 6] = w, zeta, det_u
    cfg = np.array((*fused._uav_args(setup.uav), 0.0, setup.target.dt), dtype=float)
    q = fused._constant_entries(np.asarray(setup.target.Q, dtype=float).tobytes())
    sens = fused._sensor_args(setup.sensor)
    handle = next(_handles)
    timed = clock.AVAILABLE
    flags = np.array([fused.NOMINAL if kind == "nominal" else fused.DRAWN, handle, timed])
    vals = np.zeros((K, 16))
    ints = np.zeros((K, 4), dtype=np.int64)
    loop = (
        flags, step.F, step.Q, step.ucfg, step.sens, cfg, uav, x_true, x_est, P, noise, scale,
        starts, vals, ints,
    )  # fmt: skip
    if kind == "drawn":
        fused.HYPOTHESES[handle] = _generator(planner, method, setup, seed, run)
    try:
        t0 = time.perf_counter()
        c_plan, c_all, _, _, _ = fused._planner_kernel(
            fused._CLOSED_LOOP, fused._NO_POINT[None, :], *_UNUSED, q, sens, *_UNUSED_DATA,
            True, setup.planner.maxiter, setup.planner.maxfun, fused._NO_COST,
            fused._NO_POINT[None, :], fused._NO_POINT, loop,
        )  # fmt: skip
        wall = time.perf_counter() - t0
    finally:
        fused.HYPOTHESES.pop(handle, None)
    plan_seconds = wall * c_plan / c_all if timed and c_all > 0 else wall
    return CompiledRun(vals, ints, plan_seconds)


# the arguments of the planner kernel the closed loop does not read (st, cfg, p0; tx, ty, wts)
_UNUSED = (np.empty(0), np.empty(0), np.empty(0))
_UNUSED_DATA = (np.empty((0, 0)), np.empty((0, 0)), np.empty(0))


def _generator(planner: SampledCostPlanner, method: Method, setup, seed: int, run: int) -> Callable:
    """The step's hypotheses as the Python loop draws them: the step's own stream (in step
    order, :func:`rsmhp.core.seeding.job_rngs` gives ``job_rng(..., step=k)``'s streams) and
    the planner's ``draw`` at a belief of copies."""
    from rsmhp.models.uav.planner import Belief

    rngs = (
        job_rngs(seed, "uav_plan", "step", range(1, setup.steps + 1), run=run, **method.job_key())
        if method.uses_rng
        else None
    )
    expected = [1]

    def draw(k: int, uav: np.ndarray, x_est: np.ndarray, P: np.ndarray):
        if k != expected[0]:  # the streams are consumed in step order
            raise RuntimeError(f"compiled loop asked for step {k}, expected {expected[0]}")
        expected[0] += 1
        rng = next(rngs) if rngs is not None else None
        hyp = planner.draw(Belief(uav.copy(), x_est.copy(), P.copy()), rng)
        return hyp.states, hyp.weights

    return draw
