"""The oven LQG at long horizons (rsmhp.studies.horizon.simulate_lqg,
rsmhp.studies.horizon.summarise_lqg,
claims HZ-4/HZ-5, the closed-loop run counts of rsmhp.studies.horizon.summarise_uav).

Oracles: the exact cost J and NBO's cost of each problem (closed forms of rsmhp.models.lqg.oven),
the sigma points' exactness for a quadratic cost, uniform Monte Carlo's variance (closed form:
a z-test with a tolerance from it), the regret closed forms and their limit, hand computations
of the growth statistic on tables with known errors, and the printed rules.
"""

from __future__ import annotations

import copy
import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from rsmhp.models.lqg import oven as lqg
from rsmhp.models.lqg.regret_summary import bonferroni
from rsmhp.pipeline.contracts import check_table
from rsmhp.studies.horizon import closed_forms as lh
from rsmhp.studies.horizon import simulate_lqg as E
from rsmhp.studies.horizon import summarise_lqg as A
from rsmhp.studies.horizon.claims import HZ5_RULE, hz4_rule, lqg_horizon_claims
from rsmhp.studies.horizon.summarise_uav import runs_to_resolve, summarize_closed

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
MODEL = {"x0": 0.0, "r": 10.0, "target": 1.0, "sigma": 1.0}
CFG = {
    "a_values": [0.5],
    "H": [2],
    "eps": 0.01,
    "sim_a": [0.5],
    "sim_H": [2, 3, 6],
    "replicates": 40,
    "estimators": {"n": [4, 8]},
    "regret": {"P": [8, 32], "pruned_N": 4, "methods": ["nbo", "mc", "cubature", "pruned"]},
    "bootstrap": 500,
    "claims": {"pruned": {"N": 2, "M": 4}},
}
CFG["estimators"]["pruned_N"] = [2, 16]


@pytest.fixture(scope="module")
def est() -> pd.DataFrame:
    return E.run_lqg_estimators(CFG, MODEL, seed=5)


def test_problems_plan_the_h_step_optimum():
    specs = E.problem_specs(CFG, MODEL)
    assert list(specs) == ["hz_a0.5_h2", "hz_a0.5_h3", "hz_a0.5_h6"]
    u = lqg.optimal_controls(6, x0=0.0, a=0.5, r=10.0, target=1.0)
    np.testing.assert_array_equal(specs["hz_a0.5_h6"]["u"], u)


def test_only_pruned_trees_run_and_at_equal_trajectory_counts():
    problems = {n: E.build_problem(s, MODEL) for n, s in E.problem_specs(CFG, MODEL).items()}
    pts = E.estimator_points(CFG, problems)
    for p in pts:
        if p.scheme == "pruned":  # the full tree has more than M leaves
            assert p.N ** problems[p.problem].H > p.M
            assert E.n_trajectories(p, problems[p.problem]) == p.M
    # N = 2 at H = 2 has 4 leaves: no pruned cell with M = 4 or 8 there
    assert not [p for p in pts if p.problem == "hz_a0.5_h2" and p.scheme == "pruned" and p.N == 2]
    for prob in problems:
        mc = {p.n for p in pts if p.problem == prob and p.scheme == "mc"}
        assert mc == {p.n for p in pts if p.problem == prob and p.scheme == "sobol"} == {4, 8}
    assert E.pruned_from(4, 64, [2, 4, 24]) == 4 and E.pruned_from(4, 64, [2, 3]) is None


def test_estimator_rows_against_the_exact_oracles(est):
    check_table(est, "est", E.estimator_contract(CFG, MODEL))
    for _, g in est.groupby("problem"):
        H = int(g["H"].iloc[0])
        u = lqg.optimal_controls(H, x0=0.0, a=0.5, r=10.0, target=1.0)
        kw = {"x0": 0.0, "a": 0.5, "r": 10.0, "target": 1.0}
        assert g["J_exact"].iloc[0] == pytest.approx(lqg.exact_cost(u, **kw, sigma=1.0))
        assert g["J_nbo"].iloc[0] == pytest.approx(lqg.nbo_cost(u, **kw))
        cub = g[g["scheme"] == "cubature"]["estimate"]
        assert cub.iloc[0] == pytest.approx(g["J_exact"].iloc[0], rel=1e-12)
        nbo = g[g["scheme"] == "nbo"]["estimate"]
        assert nbo.iloc[0] == pytest.approx(g["J_nbo"].iloc[0], rel=1e-12)


def test_monte_carlo_is_unbiased_with_its_closed_form_variance(est):
    """z-test of the mean of R uniform-mc estimates against J with the closed-form SD
    sqrt(Var g / n / R); and the summary's closed-form RMSE is that SD times sqrt(R)."""
    s = A.summarize_lqg_estimators(est, CFG, MODEL, seed=5)
    mc = s[(s["scheme"] == "mc") & (s["weighting"] == "uniform")]
    assert len(mc) == 6
    for _, row in mc.iterrows():
        x = A.relative_errors(est, 0.5, int(row["H"]), "mc", n=int(row["n_trajectories"]))
        se = row["rel_rmse_theory"] / math.sqrt(x.size)
        assert abs(x.mean()) < 4.5 * se  # 4.5 SE: family of 6, two-sided, ~4e-5 false alarms
        assert row["rel_bias"] == pytest.approx(x.mean())
        assert row["rel_rmse"] == pytest.approx(math.sqrt(np.mean(x * x)))
    nbo = s[s["scheme"] == "nbo"]
    np.testing.assert_allclose(nbo["rel_bias"], nbo["nbo_rel_error"], rtol=1e-12)


def test_estimators_do_not_depend_on_workers(est):
    pd.testing.assert_frame_equal(
        est.drop(columns="cpu_seconds"),
        E.run_lqg_estimators(CFG, MODEL, seed=5, n_jobs=2).drop(columns="cpu_seconds"),
    )


def _rows(errors: dict[tuple[str, int, int], np.ndarray]) -> pd.DataFrame:
    """Estimator rows with the given relative errors per (scheme, N, H), J = 10, n = 4."""
    out = []
    for (scheme, N, H), e in errors.items():
        out += [{"problem": E.problem_name(0.5, H), "scheme": scheme, "weighting": "uniform",
                 "N": N, "M": 4 if N else 0, "H": H, "n_trajectories": 4, "n_nodes": 1,
                 "replicate": r, "estimate": 10.0 * (1 + x), "J_exact": 10.0, "J_nbo": 1.0,
                 "cpu_seconds": 0.0} for r, x in enumerate(e)]  # fmt: skip
    return pd.DataFrame(out)


def test_pruned_growth_by_hand_and_its_rule():
    rng = np.random.default_rng(3)
    e = {("pruned", 2, 3): rng.normal(0, 0.3, 400), ("pruned", 2, 6): rng.normal(0, 0.6, 400),
         ("mc", 0, 3): rng.normal(0, 0.2, 400), ("mc", 0, 6): rng.normal(0, 0.2, 400)}  # fmt: skip
    df = _rows(e)

    def rmse(x):
        return math.sqrt(np.mean(x * x))

    g = A.pruned_growth(df, 0.5, 2, 4, 3, 6, seed=1, n_boot=2000)
    want = (rmse(e[("pruned", 2, 6)]) - rmse(e[("pruned", 2, 3)])) - (
        rmse(e[("mc", 0, 6)]) - rmse(e[("mc", 0, 3)])
    )
    assert g.mean == pytest.approx(want) and g.low < g.mean < g.high and g.low > 0
    assert g.mc_growth_low < 0 < g.mc_growth_high  # Monte Carlo's error does not move
    rule = hz4_rule(2, 4, 3, 6)
    assert rule.verdict({"g_low": g.low, "g_high": g.high}) == "supported"
    assert rule.verdict({"g_low": -0.2, "g_high": -0.1}) == "not supported"
    assert rule.verdict({"g_low": -0.1, "g_high": 0.1}) == "inconclusive"
    # the opposite data: Monte Carlo grows, the tree does not
    swapped = {("pruned", 2, 3): e[("mc", 0, 3)], ("pruned", 2, 6): e[("mc", 0, 6)],
               ("mc", 0, 3): e[("pruned", 2, 3)], ("mc", 0, 6): e[("pruned", 2, 6)]}  # fmt: skip
    g2 = A.pruned_growth(_rows(swapped), 0.5, 2, 4, 3, 6, seed=1, n_boot=2000)
    assert g2.mean == pytest.approx(-want) and g2.high < 0
    with pytest.raises(ValueError, match=r"no estimator rows for a = 0.5, H = 9"):
        A.pruned_growth(df, 0.5, 2, 4, 3, 9, seed=1, n_boot=100)


@settings(max_examples=30, deadline=None)
@given(a=st.floats(0.05, 0.95), r=st.floats(0.1, 50.0), P=st.integers(1, 10_000))
def test_monte_carlo_regret_tends_to_its_limit(a, r, P):
    lim = lh.mc_regret_limit(P, a=a, r=r, sigma=1.3)
    vals = [lqg.expected_regret(P, H, a=a, r=r, sigma=1.3) for H in (1, 4, 16, 400)]
    assert all(v <= lim * (1 + 1e-12) for v in vals)  # rises to the limit from below
    assert np.all(np.diff(vals) >= -1e-15 * lim)
    assert vals[-1] == pytest.approx(lim, rel=1e-9)


def test_regret_summary_limits_and_hz5_follow_the_closed_forms():
    reg = E.run_lqg_regret(CFG, MODEL, seed=4)
    check_table(reg, "reg", E.regret_contract(CFG))
    s = A.summarize_lqg_horizon_regret(reg, MODEL)
    mc = s[(s["method"] == "mc") & (s["weighting"] == "uniform")]
    for _, row in mc.iterrows():
        assert row["limit"] == pytest.approx(lh.mc_regret_limit(int(row["P"]), a=0.5, r=10.0,
                                                                sigma=1.0))  # fmt: skip
        assert row["closed_form"] == pytest.approx(
            lqg.expected_regret(int(row["P"]), int(row["H"]), a=0.5, r=10.0, sigma=1.0)
        )
    assert (s.loc[s["method"].isin(["nbo", "cubature"]), "limit"] == 0).all()
    assert s.loc[s["weighting"] == "likeliness", "limit"].isna().all()
    (hz5,) = [c for c in lqg_horizon_claims(pd.DataFrame(), s, CFG, 0.5, 4) if c.id == "HZ-5"]
    z = mc["z"].abs().max()
    assert hz5.key.value == pytest.approx(z)
    limit = bonferroni(6)  # 3 H x 2 P uniform-mc cells
    assert len(mc) == 6 and hz5.measured.startswith(f"Bonferroni limit {limit:.3g}")
    assert hz5.verdict == HZ5_RULE.verdict({"max |z|": z, "z limit": limit})
    bad = s.copy()
    bad.loc[bad["method"] == "mc", "z"] = 9.0
    (hz5b,) = [c for c in lqg_horizon_claims(pd.DataFrame(), bad, CFG, 0.5, 4)]
    assert hz5b.verdict == "not supported"


def test_hz4_runs_from_the_first_pruned_horizon(est):
    claims = {c.id: c for c in lqg_horizon_claims(est, pd.DataFrame(), CFG, 0.5, 5)}
    c = claims["HZ-4"]
    assert "H = 3 → 6" in c.key.name  # N = 2, M = 4: 4 leaves at H = 2, 8 at H = 3
    g = A.pruned_growth(est, 0.5, 2, 4, 3, 6, 5, 500)
    assert c.key.value == pytest.approx(100 * g.mean)
    assert c.verdict == hz4_rule(2, 4, 3, 6).verdict({"g_low": g.low, "g_high": g.high})
    # a model a that was not simulated has no HZ-4
    assert not [c for c in lqg_horizon_claims(est, pd.DataFrame(), CFG, 0.3, 5)]


def test_runs_to_resolve_and_the_closed_loop_summary():
    """Runs needed = the paired t-test's sample size for 80% power at the observed effect
    (rsmhp.core.stats.runs_for_power), larger than (1.96 SD / |d|)², which gives about 50% power."""
    from rsmhp.core.stats import runs_for_power, t_power

    for d, sd in ((1.0, 1.0), (-0.5, 2.0), (0.3, 1.7)):
        n = runs_to_resolve(d, sd)
        assert n == runs_for_power(sd, d, level=0.95, power=0.8)
        assert n > math.ceil((1.96 * sd / abs(d)) ** 2)
        assert t_power(int(n), sd, d) >= 0.8 > t_power(int(n) - 1, sd, d)
        # the old count gives about half the power
        assert t_power(max(2, math.ceil((1.96 * sd / abs(d)) ** 2)), sd, d) < 0.55
    assert runs_to_resolve(10.0, 0.1) == 2
    assert math.isnan(runs_to_resolve(0.0, 1.0)) and math.isnan(runs_to_resolve(1.0, np.nan))
    assert runs_to_resolve(1e-6, 1.0) == math.inf  # beyond 10⁶ runs
    rng = np.random.default_rng(2)
    rows = []
    for method, shift in (("nbo", 0.0), ("rsmhp_nt16", -1.0)):
        e = 10 + shift + rng.normal(0, 2.0, 30)
        rows += [{"model": "m", "H": 2, "method": method, "family": method[:5], "run": r,
                  "mean_error": e[r], "final_error": 0.0, "plan_ms": 1.0}
                 for r in range(30)]  # fmt: skip
    s = summarize_closed(pd.DataFrame(rows), seed=1, n_boot=500).set_index("method")
    d = s.loc["rsmhp_nt16"]
    assert d["runs_to_resolve"] == runs_to_resolve(d["error_diff"], d["diff_sd"])
    assert s.loc["nbo", "diff_sd"] == 0 and math.isnan(s.loc["nbo", "runs_to_resolve"])


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (
            lambda hz: hz["estimators"].update(n=[16, 48]),
            "horizon.lqg.estimators.n: 48 is not a power of 2",
        ),
        (
            lambda hz: hz["claims"]["pruned"].update(N=8),
            "horizon.lqg.claims.pruned.N: 8 is not in horizon.lqg.estimators.pruned_N",
        ),
        (
            lambda hz: hz["claims"]["pruned"].update(M=32),
            "horizon.lqg.claims.pruned.M: 32 is not in horizon.lqg.estimators.n",
        ),
        (
            lambda hz: hz.update(sim_H=[2, 3]),
            "horizon.lqg.claims.pruned: N = 4, M = 64 is pruned (N^H > M) at 0 of",
        ),
        (lambda hz: hz["regret"].update(methods=["tree"]), "horizon.lqg.regret.methods[0]"),
    ],
)
def test_bad_lqg_horizon_config_is_refused_naming_the_field(edit, expected):
    from rsmhp.pipeline.config import ConfigError, check_config

    cfg = copy.deepcopy(CONFIG)
    edit(cfg["horizon"]["lqg"])
    with pytest.raises(ConfigError, match=re.escape(expected)):
        check_config(cfg)


def test_hz4_carries_its_replicates_and_hz5_is_a_check():
    """HZ-4's CI resamples each cell's independent replicates: ``n`` is the replicates per
    cell, counted in the input (here 37, not the config's 40); its rule has no margin.
    HZ-5 tests Monte Carlo's regret against its closed form: a check of our own machinery,
    without ``n``."""
    rng = np.random.default_rng(9)
    cells = (("pruned", 2, 3), ("pruned", 2, 6), ("mc", 0, 3), ("mc", 0, 6))
    est = _rows({cell: rng.normal(0, 0.3, 37) for cell in cells})
    summary = pd.DataFrame(
        [{"method": "mc", "weighting": "uniform", "closed_kind": "exact", "a": 0.5, "H": H,
          "P": P, "z": 0.3, "closed_form": 1.0 / P, "limit": 1.1 / P}
         for H in (2, 6) for P in (8, 32)]
    )  # fmt: skip
    claims = {c.id: c for c in lqg_horizon_claims(est, summary, CFG, 0.5, 5)}
    assert set(claims) == {"HZ-4", "HZ-5"}
    hz4, hz5 = claims["HZ-4"], claims["HZ-5"]
    assert hz4.key.n == 37 == est.groupby(["scheme", "H"]).size().min()
    assert hz4.measured.startswith("37 replicates per cell")
    assert hz4.key.margin is None and not hz4.check
    assert hz5.check and hz5.key.n is None and hz5.key.margin is None
