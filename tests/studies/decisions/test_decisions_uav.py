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

from rsmhp.models.uav import methods as uav_methods
from rsmhp.models.uav.scoring import (
    MAP_RUN_COLUMNS,
    REGRET_COLUMNS,
    belief_states,
    map_cells,
    merge_variant,
    run_map_cell,
    score_state,
)
from rsmhp.models.uav.simulation import UAVSetup, draw_scenario, simulate_run
from rsmhp.pipeline.config import check_config
from rsmhp.report.ledger import KeyNumber
from rsmhp.report.palette import method_colour
from rsmhp.studies.decisions import claims_uav as dec_claims
from rsmhp.studies.decisions import figures as figs
from rsmhp.studies.decisions import section_uav as dec_text
from rsmhp.studies.decisions import summarise_uav as dec

ROOT = Path(__file__).resolve().parents[3]
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


def test_every_family_is_scored_open_loop():
    """The point-set planners and the tree search go through the same scoring; the tree
    search has no cost of an arbitrary plan, so its rank columns are NaN."""
    setup = UAVSetup.from_config(_short())
    state = belief_states(setup, "paper", 5, [0], [3])[0]
    block = {
        "nbo": True,
        "rqmc_nt": [16],
        "antithetic_nt": [16],
        "sigma": True,
        "dpw": [{"sims": 50}],
    }
    methods = uav_methods.from_config(block)
    rows = score_state(state, setup, methods, SCORING, 5)
    assert [r["method"] for r in rows] == [
        "nbo",
        "rqmc_nt16",
        "antithetic_nt16",
        "sigma",
        "dpw_s50",
    ]
    for r in rows:
        assert set(r) == set(REGRET_COLUMNS)
        assert r["regret"] >= -1e-9 * r["best_cost"] and np.isfinite(r["eval_cost"])
        if r["family"] == "dpw":
            assert np.isnan(r["spearman_random"]) and np.isnan(r["spearman_local"])
        else:
            assert -1 <= r["spearman_random"] <= 1


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


#: the ``decisions.claims`` config of the tests (the schema's defaults)
CLAIM_RULES = {"equivalence_margin_pp": 0.1, "map_method": ""}


def _map_claims(
    runs: pd.DataFrame, rules=CLAIM_RULES, cfg=MAP_CFG, base_limited: bool = False
) -> tuple:
    m = dec.summarize_map(runs, pd.DataFrame(columns=REGRET_COLUMNS), cfg, 1, 500)
    groups = dec.summarize_map_groups(runs, m, 1, 500, base_limited)
    claims = dec_claims.uav_claims(
        EMPTY_REGRET, EMPTY_SUMMARY, m, groups, rules, 1, 500, base_limited
    )
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
        assert claims[cid].part == "beyond" and "UAV sensitivity map" in claims[cid].setup
        # the cells whose CI lies above 0 (RS-MHP worse) are named as contrary, and only then
        cell = "footprint radius (m) 150" if limited else "footprint radius (m) unlimited"
        assert (cell in claims[cid].contrary) == (verdict == "not supported")
    assert "cells with a footprint" in claims["DEC-8a"].setup
    assert "cells without a footprint" in claims["DEC-8b"].setup


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
    assert "N_T=250" in claims["DEC-8a"].dropped  # the first N_T is the evidence
    assert "N_T=100" in claims["DEC-8a"].claim


def _two_members() -> pd.DataFrame:
    """NBO, RS-MHP N_T=100 (2 m better than NBO) and N_T=250 (1 m worse) in both cells."""
    runs = _map_runs(-2.0)
    worse = runs[runs["method"] == "rsmhp_nt100"].assign(
        method="rsmhp_nt250", mean_error=lambda d: d["mean_error"] + 3.0
    )
    return pd.concat([runs, worse])


@pytest.mark.parametrize(
    "method, compared, verdict",
    [
        ("", "rsmhp_nt100", "supported"),  # empty: the first RS-MHP member of the map
        ("rsmhp_nt100", "rsmhp_nt100", "supported"),
        ("rsmhp_nt250", "rsmhp_nt250", "not supported"),
    ],
)
def test_dec8_compares_the_configured_map_method(method, compared, verdict):
    m, groups, claims = _map_claims(_two_members(), {**CLAIM_RULES, "map_method": method})
    other = ({"rsmhp_nt100", "rsmhp_nt250"} - {compared}).pop()
    for cid, limited in (("DEC-8a", True), ("DEC-8b", False)):
        c = claims[cid]
        assert c.verdict == verdict
        g = groups[(groups["limited"] == limited) & (groups["comparison"] == f"{compared} − nbo")]
        assert (c.key.value, c.key.ci_low, c.key.ci_high) == tuple(
            g.iloc[0][["mean_diff", "ci_low", "ci_high"]]
        )
        assert f"N_T={compared[len('rsmhp_nt') :]}" in c.claim
        assert f"N_T={other[len('rsmhp_nt') :]}" in c.dropped
        # N_T=250 is worse than NBO in every cell: named as contrary whichever is compared
        assert "RS-MHP N_T=250 − NBO = +" in c.contrary
        assert "RS-MHP N_T=100 − NBO" not in c.contrary
        assert "decisions.claims.map_method" in c.measured
    assert dec_claims.map_comparison(m, method) == (f"{compared} − nbo", [other])


def test_a_map_method_not_in_the_map_is_refused():
    runs = _two_members()
    for name in ("rsmhp_nt999", "nbo"):  # not run; the baseline is no comparison
        with pytest.raises(ValueError, match=r"decisions\.claims\.map_method = '" + name):
            _map_claims(runs, {**CLAIM_RULES, "map_method": name})
    m, _, _ = _map_claims(runs)
    with pytest.raises(ValueError, match=r"allowed: rsmhp_nt100, rsmhp_nt250"):
        dec_claims.map_comparison(m, "rsmhp_nt999")
    # a map without an RS-MHP comparison gives no DEC-8 by default
    tree = m.assign(comparison=m["comparison"].str.replace("rsmhp_nt", "tree_n8_m"))
    assert dec_claims.map_comparison(tree) is None
    # and the config check refuses it before any run, naming the field
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    assert cfg["decisions"]["claims"]["map_method"] == "rsmhp_nt100"
    check_config(cfg)
    cfg["decisions"]["claims"]["map_method"] = "rsmhp_nt999"
    with pytest.raises(ValueError, match=r"decisions\.claims\.map_method: 'rsmhp_nt999'"):
        check_config(cfg)


def test_map_contrary_names_cells_whose_ci_lies_above_zero():
    m = pd.DataFrame(
        {
            "row_key": ["sensor.footprint_radius"] * 5,
            "row_value": [150.0, 120.0, 300.0, 200.0, None],
            "col_key": ["target.q"] * 5,
            "col_value": [1.0, 4.0, 16.0, 0.25, 1.0],
            "comparison": ["rsmhp_nt100 − nbo"] * 4 + ["rsmhp_nt250 − nbo"],
            "mean_diff": [0.5, 0.2, -0.3, 0.4, 0.9],
            "ci_low": [0.1, -0.1, -0.5, 0.0, 0.6],
            "ci_high": [0.9, 0.5, -0.1, 0.8, 1.2],
        }
    )
    limited = dec.limited_cells(m)
    text = dec_claims.map_contrary(m, limited, True, "rsmhp_nt100")
    assert "footprint radius (m) 150, target manoeuvrability q (m²/s³) 1:" in text  # above 0
    assert "RS-MHP N_T=100 − NBO = +0.5" in text
    assert "footprint radius (m) 120" not in text  # the CI contains 0
    assert "footprint radius (m) 300" not in text  # below 0: RS-MHP better
    assert "footprint radius (m) 200" not in text  # the CI touches 0: not above it
    assert "unlimited" not in text  # the other group
    assert text.count(";") == 0  # one cell named
    other = dec_claims.map_contrary(m, limited, False, "rsmhp_nt100")
    assert other.startswith("footprint radius (m) unlimited") and "N_T=250" in other
    assert dec_claims.map_contrary(m.assign(ci_low=-1.0), limited, True, "rsmhp_nt100") == ""


def test_base_limited_decides_the_group_of_cells_without_a_footprint_axis():
    """A map over q and the initial sd: every cell has the base config's sensor, so all of
    them are DEC-8a (base footprint) or all DEC-8b, contrary cells included."""
    runs = _map_runs(2.0).assign(row_value=lambda d: d["cell"].map({"r0c0": 1.0, "r1c0": 4.0}))
    cfg = {"rows": {"key": "target.q"}, "cols": {"key": "tracker.p0_pos_sd"}}
    for base_limited, cid in ((True, "DEC-8a"), (False, "DEC-8b")):
        _, _, claims = _map_claims(runs, cfg=cfg, base_limited=base_limited)
        assert list(claims) == [cid]
        assert claims[cid].verdict == "not supported"
        assert claims[cid].contrary.count("target manoeuvrability q (m²/s³)") == 2


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


def _regret_claims(spec: dict, rules=CLAIM_RULES) -> dict:
    df = _regret_rows(spec)
    summary = dec.summarize_uav_regret(df, 1, 500)
    empty = pd.DataFrame(columns=dec.MAP_GROUP_COLUMNS)
    claims = dec_claims.uav_claims(df, summary, pd.DataFrame(), empty, rules, 1, 500)
    return {c.id: c for c in claims}


def _holds(verdict: str, lo: float, hi: float, margin: float) -> bool:
    """Whether the CI [lo, hi] (pp) meets the condition of ``verdict`` under regret_rule."""
    inside = -margin < lo and hi < margin
    return {
        "equivalent": inside,
        "supported": not inside and lo > 0,
        "not supported": not inside and hi < 0,
        "inconclusive": not inside and lo <= 0 <= hi,
    }[verdict]


def test_regret_summary_and_claims():
    df = _regret_rows({"paper": (0.001, 0.001, 0.0002), "fp150": (0.05, 0.001, 0.01)})
    summary = dec.summarize_uav_regret(df, 1, 500)
    assert len(summary) == 4 and (summary["n_states"] == 20).all()
    # NBO's cost constant at every fp150 state: the correlation is undefined and counted
    fp = summary[(summary.model == "fp150") & (summary.method == "nbo")].iloc[0]
    assert np.isnan(fp["spearman_random"]) and fp["spearman_random_undefined"] == 20
    c = _regret_claims({"paper": (0.001, 0.001, 0.0002), "fp150": (0.05, 0.001, 0.01)})
    assert c["DEC-6"].verdict == "equivalent"  # NBO within ±0.1 pp of RS-MHP
    assert c["DEC-7-fp150"].verdict == "supported"  # RS-MHP decides better with the footprint
    k6, k7 = c["DEC-6"].key, c["DEC-7-fp150"].key
    assert k6.unit == k7.unit == "pp" and k6.reproducible == k7.reproducible == "statistical"
    assert k6.null == k7.null == 0.0  # both the same directional claim
    assert -0.1 < k6.ci_low and k6.ci_high < 0.1
    assert c["DEC-6"].part == "paper" and c["DEC-7-fp150"].part == "beyond"
    assert c["DEC-6"].setup.startswith("UAV reconstruction 'paper'")
    assert c["DEC-7-fp150"].setup.startswith("UAV variant 'fp150'")
    g = df[df.model == "fp150"].pivot_table(
        index=["run", "step"], columns="method", values="regret_rel"
    )
    d = g["nbo"] - g["rsmhp_nt100"]
    assert k7.value == pytest.approx(100 * d.mean())  # percentage points
    assert k7.ci_low < k7.value < k7.ci_high


@pytest.mark.parametrize(
    "nbo, rs, sd, verdict",
    [
        (0.010, 0.010, 0.0005, "equivalent"),  # equal: CI well inside ±0.1 pp
        (0.0106, 0.010, 0.0002, "equivalent"),  # CI above 0 yet inside ±0.1 pp: negligible
        (0.030, 0.010, 0.0005, "supported"),  # RS-MHP 2 pp better
        (0.010, 0.030, 0.0005, "not supported"),  # NBO 2 pp better
        (0.010, 0.010, 0.0020, "inconclusive"),  # CI contains 0 and leaves ±0.1 pp
    ],
)
def test_dec6_directional_rule_with_margin(nbo, rs, sd, verdict):
    c = _regret_claims({"paper": (nbo, rs, sd)})["DEC-6"]
    assert c.verdict == verdict
    assert _holds(verdict, c.key.ci_low, c.key.ci_high, 0.1)
    assert c.rule == dec_claims.regret_rule(0.1, "the reconstruction").text()
    assert "inside ±0.1 pp" in c.rule and "entirely above 0" in c.rule  # the margin is printed
    assert "±0.1 pp fixed in the config" in c.measured


@pytest.mark.parametrize(
    "nbo, rs, sd, verdict",
    [
        (0.03, 0.01, 0.002, "supported"),
        (0.01, 0.03, 0.002, "not supported"),
        (0.01, 0.01, 0.002, "inconclusive"),
        (0.01, 0.01, 0.0005, "equivalent"),
    ],
)
def test_dec7_is_the_same_claim_on_a_variant(nbo, rs, sd, verdict):
    c = _regret_claims({"paper": (0.01, 0.01, 0.001), "fp": (nbo, rs, sd)})["DEC-7-fp"]
    assert c.verdict == verdict
    assert _holds(verdict, c.key.ci_low, c.key.ci_high, 0.1)
    assert c.rule == dec_claims.regret_rule(0.1, "the model variant").text()
    assert c.part == "beyond" and "chooses better plans than NBO" in c.claim


def test_the_margin_comes_from_the_config():
    """RS-MHP 2 pp better: supported with the default margin, equivalent within ±5 pp."""
    spec = {"paper": (0.03, 0.01, 0.0005), "fp": (0.03, 0.01, 0.0005)}
    assert {c.verdict for c in _regret_claims(spec).values()} == {"supported"}
    wide = _regret_claims(spec, {**CLAIM_RULES, "equivalence_margin_pp": 5})
    for c in wide.values():
        assert c.verdict == "equivalent" and "±5 pp" in c.rule and 0 < c.key.ci_low
    with pytest.raises(ValueError, match="margin must be a number > 0"):
        _regret_claims(spec, {**CLAIM_RULES, "equivalence_margin_pp": 0})


@pytest.mark.parametrize("margin", [0.1, 0.3])
def test_regret_key_numbers_carry_their_belief_states_and_the_rules_margin(margin):
    """DEC-6/DEC-7: ``n`` is the number of belief states scored for both NBO and RS-MHP (the
    pairs the bootstrap resamples), counted in the input; ``margin`` the rule's ±m."""
    spec = {"paper": (0.03, 0.01, 0.0005), "fp": (0.01, 0.01, 0.002)}
    df = _regret_rows(spec, n_runs=7)
    summary = dec.summarize_uav_regret(df, 1, 500)
    empty = pd.DataFrame(columns=dec.MAP_GROUP_COLUMNS)
    rules = {**CLAIM_RULES, "equivalence_margin_pp": margin}
    claims = {c.id: c for c in dec_claims.uav_claims(df, summary, pd.DataFrame(), empty, rules,
                                                     1, 500)}  # fmt: skip
    assert set(claims) == {"DEC-6", "DEC-7-fp"}
    for cid, model in (("DEC-6", "paper"), ("DEC-7-fp", "fp")):
        g = df[df["model"] == model].groupby(["run", "step"])["method"].apply(set)
        states = int(sum({"nbo", "rsmhp_nt100"} <= m for m in g))
        c = claims[cid]
        assert states == 14 and c.key.n == states and f"{states} belief states" in c.measured
        assert c.key.margin == margin and f"±{margin:g} pp" in c.rule
        assert c.key.null == 0.0 and not c.check


def test_map_key_numbers_carry_no_n_and_name_the_runs_paired_in_every_cell():
    """DEC-8a/b: the rule needs every cell of the group, so no one number of runs decides it
    and the key number carries no ``n`` (no runs at 80% power); the measured text names the
    runs paired in every cell, counted in the input; DEC8_RULE has no margin."""
    runs = _map_runs(-2.0)
    drop = (
        (runs["cell"] == "r1c0") & (runs["method"] == "rsmhp_nt100") & runs["run"].isin([3, 11])
    ) | ((runs["cell"] == "r0c0") & (runs["method"] == "nbo") & (runs["run"] == 5))
    runs = runs[~drop]
    _, _, claims = _map_claims(runs)
    for cid, cell, expected in (("DEC-8a", "r1c0", 38), ("DEC-8b", "r0c0", 39)):
        g = runs[runs["cell"] == cell].groupby("run")["method"].nunique()
        paired = int((g == 2).sum())
        c = claims[cid]
        assert c.key.n is None and not c.check and c.key.margin is None
        assert paired == expected and f"{paired} paired runs per cell" in c.measured


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
    "claims": {"equivalence_margin_pp": 0.1, "map_method": "rsmhp_nt100"},
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
    assert "| unlimited" in tables["decisions_uav_map"] and "'unlimited'" in section.appendix
    assert "undefined" in tables["decisions_uav_regret"]  # NBO's constant cost in fp150
    assert "undefined" in tables["decisions_uav_map"]  # no open-loop regret states in these cells
    assert re.search(r"\|\s+40 \|", tables["decisions_uav_map"])  # runs as an integer


def test_claims_fit_the_ledger():
    _, _, _, section = _section()
    rules = {
        "DEC-6": dec_claims.regret_rule(0.1, "the reconstruction"),
        "DEC-7-fp150": dec_claims.regret_rule(0.1, "the model variant"),
        "DEC-8a": dec_claims.DEC8_RULE,
        "DEC-8b": dec_claims.DEC8_RULE,
    }
    for c in section.claims:
        # the claim carries its scope (220); DEC-8's rule names its config field (343)
        assert len(c.claim) <= 220 and len(c.paper) <= 150 and len(c.rule) <= 450, c.id
        assert c.rule == rules[c.id].text()
        assert c.key.reproducible == "statistical" and c.key.has_ci
        assert c.part == ("paper" if c.id == "DEC-6" else "beyond") and c.setup.strip()
        for text in (c.claim, c.paper, c.key.text(), c.measured, c.dropped, c.contrary):
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


REGRET_RULE_FACTS = [  # margin 0.5 pp
    (-0.49, 0.49, "equivalent"),  # inside ±0.5 pp
    (0.01, 0.49, "equivalent"),  # above 0 yet inside the margin: a negligible difference
    (-0.49, -0.01, "equivalent"),
    (0.0, 0.4, "equivalent"),  # at 0, inside the margin
    (-0.5, 0.2, "inconclusive"),  # touches -m: not inside; contains 0
    (-0.6, 0.6, "inconclusive"),  # wider than the margin on both sides
    (0.0, 0.5, "inconclusive"),  # exactly at 0 and touching +m
    (-1.0, 0.0, "inconclusive"),  # exactly at 0 from below
    (0.2, 0.5, "supported"),  # touches +m: not inside; above 0
    (0.4, 0.6, "supported"),  # straddles +m, above 0
    (1e-12, 1.0, "supported"),
    (-0.9, -0.5, "not supported"),  # touches -m from outside
    (-1.0, -1e-12, "not supported"),
]


@pytest.mark.parametrize("lo, hi, verdict", REGRET_RULE_FACTS)
def test_regret_rule_boundaries(lo, hi, verdict):
    facts = {f"{dec_claims.KEY}_low": lo, f"{dec_claims.KEY}_high": hi}
    rule = dec_claims.regret_rule(0.5, "the reconstruction")
    assert rule.verdict(facts) == verdict
    # the same facts from a key number with that CI (as DEC-6/DEC-7 build them)
    key = KeyNumber("d", (lo + hi) / 2, lo, hi, unit="pp", reproducible="statistical")
    assert rule.verdict(dec_claims.ci_facts(key)) == verdict


def test_regret_rule_gives_each_of_its_verdicts():
    rule = dec_claims.regret_rule(0.5, "the model variant")
    assert rule.verdicts == ("equivalent", "supported", "not supported", "inconclusive")
    assert {v for _, _, v in REGRET_RULE_FACTS} == set(rule.verdicts)
    assert "±0.5 pp" in rule.text() and "the model variant" in rule.text()
    with pytest.raises(ValueError, match="margin must be a number > 0"):
        dec_claims.regret_rule(0.0, "the reconstruction")


DEC8_FACTS = [
    (2, 0, -1.0, -1e-12, "supported"),  # every cell and the pooled mean below 0
    (2, 0, -1.0, 0.0, "inconclusive"),  # the pooled CI touches 0
    (1, 0, -1.0, -0.5, "inconclusive"),  # one cell undecided
    (1, 1, -1.0, -0.5, "not supported"),  # one cell above 0
    (0, 0, 1e-12, 1.0, "not supported"),  # the pooled mean above 0
    (0, 0, 0.0, 1.0, "inconclusive"),
]


@pytest.mark.parametrize("below, above, lo, hi, verdict", DEC8_FACTS)
def test_dec8_rule_boundaries(below, above, lo, hi, verdict):
    group = pd.Series(
        {"n_cells": 2, "n_below": below, "n_above": above, "ci_low": lo, "ci_high": hi}
    )
    assert dec_claims.DEC8_RULE.verdict(dec_claims.map_facts(group)) == verdict


def test_dec8_rule_gives_each_of_its_verdicts():
    assert {f[-1] for f in DEC8_FACTS} == set(dec_claims.DEC8_RULE.verdicts)
    assert "decisions.claims.map_method" in dec_claims.DEC8_RULE.text()
