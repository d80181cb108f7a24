"""Library guards: every public entry point refuses bad arguments up front, naming them.

A parametrised matrix of bad calls (each asserts the exception type and that the message
names the argument), then valid edge inputs that must keep working (unchanged numbers).
"""

from __future__ import annotations

import copy
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from rsmhp.core import cost_estimators, designs, guards, seeding, stats
from rsmhp.core.sampling import (
    GaussianNoise,
    rollout,
    rollout_cost,
    sample_independent,
    sample_tree,
    sample_tree_batch,
    top_m,
)
from rsmhp.models.lqg import oven as lqg
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

ROOT = Path(__file__).resolve().parents[1]
UAV_CFG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["uav"]

LQG = {"x0": 0.0, "a": 0.5, "r": 10.0, "target": 1.0, "sigma": 1.0}
KW = {"x0": 0.0, "a": 0.5, "r": 10.0, "target": 1.0}  # no sigma
U = np.array([0.55, 0.17])
MODEL_LQG = lqg.LQGModel(a=0.5, r=10.0, target=1.0, sigma=1.0)
LQ = LinearQuadratic.scalar_lqg(U, **LQG)
QF = LQ.quadratic_form
CHOL = np.array([[1.0]])

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
INF = float("inf")


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
        "state_variance H=2.5",
        lambda: lqg.state_variance(2.5, a=0.5, sigma=1.0),
        V,
        r"^H must be an integer >= 1, got 2\.5",
    ),
    (
        "sample_independent 2-D x0",
        lambda: sample_independent(MODEL_LQG, [[0.2], [0.3]], U, 5, _rng()),
        V,
        r"^x0 must have 0 or 1 dimension",
    ),
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
        "GaussianNoise(nan)",
        lambda: GaussianNoise(NAN),
        V,
        r"^noise covariance cov must be finite, got nan",
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
        "monte_carlo n=0",
        lambda: designs.monte_carlo(_rng(), 0, 2, CHOL),
        V,
        r"^n must be >= 1, got 0",
    ),
    (
        "UAVParams speed_min > speed_max",
        lambda: UAVParams(1.0, 9.81, 3.0, 0.7, 40.0, 35.0, 100.0),
        V,
        r"^UAVParams\.speed_min must be <= UAVParams\.speed_max, got UAVParams\.speed_min = 40\.0",
    ),
    # ---- lqg closed forms --------------------------------------------------------------------
    (
        "state_variance H=0",
        lambda: lqg.state_variance(0, a=0.5, sigma=1.0),
        V,
        r"^H must be >= 1, got 0",
    ),
    (
        "state_variance H=-3",
        lambda: lqg.state_variance(-3, a=0.5, sigma=1.0),
        V,
        r"^H must be >= 1, got -3",
    ),
    (
        "state_variance H=True",
        lambda: lqg.state_variance(True, a=0.5, sigma=1.0),
        T,
        r"^H must be an integer >= 1, got bool True",
    ),
    (
        "state_variance H='3'",
        lambda: lqg.state_variance("3", a=0.5, sigma=1.0),
        T,
        r"^H must be an integer >= 1, got str '3'",
    ),
    (
        "state_variance a=nan",
        lambda: lqg.state_variance(2, a=NAN, sigma=1.0),
        V,
        r"^a must be finite and lie in the open interval \(0, 1\), got nan",
    ),
    (
        "state_variance sigma=inf",
        lambda: lqg.state_variance(2, a=0.5, sigma=INF),
        V,
        r"^sigma must be finite and >= 0, got inf",
    ),
    (
        "state_variance sigma<0",
        lambda: lqg.state_variance(2, a=0.5, sigma=-0.1),
        V,
        r"^sigma must be >= 0, got -0\.1",
    ),
    (
        "nbo_error r<0",
        lambda: lqg.nbo_error(2, a=0.5, r=-1.0, sigma=1.0),
        V,
        r"^r must be >= 0, got -1\.0",
    ),
    (
        "nbo_cost x0=nan",
        lambda: lqg.nbo_cost(U, **{**KW, "x0": NAN}),
        V,
        r"^x0 must be finite, got nan",
    ),
    (
        "exact_cost target=inf",
        lambda: lqg.exact_cost(U, **{**LQG, "target": INF}),
        V,
        r"^target must be finite, got inf",
    ),
    (
        "exact_cost a=1",
        lambda: lqg.exact_cost(U, **{**LQG, "a": 1.0}),
        V,
        r"^a must lie in the open interval \(0, 1\), got 1\.0",
    ),
    (
        "exact_cost u with nan",
        lambda: lqg.exact_cost([0.1, NAN], **LQG),
        V,
        r"^u must be finite, got nan at index 1",
    ),
    (
        "exact_cost u 2-D",
        lambda: lqg.exact_cost(np.zeros((2, 2)), **LQG),
        V,
        r"^u must be a non-empty 1-D control sequence",
    ),
    (
        "cost_variance r=-1",
        lambda: lqg.cost_variance(U, **{**LQG, "r": -1.0}),
        V,
        r"^r must be >= 0",
    ),
    ("mhp_variance P=0", lambda: lqg.mhp_variance(0, U, **LQG), V, r"^P must be >= 1, got 0"),
    (
        "mhp_variance P=2.5",
        lambda: lqg.mhp_variance(2.5, U, **LQG),
        V,
        r"^P must be integer\(s\) >= 1, got 2\.5",
    ),
    (
        "chebyshev_bound eps=nan",
        lambda: lqg.chebyshev_bound(10, NAN, U, **LQG),
        V,
        r"^eps must be finite",
    ),
    (
        "chebyshev_bound eps=0",
        lambda: lqg.chebyshev_bound(10, 0.0, U, **LQG),
        V,
        r"^eps must be > 0",
    ),
    (
        "optimal_controls H=2.5",
        lambda: lqg.optimal_controls(2.5, **KW),
        V,
        r"^H must be an integer >= 1, got 2\.5",
    ),
    ("regret_gain H=0", lambda: lqg.regret_gain(0, a=0.5, r=1.0), V, r"^H must be >= 1, got 0"),
    (
        "expected_regret n_eff=0",
        lambda: lqg.expected_regret(0, 2, a=0.5, r=1.0, sigma=1.0),
        V,
        r"^n_eff must be >= 1, got 0",
    ),
    (
        "sample_argmin target=nan",
        lambda: lqg.sample_argmin(np.zeros((3, 2)), np.ones(3), **{**KW, "target": NAN}),
        V,
        r"^target must be finite",
    ),
    (
        "LQGModel sigma=0",
        lambda: lqg.LQGModel(a=0.5, r=1.0, target=1.0, sigma=0.0),
        V,
        r"sigma must be > 0",
    ),
    (
        "LQGModel target=nan",
        lambda: lqg.LQGModel(a=0.5, r=1.0, target=NAN, sigma=1.0),
        V,
        r"^target must be finite",
    ),
    # ---- linear_quadratic --------------------------------------------------------------------
    (
        "scalar_lqg r<0",
        lambda: LinearQuadratic.scalar_lqg(U, **{**LQG, "r": -1.0}),
        V,
        r"^r must be >= 0, got -1\.0",
    ),
    (
        "scalar_lqg x0=nan",
        lambda: LinearQuadratic.scalar_lqg(U, **{**LQG, "x0": NAN}),
        V,
        r"^x0 must be finite",
    ),
    (
        "LinearQuadratic x0 wrong size",
        lambda: dataclasses.replace(LQ, x0=[0.0, 1.0]),
        V,
        r"^x0 must have 1 entries \(the state dimension\), got shape \(2,\)",
    ),
    (
        "LinearQuadratic Sigma not PSD",
        lambda: dataclasses.replace(LQ, Sigma=[[-1.0]]),
        guards.NotPositiveDefiniteError,
        r"^Sigma must be symmetric positive semidefinite",
    ),
    (
        "LinearQuadratic u nan",
        lambda: dataclasses.replace(LQ, u=[[NAN], [0.0]]),
        V,
        r"^u must be finite",
    ),
    ("QuadraticForm.tree_variance N=1", lambda: QF.tree_variance(1), V, r"^N must be >= 2, got 1"),
    (
        "QuadraticForm.antithetic_variance n=0",
        lambda: QF.antithetic_variance(0),
        V,
        r"^n must be >= 1, got 0",
    ),
    (
        "QuadraticForm.independent_variance n=2.5",
        lambda: QF.independent_variance(2.5),
        V,
        r"^n must be an integer >= 1, got 2\.5",
    ),
    (
        "QuadraticForm.pernode_tree_variance N=0",
        lambda: QF.pernode_tree_variance(0),
        V,
        r"^N must be >= 1, got 0",
    ),
    (
        "QuadraticForm.prefix_covariance m=5",
        lambda: QF.prefix_covariance(5),
        V,
        r"^m must be in \[0, 2\], got 5",
    ),
    ("QuadraticForm.mean scale<0", lambda: QF.mean(scale=-1.0), V, r"^scale must be >= 0"),
    (
        "QuadraticForm.grid_average weights<0",
        lambda: QF.grid_average([np.ones(2), np.ones(2)], [np.array([1.0, -1.0]), np.ones(2)]),
        V,
        r"^weights\[0\] must be >= 0 with a positive sum",
    ),
    (
        "QuadraticForm.evaluate wrong width",
        lambda: QF.evaluate(np.zeros((3, 5))),
        V,
        r"^w must have shape \(\.\.\., 2\)",
    ),
    # ---- designs -----------------------------------------------------------------------------
    (
        "monte_carlo H=0",
        lambda: designs.monte_carlo(_rng(), 4, 0, CHOL),
        V,
        r"^H must be >= 1, got 0",
    ),
    (
        "monte_carlo chol nan",
        lambda: designs.monte_carlo(_rng(), 4, 2, np.array([[NAN]])),
        V,
        r"^chol must be finite",
    ),
    (
        "monte_carlo rng None",
        lambda: designs.monte_carlo(None, 4, 2, CHOL),
        T,
        r"^rng must be a Generator",
    ),
    (
        "antithetic n=0",
        lambda: designs.antithetic(_rng(), 0, 2, CHOL),
        V,
        r"^n must be >= 2, got 0",
    ),
    ("sobol n=3", lambda: designs.sobol(_rng(), 3, 2, CHOL), V, r"needs n a power of 2, got 3"),
    (
        "cubature chol not square",
        lambda: designs.cubature(2, np.ones((2, 3))),
        V,
        r"^chol must be a square",
    ),
    (
        "gauss_hermite q=0",
        lambda: designs.gauss_hermite(0, 2, CHOL),
        V,
        r"^q \(Gauss-Hermite nodes per dimension\) must be >= 1, got 0",
    ),
    (
        "gauss_hermite_order D=0",
        lambda: designs.gauss_hermite_order(16, 0),
        V,
        r"^D must be >= 1, got 0",
    ),
    # ---- sampling ----------------------------------------------------------------------------
    (
        "GaussianNoise not square",
        lambda: GaussianNoise(np.ones((2, 3))),
        V,
        r"^noise covariance cov must be a non-empty square matrix",
    ),
    (
        "GaussianNoise asymmetric",
        lambda: GaussianNoise(np.array([[1.0, 0.5], [0.0, 1.0]])),
        V,
        r"^noise covariance cov must be symmetric",
    ),
    (
        "GaussianNoise not PD",
        lambda: GaussianNoise(np.array([[1.0, 2.0], [2.0, 1.0]])),
        np.linalg.LinAlgError,
        r"^noise covariance cov must be positive definite, got smallest eigenvalue -1",
    ),
    (
        "GaussianNoise inf",
        lambda: GaussianNoise(np.diag([1.0, INF])),
        V,
        r"^noise covariance cov must be finite, got inf at index \(1, 1\)",
    ),
    (
        "sample_independent n=0",
        lambda: sample_independent(MODEL_LQG, [0.0], U, 0, _rng()),
        V,
        r"^n \(number of trajectories\) must be >= 1, got 0",
    ),
    (
        "sample_independent x0=nan",
        lambda: sample_independent(MODEL_LQG, [NAN], U, 3, _rng()),
        V,
        r"^x0 must be finite",
    ),
    (
        "sample_independent rng int",
        lambda: sample_independent(MODEL_LQG, [0.0], U, 3, 7),
        T,
        r"^rng must be a Generator, got int 7",
    ),
    (
        "sample_tree N=2.5",
        lambda: sample_tree(MODEL_LQG, [0.0], U, 2.5, _rng()),
        V,
        r"^N \(draws per step\) must be an integer >= 1, got 2\.5",
    ),
    (
        "sample_tree M=0",
        lambda: sample_tree(MODEL_LQG, [0.0], U, 3, _rng(), max_keep=0),
        V,
        r"^M \(trajectories kept\) must be >= 1, got 0",
    ),
    (
        "sample_tree level_noise not noise",
        lambda: sample_tree(MODEL_LQG, [0.0], U, 2, _rng(), level_noise=[1.0, 1.0]),
        T,
        r"^level_noise\[0\] must be a GaussianNoise",
    ),
    (
        "sample_tree_batch rngs[1] None",
        lambda: sample_tree_batch(LQ, LQ.x0, LQ.u, 2, [_rng(), None]),
        T,
        r"^rngs\[1\] must be a Generator",
    ),
    (
        "sample_tree_batch x0 wrong size",
        lambda: sample_tree_batch(LQ, [0.0, 1.0], LQ.u, 2, [_rng()]),
        V,
        r"^x0 must have 1 entries",
    ),
    (
        "rollout u nan",
        lambda: rollout(MODEL_LQG, [0.0], [NAN, 0.1], np.zeros((3, 2, 1))),
        V,
        r"^u must be finite",
    ),
    (
        "rollout_cost x0 2-D",
        lambda: rollout_cost(MODEL_LQG, np.zeros((2, 2)), U, np.zeros((3, 2, 1))),
        V,
        r"^x0 must have 0 or 1 dimension",
    ),
    ("top_m M=2.5", lambda: top_m(np.zeros(4), 2.5), V, r"^M must be an integer >= 1, got 2\.5"),
    # ---- estimators ----------------------------------------------------------------------------
    (
        "uniform_estimate nan",
        lambda: cost_estimators.uniform_estimate([1.0, NAN]),
        V,
        r"^cost must be finite, got nan at index 1",
    ),
    (
        "uniform_estimate bad axis",
        lambda: cost_estimators.uniform_estimate(np.ones(3), axis=2),
        V,
        r"^axis must be a valid axis of cost",
    ),
    (
        "likeliness_weights nan",
        lambda: cost_estimators.likeliness_weights([0.0, NAN]),
        V,
        r"^log_likeliness must be finite or -inf",
    ),
    (
        "likeliness_weights all -inf",
        lambda: cost_estimators.likeliness_weights([-INF, -INF]),
        V,
        r"^log_likeliness must not be -inf for every trajectory",
    ),
    (
        "weighted_estimate shape mismatch",
        lambda: cost_estimators.weighted_estimate(np.ones(5), np.zeros(1)),
        V,
        r"^cost and log_likeliness must have the same shape",
    ),
    (
        "nbo_estimate empty u",
        lambda: cost_estimators.nbo_estimate(MODEL_LQG, [0.0], []),
        V,
        r"control sequence u must have at least one step",
    ),
    # ---- stats ---------------------------------------------------------------------------------
    (
        "mean_ci level=1.5",
        lambda: stats.mean_ci(np.ones(3), level=1.5),
        V,
        r"^level must lie in the open interval \(0, 1\), got 1\.5",
    ),
    ("mean_ci x nan", lambda: stats.mean_ci([1.0, NAN, 2.0]), V, r"^x must be finite"),
    ("binomial_ci k > n", lambda: stats.binomial_ci(5, 3), V, r"^k must be in \[0, 3\], got 5"),
    ("binomial_ci n=0", lambda: stats.binomial_ci(0, 0), V, r"^n must be >= 1, got 0"),
    ("rmse_ci empty", lambda: stats.rmse_ci([]), V, r"err for an RMSE, got 0"),
    (
        "loglog_slope length mismatch",
        lambda: stats.loglog_slope([1.0, 2.0, 3.0], [1.0, 2.0]),
        V,
        r"^x and y must have the same length",
    ),
    (
        "loglog_slope y nan",
        lambda: stats.loglog_slope([1.0, 2.0, 3.0], [1.0, NAN, 2.0]),
        V,
        r"^y must be finite",
    ),
    # ---- seeding -------------------------------------------------------------------------------
    (
        "job_rng root_seed=True",
        lambda: seeding.job_rng(True, "e"),
        T,
        r"^root_seed must be an integer >= 0, got bool True",
    ),
    (
        "job_rng root_seed=1.5",
        lambda: seeding.job_rng(1.5, "e"),
        V,
        r"^root_seed must be an integer >= 0, got 1\.5",
    ),
    (
        "job_rng param nan",
        lambda: seeding.job_rng(1, "e", q=NAN),
        V,
        r"^job identifier parameter q: .*finite, got nan",
    ),
    (
        "canonical_job_id experiment=5",
        lambda: seeding.canonical_job_id(5),
        T,
        r"^experiment must be a non-empty string, got int 5",
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


def test_matrix_size():
    assert len(BAD) >= 70
    assert len({c[0] for c in BAD}) == len(BAD)


# --------------------------------------------------------------------------------------------
# valid edge inputs keep working, with the same numbers


def test_h_equal_one_and_numpy_integers():
    assert lqg.state_variance(1, a=0.5, sigma=2.0) == 4.0
    assert lqg.state_variance(np.int64(4), a=0.3, sigma=1.5) == lqg.state_variance(
        4, a=0.3, sigma=1.5
    )
    np.testing.assert_array_equal(
        lqg.optimal_controls(np.int32(3), **KW), lqg.optimal_controls(3, **KW)
    )
    assert lqg.mhp_variance(np.array([10, 100]), U, **LQG).shape == (2,)
    # guards return ints (and numpy ints) unchanged: the same object
    n = np.int64(7)
    assert guards.positive_int("n", n) is n


def test_whole_number_floats_are_normalised():
    """3.0 counts as 3 (as in rsmhp.core.seeding's job ids); the result equals the int's."""
    assert lqg.state_variance(3.0, a=0.4, sigma=1.0) == lqg.state_variance(3, a=0.4, sigma=1.0)
    w, wt = designs.monte_carlo(np.random.default_rng(1), 8.0, 2, CHOL)
    w2, wt2 = designs.monte_carlo(np.random.default_rng(1), 8, 2, CHOL)
    np.testing.assert_array_equal(w, w2)
    np.testing.assert_array_equal(wt, wt2)
    assert MonteCarlo(3.0).n_traj == 3
    assert "rsmhp_nt3" in uav_methods.from_config({"nbo": False, "rsmhp_nt": [3.0], "tree": []})


def test_sigma_zero_is_allowed_in_the_closed_forms():
    assert lqg.state_variance(3, a=0.5, sigma=0.0) == 0.0
    assert lqg.exact_cost(U, **{**LQG, "sigma": 0.0}) == lqg.nbo_cost(U, **KW)


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


def test_edge_bounds_are_allowed():
    # equal speed bounds: a constant-speed aircraft
    UAVParams(1.0, 9.81, 3.0, 0.7, 20.0, 20.0, 100.0)
    assert sensor.detected(np.zeros(2), np.ones(2), LOGISTIC, 0.0)  # u = 0 in [0, 1]
    assert stats.binomial_ci(0, 5)[0] == 0.0 and stats.binomial_ci(5, 5)[1] == 1.0
    assert QF.prefix_covariance(0) == 0.0 and QF.prefix_covariance(2) == pytest.approx(
        QF.variance()
    )
    # -inf log-likeliness is a zero weight, not an error
    np.testing.assert_array_equal(cost_estimators.likeliness_weights([0.0, -np.inf]), [2.0, 0.0])
    assert seeding.job_rng(np.uint32(3), "e").random() == seeding.job_rng(3, "e").random()


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
