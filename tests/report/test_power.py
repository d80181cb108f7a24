"""Runs needed at 80% power (rsmhp.report.power) against simulated experiments."""

import math

import numpy as np
import pytest
from scipy import stats

from rsmhp.report.ledger import KeyNumber
from rsmhp.report.power import runs_needed, runs_text

Z = stats.norm.ppf(0.975)


def _key(theta, se, n, null=0.0, margin=None):
    """A key number with a 95% t interval of half-width t_{0.975,n-1}·se around ``theta``."""
    half = stats.t.ppf(0.975, n - 1) * se
    return KeyNumber("d", theta, theta - half, theta + half, null=null, n=n, margin=margin)


def _exact_power(delta, sigma, n):
    """Power of the one-sided step "the 95% t CI lies beyond the boundary" at true distance
    ``delta``: P(T > t_{0.975,n-1}), T noncentral t with n-1 df and noncentrality δ√n/σ."""
    return float(stats.nct.sf(stats.t.ppf(0.975, n - 1), n - 1, delta * math.sqrt(n) / sigma))


def _fraction(theta, n, reps, decide, seed):
    """Share of simulated experiments (n unit-variance normal draws, mean theta) whose 95%
    t CI satisfies ``decide(low, high)``."""
    x = np.random.default_rng(seed).normal(theta, 1.0, size=(reps, n))
    m, s = x.mean(axis=1), x.std(axis=1, ddof=1) / math.sqrt(n)
    t = stats.t.ppf(0.975, n - 1)
    return float(np.mean(decide(m - t * s, m + t * s)))


def test_runs_against_the_exact_noncentral_t_power():
    # sigma = 1, delta = 0.3: the normal approximation gives (2.8016/0.3)^2 = 87.2; the
    # t-based n is the smallest with about 80% power
    n = runs_needed(_key(0.3, 1 / math.sqrt(20), 20))
    assert 88 <= n <= 92
    assert 0.795 <= _exact_power(0.3, 1.0, n) <= 0.82
    assert _exact_power(0.3, 1.0, n - 3) < 0.80
    # small samples: the t quantiles matter (the normal approximation would say 5)
    n_small = runs_needed(_key(1.5, 1 / math.sqrt(10), 10))
    assert 0.78 <= _exact_power(1.5, 1.0, n_small) and n_small >= 6


def test_superiority_power_is_eighty_percent():
    n = runs_needed(_key(0.3, 1 / math.sqrt(20), 20))
    reps = 4000
    got = _fraction(0.3, n, reps, lambda lo, hi: lo > 0, seed=1)
    # binomial sd sqrt(.8*.2/4000) = 0.0063; rounding n up moves the true power by < +0.01
    assert abs(got - 0.80) < 4 * math.sqrt(0.16 / reps) + 0.012


def test_equivalence_targets_the_nearer_margin():
    key = _key(0.10, 1 / math.sqrt(30), 30, margin=0.25)
    n = runs_needed(key)
    assert 0.79 <= _exact_power(0.15, 1.0, n) and _exact_power(0.15, 1.0, n - 5) < 0.80
    reps = 4000
    got = _fraction(0.10, n, reps, lambda lo, hi: (lo > -0.25) & (hi < 0.25), seed=2)
    # the far margin (0.35 away) fails rarely at this n: true power between 0.79 and 0.82
    assert abs(got - 0.80) < 4 * math.sqrt(0.16 / reps) + 0.02


def test_the_nearer_of_the_two_boundaries_decides():
    # 0.2 from the null, 0.05 from the margin, se small: the directional verdict needs few runs
    key = _key(0.20, 0.03, 40, margin=0.25)
    assert runs_needed(key) < 40


def test_non_inferiority_uses_the_null_as_boundary():
    key = _key(0.05, 0.1, 40, null=0.25)
    n = runs_needed(key)
    sigma = 0.1 * math.sqrt(40)
    assert 0.79 <= _exact_power(0.2, sigma, n) and _exact_power(0.2, sigma, n - 3) < 0.80


def test_undecidable_and_missing():
    assert runs_needed(_key(0.0, 0.1, 10)) is None  # on the boundary
    # at the margin only the null is a boundary to clear
    assert runs_needed(_key(0.25, 0.1, 10, margin=0.25)) == runs_needed(_key(0.25, 0.1, 10))
    assert runs_needed(KeyNumber("x", 1.0, 0.5, 1.5, null=0.0)) is None  # no n
    assert runs_text(KeyNumber("x", 1.0, 0.5, 1.5, null=0.0)) == "–"
    assert runs_text(_key(0.0, 0.1, 10)) == "10 (no number of runs decides it)"
    n = runs_needed(_key(0.3, 1 / math.sqrt(20), 20))
    assert runs_text(_key(0.3, 1 / math.sqrt(20), 20)) == f"20 (post hoc: {n} at 80% power)"


@pytest.mark.parametrize("bad", [dict(n=1), dict(n=2.5), dict(margin=0.0), dict(margin=-1.0)])
def test_key_number_refuses_bad_n_and_margin(bad):
    with pytest.raises(ValueError, match=r"(n|margin) must"):
        KeyNumber("d", 0.1, 0.0, 0.2, null=0.0, **bad)


def test_power_out_of_range():
    with pytest.raises(ValueError, match="power"):
        runs_needed(_key(0.3, 0.1, 20), power=1.0)
