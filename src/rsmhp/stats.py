"""Small, exact statistics helpers used by the aggregation rules.

* :func:`mean_ci` - Student-t confidence interval of a mean.
* :func:`binomial_ci` - Clopper-Pearson (exact) interval of a proportion.
* :func:`loglog_slope` - OLS slope of log(y) on log(x) with a t-based confidence interval.
* :func:`rmse_ci` - RMSE with a chi-square interval assuming the errors are N(0, s^2)-like.
* :func:`bootstrap_ci` - percentile bootstrap interval of any statistic.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

from rsmhp import guards

__all__ = ["SlopeFit", "binomial_ci", "bootstrap_ci", "loglog_slope", "mean_ci", "rmse_ci"]


def _level(level: float) -> None:
    guards.real("level", level, lo=0.0, hi=1.0, lo_open=True, hi_open=True)


def mean_ci(x: np.ndarray, level: float = 0.95) -> tuple[float, float, float]:
    r"""(mean, low, high): :math:`\bar x \pm t_{n-1,(1+level)/2}\, s/\sqrt n`."""
    _level(level)
    x = guards.finite_array("x", x)
    n = x.size
    if n < 2:
        raise ValueError(f"need at least 2 values x for a confidence interval, got {n}")
    m = float(x.mean())
    half = float(stats.t.ppf(0.5 + level / 2, n - 1) * x.std(ddof=1) / np.sqrt(n))
    return m, m - half, m + half


def binomial_ci(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """Clopper-Pearson interval for a proportion ``k/n``."""
    n = guards.positive_int("n", n)
    k = guards.integer("k", k, minimum=0, maximum=n)
    _level(level)
    ci = stats.binomtest(int(k), int(n)).proportion_ci(confidence_level=level, method="exact")
    return float(ci.low), float(ci.high)


def rmse_ci(err: np.ndarray, level: float = 0.95) -> tuple[float, float, float]:
    r"""(rmse, low, high) of errors ``err`` about 0: :math:`n\,\mathrm{MSE}/\sigma^2 \sim \chi^2_n`
    when the errors are i.i.d. :math:`N(0,\sigma^2)`; exact for unbiased Gaussian errors."""
    _level(level)
    err = guards.finite_array("err", err)
    n = err.size
    if n < 1:
        raise ValueError("need at least 1 error value err for an RMSE, got 0")
    ss = float(np.sum(err**2))
    lo = np.sqrt(ss / stats.chi2.ppf(0.5 + level / 2, n))
    hi = np.sqrt(ss / stats.chi2.ppf(0.5 - level / 2, n))
    return float(np.sqrt(ss / n)), float(lo), float(hi)


@dataclass(frozen=True)
class SlopeFit:
    slope: float
    low: float
    high: float
    intercept: float

    def contains(self, value: float) -> bool:
        return self.low <= value <= self.high


def loglog_slope(x: np.ndarray, y: np.ndarray, level: float = 0.95) -> SlopeFit:
    r"""Fit :math:`\log y = c + s \log x` by OLS; CI :math:`s \pm t_{n-2}\,\mathrm{se}(s)`."""
    _level(level)
    x, y = guards.finite_array("x", x, ndim=1), guards.finite_array("y", y, ndim=1)
    if x.shape != y.shape:
        raise ValueError(f"x and y must have the same length, got {x.size} and {y.size}")
    if x.size < 3 or np.any(x <= 0) or np.any(y <= 0):
        raise ValueError("need >= 3 strictly positive points for a log-log fit")
    res = stats.linregress(np.log(x), np.log(y))
    half = float(stats.t.ppf(0.5 + level / 2, x.size - 2) * res.stderr)
    return SlopeFit(
        float(res.slope), float(res.slope - half), float(res.slope + half), float(res.intercept)
    )


def bootstrap_ci(
    x: np.ndarray, rng: np.random.Generator, n_boot: int, level: float, stat=np.mean
) -> tuple[float, float]:
    """Percentile bootstrap CI of ``stat`` over resamples of ``x`` (with replacement): the
    ``(1 - level)/2`` and ``(1 + level)/2`` quantiles of ``stat`` over ``n_boot`` resamples
    (``n_boot x len(x)`` indices drawn from ``rng`` in one call)."""
    x = np.asarray(x, dtype=float)
    idx = rng.integers(0, x.size, size=(n_boot, x.size))
    boots = stat(x[idx], axis=1)
    lo, hi = np.quantile(boots, [0.5 - level / 2, 0.5 + level / 2])
    return float(lo), float(hi)
