"""Few-cluster statistics of :mod:`rsmhp.core.stats`: the jackknife-over-clusters t interval, the
bootstrap-t interval, Holm's adjustment, t-test power and one-sided / TOST p-values.

Oracles (no copied numbers except the hand-computed Holm example):

* :func:`rsmhp.core.stats.mean_ci` (Student t) for the jackknife of a mean, where
  :math:`\\mathrm{se}_{jack} = s/\\sqrt G` exactly;
* ``scipy.stats.ttest_1samp`` (two-sided, ``alternative="less"`` / ``"greater"``) on raw data
  for the p-values;
* Holm's step-down procedure written out as a loop, Bonferroni's bound;
* simulated paired t-tests for :func:`t_power`, simulated datasets for coverage.

Every statistical tolerance is 4 standard errors of the Monte Carlo estimate it bounds
(binomial for proportions, the delta method for a ratio of mean widths); every random draw
comes from a seeded :class:`numpy.random.Generator` (one fixed seed per test).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats as sps

from rsmhp.core.stats import (
    ClusterInterval,
    bootstrap_ci,
    bootstrap_t_ci,
    cluster_t_ci,
    holm,
    mean_ci,
    one_sided_p_value,
    runs_for_power,
    t_power,
    tost_p_value,
)

Z_TOL = 4.0  # Monte Carlo tolerance in standard errors


def _mean_stat(x: np.ndarray):
    return lambda idx: float(x[idx].mean())


# --- cluster_t_ci -------------------------------------------------------------------------


@pytest.mark.parametrize("g", [2, 3, 10, 50])
def test_cluster_t_ci_of_mean_is_student_t(g):
    rng = np.random.default_rng(1000 + g)
    for level in (0.9, 0.95, 0.99):
        x = rng.normal(3.0, 2.0, size=g)
        ci = cluster_t_ci(_mean_stat(x), g, level)
        m, lo, hi = mean_ci(x, level)
        assert isinstance(ci, ClusterInterval)
        assert ci.df == g - 1 and isinstance(ci.df, int)
        assert ci.se == pytest.approx(x.std(ddof=1) / math.sqrt(g), rel=1e-12)
        scale = max(1.0, abs(m))
        for got, want in ((ci.estimate, m), (ci.low, lo), (ci.high, hi)):
            assert abs(got - want) <= 1e-12 * scale


def test_cluster_t_ci_calls_stat_with_all_then_leave_one_out():
    g = 6
    calls: list[np.ndarray] = []

    def stat(idx):
        calls.append(np.array(idx))
        return float(np.sum(idx))

    cluster_t_ci(stat, g)
    assert len(calls) == g + 1
    assert calls[0].dtype.kind == "i" and np.array_equal(calls[0], np.arange(g))
    for i, idx in enumerate(calls[1:]):
        assert idx.ndim == 1 and idx.dtype.kind == "i"
        assert np.array_equal(idx, np.delete(np.arange(g), i))


def test_cluster_t_ci_ratio_of_equal_size_clusters_is_mean_of_ratios():
    """A ratio estimator sum(y)/sum(n) over clusters of equal size n is the mean of the
    per-cluster ratios, so its jackknife interval is that mean's t interval."""
    rng = np.random.default_rng(7)
    g, size = 12, 40
    y = rng.normal(1.0, 1.0, size=(g, size)).sum(axis=1)
    n = np.full(g, float(size))
    ci = cluster_t_ci(lambda idx: float(y[idx].sum() / n[idx].sum()), g)
    m, lo, hi = mean_ci(y / size)
    assert (ci.estimate, ci.low, ci.high) == pytest.approx((m, lo, hi), abs=1e-12)


def test_cluster_p_value_matches_ttest_1samp():
    rng = np.random.default_rng(11)
    for g in (2, 5, 10, 30):
        x = rng.normal(0.3, 1.0, size=g)
        ci = cluster_t_ci(_mean_stat(x), g)
        for null in (0.0, 0.3, -1.0, float(x.mean()) + 0.01):
            want = sps.ttest_1samp(x, null).pvalue
            assert ci.p_value(null) == pytest.approx(want, rel=1e-10, abs=1e-15)
    assert cluster_t_ci(_mean_stat(x), g).p_value() == pytest.approx(
        sps.ttest_1samp(x, 0.0).pvalue, rel=1e-10
    )


def test_cluster_p_value_with_zero_se():
    ci = cluster_t_ci(lambda idx: 2.0, 5)
    assert ci.se == 0 and ci.low == ci.high == 2.0
    assert ci.p_value(2.0) == 1.0
    assert ci.p_value(0.0) == 0.0
    with pytest.raises(TypeError, match="null"):
        ci.p_value("0")


@pytest.mark.parametrize(
    ("args", "exc", "words"),
    [
        ((lambda idx: 0.0, 1), ValueError, ["n_clusters", ">= 2", "got 1"]),
        ((lambda idx: 0.0, 0), ValueError, ["n_clusters", ">= 2", "got 0"]),
        ((lambda idx: 0.0, 2.5), ValueError, ["n_clusters", "2.5"]),
        ((lambda idx: 0.0, True), TypeError, ["n_clusters", "bool"]),
        ((3.0, 5), TypeError, ["stat", "callable"]),
        ((lambda idx: 0.0, 5, 1.0), ValueError, ["level", "got 1.0"]),
        ((lambda idx: float("nan") if idx.size < 5 else 0.0, 5), ValueError, ["stat", "finite"]),
        ((lambda idx: "x", 5), TypeError, ["stat(all clusters)"]),
    ],
)
def test_cluster_t_ci_refuses(args, exc, words):
    with pytest.raises(exc) as info:
        cluster_t_ci(*args)
    for w in words:
        assert w in str(info.value)


def test_cluster_t_ci_covers_at_nominal_level_with_ten_clusters():
    """95% coverage of the true mean by the interval of G = 10 normal cluster values, within
    4 binomial standard errors of the coverage estimate over 2000 datasets."""
    rng = np.random.default_rng(2024)
    g, n_data, mu, level = 10, 2000, 1.5, 0.95
    data = rng.normal(mu, 3.0, size=(n_data, g))
    hits = 0
    for x in data:
        ci = cluster_t_ci(_mean_stat(x), g, level)
        hits += ci.low <= mu <= ci.high
    coverage = hits / n_data
    se = math.sqrt(level * (1 - level) / n_data)
    assert abs(coverage - level) <= Z_TOL * se, (coverage, se)


def test_percentile_bootstrap_is_narrower_than_t_with_ten_clusters():
    """The percentile bootstrap interval of a mean of G = 10 values is on average narrower
    than the t interval (it uses normal-like quantiles and the 1/G variance, not t_{G-1} and
    1/(G-1)): the ratio of mean widths is below 1 by more than 4 delta-method standard errors
    over the 1000 simulated datasets."""
    rng = np.random.default_rng(99)
    g, n_data, n_boot, level = 10, 1000, 1000, 0.95
    data = rng.normal(0.0, 1.0, size=(n_data, g))
    w_t = np.empty(n_data)
    w_b = np.empty(n_data)
    for i, x in enumerate(data):
        ci = cluster_t_ci(_mean_stat(x), g, level)
        lo, hi = bootstrap_ci(x, rng, n_boot, level)
        w_t[i], w_b[i] = ci.high - ci.low, hi - lo
    ratio = w_b.mean() / w_t.mean()
    # delta method: Var(mean(b)/mean(t)) ~ Var(b - R t) / (N mean(t)^2)
    se = (w_b - ratio * w_t).std(ddof=1) / (math.sqrt(n_data) * w_t.mean())
    assert ratio + Z_TOL * se < 1.0, (ratio, se)


# --- bootstrap_t_ci -----------------------------------------------------------------------


def _bootstrap_t_reference(x, rng, n_boot, level):
    g = x.size
    m, se = x.mean(), x.std(ddof=1) / math.sqrt(g)
    idx = rng.integers(0, g, size=(n_boot, g))
    ts = []
    for row in idx:
        xb = x[row]
        se_b = xb.std(ddof=1) / math.sqrt(g)
        if se_b > 0:
            ts.append((xb.mean() - m) / se_b)
    q_lo, q_hi = np.quantile(ts, [(1 - level) / 2, (1 + level) / 2])
    return m - q_hi * se, m - q_lo * se, len(ts)


@pytest.mark.parametrize(("g", "n_boot"), [(3, 400), (10, 500)])
def test_bootstrap_t_ci_matches_a_loop(g, n_boot):
    x = np.random.default_rng(5).exponential(size=g)
    lo, hi = bootstrap_t_ci(x, np.random.default_rng(6), n_boot, 0.9)
    ref_lo, ref_hi, kept = _bootstrap_t_reference(x, np.random.default_rng(6), n_boot, 0.9)
    if g == 3:  # 3 of the 27 equally likely resamples repeat one cluster: some are dropped
        assert kept < n_boot
    assert (lo, hi) == pytest.approx((ref_lo, ref_hi), rel=1e-12, abs=1e-12)
    assert lo < x.mean() < hi


def test_bootstrap_t_ci_is_affine_equivariant_and_degenerate_for_constants():
    x = np.random.default_rng(8).normal(size=15)
    lo, hi = bootstrap_t_ci(x, np.random.default_rng(9), 300)
    lo2, hi2 = bootstrap_t_ci(4.0 + 2.5 * x, np.random.default_rng(9), 300)
    assert (lo2, hi2) == pytest.approx((4.0 + 2.5 * lo, 4.0 + 2.5 * hi), rel=1e-12)
    assert bootstrap_t_ci(np.full(7, 3.0), np.random.default_rng(1), 50) == (3.0, 3.0)


def test_bootstrap_t_ci_refuses():
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match="at least 2"):
        bootstrap_t_ci([1.0], rng, 10)
    with pytest.raises(ValueError, match="x must be finite"):
        bootstrap_t_ci([1.0, np.nan], rng, 10)
    with pytest.raises(ValueError, match="n_boot"):
        bootstrap_t_ci([1.0, 2.0], rng, 0)
    with pytest.raises(TypeError, match="rng"):
        bootstrap_t_ci([1.0, 2.0], 0, 10)
    with pytest.raises(ValueError, match="level"):
        bootstrap_t_ci([1.0, 2.0], rng, 10, level=0.0)
    # two clusters, one resample: it repeats one cluster with probability 1/2
    with pytest.raises(ValueError, match="zero standard error"):
        for seed in range(50):
            bootstrap_t_ci([1.0, 2.0], np.random.default_rng(seed), 1)


# --- holm ---------------------------------------------------------------------------------


def test_holm_hand_computed():
    # sorted: 0.005 (x4 = 0.02), 0.01 (x3 = 0.03), 0.03 (x2 = 0.06), 0.04 (x1 = 0.04 -> 0.06)
    p = np.array([0.01, 0.04, 0.03, 0.005])
    np.testing.assert_allclose(holm(p), [0.03, 0.06, 0.06, 0.02], rtol=1e-14)
    # NaN stays NaN and does not count; the cap at 1
    got = holm([0.2, np.nan, 0.5, 0.01])
    np.testing.assert_allclose(got, [0.4, np.nan, 0.5, 0.03], rtol=1e-14)
    np.testing.assert_array_equal(holm([0.7, 0.6]), [1.0, 1.0])
    assert holm([0.123])[0] == 0.123
    assert holm([]).size == 0
    assert np.isnan(holm([np.nan, np.nan])).all()


def test_holm_refuses():
    with pytest.raises(ValueError, match=r"p_values .*\[0, 1\].*1.5 at index 1"):
        holm([0.1, 1.5])
    with pytest.raises(ValueError, match="p_values"):
        holm([-0.1])
    with pytest.raises(ValueError, match="p_values"):
        holm([np.inf])
    with pytest.raises(ValueError, match="p_values must have 1 dimension"):
        holm([[0.1, 0.2]])
    with pytest.raises(TypeError, match="p_values"):
        holm(["a"])


_P = st.one_of(st.floats(0.0, 1.0), st.sampled_from([0.0, 1.0, 0.05, 0.01]), st.just(math.nan))


@settings(max_examples=300, deadline=None)
@given(p=st.lists(_P, min_size=1, max_size=25), alpha=st.floats(0.001, 0.999))
def test_holm_properties(p, alpha):
    p = np.array(p)
    adj = holm(p)
    nan = np.isnan(p)
    assert np.array_equal(np.isnan(adj), nan)
    raw, a = p[~nan], adj[~nan]
    m = raw.size
    if m == 0:
        return
    np.testing.assert_array_equal(holm(raw), a)  # NaNs do not count
    assert np.all(a >= raw)
    assert np.all(a <= np.minimum(1.0, m * raw))  # Bonferroni
    assert a.min() == min(1.0, m * raw.min())
    for i in range(m):  # order preserved
        assert np.all(a[raw >= raw[i]] >= a[i])
    # Holm's step-down procedure: reject H_(1), H_(2), ... while (m - k + 1) p_(k) <= alpha
    reject = np.zeros(m, dtype=bool)
    for k, i in enumerate(np.argsort(raw, kind="stable")):
        if (m - k) * raw[i] <= alpha:
            reject[i] = True
        else:
            break
    np.testing.assert_array_equal(a <= alpha, reject)


# --- power --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("n", "effect", "sd"), [(5, 1.0, 1.0), (10, 0.5, 2.0), (20, -0.4, 1.0), (8, 0.0, 1.5)]
)
def test_t_power_against_simulated_paired_t_tests(n, effect, sd):
    n_sim, level = 20000, 0.95
    rng = np.random.default_rng(3000 + n)
    d = rng.normal(effect, sd, size=(n_sim, n))  # paired differences
    t = d.mean(axis=1) / (d.std(axis=1, ddof=1) / math.sqrt(n))
    rejected = np.mean(np.abs(t) > sps.t.ppf((1 + level) / 2, n - 1))
    power = t_power(n, sd, effect, level)
    if effect == 0:
        assert power == pytest.approx(1 - level, abs=1e-12)
    se = math.sqrt(power * (1 - power) / n_sim)
    assert abs(rejected - power) <= Z_TOL * se, (rejected, power, se)


@pytest.mark.parametrize(
    ("sd", "effect", "level", "power"),
    [
        (1.0, 1.0, 0.95, 0.8),
        (1.0, 0.5, 0.95, 0.8),
        (2.0, -0.3, 0.99, 0.9),
        (1.0, 3.0, 0.95, 0.8),
        (1.0, 10.0, 0.95, 0.99),
        (0.7, 0.05, 0.9, 0.5),
        (1.0, 0.2, 0.95, 0.04),
    ],
)
def test_runs_for_power_is_exact(sd, effect, level, power):
    n = runs_for_power(sd, effect, level, power)
    assert isinstance(n, int) and n >= 2
    assert t_power(n, sd, effect, level) >= power
    assert n == 2 or t_power(n - 1, sd, effect, level) < power


def test_runs_for_power_known_values():
    # paired t-test, alpha = 0.05 two-sided, power 0.8: d = 0.5 needs 34 pairs, d = 1 needs 10
    # (the standard tables); the exactness above is the oracle, these guard the convention
    assert runs_for_power(1.0, 0.5) == 34
    assert runs_for_power(1.0, 1.0) == 10


@pytest.mark.parametrize("d", [0.1, 0.05, 0.02])
def test_normal_approximation_is_slightly_below_exact_n(d):
    z = sps.norm.ppf(0.975) + sps.norm.ppf(0.8)
    approx = (z / d) ** 2
    n = runs_for_power(1.0, d)
    # the t-test needs about z_{0.975}^2 / 2 ~ 1.9 more runs than the normal approximation
    assert math.ceil(approx) < n <= approx + 3


def test_power_edge_cases_and_refusals():
    assert runs_for_power(0.0, 0.3) == 2
    assert t_power(3, 0.0, 0.3) == 1.0
    assert t_power(10, 1.0, -0.5) == pytest.approx(t_power(10, 1.0, 0.5), rel=1e-12)
    with pytest.raises(ValueError, match="effect"):
        runs_for_power(1.0, 0.0)
    with pytest.raises(ValueError, match="sd"):
        runs_for_power(-1.0, 0.5)
    with pytest.raises(ValueError, match=r"max_n = 20.*power = 0.8.*effect = 0.1"):
        runs_for_power(1.0, 0.1, max_n=20)
    with pytest.raises(ValueError, match="power"):
        runs_for_power(1.0, 0.5, power=1.0)
    with pytest.raises(ValueError, match="n must be >= 2, got 1"):
        t_power(1, 1.0, 0.5)
    with pytest.raises(ValueError, match="sd = 0 and effect = 0"):
        t_power(5, 0.0, 0.0)
    with pytest.raises(TypeError, match="sd"):
        t_power(5, "1", 0.5)


# --- one-sided and TOST p-values ----------------------------------------------------------


def _summary(x):
    return float(x.mean()), float(x.std(ddof=1) / math.sqrt(x.size)), x.size - 1


def test_one_sided_p_value_matches_ttest_1samp():
    rng = np.random.default_rng(21)
    for g in (3, 10, 40):
        x = rng.normal(0.2, 1.0, size=g)
        est, se, df = _summary(x)
        for bound in (-0.5, 0.0, 0.2, 1.0):
            below = sps.ttest_1samp(x, bound, alternative="less").pvalue
            above = sps.ttest_1samp(x, bound, alternative="greater").pvalue
            assert one_sided_p_value(est, se, df, bound, "below") == pytest.approx(
                below, rel=1e-10, abs=1e-15
            )
            assert one_sided_p_value(est, se, df, bound, "above") == pytest.approx(
                above, rel=1e-10, abs=1e-15
            )


def test_tost_p_value_matches_two_ttest_1samp_and_the_interval():
    rng = np.random.default_rng(22)
    alpha = 0.05
    for g in (4, 10, 30):
        for _ in range(20):
            x = rng.normal(rng.uniform(-0.5, 0.5), 1.0, size=g)
            est, se, df = _summary(x)
            for margin in (0.2, 0.5, 1.0):
                want = max(
                    sps.ttest_1samp(x, -margin, alternative="greater").pvalue,
                    sps.ttest_1samp(x, margin, alternative="less").pvalue,
                )
                p = tost_p_value(est, se, df, margin)
                assert p == pytest.approx(want, rel=1e-10, abs=1e-15)
                # p <= alpha iff the 1 - 2 alpha t interval lies inside (-margin, margin)
                _, lo, hi = mean_ci(x, 1 - 2 * alpha)
                assert (p <= alpha) == (-margin < lo and hi < margin)


def test_one_sided_and_tost_edge_cases_and_refusals():
    assert one_sided_p_value(1.0, 0.0, 5, 2.0, "below") == 0.0
    assert one_sided_p_value(2.0, 0.0, 5, 2.0, "below") == 1.0
    assert one_sided_p_value(3.0, 0.0, 5, 2.0, "above") == 0.0
    assert one_sided_p_value(1.0, 0.5, math.inf, 0.0, "above") == pytest.approx(
        sps.norm.sf(2.0), rel=1e-12
    )
    assert tost_p_value(0.1, 0.0, 5, 0.5) == 0.0
    assert tost_p_value(0.5, 0.0, 5, 0.5) == 1.0
    with pytest.raises(ValueError, match="side must be one of"):
        one_sided_p_value(0.0, 1.0, 5, 0.0, "less")
    with pytest.raises(ValueError, match="se must be >= 0"):
        one_sided_p_value(0.0, -1.0, 5, 0.0, "above")
    with pytest.raises(ValueError, match="df must be > 0"):
        one_sided_p_value(0.0, 1.0, 0, 0.0, "above")
    with pytest.raises(ValueError, match="margin must be > 0"):
        tost_p_value(0.0, 1.0, 5, 0.0)
    with pytest.raises(TypeError, match="estimate"):
        tost_p_value(None, 1.0, 5, 1.0)


def test_mean_bootstrap_ci_is_the_mean_interval_and_nan_below_two_values():
    """The paired comparisons' one interval: bootstrap_ci of the mean on the same stream, and
    (nan, nan) without touching the stream when fewer than 2 values pair."""
    from rsmhp.core.stats import bootstrap_ci, mean_bootstrap_ci

    x = np.random.default_rng(3).normal(size=40)
    assert mean_bootstrap_ci(x, np.random.default_rng(7), 500) == bootstrap_ci(
        x, np.random.default_rng(7), 500, 0.95
    )
    rng = np.random.default_rng(7)
    state = rng.bit_generator.state
    assert all(np.isnan(v) for v in mean_bootstrap_ci(np.array([1.0]), rng, 500))
    assert rng.bit_generator.state == state
    lo, hi = mean_bootstrap_ci(x, np.random.default_rng(7), 2000, 0.95)
    assert lo < x.mean() < hi
