"""The batched covariance kernel against filterpy, and the planner built on it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rsmhp.core.stats import bootstrap_ci
from rsmhp.models.uav import kinematics, sensor, target
from rsmhp.models.uav.kernel import covariance_traces, objective
from rsmhp.models.uav.kinematics import UAVParams
from rsmhp.models.uav.planner import (
    LBFGSB,
    OPTIMISERS,
    BoxQN,
    PlannerParams,
    PlanningProblem,
    SampledCostPlanner,
    plan,
    polish,
    shift_plan,
)
from rsmhp.models.uav.sensor import SensorModel
from rsmhp.models.uav.target import TargetModel
from rsmhp.models.uav.tracker import Tracker

UAV = UAVParams(
    dt=1.0, g=9.81, accel_max=3.0, bank_max=math.pi / 4, speed_min=10, speed_max=35, altitude=100
)
SENSOR = SensorModel(0.05, 0.10, 100.0)
MODEL = TargetModel(1.0, 1.0)
PLANNER = PlannerParams(horizon=6, maxiter=30, maxfun=60)


def _inputs(rng, n_c=4, n_t=7, H=6):
    A = rng.standard_normal((4, 4))
    P0 = np.diag([2500.0, 2500.0, 25.0, 25.0]) + 10 * A @ A.T
    uav_xy = rng.uniform(-600, 600, (n_c, H, 2))
    tgt_xy = rng.uniform(-600, 600, (n_t, H, 2))
    tgt_xy[0, 2] = uav_xy[0, 2]  # one measurement taken directly overhead
    return P0, uav_xy, tgt_xy


def test_kernel_matches_filterpy_per_trajectory(rng):
    P0, uav_xy, tgt_xy = _inputs(rng)
    traces, covs = covariance_traces(P0, uav_xy, tgt_xy, 1.0, MODEL.Q, SENSOR, return_cov=True)
    for c in range(uav_xy.shape[0]):
        for i in range(tgt_xy.shape[0]):
            trk = Tracker(np.zeros(4), P0, MODEL)
            for j in range(uav_xy.shape[1]):
                trk.predict()
                trk.update(np.zeros(2), sensor.measurement_cov(uav_xy[c, j], tgt_xy[i, j], SENSOR))
                P = trk.P
                scale = np.abs(P).max()
                np.testing.assert_allclose(covs[c, i, j], P, rtol=0, atol=1e-9 * scale)
                assert traces[c, i, j] == pytest.approx(np.trace(P), rel=1e-9)
    # exact symmetry of the carried covariance
    np.testing.assert_array_equal(covs, np.swapaxes(covs, -1, -2))


def test_objective_is_mean_over_hypotheses_of_summed_traces(rng):
    P0, uav_xy, tgt_xy = _inputs(rng)
    tr = covariance_traces(P0, uav_xy, tgt_xy, 1.0, MODEL.Q, SENSOR)
    np.testing.assert_allclose(
        objective(P0, uav_xy, tgt_xy, 1.0, MODEL.Q, SENSOR), tr.sum(axis=2).mean(axis=1)
    )
    # each hypothesis is independent of the others in the batch
    alone = covariance_traces(P0, uav_xy[1:2], tgt_xy[3:4], 1.0, MODEL.Q, SENSOR)
    np.testing.assert_allclose(alone[0, 0], tr[1, 3], rtol=1e-14)


def _problem(rng, n_traj=30):
    uav_state = np.array([0.0, 0.0, 20.0, 0.0])
    x_hat = np.array([450.0, 250.0, -6.0, 4.0])
    P_hat = np.diag([900.0, 900.0, 16.0, 16.0])
    hyp = target.sample_independent(x_hat, P_hat, 6, n_traj, MODEL, rng)
    return PlanningProblem(uav_state, P_hat, hyp[..., :2], UAV, MODEL, SENSOR, PLANNER)


def test_value_and_grad_is_one_compiled_call_matching_the_numpy_oracle(rng):
    prob = _problem(rng)
    x = rng.uniform(-0.8, 0.8, 12)
    f, g = prob.value_and_grad(x)
    assert prob.n_kernel_calls == 1
    prob.value_and_grad(x.copy())  # cached: no second call
    assert prob.n_kernel_calls == 1
    states = kinematics.rollout(prob.uav_state, prob.controls(x[None]), UAV)
    ref = objective(prob.P_hat, states[..., :2], prob.target_xy, 1.0, MODEL.Q, SENSOR)[0]
    assert f == pytest.approx(ref, rel=1e-12)
    # the gradient is the fused kernel's exact one (tested against complex step in
    # test_uav_fused); here: it is the derivative of the planner's own costs()
    e = np.eye(12)[3] * 1e-6
    central = (prob.costs(x[None] + e)[0] - prob.costs(x[None] - e)[0]) / 2e-6
    assert g[3] == pytest.approx(central, rel=1e-5)


def test_gradient_is_finite_on_the_box_corners(rng):
    prob = _problem(rng)
    for x in (np.ones(12), -np.ones(12)):
        _, g = prob.value_and_grad(x)
        assert np.all(np.isfinite(g))


@pytest.mark.parametrize("seed", range(6))
def test_plans_stay_in_the_control_box(seed):
    """From warm starts on and outside the box, over random geometry, every planned control
    lies in the box and the plan is never worse than the (clipped) warm start."""
    rng = np.random.default_rng(seed)
    uav_state = np.array([*rng.uniform(-200, 200, 2), rng.uniform(10, 35), rng.uniform(-3, 3)])
    x_hat = np.array([*rng.uniform(-500, 500, 2), *rng.uniform(-10, 10, 2)])
    P_hat = np.diag(rng.uniform(1, 3000, 4))
    hyp = target.sample_independent(x_hat, P_hat, 6, 20, MODEL, rng)
    prob = PlanningProblem(uav_state, P_hat, hyp[..., :2], UAV, MODEL, SENSOR, PLANNER)
    warm = rng.uniform(-2, 2, (6, 2)) * UAV.control_scale  # partly outside the box
    res = plan(prob, warm)
    assert np.all(np.abs(res.controls) <= UAV.control_scale * (1 + 1e-12))
    x_warm = np.clip(warm / UAV.control_scale, -1, 1).reshape(1, -1)
    assert res.cost <= prob.costs(x_warm)[0]
    assert res.cost == pytest.approx(
        prob.costs((res.controls / UAV.control_scale).reshape(1, -1))[0]
    )


def test_optimizer_decreases_objective_vs_warm_start(rng):
    prob = _problem(rng)
    warm = np.zeros((6, 2))  # straight ahead (east) while the target is north-east
    res = plan(prob, warm)
    assert res.cost_warm == pytest.approx(prob.costs(np.zeros((1, 12)))[0])
    assert res.cost == pytest.approx(
        prob.costs((res.controls / UAV.control_scale).reshape(1, -1))[0]
    )
    # a real improvement, far above rounding (relative ~1e-12)
    assert res.cost < res.cost_warm * (1 - 1e-6)
    assert np.all(np.abs(res.controls) <= UAV.control_scale + 1e-12)
    np.testing.assert_allclose(res.uav_path, kinematics.rollout(prob.uav_state, res.controls, UAV))


def test_shift_plan():
    u = np.arange(12.0).reshape(6, 2)
    np.testing.assert_array_equal(shift_plan(u), np.vstack([u[1:], u[-1:]]))


# ------------------------------------------------------------------ compiled optimiser


def _belief_problem(rng, sensor_model, n_t):
    uav_state = np.array([*rng.uniform(-300, 300, 2), rng.uniform(12, 33), rng.uniform(-3, 3)])
    x_hat = np.array([*rng.uniform(-300, 300, 2), *rng.uniform(-8, 8, 2)])
    P_hat = np.diag([*rng.uniform(10, 3000, 2), *rng.uniform(1, 30, 2)])
    hyp = target.sample_independent(x_hat, P_hat, 6, n_t, MODEL, rng)

    def prob() -> PlanningProblem:  # a fresh problem (its counters) per optimiser
        return PlanningProblem(uav_state, P_hat, hyp[..., :2], UAV, MODEL, sensor_model, PLANNER)

    warm = rng.uniform(-1, 1, (6, 2)) * UAV.control_scale
    return prob, warm


@pytest.mark.parametrize("footprint", [False, True])
def test_compiled_optimiser_decides_as_well_as_scipy(footprint):
    """BoxQN against scipy's L-BFGS-B (same budgets, same starts) on 200 random belief states
    (random warm starts) with 1 and 30 hypotheses: the paired difference of final costs
    (compiled - scipy) has a 95% bootstrap interval whose upper limit is at most 0.1% of the
    mean cost (the issue's quality rule; benchmarks/optimiser_quality.py runs it on
    closed-loop belief states), and the compiled plan is never worse than its warm start."""
    sens = SensorModel(0.05, 0.10, 100.0, footprint_radius=200.0) if footprint else SENSOR
    rng = np.random.default_rng(11 if footprint else 12)
    diffs, costs = [], []
    for i in range(200):
        prob, warm = _belief_problem(rng, sens, 1 if i % 2 else 30)
        ours = BoxQN().minimise(prob(), warm)
        ref = LBFGSB().minimise(prob(), warm)
        assert ours.cost <= ours.cost_warm
        assert np.all(np.abs(ours.controls) <= UAV.control_scale * (1 + 1e-12))
        diffs.append(ours.cost - ref.cost)
        costs.append(ref.cost)
    d = np.array(diffs)
    # percentile bootstrap: the differences are heavy-tailed (a different local minimum
    # now and then, mostly in the compiled optimiser's favour), where a t interval's
    # symmetric half-width says little about the upper side
    _, upper = bootstrap_ci(d, np.random.default_rng(0), 10_000, 0.95)
    assert upper <= 1e-3 * np.mean(costs), (upper, np.mean(costs))


def test_optimiser_is_chosen_by_the_planner_params():
    draw = lambda belief, rng: None  # noqa: E731 - never called here
    for name, kind in (("boxqn", BoxQN), ("scipy", LBFGSB)):
        params = PlannerParams(6, 30, 60, optimiser=name)
        planner = SampledCostPlanner(draw, UAV, MODEL, SENSOR, params)
        assert isinstance(planner.optimiser, kind)
        assert OPTIMISERS[name] == planner.optimiser
    with pytest.raises(ValueError, match=r"optimiser must be one of \['boxqn', 'scipy'\]"):
        PlannerParams(6, 30, 60, optimiser="newton")
    # polish uses the problem's optimiser; both land on the same cost here (a convex-enough
    # start) within the stopping tolerance
    for name in ("boxqn", "scipy"):
        p = PlanningProblem(
            np.array([0.0, 0.0, 20.0, 0.0]),
            np.diag([900.0, 900.0, 9.0, 9.0]),
            np.full((5, 6, 2), 150.0),
            UAV,
            MODEL,
            SENSOR,
            PlannerParams(6, 30, 60, optimiser=name),
        )
        x, f = polish(p, np.zeros(12), 50)
        assert np.all(np.abs(x) <= 1.0)
        assert f == pytest.approx(p.costs(x[None])[0], rel=1e-12)
        assert f <= p.costs(np.zeros((1, 12)))[0]


def test_compiled_plan_reports_its_counters():
    rng = np.random.default_rng(5)
    prob, warm = _belief_problem(rng, SENSOR, 20)
    p = prob()
    res = BoxQN().minimise(p, warm)
    assert 1 <= res.n_kernel_calls <= PLANNER.maxfun
    assert 0 <= res.nit <= PLANNER.maxiter
    assert res.diagnostics["status"] in (0.0, 1.0, 2.0, 3.0, 4.0)
    x = (res.controls / UAV.control_scale).reshape(1, -1)
    assert res.cost == pytest.approx(p.costs(x)[0], rel=1e-12)
    x0 = np.clip(warm / UAV.control_scale, -1, 1).reshape(1, -1)
    assert res.cost_warm == pytest.approx(p.costs(x0)[0], rel=1e-12)
    np.testing.assert_allclose(res.uav_path, kinematics.rollout(p.uav_state, res.controls, UAV))


def test_work_counts_two_passes_per_evaluation_and_convergence_follows_the_status():
    """Oracle: work = 2 T H x evaluations (forward and adjoint pass per gradient evaluation);
    converged is True exactly for the tolerance stops (boxqn status 0/1; scipy status 0)."""
    rng = np.random.default_rng(5)
    prob, warm = _belief_problem(rng, SENSOR, 20)
    p = prob()
    res = BoxQN().minimise(p, warm)
    T, H = p.target_xy.shape[0], p.params.horizon
    assert res.work == 2 * T * H * res.n_kernel_calls
    assert res.converged == (res.diagnostics["status"] in (0.0, 1.0))
    tight = PlanningProblem(p.uav_state, p.P_hat, p.target_xy, UAV, MODEL, SENSOR,
                            PlannerParams(6, 1, 60))  # fmt: skip
    one = BoxQN().minimise(tight, warm)
    assert one.nit == 1 and one.converged is False and one.diagnostics["status"] == 2.0
    q = prob()
    s = LBFGSB().minimise(q, warm)
    assert s.work == 2 * T * H * q.n_kernel_calls and isinstance(s.converged, bool)


def test_restarts_never_worsen_the_plan_and_add_their_work():
    """The restarts keep the warm-start plan unless a fixed start finds a lower own cost;
    their work and iterations add up; the starts are held controls inside the box (the 2-D
    Halton points, bases 2 and 3, mapped to [-1, 1]), and the same for every call (no stream)."""
    from rsmhp.models.uav.methods.base import Hypotheses
    from rsmhp.models.uav.planner import Belief, restart_starts

    starts = restart_starts(6, 5)
    assert starts.shape == (5, 12) and np.all(np.abs(starts) <= 1)
    np.testing.assert_allclose(starts[:3, :2], [[0, -1 / 3], [-1 / 2, 1 / 3], [1 / 2, -7 / 9]])
    assert np.all(starts[:, 0::2] == starts[:, [0]]) and np.all(starts[:, 1::2] == starts[:, [1]])
    assert restart_starts(6, 5) is starts and not starts.flags.writeable
    rng = np.random.default_rng(11)
    P0, _, tgt = _inputs(rng, n_t=9)
    hyp = Hypotheses.equal(np.concatenate([tgt, np.zeros((9, 6, 2))], axis=2))
    belief = Belief(np.array([-400.0, 300.0, 20.0, 0.5]), np.zeros(4), P0)

    def planner(k):
        params = PlannerParams(6, 30, 60, restarts=k)
        return SampledCostPlanner(lambda b, r: hyp, UAV, MODEL, SENSOR, params)

    warm = np.zeros((6, 2))
    base = planner(0).plan(belief, warm, None)
    more = planner(4).plan(belief, warm, None)
    assert more.cost <= base.cost
    assert more.cost_warm == base.cost_warm and 0 <= more.diagnostics["restart"] <= 4
    singles = [base] + [
        BoxQN().minimise(
            PlanningProblem(belief.uav, P0, tgt, UAV, MODEL, SENSOR, PLANNER),
            (starts[i] * np.tile(UAV.control_scale, 6)).reshape(6, 2),
        )
        for i in range(4)
    ]
    assert more.work == sum(r.work for r in singles)
    assert more.cost == min(r.cost for r in singles)
    with pytest.raises(ValueError, match="restarts"):
        PlannerParams(6, 30, 60, restarts=-1)
