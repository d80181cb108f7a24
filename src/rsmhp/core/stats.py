"""Small, exact statistics helpers used by the aggregation rules.

* :func:`mean_ci` - Student-t confidence interval of a mean.
* :func:`binomial_ci` - Clopper-Pearson (exact) interval of a proportion.
* :func:`loglog_slope` - OLS slope of log(y) on log(x) with a t-based confidence interval.
* :func:`rmse_ci` - RMSE with a chi-square interval assuming the errors are N(0, s^2)-like.
* :func:`bootstrap_ci` - percentile bootstrap interval of any statistic;
  :func:`mean_bootstrap_ci` - of a mean (paired differences), NaN below 2 values.
* :func:`exceedance_test` - exceedance counts against the exact tail probability and a bound.
* :func:`detectable_scale` - the spread error an exceedance test detects (its power).

Few clusters (10 to 50 independent runs), multiplicity and power:

* :func:`cluster_t_ci` - jackknife-over-clusters t interval of any statistic
  (:class:`ClusterInterval`, with its two-sided t p-value).
* :func:`bootstrap_t_ci` - studentised (bootstrap-t) interval of a mean of cluster values.
* :func:`holm` - Holm's step-down adjusted p-values.
* :func:`t_power` - power of the two-sided one-sample (paired) t-test.
* :func:`runs_for_power` - the smallest number of runs giving a t-test that power.
* :func:`one_sided_p_value` - one-sided t p-value against a bound.
* :func:`tost_p_value` - two one-sided tests (TOST) p-value of equivalence within a margin.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy  # scipy.stats loads on first use (scipy's lazy submodules): ~0.4 s a process

from rsmhp.core import guards

__all__ = [
    "DETECTABLE_GRID",
    "POWER_RULES",
    "ClusterInterval",
    "ExceedanceTest",
    "Improvement",
    "SlopeFit",
    "binomial_ci",
    "bootstrap_ci",
    "bootstrap_t_ci",
    "ci_within",
    "cluster_t_ci",
    "detectable_scale",
    "exceedance_test",
    "holm",
    "loglog_slope",
    "mean_bootstrap_ci",
    "mean_ci",
    "one_sided_p_value",
    "paired_wins",
    "probability_of_improvement",
    "rmse_ci",
    "rule_power",
    "rule_runs",
    "runs_for_power",
    "t_power",
    "tost_p_value",
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
    half = float(scipy.stats.t.ppf(0.5 + level / 2, n - 1) * x.std(ddof=1) / np.sqrt(n))
    return m, m - half, m + half


def binomial_ci(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """Clopper-Pearson interval for a proportion ``k/n``."""
    n = guards.positive_int("n", n)
    k = guards.integer("k", k, minimum=0, maximum=n)
    _level(level)
    ci = scipy.stats.binomtest(int(k), int(n)).proportion_ci(confidence_level=level, method="exact")
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
    lo = np.sqrt(ss / scipy.stats.chi2.ppf(0.5 + level / 2, n))
    hi = np.sqrt(ss / scipy.stats.chi2.ppf(0.5 - level / 2, n))
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
    res = scipy.stats.linregress(np.log(x), np.log(y))
    half = float(scipy.stats.t.ppf(0.5 + level / 2, x.size - 2) * res.stderr)
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


def mean_bootstrap_ci(
    x: np.ndarray, rng: np.random.Generator, n_boot: int, level: float = 0.95
) -> tuple[float, float]:
    """Percentile-bootstrap CI of the mean of ``x`` (e.g. paired differences d = a − b, one
    per pair), :func:`bootstrap_ci` with ``stat = mean``; ``(nan, nan)`` for fewer than 2
    values (no resampling: ``rng`` is left untouched). The one definition the studies'
    paired comparisons use (each passes a stream keyed on its comparison)."""
    x = np.asarray(x, dtype=float)
    if x.size < 2:
        return float("nan"), float("nan")
    return bootstrap_ci(x, rng, n_boot, level)


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
            scipy.stats.binomtest(int(ki), int(ni), float(pi)).pvalue
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
    need = (scipy.stats.norm.ppf(1 - (1 - level) / cells / 2) + scipy.stats.norm.ppf(power)) * se
    best = float("inf")
    for sign in (1.0, -1.0):
        delta = sign * grid[np.abs(grid) < 1] if sign < 0 else grid
        shifted = np.abs(np.asarray(tail(eps / (1 + delta)), dtype=float) - p)
        hit = np.nonzero(shifted >= need)[0]
        if hit.size:
            best = min(best, float(abs(delta[hit[0]])))
    return best


# --- few clusters: jackknife and bootstrap-t intervals, Holm, t-test power, one-sided tests ---


def _t_p_value(t_stat: float, df: float, side: str) -> float:
    """p-value of a t statistic with ``df`` degrees of freedom: ``"two"`` (two-sided),
    ``"below"`` (H1: the mean is below the null, small t rejects) or ``"above"``."""
    if side == "two":
        return float(min(1.0, 2.0 * scipy.stats.t.sf(abs(t_stat), df)))
    if side == "below":
        return float(scipy.stats.t.cdf(t_stat, df))
    return float(scipy.stats.t.sf(t_stat, df))


def _se_zero_p_value(diff: float, side: str) -> float:
    """The p-value when the standard error is 0 and ``diff = estimate - null``: 0 if the
    estimate lies strictly on the alternative's side of the null, else 1 (no evidence)."""
    if side == "two":
        return 0.0 if diff != 0 else 1.0
    if side == "below":
        return 0.0 if diff < 0 else 1.0
    return 0.0 if diff > 0 else 1.0


@dataclass(frozen=True)
class ClusterInterval:
    r"""A t interval ``[low, high]`` of ``estimate`` with standard error ``se`` and ``df``
    degrees of freedom: :math:`\hat\theta \pm t_{df,(1+level)/2}\,\mathrm{se}`."""

    estimate: float
    low: float
    high: float
    se: float
    df: int

    def p_value(self, null: float = 0.0) -> float:
        r"""Two-sided t-test p-value of :math:`H_0: \theta = \text{null}`:
        :math:`2\,(1 - T_{df}(|\hat\theta - \text{null}|/\mathrm{se}))`; with ``se == 0`` it
        is 1 if the estimate equals ``null`` and 0 otherwise."""
        null = guards.real("null", null)
        diff = self.estimate - float(null)
        if self.se == 0:
            return _se_zero_p_value(diff, "two")
        return _t_p_value(diff / self.se, self.df, "two")


def _stat_value(name: str, value) -> float:
    return float(guards.real(name, value))


def cluster_t_ci(
    stat: Callable[[np.ndarray], float], n_clusters: int, level: float = 0.95
) -> ClusterInterval:
    r"""Jackknife-over-clusters t interval ("t with a cluster standard error") of a statistic
    of ``G = n_clusters`` independent clusters (e.g. independent runs).

    ``stat(idx)`` takes a 1-D int array of the cluster indices kept and returns a real number.
    With :math:`\hat\theta = \mathrm{stat}(0, \dots, G-1)` and the leave-one-out values
    :math:`\hat\theta_{(i)} = \mathrm{stat}(\{0, \dots, G-1\} \setminus \{i\})`,

    .. math::
        \mathrm{se} = \sqrt{\tfrac{G-1}{G} \sum_{i=1}^G
        (\hat\theta_{(i)} - \hat\theta_{(\cdot)})^2}, \qquad
        \hat\theta \pm t_{G-1,(1+\text{level})/2}\, \mathrm{se},

    :math:`\hat\theta_{(\cdot)}` the mean of the :math:`\hat\theta_{(i)}`. For the mean of
    per-cluster values, se is :math:`s/\sqrt G` and the interval is :func:`mean_ci`'s Student-t
    interval. Calls ``stat`` G + 1 times; every value must be finite. Needs ``G >= 2``.
    """
    if not callable(stat):
        raise TypeError(
            f"stat must be a callable taking an int array of cluster indices, got "
            f"{type(stat).__name__} {guards.show(stat)}"
        )
    g = guards.integer("n_clusters", n_clusters)
    if g < 2:
        raise ValueError(
            f"n_clusters must be an integer >= 2 (a jackknife over clusters leaves one out of "
            f"at least two), got {guards.show(n_clusters)}"
        )
    g = int(g)
    _level(level)
    everything = np.arange(g)
    estimate = _stat_value("stat(all clusters)", stat(everything))
    loo = np.array(
        [
            _stat_value(f"stat(clusters without {i})", stat(np.delete(everything, i)))
            for i in range(g)
        ]
    )
    se = float(np.sqrt((g - 1) / g * np.sum((loo - loo.mean()) ** 2)))
    half = float(scipy.stats.t.ppf(0.5 + level / 2, g - 1)) * se
    return ClusterInterval(estimate, estimate - half, estimate + half, se, g - 1)


def bootstrap_t_ci(
    x: np.ndarray, rng: np.random.Generator, n_boot: int, level: float = 0.95
) -> tuple[float, float]:
    r"""Studentised (bootstrap-t) interval of the mean of per-cluster values ``x``.

    ``n_boot`` resamples of the G clusters with replacement (``n_boot x G`` indices drawn from
    ``rng`` in one call, as in :func:`bootstrap_ci`) give
    :math:`t^* = (\bar x^* - \bar x)/\mathrm{se}^*` with :math:`\mathrm{se}^* = s^*/\sqrt G`;
    with :math:`q_{lo}, q_{hi}` the ``(1 - level)/2`` and ``(1 + level)/2`` quantiles of
    :math:`t^*` and :math:`\mathrm{se} = s/\sqrt G` the interval is
    :math:`(\bar x - q_{hi}\,\mathrm{se},\ \bar x - q_{lo}\,\mathrm{se})`.

    Resamples whose :math:`\mathrm{se}^*` is 0 (one cluster drawn G times, or all drawn
    values equal) have no t statistic and are dropped; the quantiles are over the others. If
    all ``x`` are equal the interval is ``(mean, mean)`` (the indices are drawn all the same, so
    ``rng`` advances alike); if every resample is dropped
    otherwise (possible only for tiny G and ``n_boot``) a :class:`ValueError` is raised.
    ``x`` needs at least 2 finite values.
    """
    x = guards.finite_array("x", x, ndim=1)
    rng = guards.generator("rng", rng)
    n_boot = int(guards.positive_int("n_boot", n_boot))
    _level(level)
    g = x.size
    if g < 2:
        raise ValueError(f"x must hold at least 2 cluster values for a bootstrap-t, got {g}")
    m = float(x.mean())
    se = float(x.std(ddof=1) / np.sqrt(g))
    idx = rng.integers(0, g, size=(n_boot, g))
    if se == 0:
        return m, m
    xb = x[idx]
    se_b = xb.std(axis=1, ddof=1) / np.sqrt(g)
    keep = se_b > 0
    if not keep.any():
        raise ValueError(
            f"every one of the n_boot = {n_boot} resamples of the {g} clusters x has a zero "
            f"standard error; increase n_boot"
        )
    t_b = (xb.mean(axis=1)[keep] - m) / se_b[keep]
    q_lo, q_hi = np.quantile(t_b, [0.5 - level / 2, 0.5 + level / 2])
    return float(m - q_hi * se), float(m - q_lo * se)


def holm(p_values: np.ndarray) -> np.ndarray:
    r"""Holm's step-down adjusted p-values, in the order given.

    With the m non-NaN p-values sorted, :math:`p_{(1)} \le \dots \le p_{(m)}`,

    .. math::
        \tilde p_{(k)} = \max_{j \le k} \min\bigl(1, (m - j + 1)\, p_{(j)}\bigr);

    rejecting every hypothesis with :math:`\tilde p \le \alpha` is Holm's procedure (reject
    :math:`H_{(1)}, H_{(2)}, \dots` while :math:`p_{(k)} \le \alpha/(m-k+1)`), which controls
    the familywise error rate at :math:`\alpha` under any dependence. NaN entries (no test)
    stay NaN and do not count in m. ``p_values``: a 1-D array of values in [0, 1] or NaN.
    """
    p = guards.float_array("p_values", p_values)
    if p.ndim != 1:
        raise ValueError(f"p_values must have 1 dimension(s), got shape {p.shape}")
    valid = ~np.isnan(p)
    bad = valid & ~((p >= 0) & (p <= 1))
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(
            f"p_values must lie in the closed interval [0, 1] (or be NaN), got {p[i]} at index {i}"
        )
    out = p.copy()
    q = p[valid]
    m = q.size
    if m == 0:
        return out
    order = np.argsort(q, kind="stable")
    scaled = np.minimum(1.0, (m - np.arange(m)) * q[order])
    adjusted = np.empty(m)
    adjusted[order] = np.maximum.accumulate(scaled)
    out[valid] = adjusted
    return out


def _power_args(sd, effect, level) -> tuple[float, float]:
    _level(level)
    sd = float(guards.real("sd", sd, lo=0.0))
    effect = float(guards.real("effect", effect))
    return sd, effect


def t_power(n: int, sd: float, effect: float, level: float = 0.95) -> float:
    r"""Power of the two-sided one-sample (paired) t-test of :math:`H_0: \mu = 0` at level
    ``1 - level`` with ``n`` units whose true mean is ``effect`` and per-unit sd ``sd``:

    .. math::
        P\bigl(|T| > t_{n-1,(1+\text{level})/2}\bigr), \qquad
        T \sim t'_{n-1}(\delta),\ \delta = \text{effect}\,\sqrt n/\text{sd}

    (noncentral t, exact for normal units). ``effect == 0`` gives the size ``1 - level``;
    ``sd == 0`` gives 1 for a nonzero effect and is refused with ``effect == 0``. ``n >= 2``.
    """
    n = int(guards.integer("n", n, minimum=2))
    sd, effect = _power_args(sd, effect, level)
    if sd == 0:
        if effect == 0:
            raise ValueError("sd = 0 and effect = 0 leave the t statistic undefined (0/0)")
        return 1.0
    df = n - 1
    crit = float(scipy.stats.t.ppf(0.5 + level / 2, df))
    nc = effect * np.sqrt(n) / sd
    return float(min(1.0, scipy.stats.nct.sf(crit, df, nc) + scipy.stats.nct.cdf(-crit, df, nc)))


def runs_for_power(
    sd: float, effect: float, level: float = 0.95, power: float = 0.8, max_n: int = 100000
) -> int:
    r"""The smallest ``n >= 2`` with :func:`t_power` ``(n, sd, effect, level) >= power``.

    The search starts at the normal approximation
    :math:`\lceil ((z_{1-\alpha/2} + z_{\text{power}})\, \text{sd}/\text{effect})^2 \rceil`,
    :math:`\alpha = 1 - \text{level}` (slightly below the exact n, which is about
    :math:`z_{1-\alpha/2}^2/2` larger), then doubles its step upwards and bisects, using that
    the power grows with n; the returned n is checked exactly (``n == 2`` or
    ``t_power(n - 1) < power``). ``effect`` must be nonzero and ``sd >= 0`` (``sd == 0``
    returns 2). :class:`ValueError` if even ``max_n`` runs do not reach ``power``.
    """
    sd, effect = _power_args(sd, effect, level)
    if effect == 0:
        raise ValueError("effect must be nonzero for a power calculation, got 0")
    power = float(guards.real("power", power, lo=0.0, hi=1.0, lo_open=True, hi_open=True))
    max_n = int(guards.integer("max_n", max_n, minimum=2))
    if sd == 0:
        return 2

    def reaches(n: int) -> bool:
        return t_power(n, sd, effect, level) >= power

    if not reaches(max_n):
        raise ValueError(
            f"even max_n = {max_n} runs do not give power = {power:g} for effect = {effect:g}, "
            f"sd = {sd:g}, level = {level:g} (power at max_n: "
            f"{t_power(max_n, sd, effect, level):.4g}); raise max_n or the effect"
        )
    z = scipy.stats.norm.ppf(0.5 + level / 2) + scipy.stats.norm.ppf(power)
    start = int(min(max_n, max(2, np.ceil((z * sd / effect) ** 2))))
    if reaches(start):
        hi = start
        while hi > 2 and reaches(hi - 1):
            hi -= 1
        return hi
    lo, step = start, 1  # reaches(lo) is False
    hi = min(max_n, lo + step)
    while not reaches(hi):
        lo, step = hi, 2 * step
        hi = min(max_n, lo + step)
    while hi - lo > 1:  # reaches(hi), not reaches(lo)
        mid = (lo + hi) // 2
        if reaches(mid):
            hi = mid
        else:
            lo = mid
    return hi


def _one_sided_args(estimate, se, df) -> tuple[float, float, float]:
    estimate = float(guards.real("estimate", estimate))
    se = float(guards.real("se", se, lo=0.0))
    df = float(guards.real("df", df, lo=0.0, lo_open=True, finite=False))
    return estimate, se, df


def one_sided_p_value(estimate: float, se: float, df: float, bound: float, side: str) -> float:
    r"""One-sided t-test p-value against ``bound`` for an estimate with standard error ``se``
    and ``df`` degrees of freedom (``df = inf``: normal), :math:`t = (\hat\theta -
    \text{bound})/\mathrm{se}`:

    * ``side="below"`` (:math:`H_1: \theta < \text{bound}`): :math:`T_{df}(t)`;
    * ``side="above"`` (:math:`H_1: \theta > \text{bound}`): :math:`1 - T_{df}(t)`.

    With ``se == 0`` the p-value is 0 if the estimate lies strictly on the :math:`H_1` side of
    the bound and 1 otherwise. Turns a one-sided confidence-bound verdict into a p-value (e.g.
    for :func:`holm`): ``p <= alpha`` iff the one-sided ``1 - alpha`` bound excludes ``bound``.
    """
    estimate, se, df = _one_sided_args(estimate, se, df)
    bound = float(guards.real("bound", bound))
    side = guards.one_of("side", side, ("below", "above"))
    diff = estimate - bound
    if se == 0:
        return _se_zero_p_value(diff, side)
    return _t_p_value(diff / se, df, side)


def tost_p_value(estimate: float, se: float, df: float, margin: float) -> float:
    r"""Two one-sided tests (TOST) p-value of equivalence, :math:`H_1: -\text{margin} < \theta
    < \text{margin}` against :math:`H_0: |\theta| \ge \text{margin}`: the larger of the
    one-sided p-values of :math:`\theta > -\text{margin}` and :math:`\theta < \text{margin}`
    (:func:`one_sided_p_value`), so ``p <= alpha`` iff the ``1 - 2 alpha`` two-sided t
    interval lies inside ``(-margin, margin)``. ``margin > 0``; ``df = inf`` is normal."""
    estimate, se, df = _one_sided_args(estimate, se, df)
    margin = float(guards.real("margin", margin, lo=0.0, lo_open=True))
    return max(
        one_sided_p_value(estimate, se, df, -margin, "above"),
        one_sided_p_value(estimate, se, df, margin, "below"),
    )


@dataclass(frozen=True)
class Improvement:
    """:func:`probability_of_improvement`: the average over scenarios ``p`` with its
    stratified-bootstrap interval [``low``, ``high``], the scenarios it averages and the share
    of them whose own probability is above 1/2."""

    p: float
    low: float
    high: float
    scenarios: int
    share_above_half: float


def paired_wins(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Per pair (lower is better): 1.0 if x < y, 0.5 if x == y, 0.0 otherwise; the terms
    whose mean is the probability of improvement of x over y."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    return (x < y) + 0.5 * (x == y)


def probability_of_improvement(
    pairs: list[tuple[np.ndarray, np.ndarray]],
    n_boot: int = 2000,
    seed: int = 0,
    level: float = 0.95,
) -> Improvement:
    r"""Probability of improvement over a set of scenarios (lower is better), as rliable
    summarises a benchmark over tasks, for paired runs. Scenario :math:`s` has paired values
    :math:`(x_{s,r}, y_{s,r})`, :math:`r = 1..n_s` (the same scenario drawn for both methods);
    its probability is :math:`p_s = \frac1{n_s}\sum_r (1[x_{s,r} < y_{s,r}] + \tfrac12
    1[x_{s,r} = y_{s,r}])`, the chance that a run of X beats the same run of Y, and the
    summary is their average :math:`P = \frac1S \sum_s p_s` (each scenario weighs the same,
    whatever its run count). Interval: stratified percentile bootstrap, ``n_boot``
    resamples of the runs with replacement within every scenario (the scenarios are fixed,
    as the tasks of a benchmark are); ``seed`` makes it reproducible. ``pairs``: one
    ``(x, y)`` per scenario, 1-D arrays of one length >= 1 each. 1/2 means no difference."""
    _level(level)
    n_boot = guards.positive_int("n_boot", n_boot)
    if not pairs:
        raise ValueError("probability_of_improvement: no scenarios")
    wins = []
    for i, (x, y) in enumerate(pairs):
        x = guards.finite_array(f"pairs[{i}][0]", x)
        y = guards.finite_array(f"pairs[{i}][1]", y)
        if x.ndim != 1 or x.shape != y.shape or x.size == 0:
            raise ValueError(
                f"pairs[{i}]: x and y must be 1-D of one length >= 1, got {x.shape} and {y.shape}"
            )
        wins.append(paired_wins(x, y))
    per = np.array([w.mean() for w in wins])
    rng = np.random.default_rng(seed)
    boot = np.zeros(n_boot)
    for w in wins:
        idx = rng.integers(0, w.size, size=(n_boot, w.size))
        boot += w[idx].mean(axis=1)
    boot /= len(wins)
    alpha = (1.0 - level) / 2
    lo, hi = np.quantile(boot, [alpha, 1.0 - alpha])
    return Improvement(
        float(per.mean()), float(lo), float(hi), len(wins), float(np.mean(per > 0.5))
    )


#: the verdict rules whose prospective power :func:`rule_power` gives
POWER_RULES = ("equivalence", "non-inferiority", "superiority")


def ci_within(n: int, sd: float, effect: float, lower: float, upper: float,
              level: float = 0.95) -> float:  # fmt: skip
    r"""The probability that the ``level`` Student-t interval of the mean of ``n`` normal
    units (true mean ``effect``, sd ``sd``) lies inside ``(lower, upper)`` (``-inf`` and
    ``inf`` allowed):

    .. math::
        P\bigl(\text{lower} < \bar d - h,\ \bar d + h < \text{upper}\bigr)
        = \mathbb E_s\Bigl[\Phi\Bigl(\frac{\text{upper} - h - \mu}{\sigma/\sqrt n}\Bigr)
          - \Phi\Bigl(\frac{\text{lower} + h - \mu}{\sigma/\sqrt n}\Bigr)\Bigr]^+,
        \qquad h = t_{n-1,(1+\text{level})/2}\, s/\sqrt n,

    exact for normal units, since :math:`\bar d` and :math:`s` are independent and
    :math:`(n-1)s^2/\sigma^2 \sim \chi^2_{n-1}`; the expectation over :math:`s` is one
    numerical integral (``scipy.integrate.quad``, absolute error below 1e-8). ``sd == 0``
    gives 1 or 0 by whether ``effect`` lies inside. ``n >= 2``."""
    n = int(guards.integer("n", n, minimum=2))
    sd, effect = _power_args(sd, effect, level)
    lower, upper = float(lower), float(upper)
    if not lower < upper:
        raise ValueError(f"ci_within: lower {lower!r} must be below upper {upper!r}")
    if sd == 0:
        return float(lower < effect < upper)
    df = n - 1
    se = sd / np.sqrt(n)
    crit = float(scipy.stats.t.ppf(0.5 + level / 2, df))

    def inside(u: float) -> float:
        h = crit * sd * np.sqrt(u / df) / np.sqrt(n)
        p = scipy.stats.norm.cdf((upper - h - effect) / se)
        p -= scipy.stats.norm.cdf((lower + h - effect) / se)
        return max(float(p), 0.0) * float(scipy.stats.chi2.pdf(u, df))

    # above u_max the interval is wider than (lower, upper): nothing to integrate there
    width = upper - lower
    u_max = df * (width * np.sqrt(n) / (2 * crit * sd)) ** 2 if np.isfinite(width) else np.inf
    hi = min(u_max, float(scipy.stats.chi2.ppf(1 - 1e-14, df)))
    mid = float(df)  # the chi-square's mean: tell quad where the mass is
    points = [mid] if 0 < mid < hi else None
    value, _ = scipy.integrate.quad(inside, 0.0, hi, points=points, epsabs=1e-10, limit=200)
    return float(min(max(value, 0.0), 1.0))


def rule_power(rule: str, n: int, sd: float, margin: float, effect: float = 0.0,
               level: float = 0.95) -> float:  # fmt: skip
    r"""Prospective power of a claim's verdict rule (:data:`POWER_RULES`) with ``n`` paired
    units of per-unit sd ``sd`` at a true mean difference ``effect`` (d < 0: the claimed
    method is better), margin :math:`\Delta` = ``margin`` > 0, the ``level`` t interval
    (:func:`ci_within`):

    * ``equivalence``: P(interval inside :math:`(-\Delta, \Delta)`) (the rule's "equivalent";
      TOST at :math:`(1-\text{level})/2` per side);
    * ``non-inferiority``: P(interval below :math:`+\Delta`) ("supported");
    * ``superiority``: P(interval below 0 and not inside :math:`(-\Delta, \Delta)`) (the
      rule's "supported": an interval inside the margin reads "equivalent" first).
    """
    margin = float(guards.real("margin", margin, lo=0.0, lo_open=True))
    if rule == "equivalence":
        return ci_within(n, sd, effect, -margin, margin, level)
    if rule == "non-inferiority":
        return ci_within(n, sd, effect, -np.inf, margin, level)
    if rule == "superiority":
        below = ci_within(n, sd, effect, -np.inf, 0.0, level)
        return max(below - ci_within(n, sd, effect, -margin, 0.0, level), 0.0)
    raise ValueError(f"rule: {rule!r} (allowed: {', '.join(POWER_RULES)})")


def rule_runs(rule: str, sd: float, margin: float, effect: float = 0.0, power: float = 0.8,
              level: float = 0.95, max_n: int = 100000) -> int | None:  # fmt: skip
    """The smallest ``n >= 2`` at which :func:`rule_power` reaches ``power`` (it grows with n
    for every rule at an effect on the rule's side), by doubling then bisection; ``None`` when
    even ``max_n`` does not reach it (e.g. equivalence at an effect outside the margin)."""
    power = float(guards.real("power", power, lo=0.0, hi=1.0, lo_open=True, hi_open=True))
    max_n = int(guards.integer("max_n", max_n, minimum=2))

    def reaches(n: int) -> bool:
        return rule_power(rule, n, sd, margin, effect, level) >= power

    if not reaches(max_n):
        return None
    lo, hi = 1, 2
    while not reaches(hi):
        lo, hi = hi, min(2 * hi, max_n)
    while hi - lo > 1:  # reaches(hi), not reaches(lo) (lo = 1 stands for "below 2")
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if reaches(mid) else (mid, hi)
    return hi
