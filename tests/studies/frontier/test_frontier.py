"""The equal-compute study's experiment (rsmhp.studies.frontier.simulate) on a short model.

Oracles: a method's closed-loop row is :func:`simulate_run`'s summary for the same model,
seed and run (pairing by run, no dependence on the other methods); a method's plan and its
evaluation cost at a belief state are :func:`score_state`'s with any other method set; the
outputs satisfy the rule's contracts; timings are positive and per step.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from rsmhp.core.seeding import job_rng
from rsmhp.models.uav import methods
from rsmhp.models.uav.scoring import belief_states, merge_variant, score_state
from rsmhp.models.uav.simulation import UAVSetup, simulate_run
from rsmhp.pipeline.contracts import check_table
from rsmhp.studies.frontier.simulate import frontier_contracts, run_frontier_model

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
MODELS = [{"name": "paper"}, {"name": "footprint150", "sensor": {"footprint_radius": 150.0}}]
SCORING = {"n_eval": 200, "polish": 1, "random_starts": 1, "eval_maxiter": 10, "n_random": 20}
FRONTIER = {
    "models": ["paper", "footprint150"],
    "runs": 3,
    "regret_runs": 1,
    "regret_steps": [0, 3],
    "track_loss_error": 50.0,
    "methods": {
        "nbo": True,
        "rsmhp_nt": [16],
        "rqmc_nt": [16],
        "antithetic_nt": [16],
        "sigma": True,
        "dpw": [{"sims": 30}],
    },
}


def _uav() -> dict:
    cfg = copy.deepcopy(CONFIG["uav"])
    cfg["scenario"]["steps"] = 6
    cfg["planner"].update(horizon=3, maxiter=6, maxfun=12)
    return cfg


@pytest.fixture(scope="module")
def footprint():
    return run_frontier_model(_uav(), MODELS, FRONTIER, SCORING, "footprint150", 5)


def test_rows_follow_the_contracts_and_pair_by_run(footprint):
    runs, regret = footprint
    c_runs, c_regret = frontier_contracts(FRONTIER, "footprint150")
    check_table(runs, "frontier runs", c_runs)
    check_table(regret, "frontier regret", c_regret)
    names = list(methods.from_config(FRONTIER["methods"]))
    assert list(dict.fromkeys(runs["method"])) == names
    assert (runs["plan_ms"] > 0).all()
    setup = UAVSetup.from_config(merge_variant(_uav(), MODELS[1]))
    for name in ("nbo", "rqmc_nt16", "dpw_s30"):
        for run in range(FRONTIER["runs"]):
            summary, _ = simulate_run(setup, methods.from_name(name), 5, run)
            row = runs[(runs["method"] == name) & (runs["run"] == run)].iloc[0]
            assert row["mean_error"] == summary["mean_error"]
            assert row["detect_rate"] == summary["detect_rate"]
            assert row["lost"] == (summary["final_error"] > FRONTIER["track_loss_error"])


def test_a_methods_open_loop_numbers_do_not_depend_on_the_others(footprint):
    _, regret = footprint
    setup = UAVSetup.from_config(merge_variant(_uav(), MODELS[1]))
    state = belief_states(setup, "footprint150", 5, [0], [3])[0]
    alone = score_state(state, setup, methods.from_config({"nbo": True, "sigma": True}), SCORING, 5)
    got = regret[regret["step"] == 3].set_index("method")
    for row in alone:
        assert got.loc[row["method"], "plan_cost"] == row["plan_cost"]
        assert got.loc[row["method"], "eval_cost"] == row["eval_cost"]
        # more methods can only lower the reference, never raise it
        assert got.loc[row["method"], "best_cost"] <= row["best_cost"] * (1 + 1e-12)


def test_unknown_model_is_refused():
    with pytest.raises(ValueError, match=r"'nowhere' is not a model of uav_models"):
        run_frontier_model(_uav(), MODELS, FRONTIER, SCORING, "nowhere", 5)


def test_paper_model_has_full_detection():
    runs, _ = run_frontier_model(
        _uav(), MODELS, dict(FRONTIER, runs=1, methods={"nbo": True}), SCORING, "paper", 5
    )
    assert np.array_equal(runs["detect_rate"].to_numpy(), [1.0])


# ------------------------------------------------------------------------ summary and figure


def _synthetic():
    """Two methods and NBO on one model, 6 runs and 4 belief states with known differences."""
    import pandas as pd

    rng = np.random.default_rng(0)
    runs, regret = [], []
    for fam, method, shift, ms in (("nbo", "nbo", 0.0, 0.05), ("rsmhp", "rsmhp_nt16", -1.0, 0.2),
                                   ("dpw", "dpw_s30", 2.0, 1.0)):  # fmt: skip
        for r in range(6):
            runs.append(
                {"model": "m", "method": method, "family": fam, "N_T": 0, "N": 0, "M": 0,
                 "run": r, "mean_error": 10.0 + r + shift + (0.1 * r if fam == "dpw" else 0),
                 "final_error": 5.0, "detect_rate": 1.0, "lost": r == 0 and fam == "dpw",
                 "plan_ms": ms * (1 + 0.01 * r)}
            )  # fmt: skip
        for k in range(4):
            regret.append({"model": "m", "run": 0, "step": k, "method": method,
                           "regret_rel": 0.01 * (k + 1) + 0.001 * shift})  # fmt: skip
    return pd.DataFrame(runs), pd.DataFrame(regret), rng


def test_summary_pairs_with_nbo():
    from rsmhp.studies.frontier.summarise import FRONTIER_SUMMARY_COLUMNS, summarize_frontier

    runs, regret, _ = _synthetic()
    raw = summarize_frontier(runs, regret)
    assert list(raw.columns) == FRONTIER_SUMMARY_COLUMNS
    s = raw.set_index("method")
    assert list(s.index) == ["nbo", "rsmhp_nt16", "dpw_s30"]
    assert s.loc["nbo", "error_diff"] == 0 and s.loc["nbo", "regret_diff_pp"] == 0
    assert s.loc["rsmhp_nt16", "error_diff"] == pytest.approx(-1.0)
    # paired differences with no spread: the CI is the point
    assert s.loc["rsmhp_nt16", "error_diff_low"] == pytest.approx(-1.0)
    assert s.loc["rsmhp_nt16", "regret_diff_pp"] == pytest.approx(-0.1)
    d = 2.0 + 0.1 * np.arange(6)
    assert s.loc["dpw_s30", "error_diff"] == pytest.approx(d.mean())
    assert (
        d.min()
        <= s.loc["dpw_s30", "error_diff_low"]
        <= d.mean()
        <= s.loc["dpw_s30", "error_diff_high"]
        <= d.max()
    )
    assert s.loc["dpw_s30", "lost_rate"] == pytest.approx(1 / 6)
    assert s.loc["dpw_s30", "plan_ms"] == pytest.approx(np.median(1.0 * (1 + 0.01 * np.arange(6))))
    assert s.loc["dpw_s30", "regret_pct"] == pytest.approx(100 * (0.025 + 0.002))
    again = summarize_frontier(runs, regret).set_index("method")
    assert again.equals(s)  # seeded per (model, method, statistic)


def test_frontier_figure_draws_one_line_per_family():
    from rsmhp.studies.frontier.figures import frontier_figure
    from rsmhp.studies.frontier.summarise import summarize_frontier

    runs, regret, _ = _synthetic()
    fig = frontier_figure(summarize_frontier(runs, regret))
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels == ["NBO", "RS-MHP", "tree search"]
    assert fig.axes[0].get_xscale() == "log"
    with pytest.raises(ValueError, match="empty"):
        frontier_figure(summarize_frontier(runs.iloc[:0], regret.iloc[:0]))


def test_bad_frontier_config_is_refused_naming_the_fields():
    from rsmhp.pipeline.config import ConfigError, check_config

    cfg = copy.deepcopy(CONFIG)
    fr = cfg["frontier"]
    fr["models"] = ["paper", "nowhere"]
    fr["methods"]["nbo"] = False
    fr["methods"]["rqmc_nt"] = [16, 48]
    fr["regret_steps"] = [0, 60]
    with pytest.raises(ConfigError) as err:
        check_config(cfg)
    msg = str(err.value)
    assert "frontier.models: ['nowhere'] not model(s) of uav_models" in msg
    assert "frontier.methods.nbo: false (allowed: true" in msg
    assert "frontier.methods.rqmc_nt[1]: 48 is not a power of 2" in msg
    assert "frontier.regret_steps: [60] not before the run's last step" in msg
    ok = copy.deepcopy(CONFIG)
    ok["frontier"]["models"] = []  # no model: the study does not run
    check_config(ok)


def test_interleaved_timing_rotates_the_order_and_times_the_closed_loop_plan():
    """Every method takes every slot equally often (repeats x states a multiple of the
    methods), the contract holds, each call's work is the closed loop's plan's work at that
    belief (same stream key), and the summary's median and per-pass range are the table's."""
    from rsmhp.models.uav.planner import Belief
    from rsmhp.studies.frontier.simulate import time_planners, timing_contract
    from rsmhp.studies.frontier.summarise import timing_summary

    names = list(methods.from_config(FRONTIER["methods"]))
    cfg = {**FRONTIER, "timing": {"runs": 1, "steps": [0, 2, 3], "repeats": len(names)}}
    t = time_planners(_uav(), MODELS, cfg, "footprint150", 5)
    check_table(t, "timing", timing_contract(cfg, "footprint150"))
    assert (t["ms"] > 0).all()
    slots = t.groupby(["method", "slot"]).size().unstack()
    assert slots.shape == (len(names), len(names)) and (slots == 3).all().all()
    # the plan is the same in every repeat (the stream is the step's), so is its work
    assert (t.groupby(["method", "run", "step"])["work"].nunique() == 1).all()
    setup = UAVSetup.from_config(merge_variant(_uav(), MODELS[1]))
    st = belief_states(setup, "footprint150", 5, [0], [2])[0]
    m = methods.from_name("rsmhp_nt16")
    rng = job_rng(5, "uav_plan", run=0, step=3, **m.job_key())
    res = m.planner(setup).plan(Belief(st.uav, st.x_hat, st.P_hat), st.warm, rng)
    got = t[(t["method"] == "rsmhp_nt16") & (t["step"] == 2)]["work"].iloc[0]
    assert got == res.work == 2 * 16 * 3 * (res.n_kernel_calls)
    s = timing_summary(t)
    one = t[t["method"] == "nbo"]
    assert s.loc[("footprint150", "nbo"), "plan_ms"] == np.median(one["ms"])
    per_pass = one.groupby("repeat")["ms"].median()
    assert s.loc[("footprint150", "nbo"), "plan_lo_ms"] == per_pass.min()
    assert s.loc[("footprint150", "nbo"), "plan_hi_ms"] == per_pass.max()


def test_frontier_summary_refuses_a_method_without_timing(footprint):
    from rsmhp.studies.frontier.simulate import TIMING_COLUMNS
    from rsmhp.studies.frontier.summarise import summarize_frontier

    runs, regret = footprint
    timing = pd.DataFrame([["footprint150", "nbo", 0, 0, 0, 0, 1.0, 10]], columns=TIMING_COLUMNS)
    with pytest.raises(ValueError, match="no interleaved timing of 'rsmhp_nt16'"):
        summarize_frontier(runs, regret, timing)
