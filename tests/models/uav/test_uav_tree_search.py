"""The tree-search planner (rsmhp.models.uav.dpw, family ``dpw``).

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
* the widening rules bound the tree: a plain-Python replay of the widening counts gives the
  root's number of actions exactly and an upper bound of the reachable depth; a tree with one
  child per action (k_o < 1, alpha_o = 0) gets deeper than the default one;
* work counts the generative model's calls: a simulation that leaves the tree at depth e
  makes 1 + H - e of them, plus the tail's nominal propagations; a one-path tree makes
  H (H + 1) / 2 in all;
* the pursuit policy turns toward the target and closes the range; the tail from the
  search's last belief is the pursuit policy on the nominal propagation (replayed in numpy);
  with rollout "warm" the plan beyond the tree is the warm start;
* names, specs, job keys and the schema of the per-member constants round-trip and refuse
  bad values naming the field; the plan stays in the box; the stream decides the plan.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as hst
from jsonschema import Draft202012Validator

from rsmhp.models.uav import dpw, kinematics, methods
from rsmhp.models.uav.methods.tree_search import (
    ALPHA_A,
    ALPHA_O,
    C_UCB,
    K_A,
    K_O,
    TreeSearch,
    TreeSearchPlanner,
)
from rsmhp.models.uav.planner import Belief
from rsmhp.models.uav.simulation import UAVSetup
from rsmhp.models.uav.stepper import Stepper

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
SETUP = UAVSetup.from_config(CONFIG["uav"])
P_HAT = np.diag([900.0, 400.0, 16.0, 9.0])
P_HAT[0, 1] = P_HAT[1, 0] = 150.0
BELIEF = Belief(np.array([0.0, 0.0, 20.0, 0.0]), np.array([300.0, -50.0, 6.0, 2.0]), P_HAT)
DEFAULTS = (C_UCB, K_A, ALPHA_A, K_O, ALPHA_O)


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
    r = dpw.search(
        BELIEF.uav, BELIEF.x_hat, BELIEF.P_hat, warm, _scale(setup), sims,
        DEFAULTS, st, np.random.default_rng(sims),
    )  # fmt: skip
    x, cost, n_b, n_a, n_root, n_chosen, best = r[:7]
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
    """H = 1, exact costs on a 41 x 41 grid of the control box. With rollout "warm" the
    search's k root actions are the warm start and k - 1 uniform draws; k - 1 draws all miss
    the best share q of the box with probability (1 - q)^(k-1), which is 1e-3 for q = 1 -
    1e-3^(1/(k-1)). So the best
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
    r = dpw.search(
        belief.uav, belief.x_hat, belief.P_hat, np.zeros((1, 2)), _scale(setup), sims,
        DEFAULTS, st, np.random.default_rng(1), rollout="warm",
    )  # fmt: skip
    _, cost, _, _, n_root, n_chosen, best = r[:7]
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
    assert a.work == b.work and a.diagnostics == b.diagnostics  # NaN-free: equal dicts
    assert not np.array_equal(a.controls, c.controls)
    assert a.controls.shape == (H, 2)
    assert (np.abs(a.controls) <= _scale(SETUP) * (1 + 1e-12)).all()
    assert a.nit == 300 and a.uav_path.shape == (H, 4) and a.hypotheses is None
    assert np.isfinite(a.cost) and a.cost > 0
    assert a.work > 0 and a.converged is None


def test_tree_search_config_round_trip_and_refusals():
    got = methods.from_config({"nbo": True, "dpw": [{"sims": 200}, {"sims": 1000}]}, "m")
    assert list(got) == ["nbo", "dpw_s200", "dpw_s1000"]
    for name, m in got.items():
        assert methods.from_name(name) == m and methods.from_spec(m.spec()) == m
    with pytest.raises(ValueError, match=r"sims"):
        TreeSearch(0)
    with pytest.raises(NotImplementedError, match=r"simulated beliefs"):
        got["dpw_s200"].hypotheses(BELIEF, SETUP, np.random.default_rng(0))


# ---------------------------------------------------------------- widening and depth


def _n_new(visits: int, k: float, alpha: float) -> int:
    """Children (or actions) a node has after ``visits`` visits under the widening rule "add
    one while count <= k max(N, 1)^alpha" (N: visits before the current one)."""
    n = 0
    for N in range(visits):
        if n <= k * max(N, 1) ** alpha:
            n += 1
    return n


def _min_visits(j: int, k_a: float, alpha_a: float, k_o: float, alpha_o: float) -> int:
    """The fewest visits of a belief node after which a belief j levels below it can exist.
    j = 1: one visit (its first action is expanded at once). j >= 2: some action must descend
    into one child ``T(j - 1)`` times; an action visited n times has expanded ``_n_new(n,
    k_o, alpha_o)`` times and descended the rest, at best always into the same child; and a
    node visited V times gives one action at most ``1 + V - _n_new(V, k_a, alpha_a)`` visits
    (a visit that creates an action goes to it)."""
    if j == 1:
        return 1
    need = _min_visits(j - 1, k_a, alpha_a, k_o, alpha_o)
    n = 1
    while n - _n_new(n, k_o, alpha_o) < need:
        n += 1
    V = 1
    while 1 + V - _n_new(V, k_a, alpha_a) < n:
        V += 1
    return V


def _depth_bound(sims: int, H: int, params) -> int:
    _, k_a, alpha_a, k_o, alpha_o = params
    j = 1
    while j < H and _min_visits(j + 1, k_a, alpha_a, k_o, alpha_o) <= sims:
        j += 1
    return j


def _plan(params, rollout="pursuit", sims=100, H=6, seed=0, warm=None, belief=BELIEF):
    setup = _setup(H)
    planner = TreeSearchPlanner(sims, setup, params, rollout)
    warm = np.zeros((H, 2)) if warm is None else warm
    return planner.plan(belief, warm, np.random.default_rng(seed))


def test_depth_statistics_obey_the_widening_rules():
    """Default constants, 100 simulations: the replay gives the root's actions exactly (the
    root is visited by every simulation) and a depth the tree cannot pass (5 at H = 6; the
    search stays at 2 on this belief: the audit's one-step random shooting)."""
    sims, H = 100, 6
    bound = _depth_bound(sims, H, DEFAULTS)
    assert bound == 5
    for seed in range(4):
        for rollout in dpw.ROLLOUTS:
            d = _plan(DEFAULTS, rollout, sims, H, seed).diagnostics
            assert 1 <= d["max_depth"] <= bound
            assert d["root_actions"] == _n_new(sims, K_A, ALPHA_A) == 13
            assert 1 <= d["mean_end_depth"] <= d["max_depth"]
            assert 0 < d["frac_depth1"] <= 1 and d["frac_horizon"] == 0
            assert d["plan_depth"] <= d["max_depth"]
            assert d["chosen_visits"] <= sims


def test_a_one_child_tree_gets_deeper_than_the_default_one():
    """With ``<=`` in the rule, k_o = 1, alpha_o = 0 keeps two children per action; k_o = 0.5
    one (a deterministic-transition tree). Both get deeper than the defaults on the same
    belief and streams, and never deeper than the replay's bound."""
    sims, H = 100, 6
    one = (C_UCB, K_A, ALPHA_A, 0.5, 0.0)
    two = (C_UCB, K_A, ALPHA_A, 1.0, 0.0)
    assert _n_new(50, 0.5, 0.0) == 1 and _n_new(50, 1.0, 0.0) == 2
    depth = {}
    for name, params in {"default": DEFAULTS, "one": one, "two": two}.items():
        ds = [_plan(params, sims=sims, H=H, seed=s).diagnostics for s in range(4)]
        assert max(d["max_depth"] for d in ds) <= _depth_bound(sims, H, params)
        depth[name] = (
            np.mean([d["max_depth"] for d in ds]),
            np.mean([d["mean_end_depth"] for d in ds]),
        )
    assert depth["one"][0] > depth["default"][0] and depth["one"][1] > depth["default"][1]
    assert depth["two"][1] > depth["default"][1]


def test_a_one_path_tree_makes_h_h_plus_1_over_2_model_calls():
    """k_a = k_o = 0.5, alpha = 0: one action per belief (the warm start's control), one
    child per action, so the tree is one path. Simulation j <= H expands at depth j and rolls
    out H - j steps (1 + H - j calls of G); later ones reach depth H inside the tree and call
    nothing: H (H + 1) / 2 calls once sims >= H, the plan is the warm start (fewer
    simulations: a path of depth sims, then the tail)."""
    path = (C_UCB, 0.5, 0.0, 0.5, 0.0)
    H = 5
    warm = np.tile(_scale(_setup(H)) * [0.3, -0.4], (H, 1))
    for rollout in dpw.ROLLOUTS:
        for sims in (3, 5, 12):
            r = _plan(path, rollout, sims, H, seed=sims, warm=warm)
            d = r.diagnostics
            n = min(sims, H)
            tail = max(H - n - 1, 0) if rollout == "pursuit" else 0
            assert d["tail_steps"] == tail
            assert r.work - tail == sum(1 + H - j for j in range(1, n + 1))
            assert d["max_depth"] == n and d["plan_depth"] == n
            assert d["frac_horizon"] == (sims - n) / sims
            assert d["mean_end_depth"] == (n + 1) / 2
            np.testing.assert_allclose(r.controls[:n], warm[:n], rtol=1e-15)
    r = _plan(path, "pursuit", 12, H, warm=warm)
    assert r.work == H * (H + 1) // 2 and r.n_kernel_calls == H + 1


@pytest.mark.parametrize("rollout", dpw.ROLLOUTS)
@pytest.mark.parametrize("H", [6, 12])
def test_work_counts_every_call_of_the_generative_model(rollout, H):
    """A simulation that leaves the tree at depth e makes one expansion and H - e rollout
    steps; the tail makes H - D - 1 nominal propagations from the path's last belief (depth D)
    with rollout "pursuit", none with "warm"."""
    st = Stepper(SETUP.uav, SETUP.target, SETUP.sensor)
    sims = 150
    for params in (DEFAULTS, (C_UCB, 2.0, 0.25, 0.5, 0.0)):
        r = dpw.search(
            BELIEF.uav, BELIEF.x_hat, BELIEF.P_hat, np.zeros((H, 2)), _scale(SETUP), sims,
            params, st, np.random.default_rng(H), rollout,
        )  # fmt: skip
        hist = r.end_depths
        assert hist.shape == (H + 1,) and hist.sum() == sims
        assert r.search_calls == sum(int(hist[e]) * (1 + H - e) for e in range(1, H + 1))
        assert r.max_depth == max(e for e in range(1, H + 1) if hist[e] > 0)
        want_tail = max(H - r.plan_depth - 1, 0) if rollout == "pursuit" else 0
        assert r.tail_steps == want_tail and r.work == r.search_calls + r.tail_steps
        # the planner reports the same numbers
        res = TreeSearchPlanner(sims, _setup(H), params, rollout).plan(
            BELIEF, np.zeros((H, 2)), np.random.default_rng(H)
        )
        assert res.work == r.work and res.diagnostics["max_depth"] == r.max_depth
        np.testing.assert_array_equal(res.controls, r.plan * _scale(SETUP))
        ends = np.arange(1, H + 1) @ hist[1:] / hist[1:].sum()
        assert res.diagnostics["mean_end_depth"] == pytest.approx(ends, rel=1e-15)
        assert res.diagnostics["frac_depth1"] == hist[1] / sims


# ---------------------------------------------------------------- pursuit and the tail


def _pursuit(uav, xh):
    return dpw.pursuit(np.asarray(uav, float), np.asarray(xh, float), Stepper(
        SETUP.uav, SETUP.target, SETUP.sensor))  # fmt: skip


def test_the_pursuit_action_turns_toward_the_target_and_closes_the_range():
    # heading east; target ahead-left / ahead-right / behind-left, and across the +-pi seam
    assert _pursuit([0, 0, 20, 0], [100, 50, 0, 0])[1] > 0
    assert _pursuit([0, 0, 20, 0], [100, -50, 0, 0])[1] < 0
    assert _pursuit([0, 0, 20, 0], [-100, 1, 0, 0])[1] == 1.0  # beyond 90 degrees: full bank
    assert _pursuit([0, 0, 20, 0], [100, 100, 0, 0])[1] == pytest.approx(0.5, rel=1e-14)
    assert _pursuit([0, 0, 20, 3.0], [-100, -20, 0, 0])[1] > 0  # bearing -2.94: turn left
    assert _pursuit([0, 0, 20, 3.0 + 10 * math.pi], [-100, -20, 0, 0])[1] > 0  # wound heading
    assert _pursuit([0, 0, 20, -3.0], [-100, 20, 0, 0])[1] < 0
    # the bank turns the aircraft toward the target: the bearing error shrinks
    for tgt in ([100, 80, 0, 0], [100, -80, 0, 0], [-50, 60, 0, 0]):
        uav = np.array([0.0, 0.0, 20.0, 0.0])
        tgt = np.asarray(tgt, float)

        def err(u, tgt=tgt):
            e = math.atan2(tgt[1] - u[1], tgt[0] - u[0]) - u[3]
            return abs(math.remainder(e, 2 * math.pi))

        u = _pursuit(uav, tgt) * _scale(SETUP)
        assert err(kinematics.step(uav, u, SETUP.uav)) < err(uav)
    # speed: far from the target it speeds up, on top of a slow one it slows to s_min
    a_max, dt = SETUP.uav.accel_max, SETUP.uav.dt
    assert _pursuit([0, 0, 20, 0], [500, 0, 0, 0])[0] == 1.0
    assert _pursuit([0, 0, 20, 0], [0, 0, 1, 0])[0] == -1.0
    v_ref = 8.0 + 50.0 / dpw.PURSUIT_TAU  # |v_hat| + range / tau, inside [s_min, s_max]
    want = (v_ref - 15.0) / (a_max * dt)
    assert -1 < want < 0
    assert _pursuit([0, 0, 15, 0], [50, 0, 0, 8])[0] == pytest.approx(want, rel=1e-14)


def test_the_tail_is_the_pursuit_policy_on_the_nominal_propagation():
    """One simulation with one action per belief (the warm start's control): the tree is the
    root and the belief b_1 = G(b_0, warm_0), drawn first from the stream, so a numpy replay
    knows b_1; the plan's steps 1..H-1 are then u_j = pi(b_j), s_{j+1} = f(s_j, u_j),
    x_{j+1} = F x_j."""
    H = 8
    setup = _setup(H)
    st = Stepper(setup.uav, setup.target, setup.sensor)
    scale = _scale(setup)
    warm = np.tile([0.4, -0.6], (H, 1))
    params = (C_UCB, 0.5, 0.0, 4.0, 0.25)
    r = dpw.search(
        BELIEF.uav, BELIEF.x_hat, BELIEF.P_hat, warm, scale, 1, params, st,
        np.random.default_rng(7), "pursuit",
    )  # fmt: skip
    assert r.plan_depth == 1 and r.tail_steps == H - 2 and r.work == H + H - 2
    uav, xh, P = BELIEF.uav.copy(), BELIEF.x_hat.copy(), BELIEF.P_hat.copy()
    scratch = [np.empty((4, 4)), np.empty(4), np.empty(4), np.empty(2), np.empty(2)]
    dpw._generate(
        uav, xh, P, warm[0], scale, st.F, st.Q, np.linalg.cholesky(st.Q), st.ucfg, st.sens,
        np.random.default_rng(7), *scratch,
    )  # fmt: skip
    np.testing.assert_array_equal(r.plan[0], warm[0])
    for j in range(1, H):
        u = _pursuit(uav, xh)
        np.testing.assert_allclose(r.plan[j], u, rtol=1e-12, atol=1e-12)
        uav = kinematics.step(uav, u * scale, setup.uav)
        xh = setup.target.F @ xh


def test_with_rollout_warm_the_plan_beyond_the_tree_is_the_warm_start():
    H = 10
    rng = np.random.default_rng(3)
    for seed in range(3):
        warm = rng.uniform(-1, 1, (H, 2)) * _scale(SETUP)
        res = _plan(DEFAULTS, "warm", 200, H, seed, warm=warm)
        D = int(res.diagnostics["plan_depth"])
        assert 1 <= D < H and res.diagnostics["tail_steps"] == 0
        np.testing.assert_allclose(res.controls[D:], warm[D:], rtol=1e-15)


def test_the_default_tail_is_not_the_zero_warm_start():
    H = 12
    res = (
        methods.from_name("dpw_s100")
        .planner(_setup(H))
        .plan(BELIEF, np.zeros((H, 2)), np.random.default_rng(0))
    )
    D = int(res.diagnostics["plan_depth"])
    assert D < H - 1
    assert (np.abs(res.controls[D:]).sum(axis=1) > 0).all()
    assert res.diagnostics["tail_steps"] == H - D - 1


# ---------------------------------------------------------------- the member's constants

_GRID = {  # multiples of 0.05 in each field's range
    "c": hst.integers(1, 2000).map(lambda k: k / 20),
    "k_a": hst.integers(1, 2000).map(lambda k: k / 20),
    "alpha_a": hst.integers(0, 20).map(lambda k: k / 20),
    "k_o": hst.integers(1, 2000).map(lambda k: k / 20),
    "alpha_o": hst.integers(0, 20).map(lambda k: k / 20),
    "rollout": hst.sampled_from(["pursuit", "warm"]),
}
_ANY = {  # any float of the range (the name holds the shortest decimal that reads back)
    "c": hst.floats(0, 100, exclude_min=True),
    "k_a": hst.floats(0, 100, exclude_min=True),
    "alpha_a": hst.floats(0, 1),
    "k_o": hst.floats(0, 100, exclude_min=True),
    "alpha_o": hst.floats(0, 1),
    "rollout": hst.sampled_from(["pursuit", "warm"]),
}


def _check_member(m: TreeSearch) -> None:
    name = m.name
    assert re.fullmatch(r"[a-z][a-z0-9_]*", name), name
    assert TreeSearch.parse(name) == m and methods.from_name(name) == m
    assert methods.from_name(name).name == name
    assert methods.from_spec(m.spec()) == m
    assert m.job_key() == {"method": name, "N_T": 0, "N": None, "M": None}
    default = TreeSearch(m.sims)
    assert (name == f"dpw_s{m.sims}") == (m == default)
    assert (m.label() == f"tree search {m.sims} sims") == (m == default)
    cfg = {"sims": m.sims, **{k: v for k, v in m.spec().items() if k not in ("family", "sims")}}
    assert Draft202012Validator(TreeSearch.schema).is_valid([cfg])
    assert TreeSearch.from_config([cfg], "dpw") == [m]


@settings(max_examples=150, deadline=None)
@given(
    sims=hst.integers(1, 1_000_000),
    fields=hst.fixed_dictionaries({}, optional=_GRID),
)
def test_names_parse_specs_round_trip_on_the_grid(sims, fields):
    _check_member(TreeSearch(sims, **fields))


@settings(max_examples=150, deadline=None)
@given(sims=hst.integers(1, 1000), fields=hst.fixed_dictionaries({}, optional=_ANY))
def test_names_parse_specs_round_trip_for_any_float(sims, fields):
    _check_member(TreeSearch(sims, **fields))


def test_default_members_keep_their_names_specs_and_streams():
    m = TreeSearch(100)
    assert m == TreeSearch(100, C_UCB, K_A, ALPHA_A, K_O, ALPHA_O, "pursuit")
    assert m.name == "dpw_s100" and m.spec() == {"family": "dpw", "sims": 100}
    assert m.job_key() == {"method": "dpw_s100", "N_T": 0, "N": None, "M": None}
    assert m == TreeSearch(100, k_o=4, alpha_a=0.25)  # ints and floats are one member
    m = TreeSearch(300, k_o=1, alpha_o=0.1)
    assert (
        m.name == "dpw_s300_ko1_ao0p1" and m.label() == "tree search 300 sims (k_o=1, alpha_o=0.1)"
    )
    assert TreeSearch(50, c=2.5, rollout="warm").name == "dpw_s50_c2p5_rwarm"
    assert "warm rollout" in TreeSearch(50, rollout="warm").label()
    assert TreeSearch(5, alpha_o=0.0).name == "dpw_s5_ao0" == TreeSearch(5, alpha_o=-0.0).name
    got = methods.from_config({"dpw": [{"sims": 300}, {"sims": 300, "k_o": 1, "alpha_o": 0.1}]})
    assert list(got) == ["nbo", "dpw_s300", "dpw_s300_ko1_ao0p1"]
    # only the exact name parses: defaults written out, padded numbers, other spellings
    for bad in ("dpw_s100_ko4", "dpw_s100_rpursuit", "dpw_s300_ko1_ao0p10", "dpw_s0300",
                "dpw_s300_ao0p1_ko1", "dpw_s300_ko1p0", "dpw_s300_c"):  # fmt: skip
        assert TreeSearch.parse(bad) is None
        with pytest.raises(ValueError, match=r"belongs to no registered family"):
            methods.from_name(bad)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("c", 0), ("c", 100.5), ("c", -1.0), ("c", float("nan")), ("k_a", 0.0), ("k_a", 101),
        ("k_o", -0.5), ("k_o", float("inf")), ("alpha_a", -0.1), ("alpha_a", 1.01),
        ("alpha_o", 2.0), ("rollout", "random"), ("rollout", None),
    ],
)  # fmt: skip
def test_bad_constants_are_refused_naming_the_field(field, value):
    with pytest.raises(ValueError, match=rf"\b{field}\b"):
        TreeSearch(100, **{field: value})
    with pytest.raises(ValueError, match=rf"dpw\[0\]\.{field}\b"):
        TreeSearch.from_config([{"sims": 100, field: value}], "dpw")
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return  # (YAML gives no NaN or inf; None is refused by the schema's type)
    assert not Draft202012Validator(TreeSearch.schema).is_valid([{"sims": 100, field: value}])


def test_bad_config_entries_are_refused():
    with pytest.raises(TypeError, match=r"c must be a real number"):
        TreeSearch(100, c="1")
    with pytest.raises(ValueError, match=r"dpw\[1\]: unknown key\(s\) \['depth'\]"):
        TreeSearch.from_config([{"sims": 1}, {"sims": 2, "depth": 3}], "dpw")
    with pytest.raises(ValueError, match=r"dpw\[0\]\.sims is required"):
        TreeSearch.from_config([{"k_o": 1}], "dpw")
    for f in ("c", "k_a", "alpha_a", "k_o", "alpha_o", "rollout"):  # bounds at the schema
        assert f in TreeSearch.schema["items"]["properties"]
    ok = [{"sims": 1, "c": 100, "k_a": 100, "alpha_a": 0, "alpha_o": 1, "rollout": "warm"}]
    assert Draft202012Validator(TreeSearch.schema).is_valid(ok)
    assert TreeSearch.from_config(ok, "dpw")[0].name == "dpw_s1_c100_ka100_aa0_ao1_rwarm"
