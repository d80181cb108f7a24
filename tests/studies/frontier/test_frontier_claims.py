"""Equal-compute claims FR-1..3 (rsmhp.studies.frontier.claims) and their statistics
(rsmhp.studies.frontier.summarise: paired differences, the budget check, the recorded run's choice).

Oracles: paired differences computed by hand from tables with known offsets; every verdict
equals its printed rule applied to the key number's CI, and flips when the data cross the
rule's boundary; the budget check against hand-picked times; the run choice per rule against
an explicit vector of differences.
"""

from __future__ import annotations

import copy
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from rsmhp.report.markdown import fmt
from rsmhp.studies.frontier.claims import KEY, fr1_rule, fr2_rule, fr3_rule, frontier_claims
from rsmhp.studies.frontier.summarise import (
    budget_check,
    paired_difference,
    select_run,
    summarize_frontier,
)

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())

#: method -> (family, closed-loop error offset m, regret offset (fraction), ms per step)
METHODS = {
    "nbo": ("nbo", 0.0, 0.0, 0.05),
    "rsmhp_nt16": ("rsmhp", -1.0, -0.002, 0.30),
    "rsmhp_nt64": ("rsmhp", -1.2, -0.0025, 0.40),
    "rqmc_nt16": ("rqmc", -1.1, -0.0025, 0.60),
    "sigma": ("sigma", -0.9, 0.001, 0.20),
    "dpw_s30": ("dpw", -3.0, 0.03, 0.45),
}
N_RUNS, N_STATES = 12, 40  # 20 runs of 2 belief states in the regret table


def _tables(methods=METHODS, noise: float = 0.05):
    """Runs and regret tables of one model 'm': per method its offset plus noise that is
    shared by all methods (the pairing removes it) and a small method-specific part."""
    rng = np.random.default_rng(7)
    common_e = rng.normal(20.0, 5.0, N_RUNS)
    common_r = rng.uniform(0.01, 0.05, N_STATES)
    runs, regret = [], []
    for method, (fam, de, dr, ms) in methods.items():
        own_e = noise * rng.standard_normal(N_RUNS)
        own_r = 0.01 * noise * rng.standard_normal(N_STATES)
        for r in range(N_RUNS):
            runs.append(
                {"model": "m", "method": method, "family": fam, "N_T": 0, "N": 0, "M": 0,
                 "run": r, "mean_error": common_e[r] + de + own_e[r], "final_error": 1.0,
                 "detect_rate": 1.0, "lost": False, "plan_ms": ms}
            )  # fmt: skip
        for k in range(N_STATES):
            regret.append({"model": "m", "run": k // 2, "step": k % 2, "method": method,
                           "regret_rel": common_r[k] + dr + own_r[k]})  # fmt: skip
    return pd.DataFrame(runs), pd.DataFrame(regret)


def _cfg(members=("rsmhp_nt16", "rqmc_nt16", "sigma", "dpw_s30"), budget=0.5, **claims):
    return {
        "models": ["m"],
        "bootstrap": 2000,
        "budget": {"ms_per_step": budget, "members": list(members)},
        "claims": {"margin_pp": 0.1, "margin_m": 0.25, "sigma_reference": "rsmhp_nt16", **claims},
    }


def _claims(cfg=None, tables=None):
    runs, regret = tables if tables is not None else _tables()
    summary = summarize_frontier(runs, regret)
    return {c.id: c for c in frontier_claims(runs, regret, summary, cfg or _cfg(), seed=11)}


# ---------------------------------------------------------------------------- statistics


def test_paired_difference_is_the_mean_of_the_pairs():
    runs, regret = _tables()
    w = runs.pivot(index="run", columns="method", values="mean_error")
    d = paired_difference(runs, "m", "dpw_s30", "rsmhp_nt16", "error", seed=3, n_boot=2000)
    want = (w["dpw_s30"] - w["rsmhp_nt16"]).to_numpy()
    assert d.n == N_RUNS and d.mean == pytest.approx(want.mean(), abs=1e-12)
    assert want.min() <= d.low <= d.mean <= d.high <= want.max()
    g = regret.pivot_table(index=["run", "step"], columns="method", values="regret_rel")
    p = paired_difference(regret, "m", "sigma", "rsmhp_nt16", "regret", seed=3, n_boot=2000)
    assert p.n == N_STATES
    assert p.mean == pytest.approx(100 * (g["sigma"] - g["rsmhp_nt16"]).mean(), abs=1e-12)
    # the shared noise (sd 1.15 pp) cancels: d = 0.3 pp + two method-specific parts of sd
    # 0.05 pp each, so SE = 0.0707 / sqrt(10) = 0.022 pp and the CI is about 4 SE wide
    se = 0.05 * np.sqrt(2) / np.sqrt(N_STATES)
    assert abs(p.mean - 0.3) < 4 * se and p.high - p.low < 8 * se
    again = paired_difference(regret, "m", "sigma", "rsmhp_nt16", "regret", seed=3, n_boot=2000)
    assert again == p  # the bootstrap stream is keyed on (model, a, b, measure)


def test_paired_difference_ci_is_the_t_interval_of_the_run_means():
    """Oracle: with the same number of states in every run, the leave-one-run-out jackknife
    of the mean equals Student's t interval of the per-run means (G - 1 df); one value per
    run (closed loop) is Student's t interval itself. The bootstrap CI is kept beside it."""
    from rsmhp.core.stats import mean_ci

    runs, regret = _tables()
    g = regret.pivot_table(index=["run", "step"], columns="method", values="regret_rel")
    per_run = (100 * (g["sigma"] - g["rsmhp_nt16"])).groupby(level="run").mean().to_numpy()
    p = paired_difference(regret, "m", "sigma", "rsmhp_nt16", "regret", seed=3, n_boot=2000)
    m, lo, hi = mean_ci(per_run)
    assert (p.clusters, p.df) == (N_STATES // 2, N_STATES // 2 - 1)
    assert (p.mean, p.low, p.high) == pytest.approx((m, lo, hi), rel=1e-12, abs=1e-12)
    assert p.se == pytest.approx(per_run.std(ddof=1) / np.sqrt(per_run.size), rel=1e-12)
    assert np.isfinite(p.boot_low) and p.boot_low < p.mean < p.boot_high
    w = runs.pivot(index="run", columns="method", values="mean_error")
    d = paired_difference(runs, "m", "dpw_s30", "nbo", "error", seed=3, n_boot=500)
    assert (d.low, d.high) == pytest.approx(mean_ci((w["dpw_s30"] - w["nbo"]).to_numpy())[1:])
    with pytest.raises(ValueError, match="at least 2 runs"):
        paired_difference(regret[regret["run"] == 0], "m", "sigma", "nbo", "regret", 3, 100)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (("nowhere", "sigma", "nbo", "error"), "model: 'nowhere' has no rows"),
        (("m", "sigma", "rsmhp_nt999", "error"), "b: 'rsmhp_nt999' has no error rows"),
        (("m", "sigma", "nbo", "speed"), "measure: 'speed'"),
    ],
)
def test_paired_difference_refuses_bad_input(args, match):
    runs, _ = _tables()
    with pytest.raises(ValueError, match=match):
        paired_difference(runs, *args, seed=1, n_boot=100)


def test_budget_check_against_hand_picked_times():
    runs, regret = _tables()
    summary = summarize_frontier(runs, regret)
    c = budget_check(summary, ["rsmhp_nt16", "rqmc_nt16", "sigma", "dpw_s30"], 0.5)
    c = c.set_index("member")
    assert c.loc["rsmhp_nt16", "fits"] and c.loc["rsmhp_nt16", "largest_fitting"] == "rsmhp_nt64"
    assert c.loc["rsmhp_nt16", "largest_ms"] == pytest.approx(0.40)
    assert not c.loc["rqmc_nt16", "fits"] and c.loc["rqmc_nt16", "largest_fitting"] == ""
    assert c.loc["sigma", "largest_fitting"] == "sigma"
    assert c.loc["dpw_s30", "plan_ms"] == pytest.approx(0.45)
    with pytest.raises(ValueError, match="budget member 'dpw_s999' has no row"):
        budget_check(summary, ["dpw_s999"], 0.5)


def test_select_run_by_each_rule():
    d = np.array([0.0, -5.0, -1.0, 3.0, -1.0, -20.0])  # mean -4, median -1
    rows = []
    for r, x in enumerate(d):
        rows += [{"model": "m", "method": "nbo", "run": r, "mean_error": 10.0},
                 {"model": "m", "method": "a", "run": r, "mean_error": 10.0 + x}]  # fmt: skip
    runs = pd.DataFrame(rows)
    assert select_run(runs, "m", "a", "nbo", "nearest_mean") == (1, -5.0)
    assert select_run(runs, "m", "a", "nbo", "nearest_median") == (2, -1.0)  # tie: lowest run
    assert select_run(runs, "m", "a", "nbo", "largest_gain") == (5, -20.0)
    assert select_run(runs, "m", "a", "nbo", "largest_loss") == (3, 3.0)
    with pytest.raises(ValueError, match=re.escape("frontier.recording.select: 'first'")):
        select_run(runs, "m", "a", "nbo", "first")
    with pytest.raises(ValueError, match="'b' has no runs"):
        select_run(runs, "m", "b", "nbo", "nearest_mean")


# ------------------------------------------------------------------------------- claims


def test_each_verdict_is_its_rule_applied_to_the_key_number():
    claims = _claims()
    assert set(claims) == {"FR-1-m", "FR-2-m", "FR-3-m"}
    rules = {
        "FR-1-m": fr1_rule(0.1),
        "FR-2-m": fr2_rule(0.1, "rsmhp_nt16"),
        "FR-3-m": fr3_rule(0.25),
    }
    for cid, c in claims.items():
        facts = {f"{KEY}_low": c.key.ci_low, f"{KEY}_high": c.key.ci_high}
        assert c.verdict == rules[cid].verdict(facts), cid
        assert c.rule == rules[cid].text()
        assert c.part == "beyond" and c.key.reproducible == "statistical"
    # RQMC − MC regret = -0.05 pp, CI inside ±0.1 pp: equivalent
    assert claims["FR-1-m"].key.value == pytest.approx(-0.05, abs=0.02)
    assert claims["FR-1-m"].verdict == "equivalent"
    # sigma − MC regret = +0.3 pp > 0.1 pp: not non-inferior; the null is the margin
    assert claims["FR-2-m"].verdict == "not supported" and claims["FR-2-m"].key.null == 0.1
    # DPW − MC error = -2 m: better, while its open-loop plans are worse (+3.2 pp): contrary
    assert claims["FR-3-m"].key.value == pytest.approx(-2.0, abs=0.1)
    assert claims["FR-3-m"].verdict == "supported"
    # the open-loop regret (+3 pp) scores plan steps below the tree's depth: reported, not
    # contrary evidence to a closed-loop claim
    assert "open-loop" not in claims["FR-3-m"].contrary
    assert "also those below the tree's depth" in claims["FR-3-m"].measured
    # the p-value behind each verdict: FR-3 supported <=> CI excludes 0 <=> p < 0.05
    for cid in claims:
        assert 0 <= claims[cid].key.p_value <= 1
    assert claims["FR-3-m"].key.p_value < 0.05
    # FR-1 equivalent: both boundaries ±0.1 pp excluded, so p (the larger) < 0.05 too
    assert claims["FR-1-m"].key.p_value < 0.05


def test_verdicts_flip_where_the_data_cross_the_rules():
    m = dict(METHODS)
    m["rqmc_nt16"] = ("rqmc", -1.1, -0.004, 0.60)  # -0.2 pp: outside the margin, below 0
    m["sigma"] = ("sigma", -0.9, -0.0015, 0.20)  # better than MC: non-inferior
    m["dpw_s30"] = ("dpw", 2.0, 0.03, 0.45)  # +3 m: tracks worse
    claims = _claims(tables=_tables(m))
    assert claims["FR-1-m"].verdict == "supported"
    assert claims["FR-2-m"].verdict == "supported"
    assert claims["FR-3-m"].verdict == "not supported" and "worse" not in claims["FR-3-m"].contrary
    # a smaller margin turns FR-1's equivalence of -0.05 pp into "supported" (CI below 0)
    assert _claims(_cfg(margin_pp=0.01))["FR-1-m"].verdict == "supported"


def test_timing_is_reported_never_a_verdict():
    fast, slow = _claims(_cfg(budget=10.0)), _claims(_cfg(budget=0.5))
    assert {k: c.verdict for k, c in fast.items()} == {k: c.verdict for k, c in slow.items()}
    fr1 = slow["FR-1-m"]
    assert "RQMC N_T=16 took 0.600 ms, over the budget" in fr1.contrary
    assert "RS-MHP N_T=64 (0.400 ms) also fits the budget on this run" in fr1.contrary
    assert "budget 0.5 ms" in fr1.measured
    assert "over the budget" not in fast["FR-1-m"].contrary


def test_missing_members_drop_their_claims_only():
    claims = _claims(_cfg(members=("rsmhp_nt16", "dpw_s30")))
    assert set(claims) == {"FR-3-m"}  # FR-1 needs RQMC, FR-2 the sigma points
    cfg = _cfg()
    del cfg["claims"]
    with pytest.raises(ValueError, match=re.escape("frontier lacks 'claims'")):
        _claims(cfg)


def test_exploratory_section_states_every_comparison_and_the_budget():
    from rsmhp.studies.frontier.section import FrontierInputs, frontier_section, frontier_tables

    runs, regret = _tables()
    summary = summarize_frontier(runs, regret)
    cfg = {**_cfg(), "runs": N_RUNS, "regret_runs": 2, "regret_steps": [0, 1, 2, 3, 4],
           "track_loss_error": 50.0}  # fmt: skip
    tables = frontier_tables(summary, cfg)
    sec = frontier_section(FrontierInputs(runs, regret, summary, tables, cfg, seed=11, horizon=6))
    # the exploratory design: its comparisons are printed, never claims of the ledger
    assert sec.key == "frontier_exploratory" and sec.claims == []
    assert "Exploratory comparisons (not claims)" in sec.body
    for c in _claims().values():
        k = c.key
        assert f"'m' {fmt(k.value, k.digits, True)}" in sec.body and f"({c.verdict})" in sec.body
    assert "56 equally weighted cubature points" in sec.appendix  # 8 (H + 1), H = 6
    assert "nan" not in sec.body.lower() and "nan" not in sec.appendix.lower()
    assert "| RQMC N_T=16 " in tables["frontier_budget"] and "| no " in tables["frontier_budget"]


# ------------------------------------------------------------------------ config checks


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (
            lambda fr, dec: fr["budget"].update(members=["rsmhp_nt16", "rqmc_nt999"]),
            "frontier.budget.members: ['rqmc_nt999'] not method(s) of frontier.methods",
        ),
        (
            lambda fr, dec: fr["budget"]["members"].append("nbo"),
            "frontier.budget.members: ['nbo'] is the baseline",
        ),
        (
            lambda fr, dec: fr["budget"]["members"].append("rsmhp_nt64"),
            "several members of one family {'rsmhp': ['rsmhp_nt256', 'rsmhp_nt64']}",
        ),
        (
            lambda fr, dec: fr["budget"]["members"].remove("sigma"),
            "no member of the frontier's famil(ies) ['sigma']",
        ),
        (
            lambda fr, dec: dec["map"]["methods"].update(sigma=False),
            "decisions.map.methods: lacks the budget member(s) ['sigma']",
        ),
        (
            lambda fr, dec: fr["claims"].update(sigma_reference="rqmc_nt256"),
            "frontier.claims.sigma_reference: 'rqmc_nt256' is not a Monte-Carlo member",
        ),
        (
            lambda fr, dec: fr["recording"].update(model="paper2"),
            "frontier.recording.model: 'paper2' is not a model of frontier.models",
        ),
    ],
)
def test_bad_budget_config_is_refused_naming_the_field(edit, expected):
    from rsmhp.pipeline.config import ConfigError, check_config

    cfg = copy.deepcopy(CONFIG)
    edit(cfg["frontier"], cfg["decisions"])
    with pytest.raises(ConfigError) as err:
        check_config(cfg)
    assert expected in str(err.value)


# ------------------------------------------------------------------------------ recording


def test_replay_check_refuses_a_stale_table():
    from rsmhp.models.uav.recording import check_replay

    table = pd.DataFrame({"method": ["nbo", "sigma"], "mean_error": [10.0, 12.5]})
    check_replay([{"method": "nbo", "mean_error": 10.0}, {"method": "sigma", "mean_error": 12.5}],
                 table)  # fmt: skip
    with pytest.raises(ValueError, match=re.escape("the replay of sigma gives mean error 12.6")):
        check_replay([{"method": "sigma", "mean_error": 12.6}], table)
    with pytest.raises(ValueError, match="method 'dpw_s30' has no row"):
        check_replay([{"method": "dpw_s30", "mean_error": 1.0}], table)


def test_recording_setup_shows_nbo_and_every_budget_member():
    from rsmhp.studies.frontier.simulate import recording_setup

    fr = CONFIG["frontier"]
    setup, methods = recording_setup(CONFIG["uav"], CONFIG["uav_models"], fr, "footprint150")
    assert [m.name for m in methods] == ["nbo", *fr["budget"]["members"]]
    assert setup.sensor.limited
    with pytest.raises(ValueError, match=re.escape("frontier.recording.model: 'nowhere'")):
        recording_setup(CONFIG["uav"], CONFIG["uav_models"], fr, "nowhere")


# ------------------------------------------------------- ledger fields: n, margin, check


def _paired_runs(table: pd.DataFrame, a: str, b: str, col: str = "method") -> int:
    """Runs of ``table`` with a row of both ``a`` and ``b``, counted by hand (the clusters of
    a cluster-t CI: every belief state of a run belongs to it)."""
    have = table.groupby(col)["run"].apply(set)
    return len(have[a] & have[b])


@pytest.mark.parametrize(("margin_pp", "margin_m"), [(0.1, 0.25), (0.2, 0.4)])
def test_exploratory_key_numbers_carry_their_runs_and_the_rules_margin(margin_pp, margin_m):
    """n: the runs the cluster-t CI rests on, counted in the input (for the regret, whose
    belief states cluster in runs, the runs with a state of both members); margin: the
    equivalence margin of FR-1's and FR-3's ci_side rule, None for FR-2's non-inferiority rule
    (its margin is the null). Some rows are dropped from the tables the claims pair (the
    summary, which only names the members run and their times, is that of the full tables)."""
    runs, regret = _tables()
    summary = summarize_frontier(runs, regret)
    runs = runs[~((runs["method"] == "dpw_s30") & runs["run"].isin([1, 5]))]
    regret = regret[~((regret["method"] == "rqmc_nt16") & (regret["run"] == 3))]
    regret = regret[~((regret["method"] == "sigma") & (regret["run"] == 8) & (regret["step"] == 0))]
    cfg = _cfg(margin_pp=margin_pp, margin_m=margin_m)
    claims = {c.id: c for c in frontier_claims(runs, regret, summary, cfg, seed=11)}
    fr1, fr2, fr3 = claims["FR-1-m"].key, claims["FR-2-m"].key, claims["FR-3-m"].key
    assert fr1.n == _paired_runs(regret, "rqmc_nt16", "rsmhp_nt16") == N_STATES // 2 - 1
    assert fr2.n == _paired_runs(regret, "sigma", "rsmhp_nt16") == N_STATES // 2  # run 8: 1 state
    assert fr3.n == _paired_runs(runs, "dpw_s30", "rsmhp_nt16") == N_RUNS - 2
    assert fr1.margin == margin_pp and f"±{margin_pp:g} pp" in claims["FR-1-m"].rule
    assert fr2.margin is None and fr2.null == margin_pp
    assert fr3.margin == margin_m and f"±{margin_m:g} m" in claims["FR-3-m"].rule
    assert not any(c.check for c in claims.values())


def test_confirmatory_key_numbers_carry_their_runs_and_the_rules_margin():
    """The preregistered FR claims: n = runs paired (one value per run, t interval over them),
    margin = the preregistered margin_m of a superiority rule, None for non-inferiority."""
    from rsmhp.studies.frontier.claims import confirm_claims
    from rsmhp.studies.frontier.summarise import ladder, summarize_configs
    from tests.pipeline.test_protocol import PREREG, _confirm_tables

    runs, timing, chosen = _confirm_tables()
    s = summarize_configs(runs, timing)
    lad = ladder(runs, s, chosen, [0.5, 2.0])
    claims = {c.id: c for c in confirm_claims(runs, s, lad, PREREG, chosen, "f" * 64)}
    ref = chosen["m"]["2"]["rsmhp"].name
    for cid, family in (("FR-1-m", "rqmc"), ("FR-2-m", "sigma"), ("FR-3-m", "dpw")):
        spec = PREREG["claims"][cid[:4]]
        c = claims[cid]
        n = _paired_runs(runs, chosen["m"]["2"][family].name, ref, col="config")
        assert c.key.n == n and f"{n} paired runs" in c.measured and not c.check
        if spec["test"] == "superiority":
            assert c.key.margin == spec["margin_m"] and c.key.null == 0.0
        else:
            assert c.key.margin is None and c.key.null == spec["margin_m"]
    assert {c.key.n for c in claims.values()} == {runs["run"].nunique()}
