"""UAV decision study: belief states, open-loop regret at a state, the map cells, and the
aggregation's verdict rules."""

from __future__ import annotations

import copy
import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from rsmhp.analysis import decisions as dec
from rsmhp.experiments.decisions_uav import (
    MAP_RUN_COLUMNS,
    REGRET_COLUMNS,
    belief_states,
    map_cells,
    merge_variant,
    run_map_cell,
    score_state,
)
from rsmhp.uav.simulation import UAVSetup, draw_scenario, method_specs, simulate_run

ROOT = Path(__file__).resolve().parents[1]
UAV = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["uav"]
SCORING = {"n_eval": 300, "polish": 1, "random_starts": 1, "eval_maxiter": 15, "n_random": 30}
METHODS = {"nbo": True, "rsmhp_nt": [20], "tree": [{"N": 3, "M": 20}]}


def _short(**sensor) -> dict:
    cfg = copy.deepcopy(UAV)
    cfg["scenario"]["steps"] = 8
    cfg["planner"].update(horizon=4, maxiter=8, maxfun=16)
    cfg["sensor"].update(sensor)
    return cfg


def test_belief_states_are_the_closed_loop_beliefs():
    setup = UAVSetup.from_config(_short())
    states = belief_states(setup, "paper", 5, [0, 1], [0, 3, 6])
    assert [(s.run, s.step) for s in states] == [(0, 0), (0, 3), (0, 6), (1, 0), (1, 3), (1, 6)]
    sc = draw_scenario(setup, 5, 1)
    np.testing.assert_array_equal(states[3].x_hat, sc.estimate)
    np.testing.assert_array_equal(states[3].P_hat, setup.P0)
    assert not states[3].warm.any()
    nbo = method_specs({"methods": {"nbo": True, "rsmhp_nt": [], "tree": []}})["nbo"]
    _, rows = simulate_run(setup, nbo, 5, 1)
    assert np.trace(states[4].P_hat) == pytest.approx(rows[2]["trace"], rel=1e-14)  # step 3
    assert (states[5].uav[0], states[5].uav[1]) == (rows[5]["uav_x"], rows[5]["uav_y"])
    with pytest.raises(ValueError, match="not before the run's last step"):
        belief_states(setup, "paper", 5, [0], [8])


def test_score_state_rows():
    setup = UAVSetup.from_config(_short())
    state = belief_states(setup, "paper", 5, [0], [3])[0]
    methods = method_specs({"methods": METHODS})
    rows = score_state(state, setup, methods, SCORING, 5)
    assert [r["method"] for r in rows] == list(methods)
    for r in rows:
        assert set(r) == set(REGRET_COLUMNS)
        # the reference is at least as good as every plan (up to summation order)
        assert r["regret"] >= -1e-9 * r["best_cost"]
        assert r["regret_methods"] >= -1e-9 * r["best_cost"]
        assert r["regret_methods"] <= r["regret"] + 1e-9 * r["best_cost"]
        assert r["regret_se"] >= 0 and r["eval_se"] > 0
        assert -1 <= r["spearman_random"] <= 1
    # the best method has zero regret against the methods' best
    assert min(r["regret_methods"] for r in rows) == pytest.approx(0.0, abs=1e-9)
    again = score_state(state, setup, methods, SCORING, 5)
    assert again == rows  # seeded by (model, run, step, method), not by call order


def test_a_certain_belief_makes_every_method_plan_alike():
    """With a nearly exact belief and almost no target noise every hypothesis is the nominal
    one: RS-MHP's and the tree's costs equal NBO's to within that spread."""
    cfg = _short()
    cfg["target"]["q"] = 1e-12
    setup = UAVSetup.from_config(cfg)
    state = belief_states(setup, "paper", 5, [0], [3])[0]
    state = dataclasses.replace(state, P_hat=1e-10 * np.eye(4))
    rows = score_state(state, setup, method_specs({"methods": METHODS}), SCORING, 5)
    costs = [r["eval_cost"] for r in rows]
    assert max(costs) - min(costs) <= 1e-6 * max(costs)


def test_variants_and_cells():
    merged = merge_variant(UAV, {"name": "x", "sensor": {"footprint_radius": 100.0}})
    assert merged["sensor"]["footprint_radius"] == 100.0
    assert merged["sensor"]["sigma_r_per_m"] == UAV["sensor"]["sigma_r_per_m"]
    assert "footprint_radius" not in UAV["sensor"]  # the input is not modified
    with pytest.raises(ValueError, match="unknown section 'planner'"):
        merge_variant(UAV, {"planner": {"horizon": 3}})
    cfg = {
        "rows": {"key": "sensor.footprint_radius", "values": [None, 150.0]},
        "cols": {"key": "target.q", "values": [1.0, 4.0, 9.0]},
    }
    cells = map_cells(cfg)
    assert [c.name for c in cells] == ["r0c0", "r0c1", "r0c2", "r1c0", "r1c1", "r1c2"]
    assert cells[4].variant == {"sensor": {"footprint_radius": 150.0}, "target": {"q": 4.0}}


def test_map_cell_runs_are_paired_and_flag_track_loss():
    cfg = {
        "rows": {"key": "sensor.footprint_radius", "values": [150.0]},
        "cols": {"key": "target.q", "values": [1.0]},
        "runs": 3,
        "methods": {"nbo": True, "rsmhp_nt": [20], "tree": []},
        "regret_runs": 1,
        "regret_steps": [0],
        "track_loss_error": 50.0,
    }
    runs, regret = run_map_cell(_short(), cfg, SCORING, "r0c0", 5)
    assert list(runs.columns) == MAP_RUN_COLUMNS
    assert len(runs) == 6 and set(runs["method"]) == {"nbo", "rsmhp_nt20"}
    assert (runs["lost"] == (runs["final_error"] > 50.0)).all()
    assert runs["detect_rate"].between(0, 1).all()
    assert set(regret["model"]) == {"r0c0"} and len(regret) == 2
    with pytest.raises(ValueError, match="unknown map cell 'r9c9'"):
        run_map_cell(_short(), cfg, SCORING, "r9c9", 5)


def _map_runs(shift: float) -> pd.DataFrame:
    rng = np.random.default_rng(0)
    rows = []
    for cell, rv in (("r0c0", None), ("r1c0", 150.0)):
        base = rng.normal(20, 3, 40)
        for m, off in (("nbo", 0.0), ("rsmhp_nt100", shift)):
            for r in range(40):
                err = base[r] + off + rng.normal(0, 0.5)
                rows.append(
                    {
                        "cell": cell,
                        "row_value": rv,
                        "col_value": 1.0,
                        "method": m,
                        "run": r,
                        "mean_error": err,
                        "final_error": err,
                        "detect_rate": 1.0,
                        "lost": err > 50,
                    }
                )
    return pd.DataFrame(rows)


@pytest.mark.parametrize(
    "shift, verdict", [(-2.0, "supported"), (2.0, "not supported"), (0.0, "inconclusive")]
)
def test_map_claim_rule(shift, verdict):
    cfg = {"rows": {"key": "sensor.footprint_radius"}, "cols": {"key": "target.q"}}
    empty = pd.DataFrame(columns=REGRET_COLUMNS)
    m = dec.summarize_map(_map_runs(shift), empty, cfg, 1, 500)
    assert len(m) == 2 and (m["n_runs"] == 40).all()
    if shift:
        assert ((m["mean_diff"] - shift).abs() < 0.3).all()
    claims = dec.uav_claims(
        empty.astype({"model": str}),
        pd.DataFrame(columns=dec.UAV_SUMMARY_COLUMNS).astype({"method": str}),
        m,
        1,
        500,
    )
    v = {c.id: c.verdict for c in claims}
    assert v["DEC-8a"] == verdict  # the footprint cell
    assert v["DEC-8b"] == verdict  # the unlimited cell


def test_regret_summary_and_claims():
    rng = np.random.default_rng(2)
    rows = []
    for model, nbo_reg in (("paper", 0.001), ("fp150", 0.05)):
        for run in range(10):
            for step in (0, 5):
                for method, reg in (("nbo", nbo_reg), ("rsmhp_nt100", 0.001)):
                    rel = abs(rng.normal(reg, reg / 5))
                    rows.append(
                        {
                            "model": model,
                            "run": run,
                            "step": step,
                            "trace_P": 1.0,
                            "method": method,
                            "family": method[:5],
                            "N_T": 1 if method == "nbo" else 100,
                            "N": 0,
                            "M": 0,
                            "plan_cost": 1.0,
                            "eval_cost": 1 + rel,
                            "eval_se": 0.01,
                            "best_cost": 1.0,
                            "regret": rel,
                            "regret_se": 1e-4,
                            "regret_rel": rel,
                            "regret_methods": rel,
                            "spearman_random": 0.9,
                            "spearman_local": 0.8,
                            "n_eval": 4000,
                        }
                    )
    df = pd.DataFrame(rows, columns=REGRET_COLUMNS)
    summary = dec.summarize_uav_regret(df, 1, 500)
    assert len(summary) == 4 and (summary["n_states"] == 20).all()
    v = {c.id: c.verdict for c in dec.uav_claims(df, summary, pd.DataFrame(), 1, 500)}
    assert v["DEC-6"] == "supported"  # NBO within the margin of RS-MHP in the reconstruction
    assert v["DEC-7-fp150"] == "supported"  # RS-MHP decides better with the footprint


def test_limited_cells_follow_the_axis_else_the_base_sensor():
    m = pd.DataFrame(
        {
            "row_key": ["sensor.footprint_radius"] * 2 + ["target.q"] * 2,
            "row_value": [None, 150.0, 1.0, 4.0],
            "col_key": ["target.q"] * 2 + ["tracker.p0_pos_sd"] * 2,
            "col_value": [1.0, 1.0, 10.0, 50.0],
        }
    )
    assert dec._limited(m).tolist() == [False, True, False, False]
    # a base footprint applies where no axis sets the radius; a null axis value overrides it
    assert dec._limited(m, base_limited=True).tolist() == [False, True, True, True]
