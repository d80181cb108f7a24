"""Aggregation, verdict rules, report rendering, stats helpers and intermediate-file checks."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from rsmhp import lqg
from rsmhp.analysis import lqg as analysis
from rsmhp.experiments.lqg import CONVERGENCE_COLUMNS, run_convergence, run_nbo_error
from rsmhp.io import IntermediateFileError, read_table, write_csv
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
    c2, c3, _ = analysis.convergence_claims(analysis.summarize_convergence(good, [1.0]), [1.0])
    assert c2.verdict == "supported" and c3.verdict == "supported"
    # errors that do not shrink with P and are far larger than the bound allows
    bad = synthetic({p: rng.normal(0, 15.0, 300) for p in ps})
    c2b, c3b, _ = analysis.convergence_claims(analysis.summarize_convergence(bad, [1.0]), [1.0])
    assert c2b.verdict != "supported"
    assert c3b.verdict == "not supported"


def test_weighted_verdict_detects_bias_and_agreement():
    err = {p: np.random.default_rng(p).normal(0, 0.1, 50) for p in (100, 200, 300)}
    lim_gap = lqg.weighted_limit(PAPER_U, **PAPER) - J
    biased = analysis.summarize_convergence(synthetic(err, weighted_offset=lim_gap), [1.0])
    assert analysis.convergence_claims(biased, [1.0])[2].verdict == "not supported"
    unbiased = analysis.summarize_convergence(synthetic(err), [1.0])
    assert analysis.convergence_claims(unbiased, [1.0])[2].verdict == "supported"


def test_nbo_error_claim_rejects_a_wrong_formula():
    conv = run_convergence(BASE, seed=2)
    nbo = analysis.summarize_nbo_error(run_nbo_error(BASE, seed=2))
    summary = analysis.summarize_convergence(conv, [1.0])
    assert analysis.nbo_error_claim(nbo, summary, conv).verdict in ("supported", "not supported")
    wrong = nbo.assign(nbo_error_closed=nbo["nbo_error_closed"] * 1.5)
    wrong = wrong.assign(z=(wrong["nbo_error_sim"] - wrong["nbo_error_closed"]) / wrong["se"])
    assert analysis.nbo_error_claim(wrong, summary, conv).verdict == "not supported"


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
