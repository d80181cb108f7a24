"""The comparison protocol (rsmhp.pipeline.protocol): streams, configurations, the tuning rule, the
preregistration file, and the closed-loop and timing runs of configurations.

Oracles: the exploratory stream is the config's seed; a configuration with the default budget
is the method itself (its closed-loop row is simulate_run's summary); the tuning rule against a
brute-force search over the same tables; the preregistration refuses what it must, naming it.
"""

from __future__ import annotations

import copy
import itertools
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from rsmhp.models.uav import methods
from rsmhp.models.uav.scoring import merge_variant
from rsmhp.models.uav.simulation import UAVSetup, simulate_run
from rsmhp.pipeline import protocol
from rsmhp.pipeline.contracts import check_table
from rsmhp.pipeline.protocol import Configuration, Preregistration, stream_seed
from rsmhp.studies.frontier.simulate import (
    config_runs_contract,
    config_timing_contract,
    run_configurations,
    time_configurations,
)

ROOT = Path(__file__).resolve().parents[2]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
MODELS = [{"name": "paper"}, {"name": "footprint150", "sensor": {"footprint_radius": 150.0}}]


def test_streams_are_the_seed_and_derived_roots():
    assert stream_seed(7, "exploratory") == 7
    tune, confirm = stream_seed(7, "tune"), stream_seed(7, "confirm")
    confirm2 = stream_seed(7, "confirm2")
    assert len({7, tune, confirm, confirm2}) == 4
    assert all(0 <= s < 2**63 for s in (tune, confirm, confirm2))
    assert stream_seed(7, "confirm") == confirm and stream_seed(8, "confirm") != confirm
    with pytest.raises(ValueError, match="stream: 'judge'"):
        stream_seed(7, "judge")


def test_configuration_names_budgets_and_refusals():
    c = Configuration("rsmhp_nt64", 100, 3)
    assert c.name == "rsmhp_nt64/it100/r3" and c.family == "rsmhp"
    assert Configuration("rsmhp_nt64").name == "rsmhp_nt64"
    assert Configuration("rsmhp_nt64", None, 2).name == "rsmhp_nt64/r2"
    assert "100 it, 3 restarts" in c.label()
    assert Configuration.from_spec(c.spec()) == c
    base = UAVSetup.from_config(CONFIG["uav"])
    s = c.setup(base).planner
    assert (s.maxiter, s.maxfun, s.restarts) == (100, 201, 3)
    assert Configuration("nbo").setup(base).planner == base.planner
    with pytest.raises(ValueError, match="sampled-cost planners only"):
        Configuration("dpw_s100", 30, 0)
    with pytest.raises(ValueError, match="belongs to no registered family"):
        Configuration("magic_nt5")
    with pytest.raises(ValueError, match="restarts"):
        Configuration("nbo", None, -1)
    with pytest.raises(ValueError, match="needs 'member'"):
        Configuration.from_spec({"maxiter": 3})


def test_configuration_names_with_a_start():
    # the names written before the start existed (committed files hold them) are unchanged
    assert Configuration("rsmhp_nt64", 30, 3).name == "rsmhp_nt64/it30/r3"
    assert Configuration("rsmhp_nt64", 30, 3, "warm").name == "rsmhp_nt64/it30/r3"
    assert Configuration("nbo").name == "nbo" and Configuration("dpw_s30").name == "dpw_s30"
    assert Configuration("nbo", None, 2).name == "nbo/r2"
    # a pursuit start: member[/it<maxiter>]/r<restarts>/pursuit
    assert Configuration("nbo", 30, 3, "pursuit").name == "nbo/it30/r3/pursuit"
    assert Configuration("rsmhp_nt64", None, 0, "pursuit").name == "rsmhp_nt64/r0/pursuit"
    assert Configuration("nbo", 30, 0, "pursuit").name == "nbo/it30/r0/pursuit"
    assert (
        Configuration("nbo", 30, 3, "pursuit").label() == "NBO (30 it, 3 restarts, pursuit start)"
    )
    assert Configuration("nbo", 30, 3).label() == "NBO (30 it, 3 restarts)"
    # specs: a warm start's is what it was (no key); a pursuit start's round-trips
    warm = Configuration("rsmhp_nt64", 30, 3)
    assert warm.spec() == {"member": "rsmhp_nt64", "maxiter": 30, "restarts": 3}
    assert Configuration.from_spec(warm.spec()) == warm
    assert Configuration.from_spec({**warm.spec(), "start": "warm"}) == warm
    pur = Configuration("rsmhp_nt64", 30, 3, "pursuit")
    assert pur.spec() == {"member": "rsmhp_nt64", "maxiter": 30, "restarts": 3, "start": "pursuit"}
    assert Configuration.from_spec(pur.spec()) == pur and pur != warm
    base = UAVSetup.from_config(CONFIG["uav"])
    assert base.planner.start == "warm"
    assert pur.setup(base).planner.start == "pursuit"
    assert warm.setup(pur.setup(base)).planner == warm.setup(base).planner  # start reset
    assert Configuration("nbo").setup(base).planner == base.planner
    # refused: an unknown start, a start for a planner without a cost estimate
    with pytest.raises(ValueError, match=r"start 'cold' \(allowed: 'warm', 'pursuit'\)"):
        Configuration("nbo", 30, 0, "cold")
    for member in ("dpw_s30", "pursuit"):
        assert Configuration(member, start="warm").name == member
        with pytest.raises(ValueError, match="sampled-cost planners only"):
            Configuration(member, start="pursuit")
        with pytest.raises(ValueError, match="sampled-cost planners only"):
            Configuration.from_spec({"member": member, "start": "pursuit"})
    with pytest.raises(ValueError, match="may have 'maxiter', 'restarts' and 'start'"):
        Configuration.from_spec({"member": "nbo", "begin": "pursuit"})


def test_candidates_cross_every_sampled_member_with_every_optimiser_budget():
    cfg = {
        "methods": {"nbo": True, "rsmhp_nt": [16, 64], "sigma": True, "dpw": [{"sims": 10}]},
        "optimiser": {"maxiter": [30, 100], "restarts": [0, 2]},
    }
    got = protocol.candidates(cfg)
    sampled = [c for c in got if c.family != "dpw"]
    # NBO is tuned like every sampled-cost family: nbo, two RS-MHP members and sigma
    assert len(sampled) == 4 * 2 * 2 and [c.member for c in got if c.family == "dpw"] == ["dpw_s10"]
    assert [c.name for c in got if c.family == "nbo"] == [
        "nbo/it30/r0", "nbo/it30/r2", "nbo/it100/r0", "nbo/it100/r2",
    ]  # fmt: skip
    assert all(c.start == "warm" for c in got)  # the default start list
    assert len({c.name for c in got}) == len(got)


def test_candidates_with_starts_and_the_pursuit_policy(monkeypatch):
    cfg = {
        "methods": {"nbo": True, "rsmhp_nt": [16, 64], "dpw": [{"sims": 10}], "pursuit": True},
        "optimiser": {"maxiter": [30, 100], "restarts": [0, 3], "start": ["warm", "pursuit"]},
    }
    got = protocol.candidates(cfg)
    names = [c.name for c in got]
    members, maxiters, restarts, starts = 3, 2, 2, 2
    assert len(got) == members * maxiters * restarts * starts + 2  # + dpw_s10, pursuit
    assert len(set(names)) == len(names)
    assert "nbo/it30/r3" in names and "nbo/it30/r3/pursuit" in names
    assert names[-2:] == ["dpw_s10", "pursuit"]
    # table order, then maxiter, then restarts, then start
    assert names[:8] == [
        "nbo/it30/r0", "nbo/it30/r0/pursuit", "nbo/it30/r3", "nbo/it30/r3/pursuit",
        "nbo/it100/r0", "nbo/it100/r0/pursuit", "nbo/it100/r3", "nbo/it100/r3/pursuit",
    ]  # fmt: skip
    assert [c.family for c in got[: 3 * 8 : 8]] == ["nbo", "rsmhp", "rsmhp"]
    assert [c.member for c in got[8:24:8]] == ["rsmhp_nt16", "rsmhp_nt64"]
    # every run of the tuning once; the untuned reference first
    conf = protocol.tuning_configurations({"candidates": cfg})
    assert conf[0] == Configuration("nbo") and conf[1:] == got
    assert len({c.name for c in conf}) == len(conf)
    ref = protocol.tuning_configurations(
        {"candidates": {"methods": {"nbo": True}, "optimiser": {"maxiter": [30], "restarts": [0]}}}
    )
    assert [c.name for c in ref] == ["nbo", "nbo/it30/r0"]
    # the reference among the candidates (a grid with the default budget) is run once
    monkeypatch.setattr(
        protocol, "candidates", lambda cfg: [Configuration("nbo"), Configuration("nbo", 30, 1)]
    )
    got = protocol.tuning_configurations({"candidates": {}})
    assert [c.name for c in got] == ["nbo", "nbo/it30/r1"]


def _tuning_tables(rng):
    configs = [
        Configuration("rsmhp_nt16", 30, 0),
        Configuration("rsmhp_nt64", 30, 0),
        Configuration("rsmhp_nt64", 30, 2),
        Configuration("sigma", 30, 0),
        Configuration("dpw_s10"),
        Configuration("dpw_s50"),
    ]
    ms = {c.name: v for c, v in zip(configs, [0.2, 0.6, 1.5, 0.3, 0.4, 2.5], strict=True)}
    err = {c.name: v for c, v in zip(configs, [12.0, 11.0, 10.5, 11.5, 13.0, 9.0], strict=True)}
    # the closed loop's own planning time: below the timing's median except for the sigma
    # points on model 'b', which spend 5x more in closed loop than at the timed states
    q, t = [], []
    for model, c, r in itertools.product(("a", "b"), configs, range(4)):
        slow = 5.0 if (model == "b" and c.member == "sigma") else 0.9
        q.append(
            {
                "model": model,
                "config": c.name,
                "run": r,
                "work_per_step": 10.0 * r,
                "mean_error": err[c.name] + (0.5 if model == "b" else 0) + 0.01 * (r - 1.5),
                "plan_ms": slow * ms[c.name] * (1 + 0.02 * (r - 1.5)),
            }
        )
        t.append({"model": model, "config": c.name, "ms": ms[c.name] * (1 + 0.01 * r)})  # fmt: skip
    return configs, pd.DataFrame(q), pd.DataFrame(t)


def test_selection_is_the_best_error_within_each_budget():
    configs, q, t = _tuning_tables(np.random.default_rng(0))
    budgets = [0.25, 1.0, 4.0]
    sel = protocol.select(q, t, configs, budgets)
    assert list(sel.columns) == protocol.SELECTION_COLUMNS
    # brute force over the same tables: the cost is the larger of the timing's median and
    # the closed loop's mean planning time
    med = t.groupby(["model", "config"])["ms"].median()
    loop = q.groupby(["model", "config"])["plan_ms"].mean()
    cost = np.maximum(med, loop.reindex(med.index))
    mean = q.groupby(["model", "config"])["mean_error"].mean()
    for model in ("a", "b"):
        for fam in ("rsmhp", "sigma", "dpw"):
            for b in budgets:
                fit = [c.name for c in configs if c.family == fam and cost[(model, c.name)] <= b]
                row = sel[(sel.model == model) & (sel.family == fam) & (sel.budget_ms == b)]
                if not fit:
                    assert row.empty
                    continue
                assert row["config"].item() == min(fit, key=lambda n: mean[(model, n)])
                assert row["fitting"].item() == len(fit)
    r = sel[(sel.model == "a") & (sel.family == "rsmhp")].set_index("budget_ms")["config"]
    assert r.to_dict() == {0.25: "rsmhp_nt16/it30/r0", 1.0: "rsmhp_nt64/it30/r0",
                           4.0: "rsmhp_nt64/it30/r2"}  # fmt: skip
    # the sigma points fit 1 ms on 'a' (0.3 ms both ways) but not on 'b', whose closed loop
    # spends 1.5 ms per step although the timing's median is 0.3 ms
    sig = sel[(sel.family == "sigma") & (sel.budget_ms == 1.0)].set_index("model")
    assert sig.loc["a", "config"] == "sigma/it30/r0"
    assert "b" not in sig.index
    assert sel[(sel.model == "b") & (sel.family == "sigma")]["budget_ms"].tolist() == [4.0]
    row = sel[(sel.model == "b") & (sel.family == "sigma")].iloc[0]
    assert row.plan_ms == pytest.approx(row.closed_loop_ms) and row.closed_loop_ms > row.timing_ms
    with pytest.raises(ValueError, match="no timing rows of 'dpw_s50'"):
        protocol.select(q, t[t.config != "dpw_s50"], configs, budgets)
    with pytest.raises(ValueError, match=r"lack columns \['plan_ms'\]"):
        protocol.select(q.drop(columns="plan_ms"), t, configs, budgets)


def test_tuned_document_round_trips_into_configurations():
    configs, q, t = _tuning_tables(np.random.default_rng(0))
    sel = protocol.select(q, t, configs, [1.0, 4.0])
    doc = protocol.tuned_document(sel, {"stream": "tune"})
    doc = yaml.safe_load(yaml.safe_dump(doc))
    per = protocol.tuned_configurations(doc, "a")
    assert per["4"]["rsmhp"] == Configuration("rsmhp_nt64", 30, 2)
    assert per["1"]["dpw"] == Configuration("dpw_s10")
    with pytest.raises(ValueError, match="no configurations for model 'c'"):
        protocol.tuned_configurations(doc, "c")


def test_nbo_is_tuned_as_a_family_and_the_start_reaches_the_tuned_file():
    """The reference nbo competes with NBO's tuned configurations (select groups by family);
    a chosen pursuit start is written to the tuned file and read back; a warm start is not
    written (tuned files written before the start existed read as they did)."""
    configs = [
        Configuration("nbo"),
        Configuration("nbo", 30, 0, "pursuit"),
        Configuration("rsmhp_nt16", 30, 0),
        Configuration("rsmhp_nt16", 30, 0, "pursuit"),
    ]
    ms = dict(zip([c.name for c in configs], [0.1, 0.5, 0.6, 2.0], strict=True))
    err = dict(zip([c.name for c in configs], [12.0, 10.0, 11.0, 9.0], strict=True))
    q = pd.DataFrame([{"model": "a", "config": n, "run": r, "work_per_step": 1.0,
                       "mean_error": err[n], "plan_ms": ms[n]}
                      for n in ms for r in range(2)])  # fmt: skip
    t = pd.DataFrame([{"model": "a", "config": n, "ms": ms[n]} for n in ms for _ in range(3)])
    sel = protocol.select(q, t, configs, [0.2, 1.0, 4.0])
    got = {(r.family, r.budget_ms): (r.config, r.start) for r in sel.itertuples()}
    assert got == {
        ("nbo", 0.2): ("nbo", "warm"),
        ("nbo", 1.0): ("nbo/it30/r0/pursuit", "pursuit"),
        ("nbo", 4.0): ("nbo/it30/r0/pursuit", "pursuit"),
        ("rsmhp", 1.0): ("rsmhp_nt16/it30/r0", "warm"),
        ("rsmhp", 4.0): ("rsmhp_nt16/it30/r0/pursuit", "pursuit"),
    }
    doc = yaml.safe_load(yaml.safe_dump(protocol.tuned_document(sel, {})))
    at = doc["chosen"]["a"]
    assert "start" not in at["0.2"]["nbo"] and "start" not in at["1"]["rsmhp"]
    assert at["4"]["rsmhp"]["start"] == "pursuit"
    per = protocol.tuned_configurations(doc, "a")
    assert per["0.2"]["nbo"] == Configuration("nbo")
    assert per["1"]["nbo"] == Configuration("nbo", 30, 0, "pursuit")
    assert per["4"]["rsmhp"] == Configuration("rsmhp_nt16", 30, 0, "pursuit")


def _prereg(tmp_path, tuned_sha, **over):
    doc = {
        "stream": "confirm",
        "tuned": {"file": "tuned.yaml", "sha256": tuned_sha},
        "models": ["a"],
        "budgets_ms": [1.0, 4.0],
        "headline_budget_ms": 1.0,
        "runs": 30,
        "claims": {},
        **over,
    }
    p = tmp_path / "prereg.yaml"
    p.write_text(yaml.safe_dump(doc))
    return p


def test_preregistration_checks_the_tuned_file_and_lists_the_configurations(tmp_path):
    configs, q, t = _tuning_tables(np.random.default_rng(0))
    doc = protocol.tuned_document(protocol.select(q, t, configs, [1.0, 4.0]), {})
    tuned = tmp_path / "tuned.yaml"
    tuned.write_text(yaml.safe_dump(doc))
    p = _prereg(tmp_path, protocol.file_sha256(tuned))
    pre = Preregistration.load(p, tuned)
    assert pre.sha256 == protocol.file_sha256(p)
    got = [c.name for c in pre.configurations(doc, "a")]
    assert got[0] == "nbo" and len(got) == len(set(got))
    assert {"rsmhp_nt64/it30/r0", "rsmhp_nt64/it30/r2", "dpw_s10", "sigma/it30/r0"} <= set(got)
    tuned.write_text(yaml.safe_dump({**doc, "provenance": {"edited": True}}))
    with pytest.raises(ValueError, match="would not be the preregistered ones"):
        Preregistration.load(p, tuned)
    with pytest.raises(ValueError, match="stream 'tune'"):
        Preregistration.load(_prereg(tmp_path, "x", stream="tune"))
    two = Preregistration.load(_prereg(tmp_path, "x", stream="confirm2"))
    assert two.doc["stream"] == "confirm2"
    with pytest.raises(ValueError, match=r"headline_budget_ms 2\.0"):
        Preregistration.load(_prereg(tmp_path, "x", headline_budget_ms=2.0))
    with pytest.raises(ValueError, match="missing claims"):
        bad = yaml.safe_load(_prereg(tmp_path, "x").read_text())
        del bad["claims"]
        (tmp_path / "bad.yaml").write_text(yaml.safe_dump(bad))
        Preregistration.load(tmp_path / "bad.yaml")
    with pytest.raises(ValueError, match="does not exist"):
        Preregistration.load(tmp_path / "none.yaml")


def test_power_runs_caps_and_reports_the_power_it_gives():
    from rsmhp.core.stats import runs_for_power, t_power

    out = protocol.power_runs(2.0, 0.5)
    assert out["runs"] == runs_for_power(2.0, 0.5) and "capped_runs" not in out
    capped = protocol.power_runs(2.0, 0.5, cap=20)
    assert capped["capped_runs"] == 20 and capped["power_at_cap"] == t_power(20, 2.0, 0.5)
    assert capped["power_at_cap"] < 0.8


# ------------------------------------------------------------------ runs of configurations


def _uav() -> dict:
    cfg = copy.deepcopy(CONFIG["uav"])
    cfg["scenario"]["steps"] = 6
    cfg["planner"].update(horizon=3, maxiter=6, maxfun=12)
    return cfg


def test_a_default_configuration_runs_its_method_and_restarts_share_its_hypotheses():
    configs = [
        Configuration("nbo"),
        Configuration("rsmhp_nt16"),
        Configuration("rsmhp_nt16", 6, 3),
        Configuration("dpw_s20"),
    ]
    seed = stream_seed(5, "tune")
    rows = run_configurations(_uav(), MODELS, "footprint150", configs, [0, 1], seed, 50.0)
    check_table(rows, "runs", config_runs_contract("x", configs, [0, 1], "footprint150"))
    setup = UAVSetup.from_config(merge_variant(_uav(), MODELS[1]))
    for name in ("nbo", "rsmhp_nt16", "dpw_s20"):
        for run in (0, 1):
            s, _ = simulate_run(setup, methods.from_name(name), seed, run)
            row = rows[(rows.config == name) & (rows.run == run)].iloc[0]
            assert (
                row["mean_error"] == s["mean_error"] and row["work_per_step"] == s["work_per_step"]
            )
    r = rows.set_index(["config", "run"])
    # the restarts spend more work on the same hypotheses (same stream key as the method)
    assert (
        r.loc["rsmhp_nt16/it6/r3", "work_per_step"] > r.loc["rsmhp_nt16", "work_per_step"]
    ).all()
    assert r.loc["dpw_s20", "plan_depth"].notna().all() and r.loc["nbo", "plan_depth"].isna().all()


def test_configuration_timing_is_round_robin_with_the_contract():
    configs = [Configuration("nbo"), Configuration("rsmhp_nt16", 6, 1), Configuration("dpw_s20")]
    timing = {"runs": 1, "steps": [0, 2, 3], "repeats": 3}
    t = time_configurations(_uav(), MODELS, "paper", configs, timing, 5)
    check_table(t, "timing", config_timing_contract("x", configs, timing, "paper"))
    slots = t.groupby(["config", "slot"]).size().unstack()
    assert (slots == 3).all().all()  # 3 repeats x 3 states = 9 calls, 3 per slot
    assert (t.groupby(["config", "run", "step"])["work"].nunique() == 1).all()


# ------------------------------------------------------------ confirmatory statistics and claims


def _confirm_tables(shift_rqmc=-0.5, shift_dpw=3.0, n=30, noise=0.3):
    """One model 'm', NBO and tuned members at two budgets: rsmhp (the reference), rqmc,
    sigma, dpw; each run's error = a shared scenario part + the member's shift + its own
    noise. Interleaved timing rows with known medians."""
    rng = np.random.default_rng(3)
    common = rng.normal(20.0, 4.0, n)
    members = {
        "nbo": ("nbo", 0.0, 0.1, None),
        "rsmhp_nt16/it30/r0": ("rsmhp", -1.0, 0.3, "rsmhp_nt16"),
        "rsmhp_nt64/it30/r1": ("rsmhp", -1.2, 1.5, "rsmhp_nt64"),
        "rqmc_nt16/it30/r0": ("rqmc", -1.0 + shift_rqmc, 0.4, "rqmc_nt16"),
        "sigma/it30/r0": ("sigma", -1.1, 0.2, "sigma"),
        "dpw_s30": ("dpw", -1.0 + shift_dpw, 0.9, "dpw_s30"),
    }
    runs, timing = [], []
    for name, (fam, shift, ms, member) in members.items():
        own = noise * rng.standard_normal(n)
        for r in range(n):
            runs.append({"model": "m", "config": name, "member": member or "nbo", "family": fam,
                         "maxiter": 30, "restarts": 1 if name.endswith("r1") else 0, "run": r,
                         "mean_error": common[r] + shift + own[r], "final_error": 1.0,
                         "detect_rate": 1.0, "lost": False, "mean_nit": 5.0,
                         # the closed loop's own time: the sigma points spend 4x the timed
                         # 0.2 ms there (over the 0.5 ms budget), the others what is timed
                         "plan_ms": 0.8 + 0.01 * (r % 3 - 1) if fam == "sigma" else ms,
                         "work_per_step": 100.0 * ms, "converged_rate": 1.0,
                         "plan_depth": 2.0 if fam == "dpw" else np.nan,
                         "max_depth": 3.0 if fam == "dpw" else np.nan,
                         "root_actions": 9.0 if fam == "dpw" else np.nan,
                         "frac_depth1": 0.2 if fam == "dpw" else np.nan})  # fmt: skip
        for rep in range(2):
            for k in range(3):
                timing.append({"model": "m", "config": name, "repeat": rep, "run": 0, "step": k,
                               "slot": 0, "ms": ms * (1 + 0.01 * k + 0.02 * rep),
                               "work": int(100 * ms)})  # fmt: skip
    chosen = {
        "m": {
            "0.5": {"rsmhp": Configuration("rsmhp_nt16", 30, 0),
                    "rqmc": Configuration("rqmc_nt16", 30, 0),
                    "sigma": Configuration("sigma", 30, 0)},
            "2": {"rsmhp": Configuration("rsmhp_nt64", 30, 1),
                  "rqmc": Configuration("rqmc_nt16", 30, 0),
                  "sigma": Configuration("sigma", 30, 0),
                  "dpw": Configuration("dpw_s30")},
        }
    }  # fmt: skip
    return pd.DataFrame(runs), pd.DataFrame(timing), chosen


PREREG = {
    "models": ["m"],
    "budgets_ms": [0.5, 2.0],
    "headline_budget_ms": 2.0,
    "runs": 30,
    "claims": {
        "FR-1": {"family": "rqmc", "against": "rsmhp", "test": "superiority", "margin_m": 0.25},
        "FR-2": {"family": "sigma", "against": "rsmhp", "test": "non-inferiority",
                 "margin_m": 0.25},
        "FR-3": {"family": "dpw", "against": "rsmhp", "test": "superiority", "margin_m": 0.25},
    },
}  # fmt: skip


def test_confirm_summary_ladder_and_claims_follow_the_data():
    from rsmhp.core.stats import mean_ci
    from rsmhp.studies.frontier.claims import confirm_claims
    from rsmhp.studies.frontier.summarise import (
        ladder,
        paired_configs,
        prob_improvement,
        summarize_configs,
    )

    runs, timing, chosen = _confirm_tables()
    s = summarize_configs(runs, timing).set_index("config")
    assert s.loc["rsmhp_nt64/it30/r1", "plan_ms"] == pytest.approx(np.median(
        [1.5 * (1 + 0.01 * k + 0.02 * r) for r in range(2) for k in range(3)]))  # fmt: skip
    w = runs.pivot(index="run", columns="config", values="mean_error")
    d = (w["dpw_s30"] - w["nbo"]).to_numpy()
    assert (s.loc["dpw_s30", "error_diff_low"], s.loc["dpw_s30", "error_diff_high"]) == (
        pytest.approx(mean_ci(d)[1:])
    )
    assert s.loc["dpw_s30", "plan_depth"] == 2.0 and np.isnan(s.loc["nbo", "plan_depth"])
    lad = ladder(runs, summarize_configs(runs, timing), chosen, [0.5, 2.0])
    r = lad.set_index(["budget_ms", "family"])
    assert r.loc[(0.5, "rsmhp"), "within_budget"] and r.loc[(2.0, "rsmhp"), "within_budget"]
    # the sigma points: timed within 0.5 ms, but their closed loop spends 0.8 ms per step
    # (the mean over runs): over the budget on the tuning rule's cost, within 2 ms
    assert r.loc[(0.5, "sigma"), "loop_ms"] == pytest.approx(0.8, abs=1e-3)
    assert r.loc[(0.5, "sigma"), "plan_ms"] < 0.5
    assert not r.loc[(0.5, "sigma"), "within_budget"] and r.loc[(2.0, "sigma"), "within_budget"]
    assert r.loc[(2.0, "rsmhp"), "diff_mc"] == 0.0
    p = paired_configs(runs, "m", "rqmc_nt16/it30/r0", "rsmhp_nt64/it30/r1")
    assert r.loc[(2.0, "rqmc"), "diff_mc"] == pytest.approx(p.mean)
    pi = prob_improvement(w["rqmc_nt16/it30/r0"].to_numpy(), w["rsmhp_nt64/it30/r1"].to_numpy())
    assert r.loc[(2.0, "rqmc"), "p_improve"] == pytest.approx(pi[0])
    assert "dpw" not in set(lad[lad.budget_ms == 0.5]["family"])
    claims = {c.id: c for c in confirm_claims(runs, summarize_configs(runs, timing), lad,
                                              PREREG, chosen, "abc123" * 6)}  # fmt: skip
    assert set(claims) == {"FR-1-m", "FR-2-m", "FR-3-m"}
    for c in claims.values():
        lo, hi = c.key.ci_low, c.key.ci_high
        assert c.verdict in ("supported", "not supported", "equivalent", "inconclusive")
        assert "preregistered, sha256 abc123abc123" in c.rule
        assert 0 <= c.key.p_value <= 1 and lo <= c.key.value <= hi
    # rqmc (shift -1.5) against the 2 ms Monte-Carlo member (-1.2): d = -0.3 m with a
    # per-run sd of 0.3 sqrt 2, SE 0.077 at 30 runs: the CI lies below -0.25 and 0
    assert claims["FR-1-m"].verdict == "supported"
    assert claims["FR-3-m"].verdict == "not supported"  # dpw +3 m worse than Monte Carlo's
    assert claims["FR-3-m"].key.p_value < 0.05
    assert "follow its tree for 2.00 of H steps" in claims["FR-3-m"].measured
    assert claims["FR-2-m"].key.null == 0.25
    assert "rsmhp_nt64" not in claims["FR-1-m"].contrary
    # contrary evidence opposes the verdict: FR-1 supported at 2 ms, and at 0.5 ms RQMC is
    # better too (-0.5 m), so nothing opposes it
    assert claims["FR-1-m"].contrary == ""


def test_confirm_figure_plots_the_cost_the_budget_counts():
    import matplotlib.pyplot as plt

    from rsmhp.studies.frontier.figures import confirm_figure
    from rsmhp.studies.frontier.summarise import ladder, summarize_configs

    runs, timing, chosen = _confirm_tables()
    lad = ladder(runs, summarize_configs(runs, timing), chosen, [0.5, 2.0])
    fig = confirm_figure(lad)
    try:
        ax = fig.axes[0]
        sigma = lad[lad.family == "sigma"].sort_values("budget_ms")
        want = np.fmax(sigma["plan_ms"], sigma["loop_ms"]).to_numpy()
        # the sigma points' closed loop (0.8 ms) is counted, not their timed 0.2 ms
        assert want == pytest.approx([0.8, 0.8], abs=0.01)
        xs = [np.asarray(line.get_xdata(), float) for line in ax.get_lines()]
        assert any(x.shape == want.shape and np.allclose(x, want) for x in xs)
        assert "budget's count" in ax.get_xlabel()
    finally:
        plt.close(fig)


def test_confirm_section_reads_its_numbers_from_the_tables():
    from rsmhp.studies.frontier.claims import confirm_claims
    from rsmhp.studies.frontier.section import ConfirmInputs, confirm_section, confirm_tables
    from rsmhp.studies.frontier.summarise import ladder, summarize_configs

    runs, timing, chosen = _confirm_tables()
    s = summarize_configs(runs, timing)
    lad = ladder(runs, s, chosen, [0.5, 2.0])
    claims = confirm_claims(runs, s, lad, PREREG, chosen, "f" * 64)
    tuned = {"provenance": {"candidates": 7, "runs per candidate": 4}, "chosen": {}}
    tables = confirm_tables(s, lad, tuned)
    sec = confirm_section(ConfirmInputs(
        s, lad, claims, tables, {**PREREG, "power_text": "p"},
        {"path": "p.yaml", "sha256": "f" * 64, "commit": "c" * 40}, tuned,
        [{"id": "FR-1-x", "key": {"value": 1.0, "ci_low": 0.5, "ci_high": 1.5, "unit": "m"},
          "verdict": "supported"}],
        superseded={"what": "budgeted on medians.",
                    "preregistration": {"sha256": "e" * 64, "commit": "d" * 40},
                    "claims": [{"id": "FR-2-y", "key": {"value": 2.0, "unit": "m"},
                                "verdict": "inconclusive"}]}))  # fmt: skip
    assert sec.key == "frontier" and len(sec.claims) == 3
    assert "sha256 eeeeeeeeeeee, commit dddddddddd; superseded, not counted" in sec.appendix
    assert "FR-2-y" in sec.appendix and "budgeted on medians." in sec.appendix
    # what the members at the claims' budget spent in closed loop (2 ms: all within it)
    assert "Closed-loop ms per step at 2 ms (mean over runs)" in sec.body
    assert "(all within it)" in sec.body
    assert "7 candidate configurations" in sec.body and "sha256 ffffffffffff" in sec.body
    for c in claims:
        assert f"{c.id}" in sec.body
    assert "FR-1-x" in sec.appendix and "76a0c01" in sec.appendix
    assert "(no tuned configurations)" in tables["frontier_confirm_tuning"]


def _git(cwd, *args):
    import subprocess

    subprocess.run(["git", *args], cwd=cwd, check=True, capture_output=True)


def test_file_commit_names_the_commit_and_refuses_a_wrong_path(tmp_path):
    import shutil
    import subprocess

    if shutil.which("git") is None:
        pytest.skip("git is not installed")
    repo = tmp_path / "repo"
    (repo / "config").mkdir(parents=True)
    (repo / "workflow" / "scripts").mkdir(parents=True)
    (repo / "workflow" / "rules").mkdir()
    f = repo / "config" / "pre.yaml"
    f.write_text("a: 1\n")
    _git(repo, "init", "-q")
    _git(repo, "-c", "user.name=t", "-c", "user.email=t@t", "add", ".")
    _git(repo, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "pre")
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=repo, capture_output=True,
                          text=True, check=True).stdout.strip()  # fmt: skip
    assert protocol.file_commit(f) == head
    # the scripts build the path from a script directory that holds '..' (Snakemake's
    # scriptdir of "../scripts/x.py" is "<repo>/workflow/rules/../scripts"): resolved first
    scriptdir = repo / "workflow" / "rules" / ".." / "scripts"
    assert protocol.file_commit(Path(scriptdir).resolve().parents[1] / "config/pre.yaml") == head
    # the unresolved parents[1] of such a path is the wrong directory: refused, not "unknown"
    with pytest.raises(FileNotFoundError, match="does not exist"):
        protocol.file_commit(Path(scriptdir).parents[1] / "config/pre.yaml")
    f.write_text("a: 2\n")
    assert protocol.file_commit(f) == "uncommitted"
    outside = tmp_path / "outside.yaml"
    outside.write_text("a: 1\n")
    assert protocol.file_commit(outside) == "unknown"
