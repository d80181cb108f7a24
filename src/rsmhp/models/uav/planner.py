r"""Receding-horizon planner: minimise the batched covariance cost over an H-step control box.

Decision variable: normalised controls :math:`x \in [-1, 1]^{2H}`, mapped to
:math:`u_j = (a_{\max} x_{2j}, \phi_{\max} x_{2j+1})`. Objective (:mod:`rsmhp.models.uav.kernel`):

.. math:: J(u) = \sum_{i=1}^{N_T} \omega_i \sum_{j=1}^{H} \mathrm{tr}\, P_j^i(u)

for fixed, weighted target hypotheses (:class:`rsmhp.models.uav.methods.Hypotheses`; NBO: the single
nominal one; RS-MHP: N_T samples of weight 1/N_T drawn once per planning step, i.e. common
random numbers across every evaluation of the optimisation).

Two protocols separate what a method decides from how it optimises:

* :class:`Planner`: plans one :class:`Belief` (UAV state, target estimate and covariance)
  from a warm start and returns a :class:`PlanResult` (controls and diagnostics). The closed
  loop and the decision study only call this; a method that is not "hypotheses + optimiser"
  (e.g. a tree search) implements it directly.
* :class:`Optimiser`: minimises a :class:`PlanningProblem` (a fixed weighted cost) from a
  start. Two: :class:`BoxQN` (the default: :mod:`rsmhp.core.boxqn`'s projected L-BFGS, the whole
  optimisation in one compiled call) and :class:`LBFGSB` (scipy's L-BFGS-B, the oracle),
  chosen by ``PlannerParams.optimiser`` (config ``uav.planner.optimiser``).
  :class:`SampledCostPlanner` combines a method's hypotheses with an optimiser: the planner
  of every sampling method.

Value and exact gradient :math:`\nabla_x J` come from the compiled kernel
(:mod:`rsmhp.models.uav.fused`: adjoint of the covariance recursion and of the kinematics; no finite
differences). Both optimisers work on the box, with at most ``maxiter`` iterations and
``maxfun`` evaluations (identical for every method), scipy's default tolerances, started from
the warm start (the previous plan shifted by one step, last control repeated; zeros at the
first step), or with ``uav.planner.start: pursuit`` from the pursuit policy's plan at the
belief (:func:`rsmhp.models.uav.dpw.pursuit_plan`).

Shared by the studies ``rsmhp.studies.frontier`` and ``rsmhp.studies.horizon`` (so it lives
below them).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np

from rsmhp.core import guards
from rsmhp.models.uav import dpw, fused
from rsmhp.models.uav.kinematics import UAVParams
from rsmhp.models.uav.sensor import SensorModel
from rsmhp.models.uav.stepper import Stepper
from rsmhp.models.uav.target import TargetModel

if TYPE_CHECKING:
    import scipy.optimize

__all__ = [
    "LBFGSB",
    "OPTIMISERS",
    "STARTS",
    "Belief",
    "BoxQN",
    "Optimiser",
    "PlanResult",
    "Planner",
    "PlannerParams",
    "PlanningProblem",
    "SampledCostPlanner",
    "lbfgsb",
    "plan",
    "polish",
    "restart_starts",
    "shift_plan",
]


#: optimiser names of ``PlannerParams.optimiser`` (config ``uav.planner.optimiser``)
OPTIMISER_NAMES = ("boxqn", "scipy")
#: the starts of a sampled-cost planner's first optimisation, ``PlannerParams.start`` (config
#: ``uav.planner.start``): ``"warm"`` the warm start (the shifted previous plan), ``"pursuit"``
#: the pursuit policy's plan at the belief (:func:`rsmhp.models.uav.dpw.pursuit_plan`)
STARTS = ("warm", "pursuit")


@dataclass(frozen=True)
class PlannerParams:
    """Horizon ``H``, optimiser budget (iterations and objective evaluations), the
    optimiser (``"boxqn"``: :class:`BoxQN`, ``"scipy"``: :class:`LBFGSB`), restarts and the
    start of the first optimisation (:data:`STARTS`; read by :class:`SampledCostPlanner`
    only)."""

    horizon: int
    maxiter: int
    maxfun: int
    optimiser: str = "boxqn"
    #: further optimisations of a sampled-cost planner from fixed starts (:func:`restart_starts`),
    #: beside the one from the warm start; the lowest own cost wins
    restarts: int = 0
    #: where a sampled-cost planner's first optimisation starts (:data:`STARTS`): the warm
    #: start, or the pursuit policy's plan at the belief; the restarts are the same either way
    start: str = "warm"

    def __post_init__(self) -> None:
        for name in ("horizon", "maxiter", "maxfun"):
            value = guards.positive_int(f"PlannerParams.{name}", getattr(self, name))
            object.__setattr__(self, name, value)  # 6.0 -> 6 (ints are kept as they are)
        object.__setattr__(
            self, "restarts", guards.integer("PlannerParams.restarts", self.restarts, minimum=0)
        )
        if self.optimiser not in OPTIMISER_NAMES:
            raise ValueError(
                f"PlannerParams.optimiser must be one of {list(OPTIMISER_NAMES)}, "
                f"got {self.optimiser!r}"
            )
        if self.start not in STARTS:
            raise ValueError(
                f"PlannerParams.start must be one of {list(STARTS)}, got {self.start!r}"
            )

    @classmethod
    def from_config(cls, uav: Mapping[str, Any]) -> PlannerParams:
        p = uav["planner"]
        # no int(): 6.7 is refused by the constructor rather than truncated to 6
        return cls(
            horizon=p["horizon"],
            maxiter=p["maxiter"],
            maxfun=p["maxfun"],
            optimiser=p.get("optimiser", "boxqn"),
            restarts=p.get("restarts", 0),
            start=p.get("start", "warm"),
        )


@dataclass
class PlanResult:
    """Optimised controls (H, 2), their cost, the warm start's cost, optimiser counters, the
    planned UAV states (H, 4) and the hypotheses the cost averaged over (``None`` for a
    planner without hypotheses); ``diagnostics`` holds planner-specific numbers.

    ``work`` is the plan's machine-independent compute, in *model steps*: one model step is
    one step of one covariance recursion (a 4x4 predict and measurement update). A
    sampled-cost planner spends :math:`T H` of them per cost evaluation and :math:`2 T H` per
    evaluation with its gradient (the forward pass and the adjoint pass), for T hypotheses
    and horizon H; a tree search one per call of its generative model (tree expansions and
    rollout steps). ``converged`` says whether the optimiser stopped on a tolerance (projected
    gradient or relative decrease) rather than on a budget (``None``: no optimiser)."""

    controls: np.ndarray
    cost: float
    cost_warm: float
    nit: int
    n_kernel_calls: int
    uav_path: np.ndarray  # (H, 4) planned UAV states
    hypotheses: Any = None  # rsmhp.models.uav.methods.Hypotheses
    diagnostics: dict[str, float] = field(default_factory=dict)
    work: int = 0  # model steps spent (see above)
    converged: bool | None = None


@dataclass(frozen=True)
class Belief:
    """What a planner sees at one step: UAV state (4,) ``(p_x, p_y, s, psi)``, the tracker's
    target estimate ``x_hat`` (4,) and covariance ``P_hat`` (4, 4)."""

    uav: np.ndarray
    x_hat: np.ndarray
    P_hat: np.ndarray


@runtime_checkable
class Planner(Protocol):
    """Plans one belief state: ``plan(belief, warm_start (H, 2), rng) -> PlanResult``. ``rng``
    is the step's own stream (``job_rng(seed, ..., step=k, **method.job_key())``); a planner
    draws every random number it needs from it. The closed loop passes ``None`` for a method
    that declares ``uses_rng = False``."""

    def plan(
        self, belief: Belief, warm_start: np.ndarray, rng: np.random.Generator | None
    ) -> PlanResult: ...


@runtime_checkable
class Optimiser(Protocol):
    """Minimises a :class:`PlanningProblem` from ``warm_start`` (H, 2) controls."""

    def minimise(self, problem: PlanningProblem, warm_start: np.ndarray) -> PlanResult: ...


class PlanningProblem:
    """The objective of one planning step with its hypotheses held fixed.

    ``value_and_grad(x)`` returns ``(J(x), grad J(x))`` from one compiled kernel call; the
    last result is cached. ``costs(xs)`` evaluates a batch of sequences (values only).

    The arguments are checked once here (``uav_state`` finite (4,) with speed > 0, ``P_hat``
    finite symmetric positive semidefinite (4, 4), ``target_xy`` finite (T, H, 2) with
    T >= 1 and H the planner's horizon, ``weights`` (T,) >= 0 summing to 1 or ``None`` for
    equal weights, and the model types), never per evaluation; ``check=False`` skips this
    (the closed loop checks its inputs once per run).
    """

    def __init__(
        self,
        uav_state: np.ndarray,
        P_hat: np.ndarray,
        target_xy: np.ndarray,
        uav: UAVParams,
        target: TargetModel,
        sensor: SensorModel,
        params: PlannerParams,
        *,
        weights: np.ndarray | None = None,
        check: bool = True,
    ) -> None:
        if check:
            guards.instance_of("uav", uav, UAVParams)
            guards.instance_of("target", target, TargetModel)
            guards.instance_of("params", params, PlannerParams)
            guards.instance_of("sensor", sensor, SensorModel)
            fused.check_uav_state(uav_state)
            guards.spd_matrix("P_hat", P_hat, semi=True, size=4)
            H = params.horizon
            guards.finite_array("target_xy", target_xy, shape=("T", H, 2), nonempty=True)
            if weights is not None:
                weights = fused.check_weights(weights, np.shape(target_xy)[0])
        self.uav_state = np.asarray(uav_state, dtype=float)
        self.P_hat = np.asarray(P_hat, dtype=float)
        self.target_xy = np.asarray(target_xy, dtype=float)
        self.uav, self.target, self.sensor, self.params = uav, target, sensor, params
        self.scale = _scale(uav, params.horizon)
        self.n_kernel_calls = 0
        self._cache: tuple[np.ndarray, float, np.ndarray] | None = None
        self._frozen = fused.Frozen(
            self.uav_state,
            uav,
            self.P_hat,
            self.target_xy,
            target.dt,
            target.Q,
            sensor,
            weights=weights,
            check=False,
        )

    def controls(self, x: np.ndarray) -> np.ndarray:
        """Normalised ``x`` (..., 2H) -> controls (..., H, 2)."""
        x = np.asarray(x, dtype=float)
        if x.ndim == 0 or x.shape[-1] != self.scale.size:
            raise ValueError(f"x must have shape (..., {self.scale.size}), got {x.shape}")
        return (x * self.scale).reshape(*x.shape[:-1], self.params.horizon, 2)

    def costs(self, xs: np.ndarray) -> np.ndarray:
        """Costs of a batch of normalised sequences ``xs`` (C, 2H) -> (C,), one kernel call."""
        self.n_kernel_calls += 1
        return fused.evaluate(np.atleast_2d(xs), self._frozen, want_grad=False)[0]

    def path(self, x: np.ndarray) -> np.ndarray:
        """Planned UAV states (H, 4) of one normalised sequence ``x`` (2H,)."""
        return fused.path(x, self._frozen)

    def work(self, evaluations: int) -> int:
        """Model steps of ``evaluations`` evaluations with gradient: :math:`2 T H` each (the
        forward covariance recursion of T hypotheses over H steps, and its adjoint)."""
        return 2 * int(evaluations) * self.target_xy.shape[0] * self.params.horizon

    def value_and_grad(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """``(J(x), grad J(x))`` for one normalised sequence ``x`` (2H,)."""
        x = np.asarray(x, dtype=float)
        if self._cache is not None and np.array_equal(self._cache[0], x):
            return self._cache[1], self._cache[2].copy()
        self.n_kernel_calls += 1
        c, g = fused.evaluate(x.reshape(1, -1), self._frozen, want_grad=True)
        f, grad = float(c[0]), g[0]
        self._cache = (x.copy(), f, grad)
        return f, grad.copy()


@functools.cache
def _scale(uav: UAVParams, horizon: int) -> np.ndarray:
    """``(a_max, phi_max)`` repeated H times (2H,), read-only (one per aircraft and H)."""
    out = np.tile(uav.control_scale, horizon)
    out.flags.writeable = False
    return out


def shift_plan(controls: np.ndarray) -> np.ndarray:
    """Warm start: drop the applied control, repeat the last one: (H, 2) -> (H, 2)."""
    controls = np.asarray(controls, dtype=float)
    if controls.ndim != 2 or controls.shape[1] != 2 or controls.shape[0] == 0:
        raise ValueError(f"controls must have shape (H, 2) with H >= 1, got {controls.shape}")
    return np.vstack([controls[1:], controls[-1:]])


@functools.cache
def _box(n: int) -> scipy.optimize.Bounds:
    """The normalised control box [-1, 1]^n (built once per size: scipy's bounds parsing is a
    large share of a small problem's optimiser overhead)."""
    from scipy.optimize import Bounds

    return Bounds(np.full(n, -1.0), np.full(n, 1.0))


def lbfgsb(problem: PlanningProblem, x0: np.ndarray, maxiter: int, maxfun: int | None = None):
    """scipy's L-BFGS-B on ``problem`` (exact gradient) over the box [-1, 1]^2H from ``x0``,
    at most ``maxiter`` iterations (and ``maxfun`` evaluations if given); the scipy result."""
    guards.instance_of("problem", problem, PlanningProblem)
    n = 2 * problem.params.horizon
    x0 = guards.finite_array("x0", x0, shape=(n,))
    maxiter = guards.positive_int("maxiter", maxiter)
    if maxfun is not None:
        maxfun = guards.positive_int("maxfun", maxfun)
    return _lbfgsb(problem, x0, maxiter, maxfun)


def _lbfgsb(problem: PlanningProblem, x0: np.ndarray, maxiter: int, maxfun: int | None = None):
    # scipy.optimize is imported here, not with the module: the default optimiser (BoxQN) does
    # not need it, and it costs every job that imports the planner ~0.4 s
    from scipy.optimize import minimize

    options = {"maxiter": maxiter} if maxfun is None else {"maxiter": maxiter, "maxfun": maxfun}
    return minimize(
        problem.value_and_grad,
        x0,
        jac=True,
        method="L-BFGS-B",
        bounds=_box(x0.size),
        options=options,
    )


def plan(problem: PlanningProblem, warm_start: np.ndarray, *, check: bool = True) -> PlanResult:
    """Minimise the problem's cost from ``warm_start`` (H, 2) controls with L-BFGS-B.

    ``check=False`` skips the checks of ``problem`` (a :class:`PlanningProblem`) and
    ``warm_start`` (finite, shape (H, 2))."""
    if check:
        guards.instance_of("problem", problem, PlanningProblem)
        guards.finite_array("warm_start", warm_start, shape=(problem.params.horizon, 2))
    x0 = np.clip(np.asarray(warm_start, dtype=float).ravel() / problem.scale, -1.0, 1.0)
    calls = problem.n_kernel_calls
    f0, _ = problem.value_and_grad(x0)
    res = _lbfgsb(problem, x0, problem.params.maxiter, problem.params.maxfun)
    x_best, f_best = (res.x, float(res.fun)) if res.fun <= f0 else (x0, f0)
    controls = problem.controls(x_best)
    return PlanResult(
        controls=controls,
        cost=f_best,
        cost_warm=f0,
        nit=int(res.nit),
        n_kernel_calls=problem.n_kernel_calls,
        uav_path=problem.path(x_best),
        work=problem.work(problem.n_kernel_calls - calls),  # the cache spares repeats
        # scipy's status 0: converged (projected gradient or relative decrease); 1: a budget
        converged=bool(res.status == 0),
    )


@dataclass(frozen=True)
class LBFGSB:
    """scipy's L-BFGS-B with the exact gradient over the box, at most ``params.maxiter``
    iterations and ``params.maxfun`` evaluations (see :func:`plan`): the oracle of
    :class:`BoxQN`, selectable with ``optimiser: scipy``."""

    def minimise(self, problem: PlanningProblem, warm_start: np.ndarray) -> PlanResult:
        return plan(problem, warm_start, check=False)


@dataclass(frozen=True)
class BoxQN:
    """The default optimiser: :func:`rsmhp.core.boxqn.minimise` (projected L-BFGS, scipy's budgets
    and tolerances) on the compiled cost, from the warm start clipped into the box, in one
    compiled call. ``diagnostics["status"]`` is its stopping reason
    (:data:`rsmhp.core.boxqn.STATUS`); ``n_kernel_calls`` counts the warm start's evaluation."""

    def minimise(self, problem: PlanningProblem, warm_start: np.ndarray) -> PlanResult:
        x0 = np.clip(np.asarray(warm_start, dtype=float).ravel() / problem.scale, -1.0, 1.0)
        p = problem.params
        x, f, f0, nit, nfev, status = fused.minimise(x0, problem._frozen, p.maxiter, p.maxfun)
        problem.n_kernel_calls += nfev
        return PlanResult(
            controls=problem.controls(x),
            cost=f,
            cost_warm=f0,
            nit=nit,
            n_kernel_calls=problem.n_kernel_calls,
            uav_path=problem.path(x),
            diagnostics={"status": float(status)},
            work=problem.work(nfev),  # the start's evaluation included
            converged=status in CONVERGED,
        )


#: the :data:`rsmhp.core.boxqn.STATUS` codes of a converged optimisation (a tolerance, not a budget,
#: stopped it)
CONVERGED = (0, 1)

#: the optimiser of each ``PlannerParams.optimiser`` name
OPTIMISERS: dict[str, Optimiser] = {"boxqn": BoxQN(), "scipy": LBFGSB()}


def polish(
    problem: PlanningProblem, x0: np.ndarray, maxiter: int, maxfun: int | None = None
) -> tuple[np.ndarray, float]:
    """Minimise ``problem`` from ``x0`` (2H,) with the optimiser ``problem.params.optimiser``
    names, at most ``maxiter`` iterations and ``maxfun`` evaluations (``None``: scipy's
    default 15000): ``(x, J(x))`` with x in the box (e.g. the open-loop reference's
    multi-start)."""
    guards.instance_of("problem", problem, PlanningProblem)
    n = 2 * problem.params.horizon
    x0 = guards.finite_array("x0", x0, shape=(n,))
    maxiter = guards.positive_int("maxiter", maxiter)
    maxfun = 15000 if maxfun is None else guards.positive_int("maxfun", maxfun)
    if problem.params.optimiser == "scipy":
        res = _lbfgsb(problem, x0, maxiter, maxfun)
        return np.clip(res.x, -1.0, 1.0), float(res.fun)
    x, f, _, _, nfev, _ = fused.minimise(x0, problem._frozen, maxiter, maxfun)
    problem.n_kernel_calls += nfev
    return x, f


def _halton(i: int, base: int) -> float:
    """The i-th (i >= 1) term of the van der Corput sequence in ``base``, in (0, 1)."""
    f, out = 1.0, 0.0
    while i > 0:
        f /= base
        out += f * (i % base)
        i //= base
    return out


@functools.cache
def restart_starts(horizon: int, restarts: int) -> np.ndarray:
    r"""The fixed starts of the restarts, normalised (restarts, 2H), read-only: restart i
    (i = 1, 2, ...) holds one control :math:`c_i` over the whole horizon, a held turn or
    acceleration, with :math:`c_i = 2 h_i - 1` and :math:`h_i` the i-th point of the 2-D
    Halton sequence (bases 2, 3): (0, −1/3) (hold speed, gentle turn), (−1/2, 1/3),
    (1/2, −7/9), ... spread over the box. The
    starts depend on nothing random, so every method and every step gets the same ones
    (a paired design of the optimiser budget) and a deterministic method needs no stream."""
    out = np.empty((restarts, 2 * horizon))
    for i in range(restarts):
        c = (2 * _halton(i + 1, 2) - 1, 2 * _halton(i + 1, 3) - 1)
        out[i] = np.tile(c, horizon)
    out.flags.writeable = False
    return out


@dataclass(frozen=True)
class SampledCostPlanner:
    """The planner of every sampling method: draw the method's weighted hypotheses for the
    belief (``draw(belief, rng)``), build the weighted cost and minimise it with
    ``optimiser`` (default: the one ``params.optimiser`` names) from the warm start, or, with
    ``params.start == "pursuit"``, from the pursuit policy's plan at the belief
    (:func:`rsmhp.models.uav.dpw.pursuit_plan` times the control scale; deterministic, it
    draws nothing); then the ``params.restarts`` restarts (:func:`restart_starts`), the same
    for either start. ``cost_warm`` is the cost of the first optimisation's start (the warm
    start's or the pursuit plan's); the pursuit plan's H - 1 nominal propagations are added
    to ``work``."""

    draw: Callable[[Belief, np.random.Generator], Any]
    uav: UAVParams
    target: TargetModel
    sensor: SensorModel
    params: PlannerParams
    optimiser: Optimiser | None = None  # None: OPTIMISERS[params.optimiser]

    def __post_init__(self) -> None:
        if self.optimiser is None:
            object.__setattr__(self, "optimiser", OPTIMISERS[self.params.optimiser])
        # the pursuit start's model step, built once per planner (not a field: equality and
        # the planner's description are the fields')
        pursue = self.params.start == "pursuit"
        stepper = Stepper(self.uav, self.target, self.sensor) if pursue else None
        object.__setattr__(self, "_stepper", stepper)

    def plan(
        self, belief: Belief, warm_start: np.ndarray, rng: np.random.Generator | None
    ) -> PlanResult:
        hyp = self.draw(belief, rng)
        problem = PlanningProblem(
            belief.uav,
            belief.P_hat,
            hyp.states[..., :2],
            self.uav,
            self.target,
            self.sensor,
            self.params,
            weights=hyp.weights,
            check=False,
        )
        start, tail = warm_start, 0
        if self.params.start == "pursuit":
            scale = self.uav.control_scale
            r = dpw.pursuit_search(
                belief.uav, belief.x_hat, belief.P_hat, self._stepper, scale,
                self.params.horizon,
            )  # fmt: skip
            start, tail = r.plan * scale, r.work
        res = self.optimiser.minimise(problem, start)
        res.work += tail
        if self.params.restarts:
            res = _restart(self.optimiser, problem, res, self.params.restarts)
        res.hypotheses = hyp
        return res


def _restart(
    optimiser: Optimiser, problem: PlanningProblem, first: PlanResult, restarts: int
) -> PlanResult:
    """The best of ``first`` and ``restarts`` optimisations from :func:`restart_starts` (the
    lowest own cost; ties keep the earlier), with the work and iterations of all of them and
    ``diagnostics["restart"]`` = which one won (0: the first optimisation, from the warm
    start or the pursuit plan)."""
    best, work, nit = first, first.work, first.nit
    winner = 0
    starts = restart_starts(problem.params.horizon, restarts)
    for i, x0 in enumerate(starts, start=1):
        res = optimiser.minimise(problem, problem.controls(x0))
        work += res.work
        nit += res.nit
        if res.cost < best.cost:
            best, winner = res, i
    best.work, best.nit = work, nit
    best.cost_warm = first.cost_warm
    best.diagnostics = {**best.diagnostics, "restart": float(winner)}
    return best
