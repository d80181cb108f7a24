"""The tree-search planner (rsmhp.uav.dpw, family ``dpw``).

Oracles:

* the generative model of the search is the closed-loop step: one call of ``_generate`` with a
  stream equals drawing the same numbers by hand and stepping :class:`Stepper` (itself tested
  against the numpy kinematics, sensor and filterpy);
* a known optimum, H = 1 on the paper's sensor (every look detects): the reward of an action
  is deterministic, tr P' of one Kalman update with R at the predicted estimate, so the
  search's cost estimates are exact (checked against the Stepper) and UCB1's guarantee holds
  exactly: the most visited root action ``a`` (n visits, N in all) costs at most
  ``c c0 sqrt(ln N / (n - 1))`` more than the best root action; the best root action is never
  worse than the warm start (always the first root action); and the best root action lies in
  the share of a dense grid of exact costs that its uniform action draws reach with
  probability 1 - 1e-3;
* the widening rules bound the tree; the plan stays in the box; the stream decides the plan.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from rsmhp.uav import dpw, methods
from rsmhp.uav.methods.tree_search import ALPHA_A, C_UCB, K_A, TreeSearch
from rsmhp.uav.planner import Belief
from rsmhp.uav.simulation import UAVSetup
from rsmhp.uav.stepper import Stepper

ROOT = Path(__file__).resolve().parents[1]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
SETUP = UAVSetup.from_config(CONFIG["uav"])
P_HAT = np.diag([900.0, 400.0, 16.0, 9.0])
P_HAT[0, 1] = P_HAT[1, 0] = 150.0
BELIEF = Belief(np.array([0.0, 0.0, 20.0, 0.0]), np.array([300.0, -50.0, 6.0, 2.0]), P_HAT)


def _setup(horizon: int):
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    cfg["uav"]["planner"]["horizon"] = horizon
    return UAVSetup.from_config(cfg["uav"])


def _scale(setup):
    return np.array([setup.uav.accel_max, setup.uav.bank_max], dtype=float)


def _one_step_cost(setup, belief, u_norm):
    """tr P after one closed-loop step with normalised control ``u_norm`` on a sensor that
    always detects (then the noise draws do not matter)."""
    st = Stepper(setup.uav, setup.target, setup.sensor)
    uav, xt, xe, P = (
        np.array(a, dtype=float) for a in (belief.uav, belief.x_hat, belief.x_hat, belief.P_hat)
    )
    _, _, tr = st.advance(
        uav, xt, xe, P, np.asarray(u_norm) * _scale(setup), np.zeros(4), np.zeros(2), 0.5
    )
    return tr


def test_the_generative_model_is_the_closed_loop_step():
    st = Stepper(SETUP.uav, SETUP.target, SETUP.sensor)
    scale = _scale(SETUP)
    act = np.array([0.3, -0.7])
    uav, xh, P = BELIEF.uav.copy(), BELIEF.x_hat.copy(), BELIEF.P_hat.copy()
    scratch = [np.empty((4, 4)), np.empty(4), np.empty(4), np.empty(2), np.empty(2)]
    tr = dpw._generate(
        uav, xh, P, act, scale, st.F, st.Q, np.linalg.cholesky(st.Q), st.ucfg, st.sens,
        np.random.default_rng(9), *scratch,
    )  # fmt: skip
    # the same numbers by hand, in the search's order
    rng = np.random.default_rng(9)
    x = BELIEF.x_hat + np.linalg.cholesky(BELIEF.P_hat) @ rng.standard_normal(4)
    w = np.linalg.cholesky(st.Q) @ rng.standard_normal(4)
    zeta = np.array([rng.standard_normal(), rng.standard_normal()])
    det_u = rng.random()
    u2, xh2, P2 = BELIEF.uav.copy(), BELIEF.x_hat.copy(), BELIEF.P_hat.copy()
    _, _, tr2 = st.advance(u2, x, xh2, P2, act * scale, w, zeta, det_u)
    np.testing.assert_allclose(uav, u2, rtol=1e-14)
    np.testing.assert_allclose(xh, xh2, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(P, P2, rtol=1e-12, atol=1e-9)
    assert math.isclose(tr, tr2, rel_tol=1e-12)


@pytest.mark.parametrize("sims", [50, 400, 3000])
def test_h1_ucb_guarantee_and_exact_costs(sims):
    setup = _setup(1)
    assert not setup.sensor.limited  # the paper's sensor: every look detects
    warm = np.array([[0.0, 0.0]])
    st = Stepper(setup.uav, setup.target, setup.sensor)
    x, cost, n_b, n_a, n_root, n_chosen, best = dpw.search(
        BELIEF.uav, BELIEF.x_hat, BELIEF.P_hat, warm, _scale(setup), sims,
        (C_UCB, K_A, ALPHA_A, 4.0, 0.25), st, np.random.default_rng(sims),
    )  # fmt: skip
    assert x.shape == (1, 2) and (np.abs(x) <= 1.0).all()
    # the estimate is the exact one-step cost of the chosen control
    assert math.isclose(cost, _one_step_cost(setup, BELIEF, x[0]), rel_tol=1e-10)
    c0 = np.trace(BELIEF.P_hat)
    assert best <= cost
    assert best <= _one_step_cost(setup, BELIEF, warm[0]) * (1 + 1e-12)
    # UCB1 with deterministic rewards
    assert n_chosen >= 2
    assert cost - best <= C_UCB * c0 * math.sqrt(math.log(sims) / (n_chosen - 1)) + 1e-9 * c0
    assert n_root <= K_A * sims**ALPHA_A + 1
    assert n_b <= sims + 1 and n_a <= sims + 1


def test_h1_best_root_action_against_the_grid_optimum():
    """H = 1, exact costs on a 41 x 41 grid of the control box. The search's k root actions
    are the warm start and k - 1 uniform draws; k - 1 draws all miss the best share q of the
    box with probability (1 - q)^(k-1), which is 1e-3 for q = 1 - 1e-3^(1/(k-1)). So the best
    root action costs at most the grid's q-quantile (failing with probability 1e-3), and the
    chosen one at most UCB1's bound more. (Uniform action widening is a coarse optimiser: 3000
    simulations give about 30 root actions.)"""
    setup = _setup(1)
    belief = Belief(np.array([0.0, 0.0, 20.0, 0.0]), np.array([600.0, 0.0, 0.0, 0.0]), P_HAT)
    axis = np.linspace(-1, 1, 41)
    grid = np.array([[a, b] for a in axis for b in axis])
    costs = np.array([_one_step_cost(setup, belief, u) for u in grid])
    st = Stepper(setup.uav, setup.target, setup.sensor)
    sims = 3000
    _, cost, _, _, n_root, n_chosen, best = dpw.search(
        belief.uav, belief.x_hat, belief.P_hat, np.zeros((1, 2)), _scale(setup), sims,
        (C_UCB, K_A, ALPHA_A, 4.0, 0.25), st, np.random.default_rng(1),
    )  # fmt: skip
    q = 1.0 - 1e-3 ** (1.0 / (n_root - 1))
    assert best <= np.quantile(costs, q)
    assert best >= costs.min() * (1 - 1e-3)  # nothing beats the optimum (grid step 0.05)
    c0 = np.trace(belief.P_hat)
    assert cost <= best + C_UCB * c0 * math.sqrt(math.log(sims) / (n_chosen - 1)) + 1e-9 * c0


def test_plans_are_in_the_box_and_follow_the_stream():
    m = methods.from_name("dpw_s300")
    assert isinstance(m, TreeSearch) and m.uses_rng
    planner = m.planner(SETUP)
    H = SETUP.planner.horizon
    warm = np.tile(_scale(SETUP) * [0.5, -0.2], (H, 1))
    a = planner.plan(BELIEF, warm, np.random.default_rng(4))
    b = planner.plan(BELIEF, warm, np.random.default_rng(4))
    c = planner.plan(BELIEF, warm, np.random.default_rng(5))
    np.testing.assert_array_equal(a.controls, b.controls)
    assert not np.array_equal(a.controls, c.controls)
    assert a.controls.shape == (H, 2)
    assert (np.abs(a.controls) <= _scale(SETUP) * (1 + 1e-12)).all()
    assert a.nit == 300 and a.uav_path.shape == (H, 4) and a.hypotheses is None
    assert np.isfinite(a.cost) and a.cost > 0


def test_tree_search_config_round_trip_and_refusals():
    got = methods.from_config({"nbo": True, "dpw": [{"sims": 200}, {"sims": 1000}]}, "m")
    assert list(got) == ["nbo", "dpw_s200", "dpw_s1000"]
    for name, m in got.items():
        assert methods.from_name(name) == m and methods.from_spec(m.spec()) == m
    with pytest.raises(ValueError, match=r"sims"):
        TreeSearch(0)
    with pytest.raises(NotImplementedError, match=r"simulated beliefs"):
        got["dpw_s200"].hypotheses(BELIEF, SETUP, np.random.default_rng(0))
