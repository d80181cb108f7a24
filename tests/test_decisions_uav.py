"""UAV decision study: belief states, open-loop regret at a state, the map cells, and the
aggregation's verdict rules."""

from __future__ import annotations

import copy
import dataclasses
import re
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
import yaml
from matplotlib.colors import to_hex

from rsmhp.analysis import decisions_uav as dec
from rsmhp.claims import decisions_uav as dec_claims
from rsmhp.experiments.decisions_uav import (
    MAP_RUN_COLUMNS,
    REGRET_COLUMNS,
    belief_states,
    map_cells,
    merge_variant,
    run_map_cell,
    score_state,
)
from rsmhp.figures import decisions as figs
from rsmhp.narrative import decisions_uav as dec_text
from rsmhp.palette import method_colour
from rsmhp.uav import methods as uav_methods
from rsmhp.uav.simulation import UAVSetup, draw_scenario, simulate_run

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
    nbo = uav_methods.from_config({"nbo": True, "rsmhp_nt": [], "tree": []})["nbo"]
    _, rows = simulate_run(setup, nbo, 5, 1)
    assert np.trace(states[4].P_hat) == pytest.approx(rows[2]["trace"], rel=1e-14)  # step 3
    assert (states[5].uav[0], states[5].uav[1]) == (rows[5]["uav_x"], rows[5]["uav_y"])
    with pytest.raises(ValueError, match="not before the run's last step"):
        belief_states(setup, "paper", 5, [0], [8])


def test_score_state_rows():
    setup = UAVSetup.from_config(_short())
    state = belief_states(setup, "paper", 5, [0], [3])[0]
    methods = uav_methods.from_config(METHODS)
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
    rows = score_state(state, setup, uav_methods.from_config(METHODS), SCORING, 5)
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


MAP_CFG = {"rows": {"key": "sensor.footprint_radius"}, "cols": {"key": "target.q"}}
EMPTY_REGRET = pd.DataFrame(columns=REGRET_COLUMNS).astype({"model": str})
EMPTY_SUMMARY = pd.DataFrame(columns=dec.UAV_SUMMARY_COLUMNS).astype({"method": str})


def _map_claims(runs: pd.DataFrame) -> dict:
    m = dec.summarize_map(runs, pd.DataFrame(columns=REGRET_COLUMNS), MAP_CFG, 1, 500)
    groups = dec.summarize_map_groups(runs, m, 1, 500)
    claims = dec_claims.uav_claims(EMPTY_REGRET, EMPTY_SUMMARY, m, groups, 1, 500)
    return m, groups, {c.id: c for c in claims}


@pytest.mark.parametrize(
    "shift, verdict", [(-2.0, "supported"), (2.0, "not supported"), (0.0, "inconclusive")]
)
def test_map_claim_rule(shift, verdict):
    m, groups, claims = _map_claims(_map_runs(shift))
    assert len(m) == 2 and (m["n_runs"] == 40).all()
    if shift:
        assert ((m["mean_diff"] - shift).abs() < 0.3).all()
    assert claims["DEC-8a"].verdict == verdict  # the footprint cell
    assert claims["DEC-8b"].verdict == verdict  # the unlimited cell
    for cid, limited in (("DEC-8a", True), ("DEC-8b", False)):
        key = claims[cid].key
        g = groups[groups["limited"] == limited].iloc[0]
        assert key.reproducible == "statistical" and key.null == 0.0 and key.unit == "m"
        assert (key.value, key.ci_low, key.ci_high) == (g["mean_diff"], g["ci_low"], g["ci_high"])
        assert key.ci_low <= key.value <= key.ci_high
        assert not claims[cid].dropped  # one comparison only: nothing left out


def test_map_group_needs_every_cell():
    """One footprint cell clearly better, another no different: the group's mean is
    significantly below 0, but not every cell is, so the verdict is inconclusive."""
    runs = pd.concat([_map_runs(-2.0), _map_runs(0.0).assign(cell=lambda d: d["cell"] + "x")])
    runs.loc[runs["cell"] == "r0c0x", "row_value"] = 120.0  # a second limited cell
    runs = runs[runs["cell"] != "r1c0x"]
    _, groups, claims = _map_claims(runs)
    g = groups[groups["limited"]].iloc[0]
    assert g["n_cells"] == 2 and g["n_below"] == 1 and g["ci_high"] < 0
    assert claims["DEC-8a"].verdict == "inconclusive"
    # the group mean is the mean over cells of the per-run differences
    d = [dec.paired_errors(runs, c, "rsmhp_nt100") for c in ("r1c0", "r0c0x")]
    assert g["mean_diff"] == pytest.approx(float(pd.concat(d, axis=1).mean(axis=1).mean()))


def test_map_group_drops_other_comparisons_by_name():
    runs = _map_runs(-2.0)
    extra = runs[runs["method"] == "rsmhp_nt100"].assign(method="rsmhp_nt250")
    _, groups, claims = _map_claims(pd.concat([runs, extra]))
    assert set(groups["comparison"]) == {"rsmhp_nt100 − nbo", "rsmhp_nt250 − nbo"}
    assert "rsmhp_nt250" in claims["DEC-8a"].dropped  # the first N_T is the evidence
    assert "N_T=100" in claims["DEC-8a"].claim


def _regret_rows(spec: dict, n_runs: int = 10, seed: int = 2) -> pd.DataFrame:
    """Synthetic regret rows: ``spec[model] = (nbo mean, RS-MHP mean, sd)`` of the relative
    regret, drawn independently per belief state (10 runs x 2 steps)."""
    rng = np.random.default_rng(seed)
    rows = []
    for model, (nbo_reg, rs_reg, sd) in spec.items():
        for run in range(n_runs):
            for step in (0, 5):
                for method, reg in (("nbo", nbo_reg), ("rsmhp_nt100", rs_reg)):
                    rel = abs(rng.normal(reg, sd))
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
                            "spearman_random": 0.9
                            if method != "nbo" or model == "paper"
                            else np.nan,
                            "spearman_local": 0.8,
                            "n_eval": 4000,
                        }
                    )
    return pd.DataFrame(rows, columns=REGRET_COLUMNS)


def _regret_claims(spec: dict) -> dict:
    df = _regret_rows(spec)
    summary = dec.summarize_uav_regret(df, 1, 500)
    empty = pd.DataFrame(columns=dec.MAP_GROUP_COLUMNS)
    claims = dec_claims.uav_claims(df, summary, pd.DataFrame(), empty, 1, 500)
    return {c.id: c for c in claims}


def test_regret_summary_and_claims():
    df = _regret_rows({"paper": (0.001, 0.001, 0.0002), "fp150": (0.05, 0.001, 0.01)})
    summary = dec.summarize_uav_regret(df, 1, 500)
    assert len(summary) == 4 and (summary["n_states"] == 20).all()
    # NBO's cost constant at every fp150 state: the correlation is undefined and counted
    fp = summary[(summary.model == "fp150") & (summary.method == "nbo")].iloc[0]
    assert np.isnan(fp["spearman_random"]) and fp["spearman_random_undefined"] == 20
    c = _regret_claims({"paper": (0.001, 0.001, 0.0002), "fp150": (0.05, 0.001, 0.01)})
    assert c["DEC-6"].verdict == "supported"  # NBO within the margin of RS-MHP
    assert c["DEC-7-fp150"].verdict == "supported"  # RS-MHP decides better with the footprint
    k6, k7 = c["DEC-6"].key, c["DEC-7-fp150"].key
    assert k6.unit == k7.unit == "pp" and k6.reproducible == k7.reproducible == "statistical"
    assert k6.null is None  # an equivalence claim has no single opposite value
    assert k7.null == 0.0
    g = df[df.model == "fp150"].pivot_table(
        index=["run", "step"], columns="method", values="regret_rel"
    )
    d = g["nbo"] - g["rsmhp_nt100"]
    assert k7.value == pytest.approx(100 * d.mean())  # percentage points
    assert k7.ci_low < k7.value < k7.ci_high


@pytest.mark.parametrize(
    "nbo, rs, sd, verdict",
    [
        (0.010, 0.010, 0.0005, "supported"),  # equal: CI well inside ±0.5 pp
        (0.030, 0.010, 0.0005, "not supported"),  # 2 pp apart: CI outside the margin
        (0.015, 0.010, 0.0020, "inconclusive"),  # 0.5 pp apart: CI straddles the margin
        (0.010, 0.030, 0.0005, "not supported"),  # NBO better by 2 pp: also not equivalent
    ],
)
def test_dec6_equivalence_rule(nbo, rs, sd, verdict):
    c = _regret_claims({"paper": (nbo, rs, sd)})["DEC-6"]
    assert c.verdict == verdict
    margin = 100 * dec_claims.EQUIVALENCE_MARGIN
    inside = -margin < c.key.ci_low and c.key.ci_high < margin
    assert inside == (verdict == "supported")
    assert f"±{margin:g} percentage points" in c.rule  # the rule prints the constant
    assert c.rule == dec_claims.DEC6_RULE.text()


@pytest.mark.parametrize(
    "nbo, rs, verdict",
    [(0.03, 0.01, "supported"), (0.01, 0.03, "not supported"), (0.01, 0.01, "inconclusive")],
)
def test_dec7_sign_rule(nbo, rs, verdict):
    c = _regret_claims({"paper": (0.01, 0.01, 0.001), "fp": (nbo, rs, 0.002)})["DEC-7-fp"]
    assert c.verdict == verdict


NAN_INF = re.compile(r"\b(nan|inf)\b", re.IGNORECASE)
WHOLE_FLOAT_CELL = re.compile(r"\|\s*[+-]?\d+\.0\s*\|")
SECTION_CFG = {
    "uav": {
        "runs": 10,
        "steps": [0, 5],
        "n_eval": 300,
        "polish": 1,
        "random_starts": 1,
        "eval_maxiter": 15,
        "n_random": 30,
        "models": [{"name": "paper"}, {"name": "fp150", "sensor": {"footprint_radius": 150.0}}],
    },
    "map": {
        "rows": {"key": "sensor.footprint_radius", "values": [None, 150.0]},
        "cols": {"key": "target.q", "values": [1.0]},
        "runs": 40,
        "bootstrap": 500,
        "track_loss_error": 50.0,
        "regret_runs": 1,
        "regret_steps": [0],
    },
}


def _section():
    regret = _regret_rows({"paper": (0.001, 0.001, 0.0002), "fp150": (0.05, 0.001, 0.01)})
    summary = dec.summarize_uav_regret(regret, 1, 500)
    runs = _map_runs(-2.0)
    m = dec.summarize_map(runs, pd.DataFrame(columns=REGRET_COLUMNS), MAP_CFG, 1, 500)
    groups = dec.summarize_map_groups(runs, m, 1, 500)
    tables = dec_text.uav_tables(summary, m)
    section = dec_text.uav_decision_section(regret, summary, m, groups, tables, SECTION_CFG, 1)
    return regret, m, tables, section


def test_section_budget_and_text():
    _, _, tables, section = _section()
    assert len(section.body.encode("utf-8")) <= 2600
    assert [c.id for c in section.claims] == ["DEC-6", "DEC-7-fp150", "DEC-8a", "DEC-8b"]
    for name in dec_text.FIGURES:
        assert f"](figures/{name}.png)" in section.body
    assert not re.search(r"^\|", section.body, re.MULTILINE)  # tables go to the appendix
    for word in ("Relative regret", "percentage points", "N_T", "footprint", "track loss"):
        assert word.lower() in section.body.lower()
    for text in (section.body, section.appendix):
        assert not NAN_INF.search(text)
    assert not re.search(r"(?<![\d.])\d+\.0(?![\d])", section.body)
    assert "{unlimited, 150}" in section.body and "above 50 m" in section.body
    for table in tables.values():
        assert table in section.appendix
        assert not NAN_INF.search(table) and not WHOLE_FLOAT_CELL.search(table)
    # the unlimited footprint and the undefined values are words, explained in the appendix
    assert "| unlimited" in tables["dec_uav_map"] and "'unlimited'" in section.appendix
    assert "undefined" in tables["dec_uav_regret"]  # NBO's constant cost in fp150
    assert "undefined" in tables["dec_uav_map"]  # no open-loop regret states in these cells
    assert re.search(r"\|\s+40 \|", tables["dec_uav_map"])  # runs as an integer


def test_claims_fit_the_ledger():
    _, _, _, section = _section()
    rules = {
        "DEC-6": dec_claims.DEC6_RULE,
        "DEC-7-fp150": dec_claims.DEC7_RULE,
        "DEC-8a": dec_claims.DEC8_RULE,
        "DEC-8b": dec_claims.DEC8_RULE,
    }
    for c in section.claims:
        assert len(c.claim) <= 120 and len(c.paper) <= 150 and len(c.rule) <= 300, c.id
        assert c.rule == rules[c.id].text()
        assert c.key.reproducible == "statistical" and c.key.has_ci
        for text in (c.claim, c.paper, c.key.text(), c.measured, c.dropped):
            assert not NAN_INF.search(text)


def test_axis_values_in_words():
    assert dec.axis_value("sensor.footprint_radius", None) == "unlimited"
    assert dec.axis_value("sensor.footprint_radius", float("nan")) == "unlimited"
    assert dec.axis_value("sensor.footprint_radius", 150.0) == "150"
    assert dec.axis_value("target.q", 0.25) == "0.25"
    assert dec.axis_label("target.q") == "target manoeuvrability q (m²/s³)"


def test_figures_use_the_palette_and_label_units():
    regret, m, _, _ = _section()
    fig = figs.uav_regret_figure(regret)
    try:
        seen = set()
        for ax in fig.axes:
            assert ax.get_yscale() == "log" and "(%" in ax.get_ylabel()
            assert "drawn at" in ax.get_title()  # the floor's clipping is counted
            for coll in ax.collections:
                if coll.get_gid():
                    assert to_hex(coll.get_facecolor()[0]) == method_colour(coll.get_gid())
                    seen.add(coll.get_gid())
        assert seen == {"nbo", "rsmhp_nt100"}
    finally:
        plt.close(fig)
    fig = figs.uav_map_figure(m)
    try:
        labels = [ax.get_ylabel() for ax in fig.axes]
        assert any("mean paired difference" in lab and "(m)" in lab for lab in labels)
        heat = fig.axes[0]
        assert heat.get_ylabel() == "footprint radius (m)"
        assert "unlimited" in [t.get_text() for t in heat.get_yticklabels()]
        assert heat.get_xlabel() == "target manoeuvrability q (m²/s³)"
    finally:
        plt.close(fig)


def test_limited_cells_follow_the_axis_else_the_base_sensor():
    m = pd.DataFrame(
        {
            "row_key": ["sensor.footprint_radius"] * 2 + ["target.q"] * 2,
            "row_value": [None, 150.0, 1.0, 4.0],
            "col_key": ["target.q"] * 2 + ["tracker.p0_pos_sd"] * 2,
            "col_value": [1.0, 1.0, 10.0, 50.0],
        }
    )
    assert dec.limited_cells(m).tolist() == [False, True, False, False]
    # a base footprint applies where no axis sets the radius; a null axis value overrides it
    assert dec.limited_cells(m, base_limited=True).tolist() == [False, True, True, True]


@pytest.mark.parametrize(
    "lo, hi, verdict",
    [
        (-0.49, 0.49, "supported"),  # inside ±0.5 pp
        (-0.5, 0.2, "inconclusive"),  # touches the margin: not inside
        (0.2, 0.5, "inconclusive"),
        (0.4, 0.6, "inconclusive"),  # straddles it
        (-0.6, 0.6, "inconclusive"),  # wider than the margin on both sides
        (0.5, 0.9, "not supported"),  # entirely at or beyond +0.5 pp
        (-0.9, -0.5, "not supported"),
    ],
)
def test_dec6_rule_boundaries(lo, hi, verdict):
    facts = {f"{dec_claims.KEY}_low": lo, f"{dec_claims.KEY}_high": hi}
    assert dec_claims.DEC6_RULE.verdict(facts) == verdict


@pytest.mark.parametrize(
    "lo, hi, verdict",
    [
        (1e-12, 1.0, "supported"),
        (0.0, 1.0, "inconclusive"),  # touches 0
        (-1.0, 0.0, "inconclusive"),
        (-1.0, -1e-12, "not supported"),
    ],
)
def test_dec7_rule_boundaries(lo, hi, verdict):
    facts = {f"{dec_claims.KEY}_low": lo, f"{dec_claims.KEY}_high": hi}
    assert dec_claims.DEC7_RULE.verdict(facts) == verdict


@pytest.mark.parametrize(
    "below, above, lo, hi, verdict",
    [
        (2, 0, -1.0, -1e-12, "supported"),  # every cell and the pooled mean below 0
        (2, 0, -1.0, 0.0, "inconclusive"),  # the pooled CI touches 0
        (1, 0, -1.0, -0.5, "inconclusive"),  # one cell undecided
        (1, 1, -1.0, -0.5, "not supported"),  # one cell above 0
        (0, 0, 1e-12, 1.0, "not supported"),  # the pooled mean above 0
        (0, 0, 0.0, 1.0, "inconclusive"),
    ],
)
def test_dec8_rule_boundaries(below, above, lo, hi, verdict):
    group = pd.Series(
        {"n_cells": 2, "n_below": below, "n_above": above, "ci_low": lo, "ci_high": hi}
    )
    assert dec_claims.DEC8_RULE.verdict(dec_claims.map_facts(group)) == verdict
