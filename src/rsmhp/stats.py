"""Small, exact statistics helpers used by the aggregation rules.

* :func:`mean_ci` - Student-t confidence interval of a mean.
* :func:`binomial_ci` - Clopper-Pearson (exact) interval of a proportion.
* :func:`loglog_slope` - OLS slope of log(y) on log(x) with a t-based confidence interval.
* :func:`rmse_ci` - RMSE with a chi-square interval assuming the errors are N(0, s^2)-like.
* :func:`bootstrap_ci` - percentile bootstrap interval of any statistic.
* :func:`exceedance_test` - exceedance counts against the exact tail probability and a bound.
* :func:`detectable_scale` - the spread error an exceedance test detects (its power).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy import stats

from rsmhp import guards

__all__ = [
    "DETECTABLE_GRID",
    "ExceedanceTest",
    "SlopeFit",
    "binomial_ci",
    "bootstrap_ci",
    "detectable_scale",
    "exceedance_test",
    "loglog_slope",
    "mean_ci",
    "rmse_ci",
]


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


#: relative spread errors the pipeline searches for the power of an exceedance test
#: (:func:`detectable_scale`; 1% steps to 50%)
DETECTABLE_GRID = np.round(np.arange(0.01, 0.5001, 0.01), 2)


@dataclass(frozen=True)
class ExceedanceTest:
    r"""Observed exceedance counts against the exact tail probability and against a bound.

    Per cell i: :math:`k_i` of :math:`n_i` replicates exceeded the tolerance; ``exact`` is the
    exact probability :math:`p_i` of that event, ``bound`` an upper bound of it (e.g.
    Chebyshev's). ``departing``: cells whose two-sided exact binomial test of
    :math:`k_i \sim \mathrm{Bin}(n_i, p_i)` rejects at familywise level ``1 - level``
    (Bonferroni over the cells), i.e. the simulation's error distribution differs from the
    exact one; ``above_bound``: cells whose Clopper-Pearson lower limit (familywise level)
    lies above the bound, i.e. the bound fails; ``exact_above_bound``: cells whose exact
    probability exceeds the bound (a bound that is not one); ``min_p``: the smallest
    Bonferroni-adjusted p-value (capped at 1) and ``worst`` the index of the cell with the
    smallest raw p-value;
    ``max_exact_ratio``: the largest exact / bound over cells with a bound below 1."""

    cells: int
    departing: int
    above_bound: int
    exact_above_bound: int
    min_p: float
    worst: int
    max_exact_ratio: float


def exceedance_test(
    k: np.ndarray, n: np.ndarray, exact: np.ndarray, bound: np.ndarray, level: float = 0.95
) -> ExceedanceTest:
    """:class:`ExceedanceTest` of the cells given as equal-length arrays."""
    _level(level)
    k, n = np.asarray(k, dtype=int), np.asarray(n, dtype=int)
    exact, bound = np.asarray(exact, dtype=float), np.asarray(bound, dtype=float)
    if not (k.shape == n.shape == exact.shape == bound.shape) or k.ndim != 1 or k.size == 0:
        raise ValueError(
            f"k, n, exact and bound must be 1-D arrays of one length >= 1, got shapes "
            f"{k.shape}, {n.shape}, {exact.shape}, {bound.shape}"
        )
    if np.any((exact < 0) | (exact > 1)) or not np.all(np.isfinite(exact)):
        raise ValueError(f"exact probabilities must lie in [0, 1], got {exact}")
    m = k.size
    alpha = (1 - level) / m
    p = np.array(
        [
            stats.binomtest(int(ki), int(ni), float(pi)).pvalue
            for ki, ni, pi in zip(k, n, exact, strict=True)
        ]
    )
    low = np.array(
        [binomial_ci(int(ki), int(ni), 1 - alpha)[0] for ki, ni in zip(k, n, strict=True)]
    )
    adjusted = np.minimum(1.0, p * m)
    informative = bound < 1
    ratio = exact[informative] / bound[informative]
    return ExceedanceTest(
        cells=m,
        departing=int(np.sum(p < alpha)),
        above_bound=int(np.sum(low > bound)),
        exact_above_bound=int(np.sum(exact > bound * (1 + 1e-9))),
        min_p=float(adjusted.min()),
        worst=int(np.argmin(p)),
        max_exact_ratio=float(ratio.max()) if ratio.size else float("nan"),
    )


def detectable_scale(
    tail: Callable[[np.ndarray], np.ndarray],
    eps: float,
    n: int,
    cells: int,
    level: float = 0.95,
    power: float = 0.8,
    grid: np.ndarray | None = None,
) -> float:
    r"""The smallest relative error δ of the spread of the estimator's error that the
    exceedance test of one cell detects with probability ``power``: if the error were
    :math:`(1+\delta)` times the exact one, its exceedance probability would be
    :math:`p' = \mathrm{tail}(\varepsilon/(1+\delta))`, and a Bonferroni-corrected two-sided
    test over ``cells`` cells with ``n`` replicates detects it (normal approximation) when
    :math:`|p' - p| \ge (z_{1-\alpha/2} + z_{\text{power}}) \sqrt{p(1-p)/n}`, with
    :math:`\alpha = (1 - \text{level})/\text{cells}`. ``tail(eps_array)`` is the exact
    exceedance probability. Searched on ``grid`` (default 0.5% to 100% in 0.5% steps, both
    signs); ``inf`` if no δ on the grid is detected."""
    _level(level)
    grid = np.arange(0.005, 1.0001, 0.005) if grid is None else np.asarray(grid, dtype=float)
    p = float(tail(np.array([eps]))[0])
    se = np.sqrt(max(p * (1 - p), 0.0) / n)
    if se == 0:
        return float("inf")
    need = (stats.norm.ppf(1 - (1 - level) / cells / 2) + stats.norm.ppf(power)) * se
    best = float("inf")
    for sign in (1.0, -1.0):
        delta = sign * grid[np.abs(grid) < 1] if sign < 0 else grid
        shifted = np.abs(np.asarray(tail(eps / (1 + delta)), dtype=float) - p)
        hit = np.nonzero(shifted >= need)[0]
        if hit.size:
            best = min(best, float(abs(delta[hit[0]])))
    return best
