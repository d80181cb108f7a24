"""LQG study: aggregation, verdict rules, report section and figures; stats helpers and
intermediate-file checks."""

from __future__ import annotations

import re

import matplotlib.colors as mcolors
import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from rsmhp.core.stats import (
    ExceedanceTest,
    binomial_ci,
    detectable_scale,
    exceedance_test,
    loglog_slope,
    mean_ci,
    rmse_ci,
)
from rsmhp.models.lqg import oven as lqg
from rsmhp.models.lqg.linear_quadratic import LinearCost, LinearQuadratic
from rsmhp.pipeline.io import IntermediateFileError, read_table, write_csv
from rsmhp.report import verdicts
from rsmhp.report.ledger import Section
from rsmhp.report.markdown import fmt
from rsmhp.report.palette import method_colour
from rsmhp.studies.lqg import claims
from rsmhp.studies.lqg import figures as figs
from rsmhp.studies.lqg import section as narrative
from rsmhp.studies.lqg import summarise as analysis
from rsmhp.studies.lqg.simulate import (
    CONVERGENCE_COLUMNS,
    LINEAR_COST_COLUMNS,
    run_convergence,
    run_linear_cost,
    run_nbo_error,
)
from tests.conftest import PAPER, PAPER_U
from tests.core.test_seeding import BASE

NAN_INF = re.compile(r"\b(nan|inf)\b", re.IGNORECASE)

J = lqg.exact_cost(PAPER_U, **PAPER)
J_NBO = lqg.nbo_cost(PAPER_U, x0=0.0, a=0.5, r=10.0, target=1.0)
#: the paper's trajectory cost g as a quadratic form of the noise (exact tail of J_P)
FORM = LinearQuadratic.from_lqg(lqg.LQGModel(**PAPER), PAPER_U).quadratic_form

#: text budgets of a claim (ledger v2: claims state their scope, rules their exceedance tests)
CLAIM_MAX, PAPER_MAX, RULE_MAX = 200, 160, 650


def synthetic(errors_by_p: dict[int, np.ndarray], weighted_offset: float = 0.0) -> pd.DataFrame:
    """A convergence table with prescribed errors J_mhp - J (paper model)."""
    rows = []
    for P, err in errors_by_p.items():
        for i, e in enumerate(err):
            rows.append(
                {
                    "a": 0.5,
                    "H": 2,
                    "sigma": 1.0,
                    "r": 10.0,
                    "target": 1.0,
                    "x0": 0.0,
                    "u": "0.55;0.17",
                    "P": P,
                    "replicate": i,
                    "J_mhp": J + e,
                    "J_mhp_weighted": J + weighted_offset + e,
                    "J_nbo": J_NBO,
                    "J_exact": J,
                }
            )
    return pd.DataFrame(rows, columns=CONVERGENCE_COLUMNS)


def test_summary_values_from_known_errors():
    err = np.array([-1.0, 0.5, 2.0, -3.0])
    s = analysis.summarize_convergence(synthetic({100: err, 400: err / 2}), [1.0, 2.5])
    first = s.iloc[0]
    assert first["mean"] == pytest.approx(J + err.mean())
    assert first["rmse"] == pytest.approx(np.sqrt(np.mean(err**2)))
    assert first["exceed_eps1"] == pytest.approx(3 / 4)  # |e| >= 1: -1, 2, -3
    assert first["exceed_eps2.5"] == pytest.approx(1 / 4)
    assert first["bound_eps1"] == pytest.approx(min(1.0, lqg.cost_variance(PAPER_U, **PAPER) / 100))
    assert first["sd_theory"] == pytest.approx(np.sqrt(lqg.mhp_variance(100, PAPER_U, **PAPER)))
    assert s["P"].tolist() == [100, 400]
    # the exact probability of |J_P - J| >= eps (generalised chi-square of the quadratic form)
    for _, row in s.iterrows():
        P = int(row["P"])
        for eps in (1.0, 2.5):
            e = analysis.eps_label(eps)
            exact = row[f"exact_eps{e}"]
            assert exact == pytest.approx(FORM.mean_error_tail(P, eps), abs=1e-12)
            # J_P is nearly Gaussian at these P (CLT): 2 Phi(-eps/sd) is within 0.005 of it
            assert exact == pytest.approx(2 * sps.norm.sf(eps / row["sd_theory"]), abs=5e-3)
            assert 0 < exact <= row[f"bound_eps{e}"]  # Chebyshev's bound holds exactly
            # the power of the cell's test: 4 replicates over 2 x 2 cells
            want = detectable_scale(
                lambda x, P=P: FORM.mean_error_tail(P, x),
                eps,
                4,
                4,
                grid=analysis.DETECTABLE_GRID,
            )
            assert row[f"detectable_eps{e}"] == want
    assert s["exact_eps1"].iloc[1] < s["exact_eps1"].iloc[0]  # larger P: rarer exceedances
    long = analysis.chebyshev_long(s, [1.0, 2.5])
    assert len(long) == 4 and {"exact", "detectable"} <= set(long.columns)
    assert long["k"].tolist() == [3, 2, 1, 0]  # (eps 1: P 100, 400), (eps 2.5: P 100, 400)


def test_fig3_and_prop3_verdicts_follow_the_data():
    rng = np.random.default_rng(0)
    var = lqg.cost_variance(PAPER_U, **PAPER)
    ps = [100, 400, 1600, 6400]
    good = synthetic({p: rng.normal(0, np.sqrt(var / p), 300) for p in ps})
    c2, c3, _ = claims.convergence_claims(analysis.summarize_convergence(good, [1.0]), [1.0])
    assert c2.verdict == "supported" and c3.verdict == "supported"
    assert c2.key.null == 0.0 and c2.key.ci_high < 0
    # no cell departs from the exact probability: every Bonferroni-adjusted p is >= 0.05
    assert c3.key.value >= 0.05 and "(4 cells)" in c3.key.name
    assert "0 cells depart from the exact probability" in c3.measured
    # errors that do not shrink with P and are far larger than NBO's error and the bound
    bad = synthetic({p: rng.normal(0, 15.0, 300) for p in ps})
    c2b, c3b, _ = claims.convergence_claims(analysis.summarize_convergence(bad, [1.0]), [1.0])
    assert c2b.verdict == "not supported"
    assert c3b.verdict == "not supported" and c3b.key.value < 0.05
    check = analysis.chebyshev_check(analysis.summarize_convergence(bad, [1.0]), [1.0])
    assert check.test.above_bound >= 1 and check.test.departing >= 1


def _pm(s: float, n: int = 40) -> np.ndarray:
    """n errors, half +s and half -s: mean 0 and RMSE exactly s."""
    return np.repeat([s, -s], n // 2)


def test_fig3_verdict_edge_cases():
    ps = [100, 400, 1600, 6400]
    # RMSE that does not fall with P (slope CI around 0), far below NBO's error: inconclusive
    flat = synthetic(dict(zip(ps, [_pm(1.0), _pm(1.2), _pm(0.9), _pm(1.1)], strict=True)))
    c = claims.fig3_claim(analysis.summarize_convergence(flat, [1.0]))
    assert c.key.ci_low < 0 < c.key.ci_high and c.verdict == "inconclusive"
    # RMSE falls, but the mean keeps a bias of 0.5 at the largest P (its CI excludes J): a bias
    # that does not vanish is evidence against the claim, not merely a lack of evidence
    shrinking = {p: _pm(20 / np.sqrt(p)) for p in ps}
    biased = synthetic({p: e + 0.5 for p, e in shrinking.items()})
    summary = analysis.summarize_convergence(biased, [1.0])
    assert not summary["ci_low"].iloc[-1] <= J <= summary["ci_high"].iloc[-1]
    c = claims.fig3_claim(summary)
    assert c.key.ci_high < 0 and c.verdict == "not supported"
    c = claims.fig3_claim(analysis.summarize_convergence(synthetic(shrinking), [1.0]))
    assert c.verdict == "supported" and c.key.value == pytest.approx(-0.5)


def _cells(k: int, n: int = 300) -> np.ndarray:
    """n errors of which k are 1.5 (exceed eps = 1) and the rest 0."""
    return np.r_[np.full(k, 1.5), np.zeros(n - k)]


def test_chebyshev_verdict_edge_cases():
    var = lqg.cost_variance(PAPER_U, **PAPER)
    # three cells, all with a bound below 1; at P = 12800 and 25600 eps = 1 is >= 4.5 sd, so
    # 0 exceedances of 300 agree with the exact probability; at P = 6400 the exact probability
    # is 0.0013 and the bound 0.096
    ps, n = [6400, 12800, 25600], 300
    bound = var / ps[0]
    # the most exceedances whose familywise (Bonferroni over 3 cells) Clopper-Pearson lower
    # limit is still at or below the bound: far too many for the exact probability
    k = max(k for k in range(n) if binomial_ci(k, n, 1 - 0.05 / 3)[0] <= bound)
    assert binomial_ci(k, n)[0] > bound  # per cell (no familywise correction) it would exceed
    errs = {ps[0]: _cells(k), ps[1]: np.zeros(n), ps[2]: np.zeros(n)}
    summary = analysis.summarize_convergence(synthetic(errs), [1.0])
    check = analysis.chebyshev_check(summary, [1.0])
    assert (check.test.cells, check.test.departing, check.test.above_bound) == (3, 1, 0)
    assert check.test.exact_above_bound == 0 and check.n_informative == 3
    assert (check.worst_P, check.worst_eps, check.worst_freq) == (6400, 1.0, k / n)
    assert check.worst_exact == pytest.approx(FORM.mean_error_tail(6400, 1.0))
    assert check.test.max_exact_ratio == pytest.approx(FORM.mean_error_tail(6400, 1.0) / bound)
    assert check.replicates == n and check.n_cells == 3
    c = claims.chebyshev_claim(summary, [1.0])
    assert c.verdict == "inconclusive" and c.key.value < 0.05 and not c.dropped
    assert c.key.value == check.test.min_p and c.rule == claims.CHEBYSHEV_RULE.text()
    assert "1 cells depart from the exact probability, 0 lie significantly above" in c.measured
    # one more exceedance: the familywise lower limit lies above the bound: not supported
    errs[ps[0]] = _cells(k + 1)
    c = claims.chebyshev_claim(analysis.summarize_convergence(synthetic(errs), [1.0]), [1.0])
    assert c.verdict == "not supported"
    assert "1 lie significantly above the bound" in c.measured


def test_chebyshev_detects_a_spread_that_is_too_small():
    # J_P - J drawn with half its true SD: far fewer exceedances than the exact probability,
    # none above the bound; with 300 replicates the test has the power to see it
    rng = np.random.default_rng(3)
    var = lqg.cost_variance(PAPER_U, **PAPER)
    ps = [100, 400]
    narrow = synthetic({p: rng.normal(0, 0.5 * np.sqrt(var / p), 300) for p in ps})
    check = analysis.chebyshev_check(analysis.summarize_convergence(narrow, [1.0]), [1.0])
    assert check.detectable < 0.5  # a 50% spread error is within the test's resolution
    assert check.test.departing >= 1 and check.test.above_bound == 0
    c = claims.chebyshev_claim(analysis.summarize_convergence(narrow, [1.0]), [1.0])
    assert c.verdict == "inconclusive" and c.key.value < 0.05
    assert f"off by {fmt(100 * check.detectable, 2)}%" in c.measured


def test_chebyshev_claim_says_when_no_bound_is_informative():
    # every bound Var(g)/(P eps^2) >= 1 and 4 replicates: the text says both
    vac = synthetic({p: np.random.default_rng(p).normal(0, 1, 4) for p in (100, 200, 300)})
    summary = analysis.summarize_convergence(vac, [0.25])
    check = analysis.chebyshev_check(summary, [0.25])
    assert check.n_informative == 0 and np.isnan(check.test.max_exact_ratio)
    assert check.detectable == np.inf and check.test.exact_above_bound == 0
    c = claims.chebyshev_claim(summary, [0.25])
    assert "no cell has a bound below 1" in c.measured
    assert "no cell detects a spread error below 50% with 80% power" in c.measured
    assert not NAN_INF.search(c.measured)


def test_weighted_verdict_detects_bias_and_agreement():
    err = {p: np.random.default_rng(p).normal(0, 0.1, 50) for p in (100, 200, 300)}
    lim_gap = lqg.weighted_limit(PAPER_U, **PAPER) - J
    biased = analysis.summarize_convergence(synthetic(err, weighted_offset=lim_gap), [1.0])
    assert claims.convergence_claims(biased, [1.0])[2].verdict == "not supported"
    unbiased = analysis.summarize_convergence(synthetic(err), [1.0])
    assert claims.convergence_claims(unbiased, [1.0])[2].verdict == "supported"
    # a CI wide enough to hold both J and the derived limit J(sigma^2/2): inconclusive
    wide = {p: _pm(30.0, 50) for p in (100, 200, 300)}
    both = analysis.summarize_convergence(synthetic(wide, weighted_offset=lim_gap / 2), [1.0])
    c = claims.weighted_claim(both)
    assert c.key.ci_low < J + lim_gap and c.key.ci_high > J
    assert c.verdict == "inconclusive"


def _nbo_grid(z: list[float]) -> pd.DataFrame:
    """An NBO-error summary with prescribed z-scores (closed form 10, SE 0.1)."""
    n = len(z)
    sim = 10.0 + 0.1 * np.asarray(z)
    return pd.DataFrame(
        {
            "a": np.linspace(0.1, 0.9, n),
            "H": 1,
            "n_replicates": 3,
            "P": 50,
            "u_value": 0.3,
            "nbo_error_sim": sim,
            "se": 0.1,
            "ci_low": sim - 0.196,
            "ci_high": sim + 0.196,
            "nbo_error_closed": 10.0,
            "z": z,
            "rel_dev": (sim - 10.0) / 10.0,
        }
    )


def test_nbo_error_claim_rejects_a_wrong_formula():
    conv = run_convergence(BASE, seed=2)
    nbo = analysis.summarize_nbo_error(run_nbo_error(BASE, seed=2))
    assert claims.nbo_error_claim(nbo, conv).verdict in ("supported", "not supported")
    wrong = nbo.assign(nbo_error_closed=nbo["nbo_error_closed"] * 1.5)
    wrong = wrong.assign(z=(wrong["nbo_error_sim"] - wrong["nbo_error_closed"]) / wrong["se"])
    assert claims.nbo_error_claim(wrong, conv).verdict == "not supported"


def test_nbo_error_verdict_at_the_bonferroni_limit():
    # the paper's setting with J_P = J exactly: z = 0 there, so the grid decides
    conv = synthetic({100: np.zeros(4), 200: np.zeros(4)})
    assert analysis.paper_setting_nbo_error(conv).z == pytest.approx(0.0, abs=1e-9)
    limit = analysis.nbo_z_limit(4)  # 4 grid cells + the paper's setting = 5 tests
    assert limit == pytest.approx(sps.norm.ppf(1 - 0.025 / 5))
    at = claims.nbo_error_claim(_nbo_grid([0.1, -limit, 0.5, 1.0]), conv)
    assert at.verdict == "supported" and at.key.value == pytest.approx(limit)
    assert "over 5 tests" in at.key.name and at.key.reproducible == "bitwise"
    above = claims.nbo_error_claim(_nbo_grid([0.1, -limit - 0.01, 0.5, 1.0]), conv)
    assert above.verdict == "not supported"


def test_read_table_reports_corrupt_files(tmp_path):
    with pytest.raises(IntermediateFileError, match="not found"):
        read_table(tmp_path / "missing.csv", ["a"])
    bad = tmp_path / "bad.csv"
    bad.write_bytes(b"\x00\x01garbage\n\xff")
    with pytest.raises(IntermediateFileError):
        read_table(bad, ["J_mhp"])
    write_csv(pd.DataFrame({"a": [1.0], "b": [2.0]}), tmp_path / "ok.csv")
    with pytest.raises(IntermediateFileError, match=r"missing column\(s\) \['J_mhp'\]"):
        read_table(tmp_path / "ok.csv", ["a", "J_mhp"])
    assert read_table(tmp_path / "ok.csv", ["a"])["b"].iloc[0] == 2.0


def test_stats_helpers():
    lo, hi = binomial_ci(0, 10)
    assert lo == 0 and hi == pytest.approx(1 - 0.025 ** (1 / 10))
    m, lo, hi = mean_ci(np.array([1.0, 2.0, 3.0]))
    assert m == 2 and hi - m == pytest.approx(4.302652729911275 * 1 / np.sqrt(3))
    x = np.array([10.0, 100.0, 1000.0, 10000.0])
    fit = loglog_slope(x, 3 * x**-0.5)
    assert fit.slope == pytest.approx(-0.5) and fit.high - fit.low < 1e-9  # exact power law
    noisy = loglog_slope(x, 3 * x**-0.5 * np.exp([0.1, -0.1, -0.1, 0.1]))
    assert noisy.contains(-0.5) and noisy.high - noisy.low > 0.01
    r, lo, hi = rmse_ci(np.array([3.0, -4.0]))
    assert r == pytest.approx(np.sqrt(12.5)) and lo < r < hi


def test_exceedance_test_counts_departures_and_bound_failures():
    # agreement: k = n p exactly, exact probability below the bound
    t = exceedance_test([50], [100], [0.5], [0.9])
    assert t == ExceedanceTest(1, 0, 0, 0, 1.0, 0, pytest.approx(0.5 / 0.9))
    # a count far from the exact probability departs; a bound of 1 cannot be exceeded
    t = exceedance_test([90], [100], [0.5], [1.0])
    assert (t.departing, t.above_bound, t.exact_above_bound) == (1, 0, 0)
    assert t.min_p == pytest.approx(sps.binomtest(90, 100, 0.5).pvalue) and t.min_p < 1e-15
    assert np.isnan(t.max_exact_ratio)  # no cell has a bound below 1
    # far above the bound (and the exact probability): both
    t = exceedance_test([30], [100], [0.05], [0.1])
    assert (t.departing, t.above_bound) == (1, 1)
    # far below the exact probability: departs, not above the bound
    t = exceedance_test([0], [200], [0.1], [0.2])
    assert (t.departing, t.above_bound) == (1, 0)
    # several cells: the worst is the one with the smallest adjusted p-value
    t = exceedance_test([50, 90, 10], [100, 100, 100], [0.5, 0.5, 0.1], [0.9, 1.0, 0.2])
    assert (t.cells, t.departing, t.above_bound, t.worst) == (3, 1, 0, 1)
    assert t.min_p == pytest.approx(3 * sps.binomtest(90, 100, 0.5).pvalue)
    assert t.max_exact_ratio == pytest.approx(0.5 / 0.9)


def test_exceedance_test_boundaries():
    # Bonferroni: p = 0.035 departs alone (< 0.05) but not next to a second cell (< 0.025)
    p61 = sps.binomtest(61, 100, 0.5).pvalue
    assert 0.025 < p61 < 0.05
    assert exceedance_test([61], [100], [0.5], [1.0]).departing == 1
    two = exceedance_test([61, 50], [100, 100], [0.5, 0.5], [1.0, 1.0])
    assert two.departing == 0 and two.min_p == pytest.approx(2 * p61) and two.worst == 0
    # adjusted p-values are capped at 1
    assert exceedance_test([50, 50], [100, 100], [0.5, 0.5], [1.0, 1.0]).min_p == 1.0
    # a Clopper-Pearson lower limit equal to the bound is not above it; just below it is
    low = binomial_ci(30, 100)[0]
    assert exceedance_test([30], [100], [0.05], [low]).above_bound == 0
    assert exceedance_test([30], [100], [0.05], [low - 1e-9]).above_bound == 1
    # ... at the familywise level over the cells
    low3 = binomial_ci(30, 100, 1 - 0.05 / 3)[0]
    cells = ([30, 0, 0], [100] * 3, [0.05, 0.01, 0.01])
    assert exceedance_test(*cells, [low, 1.0, 1.0]).above_bound == 0  # low > low3
    assert exceedance_test(*cells, [low3 - 1e-9, 1.0, 1.0]).above_bound == 1
    # an exact probability equal to its bound (to rounding) is not above it
    assert exceedance_test([5], [100], [0.2], [0.2]).exact_above_bound == 0
    assert exceedance_test([5], [100], [0.2 * (1 + 1e-12)], [0.2]).exact_above_bound == 0
    assert exceedance_test([5], [100], [0.2 * (1 + 1e-6)], [0.2]).exact_above_bound == 1


@pytest.mark.parametrize(
    "args",
    [
        ([1, 2], [10], [0.5], [1.0]),  # lengths differ
        ([[1]], [[10]], [[0.5]], [[1.0]]),  # 2-D
        ([], [], [], []),  # no cell
        ([1], [10], [1.5], [1.0]),  # not a probability
        ([1], [10], [np.nan], [1.0]),
        ([11], [10], [0.5], [1.0]),  # more hits than replicates
    ],
)
def test_exceedance_test_rejects_bad_input(args):
    with pytest.raises(ValueError):
        exceedance_test(*args)


def _gauss_tail(x):
    """Exact tail 2 Phi(-x) of |N(0, 1)|."""
    return 2 * sps.norm.sf(np.asarray(x, dtype=float))


def _detected(delta: float, eps: float, n: int, cells: int, power: float = 0.8) -> bool:
    """Whether a spread off by ``delta`` meets detectable_scale's criterion (normal approx.)."""
    p = float(_gauss_tail(eps))
    need = (sps.norm.ppf(1 - 0.05 / cells / 2) + sps.norm.ppf(power)) * np.sqrt(p * (1 - p) / n)
    return abs(float(_gauss_tail(eps / (1 + delta))) - p) >= need


def test_detectable_scale_is_the_smallest_detected_spread_error():
    d = detectable_scale(_gauss_tail, 2.0, 1000, 1)
    assert 0 < d < 0.2 and d == pytest.approx(round(d / 0.005) * 0.005)  # on the default grid
    # the criterion holds at d (on one side) and fails one grid step closer on both sides
    assert _detected(d, 2.0, 1000, 1) or _detected(-d, 2.0, 1000, 1)
    assert not _detected(d - 0.005, 2.0, 1000, 1) and not _detected(0.005 - d, 2.0, 1000, 1)
    # more replicates resolve less; more cells (Bonferroni) and more power need more
    assert detectable_scale(_gauss_tail, 2.0, 10_000, 1) < d
    assert detectable_scale(_gauss_tail, 2.0, 1000, 20) > d
    assert detectable_scale(_gauss_tail, 2.0, 1000, 1, power=0.95) > d
    # a custom grid: the answer is one of its points
    grid = np.array([0.1, 0.2, 0.4])
    assert detectable_scale(_gauss_tail, 2.0, 1000, 1, grid=grid) in (0.1, 0.2, 0.4)


def test_detectable_scale_without_power_is_infinite():
    assert detectable_scale(lambda x: np.zeros_like(np.asarray(x, float)), 1.0, 100, 1) == np.inf
    flat = detectable_scale(lambda x: np.full(np.shape(x), 0.3), 1.0, 100, 1)
    assert flat == np.inf  # the tail does not depend on the spread
    assert detectable_scale(_gauss_tail, 2.0, 5, 1, grid=np.array([0.01])) == np.inf
    with pytest.raises(ValueError):
        detectable_scale(_gauss_tail, 2.0, 100, 1, level=1.0)


# ------------------------------------------------ Prop. 3 on a linear-cost system (LIN-1)

LINEAR_CFG = {"linear_cost": {"H": 3, "n": [10, 50], "replicates": 200}}
KS = [1.5, 2.0, 3.0]


@pytest.fixture(scope="module")
def linear_runs() -> pd.DataFrame:
    return run_linear_cost(LINEAR_CFG, seed=2)


def test_run_linear_cost_rows_and_constants(linear_runs):
    df = linear_runs
    assert list(df.columns) == LINEAR_COST_COLUMNS and len(df) == 2 * 200
    assert sorted(df.groupby("n").size().to_dict().items()) == [(10, 200), (50, 200)]
    system = LinearCost.example(3)
    assert (df["H"] == 3).all()
    np.testing.assert_array_equal(df["J_exact"], system.exact_cost())
    np.testing.assert_array_equal(df["var_prop3"], system.prop3_variance())
    pd.testing.assert_frame_equal(df, run_linear_cost(LINEAR_CFG, seed=2))
    assert not np.allclose(df["estimate"], run_linear_cost(LINEAR_CFG, seed=3)["estimate"])


def test_linear_cost_check_agrees_with_prop3(linear_runs):
    check = analysis.linear_cost_check(linear_runs, KS)
    system = LinearCost.example(3)
    var, J_lin = system.prop3_variance(), system.exact_cost()
    assert check.n == (10, 50) and check.replicates == 200 and check.H == 3
    assert check.var_form == pytest.approx(check.var_prop3, rel=1e-12)
    assert check.var_prop3 == var
    assert check.z_limit == pytest.approx(sps.norm.ppf(1 - 0.025 / 5))
    # the z values, recomputed from their definitions
    for n, vz, mz in zip(check.n, check.var_z, check.mean_z, strict=True):
        est = linear_runs.loc[linear_runs["n"] == n, "estimate"].to_numpy()
        ratio = est.var(ddof=1) / (var / n)
        assert vz == pytest.approx((ratio - 1) / np.sqrt(2 / 199))
        assert mz == pytest.approx((est.mean() - J_lin) / np.sqrt(var / n / 200))
    zs = [*check.var_z, *check.mean_z, check.pooled_z]
    assert check.max_abs_z == pytest.approx(max(abs(z) for z in zs))
    assert check.max_abs_z <= check.z_limit and check.max_abs_z < 3
    # J_n is Gaussian: the exact probability of |J_n - J| >= k sd_n is 2 Phi(-k) for every n
    t = check.exceedance
    assert t.cells == 6 and t.departing == 0 and t.above_bound == 0
    assert t.exact_above_bound == 0
    assert t.max_exact_ratio == pytest.approx(max(2 * sps.norm.sf(k) * k**2 for k in KS))
    c = claims.linear_claim(check)
    assert c.id == "LIN-1" and c.verdict == "supported"
    assert c.rule == claims.LINEAR_RULE.text() and "over 5 variance and mean tests" in c.key.name
    assert c.key.value == check.max_abs_z and "H = 3" in c.setup and c.part == "paper"
    assert not NAN_INF.search(c.measured)


def test_linear_cost_check_rejects_a_wrong_variance(linear_runs):
    # the estimates' spread about J scaled by 1.3: the variance is 1.69 times the formula's
    wide = linear_runs.copy()
    wide["estimate"] = wide["J_exact"] + 1.3 * (wide["estimate"] - wide["J_exact"])
    check = analysis.linear_cost_check(wide, KS)
    assert min(check.var_z) > check.z_limit and check.pooled_z > check.z_limit
    assert check.exceedance.departing >= 1
    assert claims.linear_claim(check).verdict == "not supported"
    # the estimates themselves scaled by 1.3: mean and variance both wrong
    scaled = linear_runs.assign(estimate=linear_runs["estimate"] * 1.3)
    check = analysis.linear_cost_check(scaled, KS)
    assert min(abs(z) for z in check.mean_z) > check.z_limit
    assert claims.linear_claim(check).verdict == "not supported"
    with pytest.raises(ValueError, match="lacks columns"):
        analysis.linear_cost_check(linear_runs.drop(columns="estimate"), KS)


EXCEEDANCE_OK = {
    "cells": 6,
    "departing": 0,
    "above bound": 0,
    "exact above bound": 0,
    "detectable": 0.2,
}
LINEAR_OK = {"max |z|": 1.0, "z limit": 2.5, **EXCEEDANCE_OK}


@pytest.mark.parametrize(
    ("change", "verdict"),
    [
        ({}, "supported"),
        ({"max |z|": 2.5}, "supported"),  # |z| at the limit is within it
        ({"max |z|": 2.5 + 1e-9}, "not supported"),
        ({"above bound": 1}, "not supported"),
        ({"above bound": 1, "max |z|": 0.0}, "not supported"),
        ({"departing": 1}, "inconclusive"),
        ({"exact above bound": 1}, "inconclusive"),
        ({"cells": 0}, "inconclusive"),
    ],
)
def test_linear_rule_edges(change, verdict):
    assert claims.LINEAR_RULE.verdict({**LINEAR_OK, **change}) == verdict


EPS = [0.25, 1.0]


@pytest.fixture(scope="module")
def small(linear_runs):
    """Summaries, tables and the section of the small LQG configuration
    (tests/core/test_seeding.py)."""
    conv = run_convergence(BASE, seed=2)
    nbo = analysis.summarize_nbo_error(run_nbo_error(BASE, seed=2))
    summary = analysis.summarize_convergence(conv, EPS)
    tables = narrative.lqg_tables(summary, nbo, EPS)
    linear = analysis.linear_cost_check(linear_runs, KS)
    section = narrative.lqg_section(summary, nbo, conv, EPS, tables, linear)
    return {
        "conv": conv,
        "nbo": nbo,
        "summary": summary,
        "tables": tables,
        "section": section,
        "linear": linear,
    }


def _column(table: str, header: str) -> list[str]:
    """Cells of column ``header`` of a Markdown table."""
    rows = [[c.strip() for c in line.strip().strip("|").split("|")] for line in table.splitlines()]
    i = rows[0].index(header)
    return [r[i] for r in rows[2:]]


def test_section_budget_numbers_and_roundtrip(small, tmp_path):
    section = small["section"]
    assert len(section.body.encode("utf-8")) <= 2600
    assert [c.id for c in section.claims] == ["LQG-1", "LQG-2", "LQG-3", "LQG-4", "LIN-1"]
    for text in (section.body, section.appendix, *(c.measured for c in section.claims)):
        assert not re.search(r"\b(nan|inf)\b", text, re.IGNORECASE), text
        # integers (P, H, counts of replicates, trajectories, cells, tests) have no decimals
        assert not re.search(r"\b[PHR] = \d+\.\d", text), text
        assert not re.search(r"\d\.\d+ (replicates|trajectories|cells|tests|checks)", text), text
    for c in section.claims:
        assert len(c.claim) <= CLAIM_MAX and len(c.paper) <= PAPER_MAX, c.id
        assert len(c.rule) <= RULE_MAX, c.id
        # LQG-3 applies Chebyshev to the oven's quadratic cost, outside Prop. 3's linear premise
        assert c.part == ("beyond" if c.id == "LQG-3" else "paper") and not c.contrary
    assert {c.setup for c in section.claims[:4] if c.id != "LQG-3"} == {claims.SETUP}
    assert "outside Prop. 3's linear premise" in section.claims[2].setup
    assert section.claims[-1].setup.startswith("linear-cost")
    # LIN-1 in the body, with its key number and verdict
    lin = section.claims[-1]
    assert f"{lin.key.name} = {fmt(lin.key.value, 3)}; LIN-1 {lin.verdict}" in section.body
    conv_table = small["tables"]["lqg_convergence"]
    assert _column(conv_table, "P") == ["20", "40", "60"]
    assert set(_column(conv_table, "replicates")) == {"4"}
    cheb = small["tables"]["lqg_chebyshev"]
    assert all(re.fullmatch(r"\d+", v) for v in _column(cheb, "exceedances"))
    exact = [float(v) for v in _column(cheb, "exact probability")]
    assert len(exact) == 6 and all(0 < v <= 1 for v in exact)
    for name in narrative.FIGURES:
        assert f"(figures/{name}.png)" in section.body
    assert section.figures == [f"{f}.png" for f in narrative.FIGURES]
    for key in ("x_k", "u_k", "w_k", "σ", "weight r", "target T", "horizon H", "J_NBO", "Var(g)"):
        assert key in section.body
    for stem in narrative.TABLES:
        assert small["tables"][stem] in section.appendix
    section.save(tmp_path / "lqg.json")
    assert Section.load(tmp_path / "lqg.json") == section


def _hex(c) -> str:
    return mcolors.to_hex(c)


def test_figures_use_the_method_colours(small):
    conv, summary, nbo = small["conv"], small["summary"], small["nbo"]
    fig = figs.fig3_paper_figure(conv, summary)
    (ax,) = fig.axes
    colours = {ln.get_label().split()[0]: _hex(ln.get_color()) for ln in ax.get_lines()}
    assert colours == {
        "MHP": method_colour("mc"),
        "exact": method_colour("exact"),
        "NBO": method_colour("nbo"),
    }
    assert not ax.collections  # the paper's way: one realisation and two lines, nothing else
    assert ax.get_title() and "P" in ax.get_xlabel() and "cost" in ax.get_ylabel()
    fig = figs.convergence_figure(conv, summary)
    for ax in fig.axes:
        assert ax.get_title() and ax.get_xlabel() and "cost" in ax.get_ylabel()
    mean = [ln for ln in fig.axes[0].get_lines() if ln.get_label() == "MHP J_P, mean"]
    assert _hex(mean[0].get_color()) == method_colour("mc")
    for coll in fig.axes[0].collections:
        assert _hex(coll.get_facecolor()[0]) == method_colour("mc")
    fig = figs.error_loglog_figure(summary, EPS)
    nbo_line = [ln for ln in fig.axes[0].get_lines() if ln.get_label().startswith("NBO")]
    assert _hex(nbo_line[0].get_color()) == method_colour("nbo")
    fig = figs.nbo_error_figure(nbo)
    top, resid = fig.axes
    assert "cost" in top.get_ylabel() and "SE" in resid.get_ylabel()
    limit = analysis.nbo_z_limit(len(nbo))
    levels = sorted(ln.get_ydata()[0] for ln in resid.get_lines())
    assert levels == pytest.approx([-limit, 0.0, limit])
    assert len(set(map(str, figs.nbo_shades(4)))) == 4
    import matplotlib.pyplot as plt

    plt.close("all")


def test_nbo_residual_panel_clips_and_says_so(small):
    import matplotlib.pyplot as plt

    nbo = small["nbo"].copy()
    nbo.loc[0, "z"] = 50.0
    fig = figs.nbo_error_figure(nbo)
    resid = fig.axes[1]
    assert resid.get_ylim()[1] < 50
    texts = [t.get_text() for t in resid.texts]
    assert any("1 residuals beyond ±8 drawn at the edge" in t for t in texts)
    plt.close(fig)


# ------------------------------------------------ verdict rules (rsmhp.studies.lqg.claims) at
# their edges

FIG3_OK = {
    "slope_low": -0.6,
    "slope_high": -0.4,
    "mean_low": 18.0,
    "mean_high": 19.0,
    "J": 18.5,
    "rmse_low": 0.1,
    "rmse_high": 0.2,
    "nbo_error": 12.5,
}


@pytest.mark.parametrize(
    ("change", "verdict"),
    [
        ({}, "supported"),
        ({"J": 19.0}, "supported"),  # J on the CI's edge is inside it
        ({"slope_high": 0.0}, "inconclusive"),  # a CI touching 0 does not lie below it
        ({"slope_low": 0.0, "slope_high": 0.1}, "not supported"),  # at/above 0
        ({"rmse_high": 12.5}, "inconclusive"),  # upper limit not below NBO's error
        ({"rmse_low": 12.5, "rmse_high": 13.0}, "not supported"),  # lower limit reaches it
        ({"rmse_low": 12.4999, "rmse_high": 13.0}, "inconclusive"),  # just below it
        ({"J": 18.0}, "supported"),  # J on the CI's lower edge is inside it
        ({"J": 19.01}, "not supported"),  # the mean's CI excludes J: a bias that stays
        ({"J": 17.99}, "not supported"),
        ({"J": 19.01, "slope_high": 0.0}, "not supported"),  # the bias decides alone
    ],
)
def test_fig3_rule_edges(change, verdict):
    assert claims.FIG3_RULE.verdict({**FIG3_OK, **change}) == verdict


def test_fig3_facts_come_from_the_check(small):
    check = analysis.fig3_check(small["summary"])
    facts = claims.fig3_facts(check)
    assert set(facts) == set(FIG3_OK)
    assert (facts["mean_low"], facts["mean_high"], facts["J"]) == (
        check.ci_low,
        check.ci_high,
        check.J,
    )
    assert facts["nbo_error"] == pytest.approx(12.5)  # r sigma^2 (1 + (1-a)^2) = 10 * 1.25


@pytest.mark.parametrize(
    ("change", "verdict"),
    [
        ({}, "supported"),
        ({"departing": 1}, "inconclusive"),  # a count departs from the exact probability
        ({"exact above bound": 1}, "inconclusive"),  # the "bound" is not one
        ({"detectable": verdicts.POWER_LIMIT}, "supported"),
        ({"detectable": verdicts.POWER_LIMIT + 0.01}, "inconclusive"),  # no power: not a test
        ({"above bound": 1}, "not supported"),
        ({"above bound": 1, "departing": 0, "cells": 1}, "not supported"),
        ({"above bound": 2, "departing": 2}, "not supported"),
        ({"cells": 0}, "inconclusive"),  # no cell: no evidence
    ],
)
def test_chebyshev_rule_edges(change, verdict):
    assert claims.CHEBYSHEV_RULE.verdict({**EXCEEDANCE_OK, **change}) == verdict
    # the same rule object with another basis (EST-3 and LIN-1 reuse it)
    assert verdicts.exceedance_rule("any basis").verdict({**EXCEEDANCE_OK, **change}) == verdict


def test_chebyshev_rule_verdicts_and_facts():
    assert claims.CHEBYSHEV_RULE.verdicts == ("not supported", "supported", "inconclusive")
    assert claims.CHEBYSHEV_RULE.text().startswith("per (P, ε) cell")
    test = ExceedanceTest(
        cells=4,
        departing=2,
        above_bound=1,
        exact_above_bound=3,
        min_p=0.01,
        worst=2,
        max_exact_ratio=0.5,
    )
    assert verdicts.exceedance_facts(test) == {
        "cells": 4,
        "departing": 2,
        "above bound": 1,
        "exact above bound": 3,
        "detectable": float("inf"),  # no power stated: not a test
    }
    assert verdicts.exceedance_facts(test, 0.12)["detectable"] == 0.12


@pytest.mark.parametrize(
    ("J", "limit", "verdict"),
    [
        (2.0, 0.0, "supported"),  # J on the CI's upper edge (inside), the limit outside
        (2.0, 1.0, "inconclusive"),  # the limit on the lower edge counts as inside
        (2.0001, 0.0, "not supported"),
    ],
)
def test_weighted_rule_edges(J, limit, verdict):
    facts = {"ci_low": 1.0, "ci_high": 2.0, "J": J, "limit": limit}
    assert claims.WEIGHTED_RULE.verdict(facts) == verdict


def test_claims_print_the_rule_they_apply(small):
    section = small["section"]
    by_id = {c.id: c for c in section.claims}
    n_tests = len(small["nbo"]) + 1
    rule = claims.nbo_error_rule(analysis.nbo_z_limit(len(small["nbo"])), n_tests)
    assert by_id["LQG-1"].rule == rule.text()
    assert f"Bonferroni over {n_tests} tests" in rule.text()
    assert by_id["LQG-2"].rule == claims.FIG3_RULE.text()
    assert by_id["LQG-3"].rule == claims.CHEBYSHEV_RULE.text()
    assert by_id["LQG-4"].rule == claims.WEIGHTED_RULE.text()
    assert by_id["LIN-1"].rule == claims.LINEAR_RULE.text()
    for c in section.claims:
        assert c.rule.endswith("otherwise")
    # the claims of the section are those of lqg_claims, LIN-1 from the linear-cost check
    again = claims.lqg_claims(small["summary"], small["nbo"], small["conv"], EPS, small["linear"])
    assert again == section.claims
    assert again[-1] == claims.linear_claim(small["linear"])


def test_checks_are_the_closed_form_claims_and_no_key_number_has_n(small):
    """LQG-1, LQG-3 and LIN-1 test the simulation against closed forms (checks of our own
    machinery, counted apart from the findings); LQG-2 and LQG-4 are findings. No key number
    here is a paired mean difference judged against a margin: ``n`` and ``margin`` stay
    unset."""
    section = small["section"]
    assert {c.id for c in section.claims if c.check} == {"LQG-1", "LQG-3", "LIN-1"}
    assert all(c.key.n is None and c.key.margin is None for c in section.claims)
