"""The pursuit policy alone (family ``pursuit``) and the pursuit start of the sampled-cost
planners (``uav.planner.start: pursuit``).

Oracles:

* :func:`rsmhp.models.uav.dpw.pursuit_plan` against a plain-Python replay of its definition:
  the pursuit action written out in numpy from the formula of the ``dpw`` module docstring,
  u_j = pi(s_j, x_j), s_{j+1} = kinematics.step(s_j, u_j scale), x_{j+1} = F x_j (to 1e-12);
  it is the tree search's tail from the root (the search with no simulation: plan depth 0,
  H - 1 nominal propagations) and draws nothing from the stream it is passed;
* the family: registered, switched by ``pursuit: true``, a closed-loop run gives finite
  errors and plan depth 0, and every applied control is the pursuit action at that step's
  belief (the beliefs taken from the run's own recording); planning with or without a stream,
  or with another one, gives the same plan;
* the pursuit start: the first optimisation's start cost (``cost_warm``) is the method's own
  cost (``PlanningProblem.costs``) of the pursuit plan, clipped into the box as the optimisers
  clip a start; with the warm start, of the warm start; the restarts are unchanged; a start
  other than warm or pursuit is refused naming the field; the compiled loop is not taken.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from rsmhp.models.uav import dpw, kinematics, loop, methods
from rsmhp.models.uav.methods.pursuit import Pursuit, PursuitPlanner
from rsmhp.models.uav.planner import (
    STARTS,
    Belief,
    PlannerParams,
    PlanningProblem,
    SampledCostPlanner,
)
from rsmhp.models.uav.simulation import UAVSetup, draw_scenario, simulate_run
from rsmhp.models.uav.stepper import Stepper

ROOT = Path(__file__).resolve().parents[3]
UAV = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["uav"]
P_HAT = np.array(
    [
        [900.0, 120.0, 30.0, -4.0],
        [120.0, 400.0, 5.0, 9.0],
        [30.0, 5.0, 16.0, 1.0],
        [-4.0, 9.0, 1.0, 9.0],
    ]
)
BELIEFS = [
    Belief(np.array([0.0, 0.0, 20.0, 0.0]), np.array([300.0, -50.0, 6.0, 2.0]), P_HAT),
    Belief(np.array([40.0, -10.0, 12.0, 2.5]), np.array([-200.0, 400.0, -3.0, 7.0]), P_HAT),
    Belief(np.array([5.0, 5.0, 34.0, -1.0]), np.array([8.0, 6.0, 0.5, -0.5]), P_HAT),
]


def _setup(horizon: int = 6, steps: int = 60, **planner) -> UAVSetup:
    cfg = copy.deepcopy(UAV)
    cfg["planner"].update(horizon=horizon, **planner)
    cfg["scenario"]["steps"] = steps
    return UAVSetup.from_config(cfg)


def _pi(s: np.ndarray, xh: np.ndarray, setup: UAVSetup) -> np.ndarray:
    """The pursuit action from its formula (rsmhp.models.uav.dpw's docstring), in numpy."""
    u = setup.uav
    dx, dy = xh[0] - s[0], xh[1] - s[1]
    e = math.remainder(math.atan2(dy, dx) - s[3], 2 * math.pi)  # into [-pi, pi]
    bank = np.clip(e / (math.pi / 2), -1.0, 1.0)
    v_ref = np.clip(math.hypot(xh[2], xh[3]) + math.hypot(dx, dy) / dpw.PURSUIT_TAU,
                    u.speed_min, u.speed_max)  # fmt: skip
    accel = np.clip((v_ref - s[2]) / (u.accel_max * u.dt), -1.0, 1.0)
    return np.array([accel, bank])


def _replay(belief: Belief, setup: UAVSetup) -> np.ndarray:
    """u_j = pi(s_j, x_j), s_{j+1} = f(s_j, u_j scale), x_{j+1} = F x_j (normalised plan)."""
    scale = setup.uav.control_scale
    s, xh = np.array(belief.uav, float), np.array(belief.x_hat, float)
    out = np.empty((setup.planner.horizon, 2))
    for j in range(setup.planner.horizon):
        out[j] = _pi(s, xh, setup)
        s = kinematics.step(s, out[j] * scale, setup.uav)
        xh = setup.target.F @ xh
    return out


# ---------------------------------------------------------------- the pursuit plan


@pytest.mark.parametrize("H", [1, 6, 15])
@pytest.mark.parametrize("b", range(len(BELIEFS)))
def test_the_pursuit_plan_is_the_policy_on_the_nominal_propagation(H, b):
    setup = _setup(H)
    belief = BELIEFS[b]
    st = Stepper(setup.uav, setup.target, setup.sensor)
    scale = setup.uav.control_scale
    plan = dpw.pursuit_plan(belief.uav, belief.x_hat, belief.P_hat, st, scale, H)
    assert plan.shape == (H, 2) and (np.abs(plan) <= 1.0).all()
    np.testing.assert_allclose(plan, _replay(belief, setup), rtol=1e-12, atol=1e-12)
    # the compiled pursuit action is the formula's
    np.testing.assert_allclose(
        dpw.pursuit(belief.uav, belief.x_hat, st), _pi(belief.uav, belief.x_hat, setup),
        rtol=1e-12, atol=1e-12,
    )  # fmt: skip
    # the tree search's tail from the root: the search with no simulation, any warm start
    warm = np.random.default_rng(b).uniform(-1, 1, (H, 2))
    rng = np.random.default_rng(11)
    state = copy.deepcopy(rng.bit_generator.state)
    r = dpw.search(belief.uav, belief.x_hat, belief.P_hat, warm, scale, 0,
                   (0.5, 4.0, 0.25, 4.0, 0.25), st, rng, "pursuit")  # fmt: skip
    assert rng.bit_generator.state == state  # it draws nothing
    np.testing.assert_array_equal(r.plan, plan)
    assert (r.plan_depth, r.root_actions, r.search_calls, r.tail_steps) == (0, 0, 0, H - 1)
    assert r.work == H - 1
    assert dpw._NO_DRAWS.bit_generator.state == np.random.default_rng(0).bit_generator.state


def test_the_plan_ignores_the_covariance():
    setup = _setup(8)
    st = Stepper(setup.uav, setup.target, setup.sensor)
    b = BELIEFS[0]
    a = dpw.pursuit_plan(b.uav, b.x_hat, b.P_hat, st, setup.uav.control_scale, 8)
    c = dpw.pursuit_plan(b.uav, b.x_hat, 9.0 * b.P_hat, st, setup.uav.control_scale, 8)
    np.testing.assert_array_equal(a, c)


# ---------------------------------------------------------------- the family


def test_the_family_is_registered_and_switched_by_a_flag():
    m = methods.from_name("pursuit")
    assert isinstance(m, Pursuit) and m == Pursuit()
    assert (m.family, m.name, m.family_label) == ("pursuit", "pursuit", "pursuit policy")
    assert not m.uses_rng and not m.estimates_cost and type(m).closed_loop == "python"
    assert m.columns() == {"N_T": 0, "N": 0, "M": 0} and methods.from_spec(m.spec()) == m
    assert Pursuit.from_config(True, "p") == [m] and Pursuit.from_config(False, "p") == []
    assert "pursuit" not in methods.from_config({})  # default: off
    assert "pursuit" in methods.from_config({"pursuit": True})
    orders = {c.order for c in methods.families() if c is not Pursuit}
    assert Pursuit.order not in orders and Pursuit.order > methods.from_name("dpw_s10").order
    with pytest.raises(NotImplementedError):
        m.hypotheses(BELIEFS[0], _setup(), np.random.default_rng(0))
    with pytest.raises(TypeError):
        Pursuit.from_config("yes", "methods.pursuit")


def test_the_planner_returns_the_pursuit_plan_and_draws_nothing():
    setup = _setup(6)
    planner = methods.from_name("pursuit").planner(setup)
    assert isinstance(planner, PursuitPlanner)
    b = BELIEFS[1]
    warm = np.tile([1.0, -0.2], (6, 1))
    res = planner.plan(b, warm, None)
    scale = setup.uav.control_scale
    np.testing.assert_allclose(res.controls / scale, _replay(b, setup), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(
        res.uav_path, kinematics.rollout(b.uav, res.controls, setup.uav), rtol=1e-12, atol=1e-9
    )
    assert res.diagnostics == {"plan_depth": 0.0, "tail_steps": 5.0}
    assert (res.work, res.nit, res.converged, res.hypotheses) == (5, 0, None, None)
    assert math.isnan(res.cost_warm)
    # the reported cost: NBO's nominal cost of the plan
    nominal = np.stack([np.linalg.matrix_power(setup.target.F, j) @ b.x_hat for j in range(1, 7)])
    problem = PlanningProblem(b.uav, b.P_hat, nominal[None, :, :2], setup.uav, setup.target,
                              setup.sensor, setup.planner)  # fmt: skip
    want = problem.costs((res.controls / scale).reshape(1, -1))[0]
    assert res.cost == pytest.approx(want, rel=1e-12)
    # no stream, a stream, another stream, another warm start: the same plan
    for rng, w in ((np.random.default_rng(1), warm), (np.random.default_rng(2), np.zeros((6, 2)))):
        again = planner.plan(b, w, rng)
        np.testing.assert_array_equal(again.controls, res.controls)
        assert again.cost == res.cost and again.work == res.work


def test_a_closed_loop_run_applies_the_pursuit_action_at_every_belief():
    setup = _setup(5, steps=12)
    m = methods.from_name("pursuit")
    assert loop.path(m, setup)[0] == "python"
    seen = []
    summary, rows = simulate_run(setup, m, 7, 2, observer=seen.append)
    assert len(rows) == 12 and all(math.isfinite(r["error"]) for r in rows)
    assert summary["diagnostics"] == {"plan_depth": 0.0, "tail_steps": 4.0}
    assert summary["work_per_step"] == 4.0 and summary["mean_nit"] == 0.0
    assert math.isfinite(summary["mean_error"]) and math.isnan(summary["converged_rate"])
    sc = draw_scenario(setup, 7, 2)
    beliefs = [(sc.uav, sc.estimate)] + [(info.uav, info.estimate) for info in seen[:-1]]
    scale = setup.uav.control_scale
    for row, (uav, x_hat) in zip(rows, beliefs, strict=True):
        u = np.array([row["accel"], row["bank"]])
        np.testing.assert_allclose(u, _pi(uav, x_hat, setup) * scale, rtol=1e-12, atol=1e-12)
    # the rows do not depend on the recording nor on the seed of a planning stream (none)
    _, again = simulate_run(setup, m, 7, 2)

    def hexed(rs):
        return [{k: v.hex() if isinstance(v, float) else v for k, v in r.items()} for r in rs]

    assert hexed(again) == hexed(rows)


# ---------------------------------------------------------------- the pursuit start


def test_planner_params_start():
    assert STARTS == ("warm", "pursuit")
    assert PlannerParams(6, 30, 60).start == "warm"
    assert PlannerParams(6, 30, 60, start="pursuit").start == "pursuit"
    with pytest.raises(ValueError, match=r"PlannerParams\.start must be one of \['warm', "
                                         r"'pursuit'\], got 'bad'"):  # fmt: skip
        PlannerParams(6, 30, 60, start="bad")
    assert _setup().planner.start == "warm"  # config without the key
    assert _setup(start="pursuit").planner.start == "pursuit"


@pytest.mark.parametrize("optimiser", ["boxqn", "scipy"])
@pytest.mark.parametrize("name", ["nbo", "rsmhp_nt16"])
def test_the_pursuit_start_is_the_first_optimisations_start(name, optimiser):
    H = 6
    m = methods.from_name(name)
    warm_setup = _setup(H, maxiter=5, maxfun=11, optimiser=optimiser)
    pursuit_setup = _setup(H, maxiter=5, maxfun=11, optimiser=optimiser, start="pursuit")
    b = BELIEFS[0]
    st = Stepper(warm_setup.uav, warm_setup.target, warm_setup.sensor)
    scale = warm_setup.uav.control_scale
    plan = dpw.pursuit_plan(b.uav, b.x_hat, b.P_hat, st, scale, H)
    warm = np.tile([0.3, 0.8], (H, 1)) * scale
    for setup, start in ((warm_setup, warm), (pursuit_setup, plan * scale)):
        planner = m.planner(setup)
        assert isinstance(planner, SampledCostPlanner)
        res = planner.plan(b, warm, np.random.default_rng(4))
        hyp = res.hypotheses
        problem = PlanningProblem(b.uav, b.P_hat, hyp.states[..., :2], setup.uav, setup.target,
                                  setup.sensor, setup.planner, weights=hyp.weights)  # fmt: skip
        x0 = np.clip(np.asarray(start).ravel() / problem.scale, -1.0, 1.0)
        assert res.cost_warm == pytest.approx(problem.costs(x0[None])[0], rel=1e-12)
        assert res.cost <= res.cost_warm
        tail = H - 1 if setup.planner.start == "pursuit" else 0
        assert (res.work - tail) % (2 * hyp.n * H) == 0  # gradient evaluations + the tail
    # the two starts give two different start costs here
    a = m.planner(warm_setup).plan(b, warm, np.random.default_rng(4))
    c = m.planner(pursuit_setup).plan(b, warm, np.random.default_rng(4))
    assert a.cost_warm != c.cost_warm


def test_the_restarts_are_the_same_with_the_pursuit_start():
    """The restarts' work and iterations (with 3 restarts less with none) do not depend on the
    start; a restart that wins gives the same plan from either start."""
    H = 6
    m = methods.from_name("nbo")
    b = BELIEFS[2]
    warm = np.zeros((H, 2))
    got = {}
    for start in STARTS:
        plans = [
            m.planner(_setup(H, maxiter=5, maxfun=11, restarts=r, start=start)).plan(b, warm, None)
            for r in (0, 3)
        ]
        got[start] = plans[1]
        assert plans[1].cost_warm == plans[0].cost_warm  # the first optimisation's start
        got[start, "rest"] = (plans[1].work - plans[0].work, plans[1].nit - plans[0].nit)
    assert got["warm", "rest"] == got["pursuit", "rest"]
    won = (got["warm"].diagnostics["restart"], got["pursuit"].diagnostics["restart"])
    if won[0] == won[1] > 0:  # the same restart won from either start: the same optimisation
        np.testing.assert_array_equal(got["warm"].controls, got["pursuit"].controls)


def test_the_pursuit_start_takes_the_python_loop():
    setup = _setup(4, steps=3, start="pursuit")
    nbo = methods.from_name("nbo")
    which, why = loop.path(nbo, setup)
    assert which == "python"
    assert why == "start 'pursuit' (the compiled loop starts from the warm start only)"
    assert loop.path(nbo, _setup(4, steps=3))[0] == "compiled"
    with pytest.raises(ValueError, match="no compiled closed loop for nbo: start 'pursuit'"):
        simulate_run(setup, nbo, 1, 0, path="compiled")
    summary, rows = simulate_run(setup, nbo, 1, 0)  # auto: the Python loop
    assert len(rows) == 3 and math.isfinite(summary["mean_error"])
