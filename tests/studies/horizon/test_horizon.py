"""UAV horizon study (rsmhp.studies.horizon.simulate_uav, rsmhp.studies.horizon.summarise_uav,
rsmhp.studies.horizon.claims).

Oracles: a method's estimate is its planning cost on its own hypotheses (PlanningProblem on
the hypotheses it draws with the row's stream); the reference is the mean of the per-hypothesis
costs (fused.covariance_traces); NBO's and the sigma points' estimates do not depend on the
replicate; the noise-corrected RMSE against a hand computation and, statistically, against a
known error variance; growth and claims against their rules on tables with known errors; the
cluster-t CIs against a jackknife over runs written out here and, for a mean of per-run values,
against the Student-t interval; the runs needed against rsmhp.core.stats.runs_for_power; the warm
start beyond the base horizon against the closed loop's hold-the-last-control rule.
"""

from __future__ import annotations

import copy
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from scipy import stats as sps

from rsmhp.pipeline.contracts import check_table
from rsmhp.studies.horizon.summarise_uav import rmse_growth, state_errors, summarize_approx

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
MODELS = [{"name": "paper"}, {"name": "footprint150", "sensor": {"footprint_radius": 150.0}}]
SCORING = {"n_eval": 200, "polish": 1, "random_starts": 1, "eval_maxiter": 10, "n_random": 20}
HZ = {
    "runs": 1,
    "steps": [0, 3],
    "plans": 5,
    "n_ref": 3000,
    "replicates": 3,
    "bootstrap": 500,
    "methods": {
        "nbo": True,
        "rsmhp_nt": [16],
        "sigma": True,
        "tree": [{"N": 2, "M": 8}],
        "dpw": [{"sims": 20}],
    },
}


def _uav() -> dict:
    cfg = copy.deepcopy(CONFIG["uav"])
    cfg["scenario"]["steps"] = 5
    cfg["planner"].update(horizon=3, maxiter=6, maxfun=12)
    return cfg


@pytest.fixture(scope="module")
def paper_h4():
    from rsmhp.studies.horizon.simulate_uav import run_horizon

    return run_horizon(_uav(), MODELS, HZ, SCORING, "paper", 4, 5)


def test_rows_follow_the_contracts(paper_h4):
    from rsmhp.studies.horizon.simulate_uav import horizon_contracts

    approx, regret = paper_h4
    c_a, c_r = horizon_contracts(HZ, "paper", 4)
    check_table(approx, "approx", c_a)
    check_table(regret, "regret", c_r)
    # the tree search estimates no given plan's cost: regret and time only
    assert "dpw_s20" not in set(approx["method"]) and "dpw_s20" in set(regret["method"])
    assert (regret["plan_ms"] > 0).all()
    # deterministic methods once, random ones `replicates` times
    reps = approx.groupby("method")["replicate"].nunique()
    assert reps["nbo"] == 1 and reps["sigma"] == 1 and reps["rsmhp_nt16"] == 3


def test_estimates_and_reference_against_the_planning_cost(paper_h4):
    """Row oracle: recompute one state's reference and each method's estimate from scratch."""
    from rsmhp.core.seeding import job_rng
    from rsmhp.models.uav import fused, methods, target
    from rsmhp.models.uav.planner import Belief, PlanningProblem
    from rsmhp.models.uav.scoring import belief_states
    from rsmhp.studies.horizon.simulate_uav import horizon_setup

    approx, _ = paper_h4
    base = horizon_setup(_uav(), MODELS[0], 3)
    setup = horizon_setup(_uav(), MODELS[0], 4)
    st = belief_states(base, "paper", 5, [0], [3])[0]
    ident = {"model": "paper", "run": 0, "step": 3, "H": 4}
    ref_xy = target.sample_independent(
        st.x_hat, st.P_hat, 4, HZ["n_ref"], setup.target, job_rng(5, "horizon_ref", **ident)
    )[..., :2]
    plans = job_rng(5, "horizon_plans", **ident).uniform(-1.0, 1.0, (HZ["plans"], 8))
    args = (setup.uav, setup.target, setup.sensor, setup.planner)
    ref = PlanningProblem(st.uav, st.P_hat, ref_xy, *args)
    per = fused.covariance_traces(
        st.P_hat, np.stack([ref.path(x)[:, :2] for x in plans]), ref_xy, setup.target.dt,
        setup.target.Q, setup.sensor,
    ).sum(axis=2)  # fmt: skip
    rows = approx[(approx["step"] == 3)]
    np.testing.assert_allclose(
        rows[rows["method"] == "nbo"].sort_values("plan")["reference"], per.mean(axis=1),
        rtol=1e-12,
    )  # fmt: skip
    np.testing.assert_allclose(ref.costs(plans), per.mean(axis=1), rtol=1e-9)
    belief = Belief(st.uav, st.x_hat, st.P_hat)
    for name in ("nbo", "rsmhp_nt16", "sigma", "tree_n2_m8"):
        m = methods.from_name(name)
        rng = job_rng(5, "horizon_hyp", **ident, **m.job_key(), replicate=0)
        hyp = m.hypotheses(belief, setup, rng)
        want = PlanningProblem(
            st.uav, st.P_hat, hyp.states[..., :2], *args, weights=hyp.weights
        ).costs(plans)
        got = rows[(rows["method"] == name) & (rows["replicate"] == 0)].sort_values("plan")
        np.testing.assert_allclose(got["estimate"], want, rtol=1e-12, err_msg=name)


def _table(
    errors: dict[str, np.ndarray], se: float = 0.0, H: int = 2, steps: int = 1
) -> pd.DataFrame:
    """Approximation rows of model 'm' at horizon H: per method, estimate = reference x (1 +
    e) with e[state, plan] given, reference 100, reference SE ``se`` x 100; state s is step
    s % ``steps`` of run s // ``steps``."""
    rows = []
    for method, e in errors.items():
        for s in range(e.shape[0]):
            for p in range(e.shape[1]):
                rows.append({"model": "m", "H": H, "run": s // steps, "step": s % steps,
                             "method": method,
                             "family": method.split("_")[0], "replicate": 0, "plan": p,
                             "estimate": 100.0 * (1 + e[s, p]), "reference": 100.0,
                             "reference_se": 100.0 * se})  # fmt: skip
    return pd.DataFrame(rows)


def test_bias_and_noise_corrected_rmse_by_hand():
    e = np.array([[0.01, 0.03], [-0.02, 0.02], [0.0, 0.04]])
    s = summarize_approx(_table({"a_1": e}, se=0.01), seed=1, n_boot=400).iloc[0]
    assert s["rel_bias"] == pytest.approx(e.mean())
    assert s["rel_rmse"] == pytest.approx(np.sqrt((e**2).mean() - 0.01**2))
    assert s["ref_noise"] == pytest.approx(0.01)
    assert s["rel_rmse_low"] <= s["rel_rmse"] <= s["rel_rmse_high"]
    per = state_errors(_table({"a_1": e}, se=0.01))
    np.testing.assert_allclose(per["b"], e.mean(axis=1))
    np.testing.assert_allclose(per["q"], (e**2).mean(axis=1) - 1e-4)
    # one state per run: the cluster-t CIs are Student-t intervals of the per-run values (the
    # RMSE's that of the mean square, square-rooted and floored at 0)
    lo, hi = _student_t(e.mean(axis=1))
    assert (s["rel_bias_low"], s["rel_bias_high"]) == pytest.approx((lo, hi), rel=1e-12)
    lo, hi = _student_t((e**2).mean(axis=1) - 1e-4)
    assert (s["rel_rmse_low"], s["rel_rmse_high"]) == pytest.approx(
        (np.sqrt(max(lo, 0.0)), np.sqrt(hi)), rel=1e-12
    )


def _student_t(x: np.ndarray, level: float = 0.95) -> tuple[float, float]:
    """Student-t interval of the mean of ``x``, written out."""
    half = sps.t.ppf(0.5 + level / 2, x.size - 1) * x.std(ddof=1) / np.sqrt(x.size)
    return float(x.mean() - half), float(x.mean() + half)


def test_noise_correction_recovers_a_known_error_sd():
    """An unbiased estimator with relative error sd 2% scored against a reference with
    relative SE 3% (both normal): the raw RMS error is sqrt(2² + 3²) = 3.6%, the corrected one
    2%. Tolerance from the variance: e is about normal with variance v = 0.02² + 0.03² =
    1.3e-3, so Var(e²) = 2 v² and the mean square over n = 100000 pairs has sd
    sqrt(2 v² / n) = 5.8e-6, i.e. 5.8e-6 / (2 × 0.02) = 1.5e-4 on the RMSE; 5 sd plus the
    second-order bias of dividing by a noisy reference (about 3 × 0.03² × v / (2 × 0.02) =
    9e-5) gives 8.2e-4."""
    rng = np.random.default_rng(11)
    n_states, n_plans = 400, 250
    est_err = rng.normal(0.0, 0.02, (n_states, n_plans))
    ref_err = rng.normal(0.0, 0.03, (n_states, n_plans))
    df = _table({"a_1": est_err}, se=0.03)
    df["reference"] = 100.0 * (1 + ref_err.ravel())
    df["estimate"] = 100.0 * (1 + est_err.ravel())
    df["reference_se"] = 0.03 * df["reference"]
    s = summarize_approx(df, seed=1, n_boot=200).iloc[0]
    assert s["rel_rmse"] == pytest.approx(0.02, abs=8.2e-4)
    raw = np.sqrt((((df["estimate"] - df["reference"]) / df["reference"]) ** 2).mean())
    assert raw == pytest.approx(np.hypot(0.02, 0.03), abs=1e-3)


def test_growth_and_its_difference_between_methods():
    rng = np.random.default_rng(3)
    lo = {"tree_x": rng.normal(0, 0.01, (30, 8)), "mc_x": rng.normal(0, 0.01, (30, 8))}
    hi = {"tree_x": rng.normal(0, 0.05, (30, 8)), "mc_x": rng.normal(0, 0.012, (30, 8))}
    df = pd.concat([_table(lo, H=2), _table(hi, H=24)], ignore_index=True)
    g = rmse_growth(df, "m", "tree_x", 2, 24, seed=1, n_boot=1000)
    want = np.sqrt((hi["tree_x"] ** 2).mean()) - np.sqrt((lo["tree_x"] ** 2).mean())
    assert g.mean == pytest.approx(want) and g.low > 0 and g.n == 30
    d = rmse_growth(df, "m", "tree_x", 2, 24, seed=1, n_boot=1000, minus="mc_x")
    want_mc = np.sqrt((hi["mc_x"] ** 2).mean()) - np.sqrt((lo["mc_x"] ** 2).mean())
    assert d.mean == pytest.approx(want - want_mc) and d.low > 0
    with pytest.raises(ValueError, match="H = 12 has no cost-approximation rows"):
        rmse_growth(df, "m", "tree_x", 2, 12, seed=1, n_boot=100)


def _jackknife_growth(lo: dict, hi: dict, steps: int, method: str, minus: str | None):
    """(estimate, low, high, se, p) of the RMSE growth by a jackknife over runs written out:
    leave out run i (its ``steps`` states) at both horizons, recompute the growth from the
    errors (reference SE 0, so q = mean over plans of e²), and take the t interval with
    runs − 1 df around the full-sample growth."""

    def growth(keep: np.ndarray) -> float:
        def g(m: str) -> float:
            return np.sqrt((hi[m][keep] ** 2).mean()) - np.sqrt((lo[m][keep] ** 2).mean())

        return g(method) - (g(minus) if minus else 0.0)

    n_states = lo[method].shape[0]
    runs = np.arange(n_states) // steps
    G = runs.max() + 1
    full = growth(np.ones(n_states, bool))
    loo = np.array([growth(runs != i) for i in range(G)])
    se = np.sqrt((G - 1) / G * ((loo - loo.mean()) ** 2).sum())
    half = sps.t.ppf(0.975, G - 1) * se
    return full, full - half, full + half, se, 2 * sps.t.sf(abs(full) / se, G - 1)


@pytest.mark.parametrize("minus", [None, "mc_x"])
def test_growth_ci_is_the_jackknife_over_runs(minus):
    """5 runs of 2 belief states each: the published CI is the cluster-t interval of a
    jackknife that leaves out whole runs (written out in _jackknife_growth), with its t-test
    p-value; the percentile bootstrap over runs is kept beside it."""
    rng = np.random.default_rng(12)
    lo = {m: rng.normal(0, 0.01, (10, 4)) for m in ("tree_x", "mc_x")}
    hi = {"tree_x": rng.normal(0, 0.03, (10, 4)), "mc_x": rng.normal(0, 0.015, (10, 4))}
    df = pd.concat([_table(lo, H=2, steps=2), _table(hi, H=24, steps=2)], ignore_index=True)
    g = rmse_growth(df, "m", "tree_x", 2, 24, seed=3, n_boot=2000, minus=minus)
    est, low, high, se, p = _jackknife_growth(lo, hi, 2, "tree_x", minus)
    assert (g.n, g.runs, g.df) == (10, 5, 4)
    assert g.mean == pytest.approx(est, rel=1e-12)
    assert (g.low, g.high, g.se) == pytest.approx((low, high, se), rel=1e-10)
    assert g.p_value == pytest.approx(p, rel=1e-10)
    # the bootstrap CI is the 2.5% and 97.5% quantiles of resampled growths: a different
    # interval around the same estimate
    assert g.boot_low < g.mean < g.boot_high and (g.boot_low, g.boot_high) != (g.low, g.high)


def test_claims_follow_their_rules():
    from rsmhp.studies.horizon.claims import (
        KEY,
        horizon_claims,
        horizon_evidence,
        hz1_rule,
        hz2_rule,
    )

    rng = np.random.default_rng(4)
    lo = {m: rng.normal(0, 0.01, (25, 6)) for m in ("nbo", "tree_n4_m256", "rsmhp_nt256")}
    hi = {"nbo": rng.normal(0.02, 0.03, (25, 6)), "tree_n4_m256": rng.normal(0, 0.01, (25, 6)),
          "rsmhp_nt256": rng.normal(0, 0.04, (25, 6))}  # fmt: skip
    # H = 4: the first horizon at which the tree (4^(H+1) > 256 leaves) is pruned
    df = pd.concat([_table(lo, H=4), _table(hi, H=24)], ignore_index=True)
    df["family"] = df["method"].map({"nbo": "nbo", "tree_n4_m256": "tree", "rsmhp_nt256": "rsmhp"})
    summary = summarize_approx(df, seed=1, n_boot=300)
    cfg = {"bootstrap": 1000, "claims": {"tree": "tree_n4_m256", "monte_carlo": "rsmhp_nt256"}}
    claims = {c.id: c for c in horizon_claims(df, summary, cfg, seed=2)}
    assert set(claims) == {"HZ-1-m", "HZ-2-m"}
    for cid, rule in (("HZ-1-m", hz1_rule(4, 24)), ("HZ-2-m", hz2_rule("tree_n4_m256",
                      "rsmhp_nt256", 4, 24))):  # fmt: skip
        k = claims[cid].key
        assert claims[cid].verdict == rule.verdict({f"{KEY}_low": k.ci_low / 100,
                                                   f"{KEY}_high": k.ci_high / 100})  # fmt: skip
        assert claims[cid].part == "beyond"
    assert claims["HZ-1-m"].verdict == "supported"  # NBO's error grows 1% -> 3.6%
    assert claims["HZ-2-m"].verdict == "not supported"  # here Monte Carlo's grows, the tree's not
    # the primary test's p-value: a t-test that the CI inverts (excludes 0 iff p < 0.05); the
    # bootstrap verdict is the rule's on the bootstrap CI
    evidence = horizon_evidence(df, summary, cfg, seed=2)
    assert [e.claim for e in evidence] == list(claims.values())
    for e, rule in zip(evidence, (hz1_rule(4, 24), hz2_rule("tree_n4_m256", "rsmhp_nt256", 4,
                       24)), strict=True):  # fmt: skip
        k = e.claim.key
        assert k.p_value == e.p_value and e.df == 25 - 1
        assert (e.p_value < 0.05) == (k.ci_low > 0 or k.ci_high < 0)
        # a decisive verdict: the two-sided t-test of 0, with the se the CI implies
        se = (k.ci_high - k.ci_low) / 2 / sps.t.ppf(0.975, e.df)
        assert e.p_value == pytest.approx(2 * sps.t.sf(abs(k.value) / se, e.df), rel=1e-6)
        assert e.boot_verdict == rule.verdict({f"{KEY}_low": e.boot_low / 100,
                                               f"{KEY}_high": e.boot_high / 100})  # fmt: skip
        assert "p = " in e.claim.measured and "percentile bootstrap" in e.claim.measured
    # with H = 2 and 24 only, the tree (64 leaves at H = 2) is not pruned at H = 2: HZ-2 starts
    # at the first pruned horizon, here only 24, so there is no HZ-2
    df2 = df.assign(H=df["H"].replace({4: 2}))
    ids = {c.id for c in horizon_claims(df2, summarize_approx(df2, 1, 200), cfg, seed=2)}
    assert ids == {"HZ-1-m"}


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (lambda hz: hz.update(models=["nowhere"]), "horizon.uav.models: ['nowhere'] not model"),
        (lambda hz: hz.update(steps=[0, 60]), "horizon.uav.steps: [60] not before"),
        (lambda hz: hz["methods"].update(nbo=False), "horizon.uav.methods.nbo: false"),
        (
            lambda hz: hz["claims"].update(tree="rsmhp_nt64"),
            "horizon.uav.claims.tree: 'rsmhp_nt64' is not a PrunedTree member",
        ),
        (
            lambda hz: hz["claims"].update(closed_model="paper2"),
            "horizon.uav.claims.closed_model: 'paper2' is not a model of horizon.uav.models",
        ),
        (
            lambda hz: hz["recording"].update(model="paper2"),
            "horizon.uav.recording.model: 'paper2' is not a model of horizon.uav.models",
        ),
        (
            lambda hz: hz["recording"].update(H=5),
            "horizon.uav.recording.H: 5 is not a horizon of horizon.uav.H",
        ),
        (
            lambda hz: hz["recording"].update(select="best"),
            "horizon.uav.recording.select",
        ),
    ],
)
def test_bad_horizon_config_is_refused_naming_the_field(edit, expected):
    from rsmhp.pipeline.config import ConfigError, check_config

    cfg = copy.deepcopy(CONFIG)
    edit(cfg["horizon"]["uav"])
    with pytest.raises(ConfigError, match=re.escape(expected)):
        check_config(cfg)


def test_closed_loop_rows_are_the_simulations_and_pair_across_horizons():
    """Oracle: each row is simulate_run's summary for the same model, H, seed and run; the
    scenario (initial target and UAV) is the same at every H, so runs pair across H."""
    from rsmhp.models.uav import methods
    from rsmhp.models.uav.simulation import draw_scenario, simulate_run
    from rsmhp.studies.horizon.simulate_uav import (
        closed_contract,
        horizon_setup,
        run_horizon_closed,
    )

    cfg = {**HZ, "closed_runs": 2, "methods": {"nbo": True, "rsmhp_nt": [16]}}
    rows = {H: run_horizon_closed(_uav(), MODELS, cfg, "paper", H, 9) for H in (2, 4)}
    for H, df in rows.items():
        check_table(df, "closed", closed_contract(cfg, "paper", H))
        setup = horizon_setup(_uav(), MODELS[0], H)
        want, _ = simulate_run(setup, methods.from_name("rsmhp_nt16"), 9, 1)
        got = df[(df["method"] == "rsmhp_nt16") & (df["run"] == 1)].iloc[0]
        assert got["mean_error"] == want["mean_error"] and got["plan_ms"] > 0
    a, b = (horizon_setup(_uav(), MODELS[0], H) for H in (2, 4))
    np.testing.assert_array_equal(draw_scenario(a, 9, 1).target, draw_scenario(b, 9, 1).target)


def test_advantage_growth_and_hz3_against_their_rule():
    from rsmhp.studies.horizon.claims import _hz3, hz3_rule
    from rsmhp.studies.horizon.summarise_uav import advantage_growth, summarize_closed

    rng = np.random.default_rng(8)
    n = 40
    base = rng.normal(100.0, 30.0, n)  # shared by every method and H: cancels in the pairing
    rows = []
    for H, adv in ((2, -5.0), (24, -20.0)):
        for method, shift in (("nbo", 0.0), ("rsmhp_nt256", adv)):
            e = base + shift + rng.normal(0.0, 2.0, n)
            rows += [{"model": "m", "H": H, "method": method, "family": method[:5], "run": r,
                      "mean_error": e[r], "final_error": 0.0, "plan_ms": 1.0}
                     for r in range(n)]  # fmt: skip
    closed = pd.DataFrame(rows)
    w = closed.pivot_table(index="run", columns=["H", "method"], values="mean_error")
    D = (w[(24, "rsmhp_nt256")] - w[(24, "nbo")]) - (w[(2, "rsmhp_nt256")] - w[(2, "nbo")])
    a = advantage_growth(closed, "m", "rsmhp_nt256", 2, 24, seed=1, n_boot=2000)
    assert a.mean == pytest.approx(D.mean()) and a.n == n and a.high < 0
    # a mean of per-run values: the jackknife over runs gives the Student-t interval
    assert (a.low, a.high) == pytest.approx(_student_t(D.to_numpy()), rel=1e-10)
    t_stat = D.mean() / (D.std(ddof=1) / np.sqrt(n))
    assert a.p_value == pytest.approx(2 * sps.t.sf(abs(t_stat), n - 1), rel=1e-8, abs=1e-300)
    assert a.boot_low < a.mean < a.boot_high
    assert a.d_lo == pytest.approx(-5.0, abs=1.5) and a.d_hi == pytest.approx(-20.0, abs=1.5)
    c = _hz3(closed, "m", "rsmhp_nt256", 2, 24, seed=1, n_boot=2000)
    assert c.key.p_value == a.p_value  # supported: the two-sided p-value behind it
    assert (
        c.verdict
        == hz3_rule("rsmhp_nt256", 2, 24).verdict({"D_low": c.key.ci_low, "D_high": c.key.ci_high})
        == "supported"
    )
    s = summarize_closed(closed, seed=1, n_boot=500).set_index(["H", "method"])
    d24 = (w[(24, "rsmhp_nt256")] - w[(24, "nbo")]).to_numpy()
    assert s.loc[(24, "rsmhp_nt256"), "error_diff"] == pytest.approx(d24.mean())
    assert (
        s.loc[(24, "rsmhp_nt256"), "error_diff_low"],
        s.loc[(24, "rsmhp_nt256"), "error_diff_high"],
    ) == pytest.approx(_student_t(d24), rel=1e-10)
    assert s.loc[(2, "nbo"), "error_diff"] == 0
    with pytest.raises(ValueError, match="no closed-loop runs of 'rsmhp_nt64' at H = 2"):
        advantage_growth(closed, "m", "rsmhp_nt64", 2, 24, seed=1, n_boot=100)


def test_warm_start_beyond_the_base_horizon_holds_the_last_control():
    """Oracle: the closed loop's shift_plan, which drops the applied control and repeats the
    last one; _warm extends a shifted plan the same way (and cuts it to a shorter H)."""
    from rsmhp.models.uav.planner import shift_plan
    from rsmhp.models.uav.scoring import BeliefState
    from rsmhp.studies.horizon.simulate_uav import _warm

    plan = np.array([[0.1, -0.2], [0.3, 0.4], [-0.5, 0.6]])
    st = BeliefState("m", 0, 1, np.zeros(4), np.zeros(4), np.eye(4), shift_plan(plan))
    long = _warm(st, 7)
    assert long.shape == (7, 2)
    np.testing.assert_array_equal(long[:3], st.warm)
    np.testing.assert_array_equal(long[3:], np.tile(plan[-1], (4, 1)))  # the last control held
    # one step beyond: what the closed loop's next shift would give
    np.testing.assert_array_equal(_warm(st, 4), np.vstack([st.warm, shift_plan(st.warm)[-1:]]))
    np.testing.assert_array_equal(_warm(st, 2), st.warm[:2])
    np.testing.assert_array_equal(_warm(st, 3), st.warm)
    assert not np.shares_memory(_warm(st, 2), st.warm)


def test_the_p_value_behind_each_verdict():
    """The key number's p_value (the report's Holm correction reads it): the two-sided t-test
    of 0 for a decisive verdict; for an inconclusive one the doubled one-sided p-value towards
    the claimed side, 1 when the estimate lies on the other side (as for the FR claims)."""
    from rsmhp.studies.horizon.claims import _verdict_p

    est, se, df = 0.3, 0.2, 9
    two_sided = 2 * sps.t.sf(abs(est) / se, df)
    assert _verdict_p("supported", est, se, df, "above") == pytest.approx(two_sided)
    assert _verdict_p("not supported", -est, se, df, "above") == pytest.approx(two_sided)
    assert _verdict_p("inconclusive", est, se, df, "above") == pytest.approx(two_sided)
    assert _verdict_p("inconclusive", est, se, df, "below") == 1.0


def test_key_numbers_carry_the_runs_their_cis_rest_on():
    """HZ-1/HZ-2: the cluster-t CI's clusters are runs, so ``n`` is the number of runs with a
    belief state shared by every member and horizon the growth compares; HZ-3: the runs
    paired at both horizons. Counted in the input, some rows dropped; no margin (the rules
    have none) and no claim is a check of our own machinery."""
    from rsmhp.studies.horizon.claims import horizon_claims

    rng = np.random.default_rng(6)
    methods = ("nbo", "tree_n4_m256", "rsmhp_nt256")
    lo = {m: rng.normal(0, 0.01, (24, 3)) for m in methods}
    hi = {m: rng.normal(0.01, 0.02, (24, 3)) for m in methods}
    # 24 belief states: 2 steps of 12 runs
    df = pd.concat([_table(lo, H=4, steps=2), _table(hi, H=24, steps=2)], ignore_index=True)
    df["family"] = df["method"].map({"nbo": "nbo", "tree_n4_m256": "tree", "rsmhp_nt256": "rsmhp"})
    gone = ((df["method"] == "nbo") & (df["H"] == 24) & (df["run"] == 3)) | (
        (df["method"] == "tree_n4_m256") & (df["H"] == 4) & df["run"].isin([0, 7])
    )
    gone |= (df["method"] == "rsmhp_nt256") & (df["run"] == 9) & (df["step"] == 0)  # 1 state
    df = df[~gone].reset_index(drop=True)
    rows = []
    for H in (2, 24):
        for method in ("nbo", "rsmhp_nt256"):
            e = 100.0 + rng.normal(0.0, 2.0, 15)
            skip = (2, 4) if (method, H) == ("nbo", 24) else ()  # runs without a result
            rows += [{"model": "m", "H": H, "method": method, "family": method[:5], "run": r,
                      "mean_error": e[r], "final_error": 0.0, "plan_ms": 1.0}
                     for r in range(15) if r not in skip]  # fmt: skip
    closed = pd.DataFrame(rows)
    cfg = {"bootstrap": 300, "claims": {"tree": "tree_n4_m256", "monte_carlo": "rsmhp_nt256",
                                        "closed_model": "m"}}  # fmt: skip
    summary = summarize_approx(df, seed=1, n_boot=200)
    claims = {c.id: c for c in horizon_claims(df, summary, cfg, seed=2, closed=closed)}
    assert set(claims) == {"HZ-1-m", "HZ-2-m", "HZ-3-m"}

    def runs_with_all(pairs: list[tuple[str, int]]) -> int:
        """Runs with a belief state that every (method, H) of ``pairs`` has."""
        have = [set(zip(*[df.loc[(df["method"] == m) & (df["H"] == h), c] for c in ("run", "step")],
                        strict=True)) for m, h in pairs]  # fmt: skip
        return len({run for run, _ in set.intersection(*have)})

    n1 = runs_with_all([("nbo", 4), ("nbo", 24)])
    n2 = runs_with_all([(m, h) for m in methods[1:] for h in (4, 24)])
    w = closed.pivot_table(index="run", columns=["H", "method"], values="mean_error")
    n3 = int(w.notna().all(axis=1).sum())
    assert (n1, n2, n3) == (11, 10, 13)
    for cid, n in (("HZ-1-m", n1), ("HZ-2-m", n2), ("HZ-3-m", n3)):
        c = claims[cid]
        assert c.key.n == n and c.key.margin is None and not c.check
    assert f"of {n1} runs" in claims["HZ-1-m"].measured
    assert claims["HZ-3-m"].measured.startswith(f"{n3} paired runs")
