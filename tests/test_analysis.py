"""LQG study: aggregation, verdict rules, report section and figures; stats helpers and
intermediate-file checks."""

from __future__ import annotations

import re

import matplotlib.colors as mcolors
import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from rsmhp import lqg
from rsmhp.analysis import lqg as analysis
from rsmhp.claims import lqg as claims
from rsmhp.experiments.lqg import CONVERGENCE_COLUMNS, run_convergence, run_nbo_error
from rsmhp.figures import lqg as figs
from rsmhp.io import IntermediateFileError, read_table, write_csv
from rsmhp.ledger import Section
from rsmhp.narrative import lqg as narrative
from rsmhp.palette import method_colour
from rsmhp.stats import binomial_ci, loglog_slope, mean_ci, rmse_ci

from .conftest import PAPER, PAPER_U
from .test_seeding import BASE

J = lqg.exact_cost(PAPER_U, **PAPER)
J_NBO = lqg.nbo_cost(PAPER_U, x0=0.0, a=0.5, r=10.0, target=1.0)


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


def test_fig3_and_prop3_verdicts_follow_the_data():
    rng = np.random.default_rng(0)
    var = lqg.cost_variance(PAPER_U, **PAPER)
    ps = [100, 400, 1600, 6400]
    good = synthetic({p: rng.normal(0, np.sqrt(var / p), 300) for p in ps})
    c2, c3, _ = claims.convergence_claims(analysis.summarize_convergence(good, [1.0]), [1.0])
    assert c2.verdict == "supported" and c3.verdict == "supported"
    assert c2.key.null == 0.0 and c2.key.ci_high < 0
    # errors that do not shrink with P and are far larger than NBO's error and the bound
    bad = synthetic({p: rng.normal(0, 15.0, 300) for p in ps})
    c2b, c3b, _ = claims.convergence_claims(analysis.summarize_convergence(bad, [1.0]), [1.0])
    assert c2b.verdict == "not supported"
    assert c3b.verdict == "not supported" and c3b.key.value >= 1


def _pm(s: float, n: int = 40) -> np.ndarray:
    """n errors, half +s and half -s: mean 0 and RMSE exactly s."""
    return np.repeat([s, -s], n // 2)


def test_fig3_verdict_edge_cases():
    ps = [100, 400, 1600, 6400]
    # RMSE that does not fall with P (slope CI around 0), far below NBO's error: inconclusive
    flat = synthetic(dict(zip(ps, [_pm(1.0), _pm(1.2), _pm(0.9), _pm(1.1)], strict=True)))
    c = claims.fig3_claim(analysis.summarize_convergence(flat, [1.0]))
    assert c.key.ci_low < 0 < c.key.ci_high and c.verdict == "inconclusive"
    # RMSE falls like P^-1/2, but the mean keeps a bias of 0.5 at the largest P: inconclusive
    shrinking = {p: _pm(20 / np.sqrt(p)) for p in ps}
    biased = synthetic({p: e + 0.5 for p, e in shrinking.items()})
    c = claims.fig3_claim(analysis.summarize_convergence(biased, [1.0]))
    assert c.key.ci_high < 0 and c.verdict == "inconclusive"
    c = claims.fig3_claim(analysis.summarize_convergence(synthetic(shrinking), [1.0]))
    assert c.verdict == "supported" and c.key.value == pytest.approx(-0.5)


def test_chebyshev_verdict_edge_cases():
    rng = np.random.default_rng(1)
    var = lqg.cost_variance(PAPER_U, **PAPER)
    # every bound Var(g)/(P eps^2) >= 1: no evidence, the cells are named as left out
    vac = synthetic({p: rng.normal(0, 1, 50) for p in (100, 200, 300)})
    c = claims.chebyshev_claim(analysis.summarize_convergence(vac, [0.25]), [0.25])
    assert c.verdict == "inconclusive" and c.key.value == 0
    assert c.dropped.startswith("3 of 3 cells")
    # three informative cells; the first exceeds its bound per cell (95% Clopper-Pearson lower
    # limit above it) but not familywise (Bonferroni over 3 cells): supported
    ps, n = [6400, 12800, 25600], 300
    bound = var / ps[0]
    k = next(
        k
        for k in range(n)
        if binomial_ci(k, n)[0] > bound and binomial_ci(k, n, 1 - 0.05 / 3)[0] <= bound
    )
    errs = {ps[0]: np.r_[np.full(k, 1.5), np.zeros(n - k)], ps[1]: np.zeros(n), ps[2]: np.zeros(n)}
    c = claims.chebyshev_claim(analysis.summarize_convergence(synthetic(errs), [1.0]), [1.0])
    assert c.verdict == "supported" and c.key.value == 0 and not c.dropped
    assert "lower limits above the bound (no familywise correction): 1" in c.measured
    # one more exceedance than the familywise limit allows: not supported
    k2 = next(k2 for k2 in range(k, n) if binomial_ci(k2, n, 1 - 0.05 / 3)[0] > bound)
    errs[ps[0]] = np.r_[np.full(k2, 1.5), np.zeros(n - k2)]
    c = claims.chebyshev_claim(analysis.summarize_convergence(synthetic(errs), [1.0]), [1.0])
    assert c.verdict == "not supported" and c.key.value == 1


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


EPS = [0.25, 1.0]


@pytest.fixture(scope="module")
def small():
    """Summaries, tables and the section of the small LQG configuration (tests/test_seeding)."""
    conv = run_convergence(BASE, seed=2)
    nbo = analysis.summarize_nbo_error(run_nbo_error(BASE, seed=2))
    summary = analysis.summarize_convergence(conv, EPS)
    tables = narrative.lqg_tables(summary, nbo, EPS)
    section = narrative.lqg_section(summary, nbo, conv, EPS, tables)
    return {"conv": conv, "nbo": nbo, "summary": summary, "tables": tables, "section": section}


def _column(table: str, header: str) -> list[str]:
    """Cells of column ``header`` of a Markdown table."""
    rows = [[c.strip() for c in line.strip().strip("|").split("|")] for line in table.splitlines()]
    i = rows[0].index(header)
    return [r[i] for r in rows[2:]]


def test_section_budget_numbers_and_roundtrip(small, tmp_path):
    section = small["section"]
    assert len(section.body.encode("utf-8")) <= 2600
    assert [c.id for c in section.claims] == ["LQG-1", "LQG-2", "LQG-3", "LQG-4"]
    for text in (section.body, section.appendix, *(c.measured for c in section.claims)):
        assert not re.search(r"\b(nan|inf)\b", text, re.IGNORECASE), text
        # integers (P, H, counts of replicates, trajectories, cells, tests) have no decimals
        assert not re.search(r"\b[PHR] = \d+\.\d", text), text
        assert not re.search(r"\d\.\d+ (replicates|trajectories|cells|tests|checks)", text), text
    for c in section.claims:
        assert len(c.claim) <= 120 and len(c.paper) <= 150 and len(c.rule) <= 300
    conv_table = small["tables"]["lqg_convergence"]
    assert _column(conv_table, "P") == ["20", "40", "60"]
    assert set(_column(conv_table, "replicates")) == {"4"}
    cheb = small["tables"]["lqg_chebyshev"]
    assert all(re.fullmatch(r"\d+", v) for v in _column(cheb, "exceedances"))
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


# ------------------------------------------------ verdict rules (rsmhp.claims.lqg) at their edges

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
        ({"J": 19.01}, "inconclusive"),  # mean biased, RMSE and slope fine
    ],
)
def test_fig3_rule_edges(change, verdict):
    assert claims.FIG3_RULE.verdict({**FIG3_OK, **change}) == verdict


@pytest.mark.parametrize(
    ("informative", "count", "verdict"),
    [(0, 0, "inconclusive"), (3, 0, "supported"), (3, 1, "not supported")],
)
def test_chebyshev_rule_edges(informative, count, verdict):
    assert claims.CHEBYSHEV_RULE.verdict({"informative cells": informative, "count": count}) == (
        verdict
    )


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
    for c in section.claims:
        assert c.rule.endswith("otherwise")
