"""Prospective power of the verdict rules (rsmhp.core.stats.ci_within, rule_power,
rule_runs): against the noncentral t where one exists, against simulation where none does
(tolerances from the binomial variance of the simulated frequency), and the audit's figure."""

import numpy as np
import pytest
import scipy.stats

from rsmhp.core.stats import ci_within, rule_power, rule_runs


@pytest.mark.parametrize(
    ("n", "sd", "effect", "upper"),
    [(5, 1.0, 0.0, 1.0), (30, 2.0, -0.5, 0.25), (150, 69.8, 0.0, 0.25)],
)
def test_a_one_sided_bound_is_the_noncentral_t(n, sd, effect, upper):
    # mean + h < upper  <=>  T = (mean - upper)/(s/sqrt n) < -t,
    # T ~ t'(n - 1, (effect - upper) sqrt n / sd)
    crit = scipy.stats.t.ppf(0.975, n - 1)
    exact = scipy.stats.nct.cdf(-crit, n - 1, (effect - upper) * np.sqrt(n) / sd)
    assert ci_within(n, sd, effect, -np.inf, upper) == pytest.approx(exact, abs=1e-7)


def _simulated(n, sd, effect, lower, upper, reps, seed):
    d = np.random.default_rng(seed).normal(effect, sd, (reps, n))
    m, s = d.mean(axis=1), d.std(axis=1, ddof=1)
    h = scipy.stats.t.ppf(0.975, n - 1) * s / np.sqrt(n)
    return float(np.mean((lower < m - h) & (m + h < upper)))


@pytest.mark.parametrize(
    ("n", "sd", "effect", "lower", "upper"),
    [(20, 1.0, 0.0, -0.6, 0.6), (12, 1.0, 0.2, -0.8, 0.8), (40, 3.0, -1.0, -0.25, 0.0)],
)
def test_a_two_sided_window_agrees_with_simulation(n, sd, effect, lower, upper):
    reps = 40_000
    p = ci_within(n, sd, effect, lower, upper)
    sim = _simulated(n, sd, effect, lower, upper, reps, seed=n)
    se = np.sqrt(max(p * (1 - p), 1e-4) / reps)
    assert abs(sim - p) < 4.5 * se  # a false alarm about once in 150,000 runs


def test_the_rules_and_their_run_counts():
    # superiority: "supported" = interval below 0 and not inside the margin
    # (400 units of sd 1: the interval, 0.2 wide, can fit inside (-0.25, 0) and then reads
    # "equivalent", so "supported" is rarer than "below 0")
    sup = rule_power("superiority", 400, 1.0, 0.25, effect=-0.1)
    below = ci_within(400, 1.0, -0.1, -np.inf, 0.0)
    inside = ci_within(400, 1.0, -0.1, -0.25, 0.0)
    assert 0 < inside and 0 < sup < below and sup == pytest.approx(below - inside)
    assert rule_power("equivalence", 20, 1.0, 0.6) == ci_within(20, 1.0, 0.0, -0.6, 0.6)
    # the smallest n reaching 80%
    for rule, sd, margin, effect in [("equivalence", 1.0, 0.5, 0.0),
                                     ("non-inferiority", 2.0, 0.5, 0.0),
                                     ("superiority", 2.0, 0.25, -1.0)]:  # fmt: skip
        n = rule_runs(rule, sd, margin, effect)
        assert rule_power(rule, n, sd, margin, effect) >= 0.8
        assert n == 2 or rule_power(rule, n - 1, sd, margin, effect) < 0.8
    # equivalence at a true difference outside the margin never gets there
    assert rule_runs("equivalence", 1.0, 0.5, effect=0.6, max_n=5000) is None
    with pytest.raises(ValueError, match="rule: 'tost'"):
        rule_power("tost", 10, 1.0, 0.5)
    with pytest.raises(ValueError, match="lower"):
        ci_within(10, 1.0, 0.0, 1.0, -1.0)


def test_the_audits_figure_for_fr2_on_footprint150():
    """The second preregistration stated 0.99 power for FR-2-footprint150 at a 25 m effect,
    but its rule is non-inferiority at 0.25 m: at a true difference of 0 (sd 69.8 m, 150 runs)
    the upper limit d + t s/sqrt(n) must fall below 0.25 m, probability about
    Phi((0.25 - t sd/sqrt n) / (sd/sqrt n)) = Phi(-1.94) = 0.026 (normal approximation)."""
    n, sd = 150, 69.8
    approx = scipy.stats.norm.cdf((0.25 - 1.976 * sd / np.sqrt(n)) / (sd / np.sqrt(n)))
    assert approx == pytest.approx(0.026, abs=0.001)
    assert rule_power("non-inferiority", n, sd, 0.25) == pytest.approx(approx, abs=0.003)
