r"""The compiled closed loop: a whole run of :func:`rsmhp.models.uav.simulation.simulate_run` in
one compiled call, for every family that declares it.

What runs where
---------------
Python sets the run up once (scenario, the truth's process noise, the measurement normals, the
detection uniforms: the same draws from the same keyed streams as the Python loop) and collects
the step rows at the end. The 60 steps run in one call of the planner kernel
(:func:`rsmhp.models.uav.fused._planner_kernel`, its closed-loop mode): the step's hypotheses, the
planner's cost arguments, the optimisation from the shifted warm start (and from each restart
start), the first control, the target moved and the tracker's prediction and update (the Python
loop's compiled step, :func:`rsmhp.models.uav.stepper._advance`, called through numba's object
mode rather than linked, which would add its 7 s compile to the planner kernel's at set-up),
the row. A family says how its hypotheses are made by its class attribute ``closed_loop``
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
optimiser is scipy's L-BFGS-B, when its planner starts from the pursuit plan rather than the
warm start (``uav.planner.start``), or when the method's planner is not the default
:class:`rsmhp.models.uav.planner.SampledCostPlanner` with :class:`~rsmhp.models.uav.planner.BoxQN`.
:func:`path` names the path a run takes and why; ``check_method`` reports it per family.

Every step row is the Python loop's, bit for bit (``tests/models/uav/test_uav_loop.py``: float
hex of every column, every built-in family, both sensor models, restarts). The one
measurement, ``plan_seconds``, is taken with the processor's cycle counter
(:mod:`rsmhp.core.clock`) from the start of each step to the end of its optimisations (as the
Python loop times from the step's stream to the end of the plan), converted to seconds with
the wall time of the whole compiled call; without a cycle counter (not x86-64) it is the
run's wall time.

The arrays of ``loop`` (the planner kernel's closed-loop mode)
----------------------------------------------------------------
``flags`` (3,) int64: hypothesis kind (``fused.NOMINAL`` / ``fused.DRAWN``), the handle of
the run's Python side in ``fused.CONTEXTS`` (its draws and the step after the plan, on the
same state arrays), cycle counter on; ``F`` (4, 4); the planner's ``cfg`` (8,) (its weight
divisor set per step); the UAV state, true target and estimate (4,) and covariance (4, 4),
updated in place; ``scale``
(2H,) the control scale; ``starts`` (R, 2H) the restarts' normalised starts as the Python
loop clips them; outputs ``vals`` (K, 16): the 14 step values of
:data:`rsmhp.models.uav.simulation.STEP_VALUES`, the optimiser status and the winning start;
``ints`` (K, 4): iterations, kernel calls, work, detected.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass

import numpy as np

from rsmhp.core import clock
from rsmhp.core.seeding import job_rngs
from rsmhp.models.uav import fused
from rsmhp.models.uav.methods import Method
from rsmhp.models.uav.planner import Belief, BoxQN, SampledCostPlanner, restart_starts
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
    if setup.planner.start != "warm":
        return "python", (
            f"start {setup.planner.start!r} (the compiled loop starts from the warm start only)"
        )
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
    kind = type(method).closed_loop
    scale = np.tile(setup.uav.control_scale, H).astype(float)
    R = setup.planner.restarts
    starts = np.empty((R, 2 * H))
    for i, x0 in enumerate(restart_starts(H, R)):  # as BoxQN.minimise clips problem.controls(x0)
        starts[i] = np.clip((x0 * scale).reshape(H, 2).ravel() / scale, -1.0, 1.0)
    cfg = np.array((*fused._uav_args(setup.uav), 0.0, setup.target.dt), dtype=float)
    q = fused._constant_entries(np.asarray(setup.target.Q, dtype=float).tobytes())
    sens = fused._sensor_args(setup.sensor)
    handle = next(_handles)
    timed = clock.AVAILABLE
    flags = np.array([fused.NOMINAL if kind == "nominal" else fused.DRAWN, handle, timed])
    vals = np.zeros((K, 16))
    ints = np.zeros((K, 4), dtype=np.int64)
    # the state arrays: updated in place by the compiled loop and by the context's steps
    state = (
        np.array(scenario.uav, dtype=float), np.array(scenario.target, dtype=float),
        np.array(scenario.estimate, dtype=float), np.array(setup.P0, dtype=float),
    )  # fmt: skip
    F = np.ascontiguousarray(setup.target.F, dtype=float)
    loop = (flags, F, cfg, *state, scale, starts, vals, ints)
    fused.CONTEXTS[handle] = _Context(setup, method, seed, run, state, w, zeta, det_u)
    try:
        t0 = time.perf_counter()
        c_plan, c_all, _, _, _ = fused._planner_kernel(
            fused._CLOSED_LOOP, fused._NO_POINT[None, :], *_UNUSED, q, sens, *_UNUSED_DATA,
            True, setup.planner.maxiter, setup.planner.maxfun, fused._NO_COST,
            fused._NO_POINT[None, :], fused._NO_POINT, loop,
        )  # fmt: skip
        wall = time.perf_counter() - t0
    finally:
        fused.CONTEXTS.pop(handle, None)
    plan_seconds = wall * c_plan / c_all if timed and c_all > 0 else wall
    return CompiledRun(vals, ints, plan_seconds)


class _Context:
    """The Python side of one compiled run: the step's hypotheses as the Python loop draws
    them (the step's own stream: :func:`rsmhp.core.seeding.job_rngs` gives
    ``job_rng(..., step=k)``'s streams in step order; the planner's ``draw`` at a belief of
    copies), and the step after the plan by the Python loop's compiled
    :class:`rsmhp.models.uav.stepper.Stepper` with the run's noise."""

    def __init__(self, setup, method: Method, seed: int, run: int, state, w, zeta, det_u) -> None:
        self.planner = method.planner(setup)
        self.rngs = (
            job_rngs(seed, "uav_plan", "step", range(1, setup.steps + 1), run=run,
                     **method.job_key())
            if method.uses_rng
            else None
        )  # fmt: skip
        self.next_draw = 1
        self.stepper = Stepper(setup.uav, setup.target, setup.sensor)
        self.w, self.zeta, self.det_u = w, zeta, det_u
        self.uav, self.x_true, self.x_est, self.P = state
        self.control = np.empty(2)

    def draw(self, k: int):
        if k != self.next_draw:  # the streams are consumed in step order
            raise RuntimeError(f"compiled loop asked for step {k}, expected {self.next_draw}")
        self.next_draw += 1
        rng = next(self.rngs) if self.rngs is not None else None
        belief = Belief(self.uav.copy(), self.x_est.copy(), self.P.copy())
        hyp = self.planner.draw(belief, rng)
        return hyp.states, hyp.weights

    def advance(self, k: int, u0: float, u1: float):
        self.control[0], self.control[1] = u0, u1
        return self.stepper.advance(
            self.uav, self.x_true, self.x_est, self.P, self.control, self.w[k - 1],
            self.zeta[k - 1], self.det_u[k - 1],
        )  # fmt: skip


# the arguments of the planner kernel the closed loop does not read (st, cfg, p0; tx, ty, wts)
_UNUSED = (np.empty(0), np.empty(0), np.empty(0))
_UNUSED_DATA = (np.empty((0, 0)), np.empty((0, 0)), np.empty(0))
