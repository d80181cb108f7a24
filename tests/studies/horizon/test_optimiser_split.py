"""Optimiser split of the UAV open-loop regret (rsmhp.studies.horizon.simulate_optimiser,
rsmhp.studies.horizon.summarise_optimiser).

Oracles: the split is the definition (regret = approximation + optimisation regret, up to
one rounding); the reference is the minimum of every J_ev evaluated at the state (so no regret
is negative and J_ref <= every eval_cost); x*_m is at least as good on the method's own cost
as every budget plan; with the restarts fixed, more iterations from the same warm start follow
the same L-BFGS path, so the own cost never rises with maxiter; a budget's plan equals the
plan that Method.planner makes with that budget (an independent route), and at the decision
study's budget its evaluation cost equals score_state's (same hypotheses, same evaluation
set); a plan's evaluation cost does not depend on the other methods (paired design); the
table meets its contract and is a function of the seed; the summary's means and intervals
against Student's t on a hand-made table.
"""

from __future__ import annotations

import copy
import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from scipy import stats as sps

from rsmhp.core.seeding import job_rng
from rsmhp.models.uav.planner import Belief
from rsmhp.models.uav.scoring import belief_states, score_state
from rsmhp.pipeline.contracts import check_table
from rsmhp.studies.horizon.simulate_optimiser import (
    SPLIT_COLUMNS,
    budgets,
    run_optimiser_split,
    split_contract,
    split_methods,
)
from rsmhp.studies.horizon.simulate_uav import _warm, horizon_setup
from rsmhp.studies.horizon.summarise_optimiser import SUMMARY_COLUMNS, summarize_split

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
PAPER = {"name": "paper"}
SEED = 7
H = 4
SCORING = {"n_eval": 200, "polish": 2, "random_starts": 1, "eval_maxiter": 15, "n_random": 10}
CFG = {
    "runs": 2,
    "steps": [0, 3],
    "methods": {
        "nbo": True,
        "rsmhp_nt": [16],
        "rqmc_nt": [16],
        "sigma": True,
        "dpw": [{"sims": 10}],
    },
    # (6, 12, 0) is the base planner budget of _uav(): the decision study's plan
    "budgets": [
        {"maxiter": 2, "restarts": 0},
        {"maxiter": 6, "maxfun": 12, "restarts": 0},
        {"maxiter": 30, "restarts": 0},
        {"maxiter": 30, "restarts": 2},
    ],
    "polish_starts": 2,
    "polish_maxiter": 200,
}
KEY = ["run", "step", "method"]


def _uav() -> dict:
    cfg = copy.deepcopy(CONFIG["uav"])
    cfg["scenario"]["steps"] = 5
    cfg["planner"].update(horizon=3, maxiter=6, maxfun=12)
    return cfg


@pytest.fixture(scope="module")
def table() -> pd.DataFrame:
    return run_optimiser_split(_uav(), PAPER, H, CFG, SCORING, SEED)


def test_contract_and_skipped_tree_search(table):
    df = check_table(table.copy(), "split.csv", split_contract(CFG, "paper", H))
    assert list(df.columns) == SPLIT_COLUMNS
    assert set(df["method"]) == {"nbo", "rsmhp_nt16", "rqmc_nt16", "sigma"}  # no dpw
    assert "dpw_s10" not in split_methods(CFG) and len(df) == 2 * 2 * 4 * 4
    assert set(df["star_source"]) <= {"budget", "polish"}


def test_split_is_additive_and_nonnegative(table):
    r, a, o = (table[c].to_numpy() for c in ("regret", "approx_regret", "optim_regret"))
    np.testing.assert_allclose(a + o, r, rtol=0, atol=1e-14)
    assert (r >= 0).all() and (a >= 0).all()
    for _, g in table.groupby(["run", "step"]):
        assert g["ref_cost"].nunique() == 1  # one reference per state, shared by methods
        assert (g["ref_cost"] <= g["eval_cost"]).all()
    np.testing.assert_allclose(
        table["regret"], (table["eval_cost"] - table["ref_cost"]) / table["ref_cost"], rtol=1e-14
    )


def test_star_is_best_on_own_cost(table):
    assert (table["star_own_cost"] <= table["own_cost"]).all()
    for _, g in table.groupby(KEY):
        assert g["star_own_cost"].nunique() == 1 and g["approx_regret"].nunique() == 1
        assert g["star_source"].nunique() == 1
    # the star came from a budget plan exactly when some budget plan reaches its own cost
    best_budget = table.groupby(KEY)["own_cost"].min()
    star = table.groupby(KEY)[["star_own_cost", "star_source"]].first()
    from_budget = star["star_source"] == "budget"
    assert (best_budget[from_budget] == star["star_own_cost"][from_budget]).all()
    assert (best_budget[~from_budget] > star["star_own_cost"][~from_budget]).all()


def test_more_iterations_never_raise_own_cost(table):
    one = table[table["restarts"] == 0].sort_values([*KEY, "maxiter"])
    for _, g in one.groupby(KEY):
        cost, nit = g["own_cost"].to_numpy(), g["nit"].to_numpy()
        assert (np.diff(cost) <= 0).all() and (np.diff(nit) >= 0).all()
        assert (nit <= g["maxiter"].to_numpy()).all()
        # once converged, a larger budget changes nothing
        conv = g["converged"].to_numpy()
        if conv.any():
            k = int(np.argmax(conv))
            assert (cost[k:] == cost[k]).all() and (nit[k:] == nit[k]).all()
    # restarts only add: the best of more optimisations, at least the warm start's one
    both = table[table["maxiter"] == 30].pivot_table(
        index=KEY, columns="restarts", values="own_cost"
    )
    assert (both[2] <= both[0]).all()
    nits = table[table["maxiter"] == 30].pivot_table(index=KEY, columns="restarts", values="nit")
    assert (nits[2] >= nits[0]).all()


def _states():
    uav = _uav()
    base = horizon_setup(uav, PAPER, 3)
    setup = horizon_setup(uav, PAPER, H)
    states = belief_states(base, "paper", SEED, range(CFG["runs"]), CFG["steps"])
    return setup, [dataclasses.replace(s, warm=_warm(s, H)) for s in states]


def test_budget_plan_is_the_methods_own_plan(table):
    """Each row's counters and own cost equal Method.planner's plan with that budget and the
    decision study's stream; at the base budget its eval_cost equals score_state's."""
    setup, states = _states()
    planners = split_methods(CFG)
    scored = {}
    for st in states:
        for row in score_state(st, setup, planners, SCORING, SEED):
            scored[(st.run, st.step, row["method"])] = row["eval_cost"]
    by_key = table.set_index([*KEY, "maxiter", "restarts"])
    for st in states:
        belief = Belief(st.uav, st.x_hat, st.P_hat)
        for name, m in planners.items():
            for maxiter, maxfun, restarts in budgets(CFG):
                params = dataclasses.replace(
                    setup.planner, maxiter=maxiter, maxfun=maxfun, restarts=restarts
                )
                rng = job_rng(
                    SEED, "decisions_uav_plan", model="paper", run=st.run, step=st.step,
                    **m.job_key(),
                )  # fmt: skip
                res = m.planner(dataclasses.replace(setup, planner=params)).plan(
                    belief, st.warm, rng
                )
                row = by_key.loc[(st.run, st.step, name, maxiter, restarts)]
                assert row["nit"] == res.nit and row["work"] == res.work
                assert row["converged"] == res.converged
                np.testing.assert_allclose(row["own_cost"], res.cost, rtol=1e-12)
            base = by_key.loc[(st.run, st.step, name, 6, 0)]
            np.testing.assert_allclose(
                base["eval_cost"], scored[(st.run, st.step, name)], rtol=1e-12
            )


def test_deterministic_and_paired(table):
    again = run_optimiser_split(_uav(), PAPER, H, CFG, SCORING, SEED)
    pd.testing.assert_frame_equal(table, again)
    alone = run_optimiser_split(
        _uav(), PAPER, H, {**CFG, "methods": {"nbo": False, "rqmc_nt": [16]}}, SCORING, SEED
    )
    mine = table[table["method"] == "rqmc_nt16"].reset_index(drop=True)
    same = ["run", "step", "maxiter", "restarts", "nit", "converged", "work", "own_cost",
            "eval_cost", "star_own_cost", "star_source"]  # fmt: skip
    pd.testing.assert_frame_equal(mine[same], alone[same])
    # the reference can only go down with more methods: regrets only up
    assert (mine["ref_cost"].to_numpy() <= alone["ref_cost"].to_numpy()).all()
    other = run_optimiser_split(_uav(), PAPER, H, CFG, SCORING, SEED + 1)
    assert not np.allclose(other["eval_cost"], table["eval_cost"])


def test_budgets_parse_and_refuse():
    assert budgets({"budgets": [{"maxiter": 30, "restarts": 0}]}) == [(30, 61, 0)]
    assert budgets({"budgets": [{"maxiter": 30, "maxfun": 60}]}) == [(30, 60, 0)]
    with pytest.raises(ValueError, match="appear twice"):
        budgets({"budgets": [{"maxiter": 30, "restarts": 0}, {"maxiter": 30, "maxfun": 9}]})
    with pytest.raises(ValueError, match="non-empty"):
        budgets({"budgets": []})


def test_summary_against_student_t():
    rng = np.random.default_rng(3)
    rows = []
    for run in range(5):
        for maxiter, conv in ((30, False), (300, True)):
            a = rng.uniform(0, 0.1)
            o = rng.normal(0, 0.05)
            rows.append(
                {
                    "model": "paper", "H": 12, "run": run, "step": 0, "method": "nbo",
                    "family": "nbo", "maxiter": maxiter, "restarts": 0, "nit": maxiter // 3,
                    "converged": conv, "work": 10 * run, "regret": a + o, "approx_regret": a,
                    "optim_regret": o, "star_source": "polish" if run < 2 else "budget",
                }
            )  # fmt: skip
    df = pd.DataFrame(rows)
    out = summarize_split(df)
    assert list(out.columns) == SUMMARY_COLUMNS and len(out) == 2
    for _, s in out.iterrows():
        g = df[df["maxiter"] == s["maxiter"]]
        assert s["states"] == 5 and s["runs"] == 5
        for prefix, col in (("regret", "regret"), ("approx", "approx_regret"),
                            ("optim", "optim_regret")):  # fmt: skip
            x = 100 * g[col].to_numpy()
            half = sps.t.ppf(0.975, 4) * x.std(ddof=1) / np.sqrt(5)
            np.testing.assert_allclose(s[f"{prefix}_pct"], x.mean(), rtol=1e-12)
            np.testing.assert_allclose(
                [s[f"{prefix}_lo"], s[f"{prefix}_hi"]],
                [x.mean() - half, x.mean() + half],
                rtol=1e-10,
            )
        np.testing.assert_allclose(s["regret_pct"], s["approx_pct"] + s["optim_pct"], rtol=1e-12)
        assert s["converged_share"] == float(s["maxiter"] == 300)
        assert s["mean_nit"] == s["maxiter"] // 3 and s["mean_work"] == 20.0
        assert s["polish_star_share"] == 0.4
    # several states per run: the run is the cluster; one run gives no interval
    two = pd.concat([df, df.assign(step=5)], ignore_index=True)
    pd.testing.assert_frame_equal(
        summarize_split(two).drop(columns="states"), out.drop(columns="states")
    )
    lone = summarize_split(df[df["run"] == 0])
    assert lone[["regret_lo", "regret_hi"]].isna().all().all()
