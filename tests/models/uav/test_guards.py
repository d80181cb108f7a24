"""Library guards of rsmhp.models.uav: every public entry point refuses bad arguments up front.

A parametrised matrix of bad calls (kinematics, target, sensor, tracker, kernel, fused, planner,
methods, simulation; each asserts the exception type and that the message names the argument),
then valid edge inputs that must keep working (unchanged numbers).
"""

from __future__ import annotations

import copy
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from rsmhp.core import guards
from rsmhp.core.sampling import GaussianNoise
from rsmhp.models.lqg.linear_quadratic import LinearQuadratic
from rsmhp.models.uav import fused, kernel, kinematics, sensor, target
from rsmhp.models.uav import methods as uav_methods
from rsmhp.models.uav.kinematics import UAVParams
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.models.uav.methods.nbo import NBO as NBOMethod
from rsmhp.models.uav.methods.pruned_tree import PrunedTree
from rsmhp.models.uav.planner import PlannerParams, PlanningProblem, lbfgsb, plan, shift_plan
from rsmhp.models.uav.recording import ellipse_polygon
from rsmhp.models.uav.sensor import SensorModel
from rsmhp.models.uav.simulation import UAVSetup, draw_scenario, simulate_run
from rsmhp.models.uav.target import TargetModel
from rsmhp.models.uav.tracker import Tracker

ROOT = Path(__file__).resolve().parents[3]
UAV_CFG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["uav"]

UAV = UAVParams(1.0, 9.81, 3.0, math.pi / 4, 10.0, 35.0, 100.0)
SENSOR = SensorModel(0.05, 0.10, 100.0)
LOGISTIC = SensorModel(0.05, 0.10, 100.0, footprint_radius=200.0, detection="logistic")
MODEL = TargetModel(1.0, 1.0)
PLANNER = PlannerParams(horizon=3, maxiter=5, maxfun=10)
UAV_STATE = np.array([0.0, 0.0, 20.0, 0.0])
X_HAT = np.array([300.0, 200.0, -5.0, 3.0])
P_HAT = np.diag([900.0, 900.0, 16.0, 16.0])
TXY = np.tile(np.array([300.0, 200.0]), (4, 3, 1))  # (T=4, H=3, 2)
UXY = np.zeros((2, 3, 2))  # (C=2, H=3, 2)
NEG_DEF = -np.eye(4)
NAN = float("nan")


def _cfg(**changes) -> dict:
    cfg = copy.deepcopy(UAV_CFG)
    cfg["scenario"]["steps"] = 2
    cfg["planner"].update(horizon=2, maxiter=2, maxfun=4)
    for path, value in changes.items():
        section, key = path.split("__")
        cfg[section][key] = value
    return cfg


SETUP = UAVSetup.from_config(_cfg())
NBO = NBOMethod()


def _rng() -> np.random.Generator:
    return np.random.default_rng(0)


def _problem(**kw) -> PlanningProblem:
    args = {"uav_state": UAV_STATE, "P_hat": P_HAT, "target_xy": TXY} | kw
    return PlanningProblem(
        args["uav_state"], args["P_hat"], args["target_xy"], UAV, MODEL, SENSOR, PLANNER
    )


def _frozen() -> fused.Frozen:
    return fused.Frozen(UAV_STATE, UAV, P_HAT, TXY, 1.0, MODEL.Q, SENSOR)


V, T = ValueError, TypeError


# (id, call, exception, regex the message must match: it names the argument)
BAD = [
    # ---- the cases reported by the user --------------------------------------------------
    (
        "simulate_run N_T=0",
        lambda: simulate_run(SETUP, MonteCarlo(0), 1, 1),
        V,
        r"n_traj \(N_T\) must be >= 1, got 0",
    ),
    (
        "objective negative-definite P0",
        lambda: kernel.objective(NEG_DEF, UXY, TXY, 1.0, MODEL.Q, SENSOR),
        guards.NotPositiveDefiniteError,
        r"^P0 must be symmetric positive semidefinite",
    ),
    (
        "objective zero horizon",
        lambda: kernel.objective(
            P_HAT, np.zeros((2, 0, 2)), np.zeros((4, 0, 2)), 1.0, MODEL.Q, SENSOR
        ),
        V,
        r"^uav_xy must have shape \(C, H, 2\) with every dimension >= 1",
    ),
    (
        "objective xy width 3",
        lambda: kernel.objective(P_HAT, np.zeros((2, 3, 3)), TXY, 1.0, MODEL.Q, SENSOR),
        V,
        r"^uav_xy must have shape \(C, H, 2\)",
    ),
    (
        "UAVSetup steps=0",
        lambda: UAVSetup.from_config(_cfg(scenario__steps=0)),
        V,
        r"^UAVSetup\.steps must be >= 1, got 0",
    ),
    (
        "PlannerParams horizon=0",
        lambda: PlannerParams(0, 30, 60),
        V,
        r"^PlannerParams\.horizon must be >= 1, got 0",
    ),
    (
        "nominal horizon=0",
        lambda: target.nominal(X_HAT, 0, MODEL),
        V,
        r"^horizon must be >= 1, got 0",
    ),
    (
        "PlanningProblem zero-horizon hypotheses",
        lambda: _problem(target_xy=np.zeros((4, 0, 2))),
        V,
        r"^target_xy must have shape \(T, 3, 2\)",
    ),
    (
        "UAVParams speed_min > speed_max",
        lambda: UAVParams(1.0, 9.81, 3.0, 0.7, 40.0, 35.0, 100.0),
        V,
        r"^UAVParams\.speed_min must be <= UAVParams\.speed_max, got UAVParams\.speed_min = 40\.0",
    ),
    # ---- uav: kinematics, target, sensor, tracker ------------------------------------------
    (
        "UAVParams dt=0",
        lambda: UAVParams(0.0, 9.81, 3.0, 0.7, 10.0, 35.0, 100.0),
        V,
        r"^UAVParams\.dt must be > 0, got 0\.0",
    ),
    (
        "UAVParams g=nan",
        lambda: UAVParams(1.0, NAN, 3.0, 0.7, 10.0, 35.0, 100.0),
        V,
        r"^UAVParams\.g must be finite and > 0, got nan",
    ),
    (
        "UAVParams bank_max=pi/2",
        lambda: UAVParams(1.0, 9.81, 3.0, math.pi / 2, 10.0, 35.0, 100.0),
        V,
        r"^UAVParams\.bank_max must lie in the half-open interval \[0, 1\.5708\)",
    ),
    (
        "UAVParams speed_min=0",
        lambda: UAVParams(1.0, 9.81, 3.0, 0.7, 0.0, 35.0, 100.0),
        V,
        r"^UAVParams\.speed_min must be > 0, got 0\.0",
    ),
    (
        "UAVParams altitude str",
        lambda: UAVParams(1.0, 9.81, 3.0, 0.7, 10.0, 35.0, "100"),
        T,
        r"^UAVParams\.altitude must be a real number > 0, got str '100'",
    ),
    (
        "kinematics.step control width 3",
        lambda: kinematics.step(UAV_STATE, np.zeros(3), UAV),
        V,
        r"^control must have shape \(\.\.\., 2\), got \(3,\)",
    ),
    (
        "kinematics.rollout speed 0",
        lambda: kinematics.rollout([0.0, 0.0, 0.0, 0.0], np.zeros((3, 2)), UAV),
        V,
        r"^state speed state\[\.\.\., 2\] must be > 0",
    ),
    (
        "kinematics.rollout zero horizon",
        lambda: kinematics.rollout(UAV_STATE, np.zeros((0, 2)), UAV),
        V,
        r"^controls must have shape \(\.\.\., H, 2\) with H >= 1",
    ),
    ("turn_rate speed=0", lambda: kinematics.turn_rate(0.0, 0.1, 9.81), V, r"^speed must be > 0"),
    (
        "TargetModel q=nan",
        lambda: TargetModel(1.0, NAN),
        V,
        r"^TargetModel\.q must be finite and > 0, got nan",
    ),
    ("TargetModel q=0", lambda: TargetModel(1.0, 0.0), V, r"^TargetModel\.q must be > 0, got 0\.0"),
    (
        "process_noise q<0",
        lambda: target.process_noise(1.0, -1.0),
        V,
        r"^q must be >= 0, got -1\.0",
    ),
    (
        "target.sample_independent P_hat nan",
        lambda: target.sample_independent(X_HAT, np.full((4, 4), NAN), 3, 5, MODEL, _rng()),
        V,
        r"^P_hat must be finite",
    ),
    (
        "target.sample_independent P_hat not PD",
        lambda: target.sample_independent(X_HAT, NEG_DEF, 3, 5, MODEL, _rng()),
        guards.NotPositiveDefiniteError,
        r"^P_hat must be symmetric positive definite",
    ),
    (
        "target.sample_independent n=0",
        lambda: target.sample_independent(X_HAT, P_HAT, 3, 0, MODEL, _rng()),
        V,
        r"^n must be >= 1, got 0",
    ),
    (
        "target.sample_independent x_hat (3,)",
        lambda: target.sample_independent(X_HAT[:3], P_HAT, 3, 5, MODEL, _rng()),
        V,
        r"^x_hat must have shape \(4,\), got \(3,\)",
    ),
    (
        "target.pruned_tree M=0",
        lambda: target.pruned_tree(X_HAT, P_HAT, 3, 4, 0, MODEL, _rng()),
        V,
        r"^M \(trajectories kept\) must be >= 1, got 0",
    ),
    (
        "target.pruned_tree model",
        lambda: target.pruned_tree(X_HAT, P_HAT, 3, 4, 5, "model", _rng()),
        T,
        r"^model must be a TargetModel",
    ),
    (
        "SensorModel sigma_r bool",
        lambda: SensorModel(True, 0.1, 100.0),
        T,
        r"^SensorModel\.sigma_r_per_m must be a real number > 0, got bool",
    ),
    (
        "SensorModel altitude=0",
        lambda: SensorModel(0.05, 0.1, 0.0),
        V,
        r"^SensorModel\.altitude must be > 0, got 0\.0",
    ),
    (
        "SensorModel footprint nan",
        lambda: SensorModel(0.05, 0.1, 100.0, footprint_radius=NAN),
        V,
        r"^SensorModel\.footprint_radius must not be NaN",
    ),
    (
        "measurement_cov xy width 3",
        lambda: sensor.measurement_cov(np.zeros(3), np.zeros(2), SENSOR),
        V,
        r"^uav_xy must have shape \(\.\.\., 2\), got \(3,\)",
    ),
    (
        "measurement_noise std_normal width 1",
        lambda: sensor.measurement_noise(np.zeros(2), np.ones(2), SENSOR, np.zeros(1)),
        V,
        r"^std_normal must have shape \(\.\.\., 2\)",
    ),
    (
        "measurement_cov sensor missing",
        lambda: sensor.measurement_cov(np.zeros(2), np.ones(2), None),
        T,
        r"^sensor must be a SensorModel",
    ),
    (
        "detected u=1.5",
        lambda: sensor.detected(np.zeros(2), np.ones(2), LOGISTIC, 1.5),
        V,
        r"^u must lie in the closed interval \[0, 1\], got 1\.5",
    ),
    (
        "Tracker P0 negative-definite",
        lambda: Tracker(X_HAT, NEG_DEF, MODEL),
        guards.NotPositiveDefiniteError,
        r"^P0 must be symmetric positive semidefinite",
    ),
    ("Tracker x0 nan", lambda: Tracker(np.full(4, NAN), P_HAT, MODEL), V, r"^x0 must be finite"),
    (
        "Tracker.update z nan",
        lambda: Tracker(X_HAT, P_HAT, MODEL).update([NAN, 0.0], np.eye(2)),
        V,
        r"^z must be finite",
    ),
    (
        "Tracker.update R asymmetric",
        lambda: Tracker(X_HAT, P_HAT, MODEL).update([0.0, 0.0], [[1.0, 0.5], [0.0, 1.0]]),
        V,
        r"^R must be symmetric",
    ),
    (
        "ellipse_polygon cov not PD",
        lambda: ellipse_polygon(np.zeros(2), -np.eye(2)),
        guards.NotPositiveDefiniteError,
        r"^cov must be symmetric positive definite",
    ),
    # ---- uav: kernel, fused, planner ---------------------------------------------------------
    (
        "objective horizons differ",
        lambda: kernel.objective(P_HAT, UXY, np.zeros((4, 2, 2)), 1.0, MODEL.Q, SENSOR),
        V,
        r"^target_xy must have the horizon of uav_xy \(H = 3\)",
    ),
    (
        "objective dt=0",
        lambda: kernel.objective(P_HAT, UXY, TXY, 0.0, MODEL.Q, SENSOR),
        V,
        r"^dt must be > 0, got 0\.0",
    ),
    (
        "objective Q nan",
        lambda: kernel.objective(P_HAT, UXY, TXY, 1.0, np.full((4, 4), NAN), SENSOR),
        V,
        r"^Q must be finite",
    ),
    (
        "fused.covariance_traces P0 (3, 3)",
        lambda: fused.covariance_traces(np.eye(3), UXY, TXY, 1.0, MODEL.Q, SENSOR),
        V,
        r"^P0 must have shape \(4, 4\), got \(3, 3\)",
    ),
    (
        "fused.cost x width",
        lambda: fused.cost(np.zeros((1, 5)), UAV_STATE, UAV, P_HAT, TXY, 1.0, MODEL.Q, SENSOR),
        V,
        r"^x must have shape \(C, 2H\) = \(C, 6\)",
    ),
    (
        "fused.cost_and_grad x nan",
        lambda: fused.cost_and_grad(
            np.full(6, NAN), UAV_STATE, UAV, P_HAT, TXY, 1.0, MODEL.Q, SENSOR
        ),
        V,
        r"^x must be finite",
    ),
    (
        "Frozen uav_state speed 0",
        lambda: fused.Frozen(np.zeros(4), UAV, P_HAT, TXY, 1.0, MODEL.Q, SENSOR),
        V,
        r"^uav_state\[2\] \(speed\) must be > 0",
    ),
    (
        "fused.path wrong size",
        lambda: fused.path(np.zeros(5), _frozen()),
        V,
        r"^x must have 2H = 6 entries",
    ),
    (
        "PlanningProblem P_hat negative-definite",
        lambda: _problem(P_hat=NEG_DEF),
        guards.NotPositiveDefiniteError,
        r"^P_hat must be symmetric positive semidefinite",
    ),
    (
        "PlanningProblem hypotheses wrong horizon",
        lambda: _problem(target_xy=np.zeros((4, 5, 2))),
        V,
        r"^target_xy must have shape \(T, 3, 2\)",
    ),
    (
        "PlanningProblem uav_state nan",
        lambda: _problem(uav_state=np.array([0.0, NAN, 20.0, 0.0])),
        V,
        r"^uav_state must be finite",
    ),
    (
        "plan warm_start shape",
        lambda: plan(_problem(), np.zeros((2, 2))),
        V,
        r"^warm_start must have shape \(3, 2\), got \(2, 2\)",
    ),
    (
        "lbfgsb maxiter=0",
        lambda: lbfgsb(_problem(), np.zeros(6), 0),
        V,
        r"^maxiter must be >= 1, got 0",
    ),
    (
        "shift_plan empty",
        lambda: shift_plan(np.zeros((0, 2))),
        V,
        r"^controls must have shape \(H, 2\) with H >= 1",
    ),
    (
        "PlannerParams maxfun=2.5",
        lambda: PlannerParams(6, 30, 2.5),
        V,
        r"^PlannerParams\.maxfun must be an integer >= 1, got 2\.5",
    ),
    (
        "PlannerParams.from_config horizon=6.7",
        lambda: PlannerParams.from_config(_cfg(planner__horizon=6.7)),
        V,
        r"^PlannerParams\.horizon must be an integer >= 1, got 6\.7",
    ),
    (
        "PlanningProblem.controls wrong width",
        lambda: _problem().controls(np.zeros(5)),
        V,
        r"^x must have shape \(\.\.\., 6\), got \(5,\)",
    ),
    # ---- uav: simulation ---------------------------------------------------------------------
    (
        "methods.from_spec family",
        lambda: uav_methods.from_spec({"family": "bogus"}),
        V,
        r"^method spec: unknown family 'bogus' \(allowed: \[",
    ),
    (
        "PrunedTree M=0",
        lambda: PrunedTree(8, 0),
        V,
        r"^max_keep \(M\) must be >= 1, got 0",
    ),
    (
        "MonteCarlo N_T=2.5",
        lambda: MonteCarlo(2.5),
        V,
        r"^n_traj \(N_T\) must be an integer >= 1, got 2\.5",
    ),
    (
        "methods.from_config unknown key",
        lambda: uav_methods.from_config({"nbo": True, "bogus": [1]}, "uav.methods"),
        V,
        r"^uav\.methods: unknown method key\(s\) \['bogus'\] \(allowed: \[",
    ),
    (
        "methods.from_name unknown",
        lambda: uav_methods.from_name("rsmhp_ntx"),
        V,
        r"^method 'rsmhp_ntx' belongs to no registered family",
    ),
    (
        "methods.from_config rsmhp_nt=[0]",
        lambda: uav_methods.from_config({"nbo": True, "rsmhp_nt": [0], "tree": []}, "uav.methods"),
        V,
        r"^uav\.methods\.rsmhp_nt\[0\] must be >= 1, got 0",
    ),
    (
        "methods.from_config tree N=2.5",
        lambda: uav_methods.from_config(
            {"nbo": True, "rsmhp_nt": [], "tree": [{"N": 2.5, "M": 4}]}, "uav.methods"
        ),
        V,
        r"^uav\.methods\.tree\[0\]\.N must be an integer >= 1, got 2\.5",
    ),
    (
        "UAVSetup P0 singular",
        lambda: UAVSetup.from_config(_cfg(tracker__p0_vel_sd=0.0)),
        guards.NotPositiveDefiniteError,
        r"^UAVSetup\.P0 must be symmetric positive definite",
    ),
    (
        "UAVSetup scenario speeds reversed",
        lambda: UAVSetup.from_config(_cfg(scenario__target_speed_min=20.0)),
        V,
        r"^scenario\.target_speed_min must be <= scenario\.target_speed_max, "
        r"got scenario\.target_speed_min = 20\.0",
    ),
    (
        "UAVSetup scenario uav_speed nan",
        lambda: UAVSetup.from_config(_cfg(scenario__uav_speed=NAN)),
        V,
        r"^scenario\.uav_speed must be finite and > 0, got nan",
    ),
    (
        "UAVSetup scenario missing key",
        lambda: dataclasses.replace(SETUP, scenario={"target_box": 1.0}),
        V,
        r"^UAVSetup\.scenario is missing \['target_speed_min'",
    ),
    ("draw_scenario run=-1", lambda: draw_scenario(SETUP, 1, -1), V, r"^run must be >= 0, got -1"),
    (
        "simulate_run seed=1.5",
        lambda: simulate_run(SETUP, NBO, 1.5, 1),
        V,
        r"^seed must be an integer >= 0, got 1\.5",
    ),
    (
        "simulate_run method dict",
        lambda: simulate_run(SETUP, {"name": "nbo"}, 1, 1),
        T,
        r"^method must be a Method, got dict",
    ),
    (
        "simulate_run observer",
        lambda: simulate_run(SETUP, NBO, 1, 1, observer=5),
        T,
        r"^observer must be callable or None, got int",
    ),
]


@pytest.mark.parametrize(("call", "exc", "match"), [c[1:] for c in BAD], ids=[c[0] for c in BAD])
def test_bad_call_is_refused_naming_the_argument(call, exc, match):
    with pytest.raises(exc, match=match) as info:
        call()
    # the exact type asked for (a TypeError is not accepted for a ValueError case and
    # vice versa; NotPositiveDefiniteError is a LinAlgError, hence a ValueError)
    assert isinstance(info.value, exc)
    assert not (exc is ValueError and isinstance(info.value, TypeError))
    assert not (exc is TypeError and isinstance(info.value, ValueError))


# --------------------------------------------------------------------------------------------
# valid edge inputs keep working, with the same numbers


def test_semidefinite_covariances_where_allowed():
    # the planner's posterior may be singular (a perfectly known coordinate)
    P0 = np.diag([0.0, 100.0, 0.0, 4.0])
    out = kernel.objective(P0, UXY, TXY, 1.0, MODEL.Q, SENSOR)
    assert out.shape == (2,) and np.all(np.isfinite(out))
    np.testing.assert_allclose(
        fused.covariance_traces(P0, UXY, TXY, 1.0, MODEL.Q, SENSOR).sum(axis=2).mean(axis=1),
        out,
        rtol=1e-12,
    )
    Tracker(X_HAT, np.zeros((4, 4)), MODEL)
    # a singular noise covariance is fine for the exact oracles of a linear-quadratic problem
    lq = LinearQuadratic(
        A=np.eye(2),
        B=np.eye(2),
        Sigma=np.diag([1.0, 0.0]),
        Q=np.eye(2),
        R=np.eye(2),
        Qf=np.eye(2),
        target=[0.0, 0.0],
        x0=[1.0, 1.0],
        u=np.zeros((2, 2)),
    )
    assert np.isfinite(lq.exact_cost())
    # ... while a noise model must be positive definite (it has a density)
    with pytest.raises(np.linalg.LinAlgError, match="cov must be positive definite"):
        GaussianNoise(np.diag([1.0, 0.0]))


def test_checked_and_unchecked_paths_agree():
    """check=False (the closed loop's path) computes exactly what the checked call does."""
    a = target.sample_independent(X_HAT, P_HAT, 3, 5, MODEL, np.random.default_rng(4))
    b = target.sample_independent(X_HAT, P_HAT, 3, 5, MODEL, np.random.default_rng(4), check=False)
    np.testing.assert_array_equal(a, b)
    p1 = _problem()
    p2 = PlanningProblem(UAV_STATE, P_HAT, TXY, UAV, MODEL, SENSOR, PLANNER, check=False)
    r1, r2 = plan(p1, np.zeros((3, 2))), plan(p2, np.zeros((3, 2)), check=False)
    np.testing.assert_array_equal(r1.controls, r2.controls)
    assert r1.cost == r2.cost


def test_a_short_closed_loop_run_still_works():
    summary, rows = simulate_run(SETUP, NBO, np.int64(3), 0)
    assert len(rows) == 2 and np.isfinite(summary["mean_error"])
