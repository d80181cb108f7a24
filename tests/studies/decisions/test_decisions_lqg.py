"""LQG decision study: closed forms of the optimum and the regret, and the simulation
against them (tolerances from the chi-square variance of the regret)."""

from __future__ import annotations

import itertools
import re

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.colors import to_hex
from scipy import stats
from scipy.optimize import minimize

from rsmhp.core import designs
from rsmhp.core.cost_estimators import likeliness_weights
from rsmhp.core.sampling import rollout_cost, sample_tree
from rsmhp.core.seeding import job_rng
from rsmhp.models.lqg import oven as lqg
from rsmhp.models.lqg import regret_summary as dec
from rsmhp.models.lqg.regret import (
    DrawCell,
    RegretCell,
    _shifts,
    cell_rows,
    draw_cells,
    regret_cells,
    run_lqg_regret,
    sobol_budget,
)
from rsmhp.report.markdown import fmt
from rsmhp.report.palette import method_colour
from rsmhp.studies.decisions import claims_lqg as dec_claims
from rsmhp.studies.decisions import figures as figs
from rsmhp.studies.decisions import section_lqg as dec_text

MODEL = {"x0": 0.0, "r": 10.0, "target": 1.0, "sigma": 1.0}

problems = st.fixed_dictionaries(
    {
        "H": st.integers(1, 8),
        "a": st.floats(0.05, 0.95),
        "r": st.floats(0.1, 100.0),
        "x0": st.floats(-5.0, 5.0),
        "target": st.floats(-5.0, 5.0),
    }
)


def _kw(p):
    return {k: p[k] for k in ("x0", "a", "r", "target")}


@settings(max_examples=40, deadline=None)
@given(problems)
def test_optimal_controls_minimise_the_exact_cost(p):
    kw = _kw(p)
    u_star = lqg.optimal_controls(p["H"], **kw)
    j = lambda u: lqg.exact_cost(u, **kw, sigma=1.0)  # noqa: E731
    res = minimize(j, np.zeros(p["H"]), method="BFGS", options={"gtol": 1e-11})
    # J is a strictly convex quadratic: the numerical minimiser agrees with the closed form
    assert j(u_star) <= res.fun + 1e-10 * max(1.0, abs(res.fun))
    np.testing.assert_allclose(u_star, res.x, atol=1e-5)
    # NBO's cost has the same minimiser (certainty equivalence)
    nbo = minimize(lambda u: lqg.nbo_cost(u, **kw), np.zeros(p["H"]), method="BFGS")
    np.testing.assert_allclose(u_star, nbo.x, atol=1e-5)


@settings(max_examples=40, deadline=None)
@given(problems, st.integers(0, 2**32 - 1))
def test_regret_is_the_exact_cost_difference(p, seed):
    kw = _kw(p)
    u = np.random.default_rng(seed).normal(0.0, 2.0, p["H"])
    diff = lqg.exact_cost(u, **kw, sigma=0.7) - lqg.exact_cost(
        lqg.optimal_controls(p["H"], **kw), **kw, sigma=0.7
    )
    reg = lqg.regret(u, **kw)
    assert reg >= 0.0
    assert reg == pytest.approx(diff, rel=1e-9, abs=1e-9 * lqg.exact_cost(u, **kw, sigma=0.7))


@settings(max_examples=30, deadline=None)
@given(problems, st.integers(1, 50), st.booleans(), st.integers(0, 2**32 - 1))
def test_sample_argmin_minimises_the_library_sample_cost(p, n, weighted, seed):
    """The argmin of the estimator's own arithmetic (rollout_cost on LQGModel, weighted
    average): zero gradient by exact central differences of the quadratic, no better point
    nearby, regret = kappa * e_bar^2."""
    rng = np.random.default_rng(seed)
    kw = _kw(p)
    H = p["H"]
    model = lqg.LQGModel(a=p["a"], r=p["r"], target=p["target"], sigma=1.3)
    noise = rng.normal(0.0, 1.3, (n, H, 1))
    omega = rng.uniform(0.1, 2.0, n) if weighted else np.full(n, 1.0 / n)

    def j_hat(u):
        return float(omega @ rollout_cost(model, [p["x0"]], u, noise) / omega.sum())

    u_hat = lqg.sample_argmin(noise, omega, **kw)
    scale = max(1.0, j_hat(u_hat))
    for k in range(H):
        step = np.zeros(H)
        step[k] = 1e-3
        grad_k = (j_hat(u_hat + step) - j_hat(u_hat - step)) / 2e-3
        assert abs(grad_k) <= 1e-7 * scale / 1e-3
    for _ in range(5):
        assert j_hat(u_hat + rng.normal(0.0, 0.05, H)) >= j_hat(u_hat) - 1e-12 * scale
    c = lqg.coefficients(H, p["a"])
    e_bar = float(omega @ (noise[:, :, 0] @ c) / omega.sum())
    expected = lqg.regret_gain(H, a=p["a"], r=p["r"]) * e_bar**2
    assert lqg.regret(u_hat, **kw) == pytest.approx(expected, rel=1e-8, abs=1e-14)


def test_nbo_antithetic_and_cubature_have_zero_regret():
    kw = {"x0": 0.3, "a": 0.5, "r": 10.0, "target": 1.0}
    H = 4
    rng = np.random.default_rng(1)
    chol = np.array([[1.0]])
    j_star = lqg.exact_cost(lqg.optimal_controls(H, **kw), **kw, sigma=1.0)
    nbo = lqg.sample_argmin(np.zeros((1, H)), np.ones(1), **kw)
    anti, wa = designs.antithetic(rng, 100, H, chol)
    cub, wc = designs.cubature(H, chol)
    for noise, w in ((np.zeros((1, H)), np.ones(1)), (anti, wa), (cub, wc)):
        assert lqg.regret(lqg.sample_argmin(noise, w, **kw), **kw) <= 1e-24 * j_star
    np.testing.assert_allclose(nbo, lqg.optimal_controls(H, **kw), rtol=1e-14)


def test_sample_argmin_rejects_bad_input():
    kw = {"x0": 0.0, "a": 0.5, "r": 1.0, "target": 1.0}
    with pytest.raises(ValueError, match="weights must have shape"):
        lqg.sample_argmin(np.zeros((3, 2)), np.ones(2), **kw)
    with pytest.raises(ValueError, match="positive sum"):
        lqg.sample_argmin(np.zeros((3, 2)), np.zeros(3), **kw)
    with pytest.raises(ValueError, match="finite"):
        lqg.sample_argmin(np.full((3, 2), np.nan), np.ones(3), **kw)
    with pytest.raises(ValueError, match="shape"):
        lqg.sample_argmin(np.zeros(3), np.ones(3), **kw)
    with pytest.raises(ValueError, match="H must be an integer"):
        lqg.optimal_controls(2.5, **kw)
    with pytest.raises(ValueError, match="n_eff"):
        lqg.expected_regret(0, 2, a=0.5, r=1.0, sigma=1.0)


def _chi2_check(regrets: np.ndarray, mean: float) -> None:
    """Regret = mean * chi2_1: the sample mean within 4 standard errors (sd of chi2_1 is
    sqrt(2)), and a KS test against the scaled chi2_1 law."""
    R = regrets.size
    z = (regrets.mean() - mean) / (mean * np.sqrt(2.0 / R))
    assert abs(z) < 4.0, z
    assert stats.kstest(regrets / mean, stats.chi2(1).cdf).pvalue > 1e-3


@pytest.mark.parametrize("P", [3, 40])
def test_mc_regret_is_scaled_chi_square(P):
    a, H, R = 0.4, 3, 3000
    kw = {"x0": 0.0, "a": a, "r": 5.0, "target": 2.0}
    rng = np.random.default_rng(P)
    chol = np.array([[0.8]])
    reg = np.array(
        [
            lqg.regret(lqg.sample_argmin(*designs.monte_carlo(rng, P, H, chol), **kw), **kw)
            for _ in range(R)
        ]
    )
    _chi2_check(reg, lqg.expected_regret(P, H, a=a, r=5.0, sigma=0.8))


def test_shared_draw_tree_regret_is_that_of_n_trajectories():
    """Uniform average over the N^H leaves: e_bar is exactly sum_k c_k (mean of level k's N
    draws), so the regret is kappa v_H / N times chi2_1, not kappa v_H / N^H."""
    a, H, N, R = 0.5, 3, 4, 2000
    kw = {"x0": 0.0, "a": a, "r": 10.0, "target": 1.0}
    model = lqg.LQGModel(a=a, r=10.0, target=1.0, sigma=1.0)
    c = lqg.coefficients(H, a)
    rng = np.random.default_rng(7)
    reg = np.empty(R)
    for i in range(R):
        state = rng.bit_generator.state
        leaves = sample_tree(model, [0.0], np.zeros(H), N, rng).leaves
        rng2 = np.random.default_rng()
        rng2.bit_generator.state = state
        level_means = [rng2.standard_normal(N).mean() for _ in range(H)]
        noise = leaves.noise[:, :, 0]
        assert noise.shape == (N**H, H)
        np.testing.assert_allclose(noise.mean(axis=0) @ c, np.dot(c, level_means), atol=1e-13)
        reg[i] = lqg.regret(lqg.sample_argmin(noise, np.full(N**H, N ** -float(H)), **kw), **kw)
    _chi2_check(reg, lqg.expected_regret(N, H, a=a, r=10.0, sigma=1.0))


def test_sobol_budget_and_cells():
    assert [sobol_budget(p) for p in (10, 30, 100, 300, 1000, 3000, 10000)] == [
        8,
        32,
        128,
        256,
        1024,
        4096,
        8192,
    ]
    cfg = {
        "a_values": [0.5],
        "H_values": [2, 4],
        "P": [10, 100],
        "tree_N": [2, 10, 100],
        "pruned_N": 10,
        "max_leaves": 10000,
        "replicates": 3,
        "methods": ["nbo", "mc", "antithetic", "sobol", "cubature", "tree", "pruned"],
    }
    cells = regret_cells(cfg)
    trees = [(c.H, c.N) for c in cells if c.method == "tree"]
    assert trees == [(2, 2), (2, 10), (2, 100), (4, 2), (4, 10)]  # N^H <= max_leaves
    pruned = [(c.H, c.M) for c in cells if c.method == "pruned"]
    assert pruned == [(2, 10), (4, 10), (4, 100)]  # only M < N^H prunes
    assert RegretCell(0.5, 4, "cubature", P=8) in cells
    with pytest.raises(ValueError, match="unknown method 'bogus'"):
        regret_cells({**cfg, "methods": ["bogus"]})


def test_run_is_deterministic_and_complete():
    cfg = {
        "a_values": [0.3, 0.7],
        "H_values": [2, 3],
        "P": [10, 30],
        "tree_N": [2, 3],
        "pruned_N": 4,
        "max_leaves": 100,
        "replicates": 4,
        "methods": ["nbo", "mc", "antithetic", "sobol", "cubature", "tree", "pruned"],
    }
    one = run_lqg_regret(cfg, MODEL, 11, n_jobs=1)
    two = run_lqg_regret(cfg, MODEL, 11, n_jobs=2)
    assert one.equals(two)
    assert list(one.columns[:10]) == [
        "problem",
        "a",
        "H",
        "method",
        "weighting",
        "N",
        "M",
        "P",
        "replicate",
        "regret",
    ]
    assert {"u_hat_0", "u_hat_1", "u_hat_2"} <= set(one.columns)
    assert one.loc[one.H == 2, "u_hat_2"].isna().all()
    assert (one.regret >= 0).all()
    counts = one.groupby(["a", "H", "method", "weighting", "N", "M", "P"]).size()
    det = counts.index.get_level_values("method").isin(["nbo", "cubature"])
    assert (counts[det] == 1).all() and (counts[~det] == 4).all()
    # weighted rows exist exactly for mc, tree, pruned
    assert set(one.loc[one.weighting == "likeliness", "method"]) == {"mc", "tree", "pruned"}
    # the argmin in the row reproduces the row's regret
    row = one[(one.method == "mc") & (one.H == 3)].iloc[0]
    u = row[["u_hat_0", "u_hat_1", "u_hat_2"]].to_numpy(float)
    kw = {"x0": 0.0, "a": row.a, "r": 10.0, "target": 1.0}
    assert lqg.regret(u, **kw) == pytest.approx(row.regret, rel=1e-12)
    # a different seed gives different draws
    assert not run_lqg_regret(cfg, MODEL, 12, n_jobs=1).regret.equals(one.regret)


@settings(max_examples=30, deadline=None)
@given(
    H=st.integers(1, 4),
    N=st.integers(2, 6),
    M=st.integers(1, 40),
    pruned=st.booleans(),
    seed=st.integers(0, 2**31),
)
def test_tree_shifts_are_those_of_the_enumerated_tree(H, N, M, pruned, seed):
    """The study's e_bar of the shared-draw tree (full: separated by level; pruned: the
    compiled pruning) against sample_tree's leaves from the same stream, for three values of
    a at once and for every horizon h <= H from the draws of H levels (a tree of h levels
    is the first h levels of the process): both weightings, and the number of leaves."""
    a_values = [0.2, 0.5, 0.9]
    model = lqg.LQGModel(a=0.5, r=10.0, target=1.0, sigma=0.7)
    C = {h: np.stack([lqg.coefficients(h, a) for a in a_values]) for h in range(1, H + 1)}
    cell = DrawCell("pruned" if pruned else "tree", N=N, M=M if pruned else 0, H=tuple(C))
    got = _shifts(cell, C, model.noise, np.random.default_rng(seed))
    for h in C:
        rng = np.random.default_rng(seed)
        leaves = sample_tree(model, [0.0], np.zeros(h), N, rng, max_keep=M if pruned else None)
        e = leaves.leaves.noise[:, :, 0] @ C[h].T  # (leaves, A)
        lik = likeliness_weights(leaves.leaves.log_likeliness)
        n, by = got[h]
        assert n == e.shape[0]
        np.testing.assert_allclose(by["uniform"], e.mean(axis=0), rtol=1e-12, atol=1e-13)
        np.testing.assert_allclose(by["likeliness"], lik @ e / lik.sum(), rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("method", ["mc", "antithetic", "sobol", "cubature", "nbo"])
def test_cell_rows_are_the_sample_argmins_of_their_draws(method):
    """Every row against lqg.sample_argmin and lqg.regret on the replicate's own draws
    (job_rng(seed, "decisions_lqg", method=, N=, M=, P=, replicate=r), the same for every a;
    a horizon H uses the first H steps of the longest): argmins and regret to 1e-12."""
    H_max, P, reps, seed = 3, 16, 3, 5
    a_values = [0.3, 0.7]
    horizons = (H_max,) if method == "cubature" else (2, H_max)
    cell = DrawCell(method, P={"cubature": 2 * H_max, "nbo": 1}.get(method, P), H=horizons)
    frames = cell_rows(cell, a_values, MODEL, seed, reps)
    chol = np.array([[MODEL["sigma"]]])
    for a, H in itertools.product(a_values, horizons):
        kw = {"x0": MODEL["x0"], "a": a, "r": MODEL["r"], "target": MODEL["target"]}
        df = frames[RegretCell(a, H, method, P=cell.P)]
        for rep in range(1 if method in ("nbo", "cubature") else reps):
            rng = job_rng(seed, "decisions_lqg", method=method, N=0, M=0, P=cell.P, replicate=rep)
            if method == "nbo":
                w, wt = np.zeros((1, H)), np.ones(1)
            elif method == "cubature":
                w, wt = designs.cubature(H, chol)
            else:
                draw = getattr(designs, {"mc": "monte_carlo"}.get(method, method))
                w, wt = draw(rng, P, H_max, chol)
                w = w[:, :H]  # the first H steps of draws for the longest horizon
            weightings = {"uniform": wt}
            if method == "mc":
                noise = lqg.LQGModel(a=a, r=1.0, target=0.0, sigma=MODEL["sigma"]).noise
                weightings["likeliness"] = likeliness_weights(noise.logpdf(w).sum(axis=1))
            for weighting, omega in weightings.items():
                row = df[(df.replicate == rep) & (df.weighting == weighting)].iloc[0]
                u_hat = lqg.sample_argmin(w, omega, **kw)
                got = row[[f"u_hat_{k}" for k in range(H)]].to_numpy(float)
                np.testing.assert_allclose(got, u_hat, rtol=1e-12, atol=1e-14)
                assert row.regret == pytest.approx(lqg.regret(u_hat, **kw), rel=1e-10, abs=1e-28)


def test_draw_cells_share_the_draws_of_every_a_and_horizon():
    cfg = {
        "a_values": [0.3, 0.5, 0.7],
        "H_values": [2, 4],
        "P": [10, 100],
        "tree_N": [2, 10],
        "pruned_N": 10,
        "max_leaves": 10000,
        "replicates": 3,
        "methods": ["nbo", "mc", "sobol", "tree", "pruned"],
    }
    cells, groups = regret_cells(cfg), draw_cells(cfg)
    by_key = {(g.method, g.N, g.M, g.P): g for g in groups}
    for c in cells:  # every cell belongs to exactly one group, which lists its horizon
        assert c.H in by_key[DrawCell.key(c)].H
    assert sum(len(g.H) for g in groups) * 3 == len(cells)
    assert by_key[("mc", 0, 0, 10)].H == (2, 4)
    assert by_key[("tree", 2, 0, 0)].H == (2, 4) and by_key[("tree", 10, 0, 0)].H == (2, 4)


# ------------------------------------------------------------------ aggregation and claims


def _synthetic(
    nbo_regret: float, pruned_slope: float, seed: int = 3, pruned: dict | None = None
) -> pd.DataFrame:
    """Regret rows drawn from the closed forms (chi2_1 laws) for a small grid; the pruned
    tree's mean follows M^pruned_slope, or ``pruned[M]`` (mean per M) if given."""
    rng = np.random.default_rng(seed)
    rows = []
    R = 400
    for a in (0.4, 0.6):
        for H in (2, 4):
            base = {"problem": f"p{a}{H}", "a": a, "H": H, "replicate": 0, "shift": 0.0}
            rows.append(
                {
                    **base,
                    "method": "nbo",
                    "weighting": "uniform",
                    "N": 0,
                    "M": 0,
                    "P": 1,
                    "regret": nbo_regret,
                }
            )
            for P in (10, 100, 1000):
                mean = lqg.expected_regret(P, H, a=a, r=MODEL["r"], sigma=MODEL["sigma"])
                for r, x in enumerate(mean * rng.chisquare(1, R)):
                    rows.append(
                        {
                            **base,
                            "method": "mc",
                            "weighting": "uniform",
                            "N": 0,
                            "M": 0,
                            "P": P,
                            "replicate": r,
                            "regret": x,
                        }
                    )
                m_mean = pruned[P] if pruned else 0.2 * (P / 10) ** pruned_slope
                for r, x in enumerate(m_mean * rng.chisquare(1, R)):
                    rows.append(
                        {
                            **base,
                            "method": "pruned",
                            "weighting": "uniform",
                            "N": 10,
                            "M": P,
                            "P": P,
                            "replicate": r,
                            "regret": x,
                        }
                    )
            for N in (2, 4, 8):
                if N**H > 5000:
                    continue
                mean = lqg.expected_regret(N, H, a=a, r=MODEL["r"], sigma=MODEL["sigma"])
                for r, x in enumerate(mean * rng.chisquare(1, R)):
                    rows.append(
                        {
                            **base,
                            "method": "tree",
                            "weighting": "uniform",
                            "N": N,
                            "M": 0,
                            "P": N**H,
                            "replicate": r,
                            "regret": x,
                        }
                    )
    return pd.DataFrame(rows)


def _verdicts(df: pd.DataFrame) -> dict[str, str]:
    summary = dec.summarize_lqg_regret(df, MODEL)
    scaling = dec.lqg_scaling(summary)
    return {c.id: c.verdict for c in dec_claims.lqg_claims(summary, scaling, MODEL)}


def test_claims_follow_their_rules():
    v = _verdicts(_synthetic(nbo_regret=0.0, pruned_slope=0.0))
    assert v["DEC-1"] == "not supported"  # NBO optimal
    assert v["DEC-2"] == "supported"  # chi2 draws with the closed-form mean
    assert v["DEC-3"] == "supported"
    assert v["DEC-4"] == "inconclusive"  # flat in M: no cell falls, none rises
    v = _verdicts(_synthetic(nbo_regret=1.0, pruned_slope=-1.0))
    assert v["DEC-1"] == "supported"  # 1.0 is far above 1% of J*
    assert v["DEC-4"] == "supported"  # every cell falls 100-fold from M = 10 to 1000
    # a U shape in M (lowest at M = 100, back up 10-fold at M = 1000): DEC-4 not supported
    v = _verdicts(
        _synthetic(nbo_regret=0.0, pruned_slope=0.0, pruned={10: 0.2, 100: 0.02, 1000: 0.2})
    )
    assert v["DEC-4"] == "not supported"


def test_a_wrong_closed_form_is_detected():
    df = _synthetic(nbo_regret=0.0, pruned_slope=0.0)
    df.loc[df.method == "tree", "regret"] *= 1.5  # 50% off the closed form
    assert _verdicts(df)["DEC-3"] == "not supported"
    df = _synthetic(nbo_regret=0.0, pruned_slope=0.0)
    df.loc[df.method == "mc", "regret"] *= 1.5
    assert _verdicts(df)["DEC-2"] == "not supported"  # slopes fine, |z| far beyond the limit


# ------------------------------------------------- verdict rules on hand-made summaries

_SUMMARY_DEFAULTS = {"problem": "p", "N": 0, "M": 0, "n": 500, "median": 1.0, "J_star": 10.0}


def _summary(rows: list[dict]) -> pd.DataFrame:
    out = []
    for r in rows:
        r = {**_SUMMARY_DEFAULTS, **r}
        r.setdefault("mean", 1.0)
        r.setdefault("ci_low", r["mean"])
        r.setdefault("ci_high", r["mean"])
        r.setdefault("rel_mean", r["mean"] / r["J_star"])
        r.setdefault("closed_form", np.nan)
        r.setdefault("closed_kind", "none")
        r.setdefault("z", np.nan)
        out.append(r)
    return pd.DataFrame(out, columns=dec.LQG_SUMMARY_COLUMNS)


def _scaling(method: str, fits: list[tuple[float, float, float]]) -> pd.DataFrame:
    """One slope fit (slope, low, high) per (a, H) cell a = 0.5, H = 2, 3, ..."""
    return pd.DataFrame(
        [
            {
                "a": 0.5,
                "H": 2 + i,
                "method": method,
                "weighting": "uniform",
                "x": "N" if method == "tree" else "P",
                "n_points": 6,
                "slope": s,
                "low": lo,
                "high": hi,
            }
            for i, (s, lo, hi) in enumerate(fits)
        ],
        columns=dec.SCALING_COLUMNS,
    )


def _claim(summary: pd.DataFrame, scaling: pd.DataFrame, cid: str):
    return {c.id: c for c in dec_claims.lqg_claims(summary, scaling, MODEL)}[cid]


@pytest.mark.parametrize(
    "rel, verdict",
    [
        (1e-31, "not supported"),
        (1e-9, "not supported"),
        (1e-4, "inconclusive"),
        (0.01, "supported"),
    ],
)
def test_dec1_rule_edges(rel, verdict):
    summary = _summary(
        [
            {
                "a": 0.5,
                "H": 2,
                "method": "nbo",
                "weighting": "uniform",
                "P": 1,
                "n": 1,
                "mean": 10.0 * rel,
                "closed_form": 0.0,
                "closed_kind": "exact",
            }
        ]
    )
    c = _claim(summary, _scaling("mc", [])[:0], "DEC-1")
    assert c.verdict == verdict
    assert c.key.value == pytest.approx(rel) and c.key.reproducible == "bitwise"
    assert not c.key.has_ci


def _mc_summary(z: float) -> pd.DataFrame:
    return _summary(
        [
            {
                "a": 0.5,
                "H": 2,
                "method": "mc",
                "weighting": "uniform",
                "P": p,
                "closed_form": 1.0 / p,
                "closed_kind": "exact",
                "z": z if p == 10 else 0.1,
            }
            for p in (10, 100, 1000)
        ]
    )


@pytest.mark.parametrize(
    "fits, z, verdict",
    [
        ([(-1.0, -1.05, -0.95), (-0.99, -1.02, -0.96)], 1.0, "supported"),
        ([(-1.0, -1.05, -0.95), (-0.5, -1.2, 0.01)], 1.0, "not supported"),  # reaches 0
        ([(-1.0, -1.05, -0.95), (-0.99, -1.02, -0.96)], 3.0, "not supported"),  # |z| > 2.39
        ([(-1.0, -1.05, -0.95), (-0.8, -0.85, -0.75)], 1.0, "inconclusive"),  # misses -1
    ],
)
def test_dec2_rule_edges(fits, z, verdict):
    c = _claim(_mc_summary(z), _scaling("mc", fits), "DEC-2")
    assert c.verdict == verdict
    # the key number is the flattest slope (the CI that reaches highest), null 0
    flat = max(fits, key=lambda f: f[2])
    assert (c.key.value, c.key.ci_low, c.key.ci_high) == flat
    assert c.key.null == 0.0 and c.key.reproducible == "bitwise"


#: pruned-tree regret (mean, CI low, CI high) at M = 10, 30, 100 in one (a, H) cell
FALL = [(1.0, 0.9, 1.1), (0.5, 0.45, 0.55), (0.2, 0.15, 0.25)]  # largest M below smallest
U = [(1.0, 0.9, 1.1), (0.3, 0.25, 0.35), (0.6, 0.5, 0.7)]  # falls, then rises: a U
U_HIGH = [(0.5, 0.45, 0.55), (0.3, 0.25, 0.35), (0.9, 0.8, 1.0)]  # rises above the start
U_TOUCH = [(1.0, 0.9, 1.1), (0.3, 0.25, 0.35), (0.45, 0.35, 0.55)]  # CIs touch: no rise
FLAT = [(1.0, 0.8, 1.2), (0.9, 0.7, 1.1), (0.95, 0.75, 1.15)]  # neither
FALL_TOUCH = [(1.0, 0.9, 1.1), (0.8, 0.7, 0.9), (0.7, 0.5, 0.9)]  # CIs touch: no fall


def _pruned_rows(cells: dict[int, list], a: float = 0.5, N: int = 10) -> list[dict]:
    """Uniform pruned-tree summary rows: ``cells[H]`` the (mean, low, high) at M = 10, 30, 100."""
    return [
        {
            "a": a,
            "H": h,
            "method": "pruned",
            "weighting": "uniform",
            "N": N,
            "M": m,
            "P": m,
            "mean": mean,
            "ci_low": lo,
            "ci_high": hi,
        }
        for h, shape in cells.items()
        for m, (mean, lo, hi) in zip((10, 30, 100), shape, strict=True)
    ]


def _pruned_summary(cells: dict[int, list]) -> pd.DataFrame:
    """The cells of ``cells`` and a cell (a = 0.5, H = 9) with a single M (no shape)."""
    single = {"a": 0.5, "H": 9, "method": "pruned", "weighting": "uniform", "N": 10, "M": 10}
    return _summary([*_pruned_rows(cells), {**single, "P": 10}])


def test_pruned_shape_finds_falls_and_u_shapes():
    u_rows = _pruned_rows({2: U})
    rows = [
        *reversed(u_rows),  # any row order: sorted by M
        *_pruned_rows({3: FALL, 5: [(1.0, 0.9, 1.1), (0.3, 0.25, 0.35), (0.6, 0.35, 0.9)]}),
        *_pruned_rows({4: FALL})[:2],  # 2 values of M: no shape
        # likeliness weighting, other methods and another N are not the pruned tree's shape
        {**u_rows[1], "weighting": "likeliness", "mean": 0.01, "ci_low": 0.0, "ci_high": 0.02},
        {"a": 0.5, "H": 3, "method": "tree", "weighting": "uniform", "N": 10, "P": 1000,
         "mean": 2.0},
        {"a": 0.5, "H": 3, "method": "tree", "weighting": "uniform", "N": 4, "P": 64,
         "mean": 9.0},
    ]  # fmt: skip
    shape = dec.pruned_shape(_summary(rows))
    assert list(shape.columns) == dec.SHAPE_COLUMNS
    assert shape["H"].tolist() == [2, 3, 5]
    by = {int(r["H"]): r for _, r in shape.iterrows()}
    u, fall, touch = by[2], by[3], by[5]
    assert (u["M_first"], u["M_best"], u["M_last"], u["n_M"], u["N"]) == (10, 30, 100, 3, 10)
    assert (u["mean_first"], u["mean_best"], u["mean_last"]) == (1.0, 0.3, 0.6)
    assert (u["low_best"], u["high_best"], u["low_last"], u["high_last"]) == (0.25, 0.35, 0.5, 0.7)
    assert u["falls"] and u["rises"]  # 0.7 < 0.9 (the start) and 0.5 > 0.35 (the best)
    assert np.isnan(u["tree_mean"])  # no unpruned tree in that cell
    assert fall["falls"] and not fall["rises"] and fall["M_best"] == 100
    assert fall["tree_mean"] == 2.0  # the tree with the same N, not N = 4
    # the CIs touch (0.35 = 0.35 at the best M, 0.9 = 0.9 at the start): neither
    assert not touch["falls"] and not touch["rises"]
    # no pruned cell with 3 values of M: an empty table with the columns
    empty = dec.pruned_shape(_summary(_pruned_rows({4: FALL})[:2]))
    assert empty.empty and list(empty.columns) == dec.SHAPE_COLUMNS


@pytest.mark.parametrize(
    "cells, verdict, ratio, rising",
    [
        ({2: FALL, 3: FALL, 4: FALL}, "supported", 1.0, []),
        ({2: FALL, 3: U, 4: FALL}, "not supported", 2.0, [3]),  # a U beats every fall
        ({2: U_HIGH, 3: FALL, 4: FLAT}, "not supported", 3.0, [2]),
        ({2: FALL, 3: U_TOUCH, 4: FALL}, "supported", 1.5, []),  # touching CIs: no rise
        ({2: FALL, 3: FLAT, 4: FALL}, "inconclusive", 0.95 / 0.9, []),  # one cell neither
        ({2: FALL, 3: FALL_TOUCH, 4: FALL}, "inconclusive", 1.0, []),  # touching: no fall
    ],
)
def test_dec4_shape_rule_edges(cells, verdict, ratio, rising):
    summary = _pruned_summary(cells)
    c = _claim(summary, _scaling("pruned", [])[:0], "DEC-4")
    assert c.verdict == verdict
    shape = dec.pruned_shape(summary)
    facts = {
        "cells": len(shape),
        "cells falling": int(shape["falls"].sum()),
        "cells rising": int(shape["rises"].sum()),
    }
    assert dec_claims.RULES["DEC-4"].verdict(facts) == verdict
    assert c.rule == dec_claims.RULES["DEC-4"].text()
    # key number: the largest regret at the largest M over the lowest regret over M
    assert c.key.value == pytest.approx(ratio)
    assert not c.key.has_ci and c.key.reproducible == "bitwise"
    worst = max(cells, key=lambda h: cells[h][2][0] / min(m for m, _, _ in cells[h]))
    assert f"a = 0.5, H = {worst})" in c.key.name
    # the rising cells, and only they, are named as contrary evidence
    for h in cells:
        assert (f"a = 0.5, H = {h}:" in c.contrary) == (h in rising)
    assert ("rises:" in c.contrary) == bool(rising)
    # the (a, H) cell with a single M is named as left out
    assert "(a = 0.5, H = 9)" in c.dropped and "fewer than 3 values of M" in c.dropped
    assert c.part == "paper" and c.setup == dec_claims.SETUP


def test_dec4_names_the_unpruned_tree_and_is_absent_without_a_shape():
    tree = {"a": 0.5, "H": 2, "method": "tree", "weighting": "uniform", "N": 10, "P": 100}
    closed = {"closed_form": 5.0, "closed_kind": "exact", "z": 0.0}
    summary = _summary([*_pruned_rows({2: FALL}), {**tree, **closed, "mean": 5.0}])
    c = _claim(summary, _scaling("pruned", [])[:0], "DEC-4")
    assert "unpruned tree with the same N" in c.measured and "5.00 (a = 0.5, H = 2)" in c.measured
    assert not c.dropped  # every pruned cell has 3 values of M
    # a tree below the pruned tree at the largest M is not said to be above it
    summary.loc[summary.method == "tree", ["mean", "closed_form"]] = 0.1
    low = _claim(summary, _scaling("pruned", [])[:0], "DEC-4")
    assert "unpruned tree" not in low.measured
    # no pruned cell with 3 values of M: no DEC-4 claim
    few = _summary(_pruned_rows({2: FALL})[:2])
    assert "DEC-4" not in {x.id for x in dec_claims.lqg_claims(few, _scaling("mc", [])[:0], MODEL)}


def test_dec5_rule_is_the_z_check_alone():
    def summary(H: int, z: float) -> pd.DataFrame:
        return _summary(
            [
                {
                    "a": 0.5,
                    "H": H,
                    "method": "mc",
                    "weighting": "likeliness",
                    "P": p,
                    "closed_form": 1.0 / p,
                    "closed_kind": "asymptotic",
                    "z": z,
                }
                for p in (10, 100, 1000)
            ]
        )

    ok = _claim(summary(6, 1.0), _scaling("mc", [])[:0], "DEC-5")
    assert ok.verdict == "supported"
    assert "1 cells with P < 100" in ok.dropped  # P = 10 left out, and said so
    assert ok.part == "beyond" and ok.setup == dec_claims.SETUP
    assert ok.claim.startswith("In the oven LQG with open-loop controls")
    # (4/3)^(8/2)/3 > 1: at H = 8 weighting decides worse than uniform sampling; that is
    # derived, not measured, so it is reported but no longer decides the verdict
    h8 = _claim(summary(8, 1.0), _scaling("mc", [])[:0], "DEC-5")
    assert lqg.weighted_regret_ratio(8) > 1
    assert h8.verdict == "supported"
    assert f"{fmt(lqg.weighted_regret_ratio(8), 2)} (H = 8)" in h8.measured
    assert "(4/3)^{H/2}/3 < 1" not in h8.rule
    # P = 10 does not count: a huge z there changes nothing
    s = summary(6, 1.0)
    s.loc[s.P == 10, "z"] = 50.0
    assert _claim(s, _scaling("mc", [])[:0], "DEC-5").verdict == "supported"
    s.loc[s.P == 100, "z"] = 5.0
    assert _claim(s, _scaling("mc", [])[:0], "DEC-5").verdict == "not supported"


# ------------------------------------------------------------ section, tables, figure

NAN_INF = re.compile(r"\b(nan|inf)\b", re.IGNORECASE)
WHOLE_FLOAT_CELL = re.compile(r"\|\s*[+-]?\d+\.0\s*\|")
CFG = {"replicates": 400, "a_values": [0.4, 0.6], "H_values": [2, 4], "pruned_N": 10}


def _section():
    df = _synthetic(nbo_regret=0.0, pruned_slope=0.0)
    summary = dec.summarize_lqg_regret(df, MODEL)
    scaling = dec.lqg_scaling(summary)
    tables = dec_text.lqg_tables(summary, scaling)
    return summary, tables, dec_text.lqg_decision_section(summary, scaling, tables, MODEL, CFG)


def test_section_budget_and_text():
    _, tables, section = _section()
    assert len(section.body.encode("utf-8")) <= 2600
    assert [c.id for c in section.claims] == ["DEC-1", "DEC-2", "DEC-3", "DEC-4"]
    assert section.figures == list(dec_text.FIGURES)
    for name in section.figures:
        assert f"](figures/{name}.png)" in section.body
    assert "### Claims" not in section.body
    assert not re.search(r"^\|", section.body, re.MULTILINE)  # tables go to the appendix
    for text in (section.body, section.appendix):
        assert not NAN_INF.search(text)
    # configuration values print as written (r = 10, a = 0.4), not 10.0 or 0.400
    assert "r = 10," in section.body and "0.400" not in section.body
    assert not re.search(r"(?<![\d.])\d+\.0(?![\d])", section.body)
    for table in (tables["decisions_lqg_regret"], tables["decisions_lqg_scaling"]):
        assert table in section.appendix
        assert not NAN_INF.search(table) and not WHOLE_FLOAT_CELL.search(table)
    # absent closed forms are words, explained next to the table
    assert (
        "| none" in tables["decisions_lqg_regret"]
        and "'none' in the closed-form" in section.appendix
    )
    assert re.search(r"\|\s+400 \|", tables["decisions_lqg_regret"])  # replicates as an integer


def test_claims_fit_the_ledger():
    _, _, section = _section()
    parts = {"DEC-1": "paper", "DEC-2": "beyond", "DEC-3": "beyond", "DEC-4": "paper"}
    for c in section.claims:
        # the claim carries its scope (220); DEC-4's rule states its basis (419 characters)
        assert len(c.claim) <= 220 and len(c.paper) <= 150 and len(c.rule) <= 450, c.id
        assert c.claim.startswith("In the oven LQG with open-loop controls"), c.id
        assert c.rule == dec_claims.RULES[c.id].text()
        assert c.key.reproducible == "bitwise"
        assert c.part == parts[c.id] and c.setup == dec_claims.SETUP
        for text in (c.claim, c.paper, c.key.text(), c.measured, c.dropped, c.contrary):
            assert not NAN_INF.search(text)
    for rule in dec_claims.RULES.values():
        assert len(rule.text()) <= 450


def test_figure_colours_are_the_palette():
    summary, _, _ = _section()
    fig = figs.lqg_regret_figure(summary)
    try:
        seen = set()
        for ax in fig.axes:
            assert ax.get_xscale() == ax.get_yscale() == "log"
            for line in ax.lines:
                gid = line.get_gid()
                if gid:
                    method = gid.split("/")[0]
                    assert to_hex(line.get_color()) == method_colour(method), gid
                    seen.add(gid)
        assert {"mc/uniform", "tree/uniform", "pruned/uniform", "mc/closed form"} <= seen
        assert not any(g.startswith(("nbo", "antithetic", "cubature")) for g in seen)
        assert "regret" in fig.axes[0].get_ylabel() and "(count)" in fig.axes[-1].get_xlabel()
    finally:
        plt.close(fig)


def test_summary_z_scores_and_j_star():
    df = _synthetic(nbo_regret=0.0, pruned_slope=0.0)
    summary = dec.summarize_lqg_regret(df, MODEL)
    exact = summary[summary.closed_kind == "exact"]
    assert (exact.loc[exact.method == "mc", "z"].abs() < 4).all()
    j_star = lqg.exact_cost(
        lqg.optimal_controls(2, x0=0.0, a=0.4, r=10.0, target=1.0),
        x0=0.0,
        a=0.4,
        r=10.0,
        target=1.0,
        sigma=1.0,
    )
    assert summary.loc[(summary.a == 0.4) & (summary.H == 2), "J_star"].iloc[0] == pytest.approx(
        j_star
    )


# -------------------------------------------------- verdict rules (RULES) at their exact limits


def test_dec_rules_at_their_limits():
    rules = dec_claims.RULES
    assert rules["DEC-1"].verdict({"max NBO regret / J(u*)": dec_claims.NBO_ROUNDING}) == (
        "not supported"
    )
    assert rules["DEC-1"].verdict({"max NBO regret / J(u*)": dec_claims.NBO_SEVERE}) == "supported"
    z = {"max |z|": 2.5, "z limit": 2.5}  # at the limit: within it
    assert rules["DEC-3"].verdict(z) == "supported"
    assert rules["DEC-3"].verdict({**z, "max |z|": float("nan")}) == "not supported"  # no cell
    fits = {"highest upper limit": -0.5, "highest lower limit": -1.0, "lowest upper limit": -1.0}
    assert rules["DEC-2"].verdict({**fits, **z}) == "supported"  # CIs reaching -1 contain it
    assert rules["DEC-2"].verdict({**fits, **z, "highest upper limit": 0.0}) == "not supported"
    assert rules["DEC-2"].verdict({**fits, **z, "highest lower limit": -0.99}) == "inconclusive"
    shape = {"cells": 2, "cells falling": 2, "cells rising": 0}
    assert rules["DEC-4"].verdict(shape) == "supported"
    assert rules["DEC-4"].verdict({**shape, "cells falling": 1}) == "inconclusive"
    assert rules["DEC-4"].verdict({**shape, "cells rising": 1}) == "not supported"  # one U
    assert rules["DEC-4"].verdict({**shape, "cells falling": 0, "cells rising": 2}) == (
        "not supported"
    )
    assert rules["DEC-4"].verdict({"cells": 0, "cells falling": 0, "cells rising": 0}) == (
        "inconclusive"  # no cell: nothing falls
    )
    assert rules["DEC-5"].verdict(z) == "supported"  # no deterministic part any more
    assert rules["DEC-5"].verdict({**z, "max |z|": np.nextafter(2.5, 3.0)}) == "not supported"
    assert rules["DEC-5"].verdict({**z, "max |z|": float("nan")}) == "not supported"
    # the printed rules state the constants and the comparisons they use
    assert "1e-9 × J(u*)" in rules["DEC-1"].text() and "1% of J(u*)" in rules["DEC-1"].text()
    assert "U shape" in rules["DEC-4"].text() and "smallest M" in rules["DEC-4"].text()
    assert "(4/3)^{H/2}/3 < 1" not in rules["DEC-5"].text()
    assert f"P ≥ {dec.WEIGHTED_MIN_P}" in rules["DEC-5"].text()


_Z_OK = {"max |z|": 2.0, "z limit": 2.5}
_Z_BAD = {"max |z|": 3.0, "z limit": 2.5}
_FITS = {"highest upper limit": -0.5, "highest lower limit": -1.1, "lowest upper limit": -0.9}

#: per rule, constructed facts and the verdict they must give
RULE_FACTS = {
    "DEC-1": [
        ({"max NBO regret / J(u*)": 0.0}, "not supported"),
        ({"max NBO regret / J(u*)": 1e-4}, "inconclusive"),
        ({"max NBO regret / J(u*)": 0.5}, "supported"),
    ],
    "DEC-2": [
        ({**_FITS, **_Z_OK}, "supported"),
        ({**_FITS, **_Z_BAD}, "not supported"),
        ({**_FITS, **_Z_OK, "highest upper limit": 0.1}, "not supported"),
        ({**_FITS, **_Z_OK, "lowest upper limit": -1.1}, "inconclusive"),  # misses -1
    ],
    "DEC-3": [(_Z_OK, "supported"), (_Z_BAD, "not supported")],
    "DEC-4": [
        ({"cells": 3, "cells falling": 3, "cells rising": 0}, "supported"),
        ({"cells": 3, "cells falling": 3, "cells rising": 1}, "not supported"),
        ({"cells": 3, "cells falling": 2, "cells rising": 0}, "inconclusive"),
    ],
    "DEC-5": [(_Z_OK, "supported"), (_Z_BAD, "not supported")],
}


@pytest.mark.parametrize("cid", sorted(dec_claims.RULES))
def test_every_rule_gives_each_of_its_verdicts(cid):
    rule = dec_claims.RULES[cid]
    for facts, verdict in RULE_FACTS[cid]:
        assert rule.verdict(facts) == verdict, facts
    assert {v for _, v in RULE_FACTS[cid]} == set(rule.verdicts)


def test_weighted_mc_regret_matches_the_first_order_closed_form():
    """Likeliness-weighted argmin over P i.i.d. trajectories: mean regret
    kappa v_H (4/3)^{H/2} / (3P) to first order in 1/P
    (rsmhp.models.lqg.oven.weighted_expected_regret)."""
    a, H, P, R, sigma = 0.5, 2, 400, 2000, 1.0
    kw = {"x0": 0.0, "a": a, "r": 10.0, "target": 1.0}
    rng = np.random.default_rng(11)
    reg = np.empty(R)
    for i in range(R):
        noise = rng.normal(0.0, sigma, (P, H))
        logw = -0.5 * (noise**2).sum(axis=1) / sigma**2
        reg[i] = lqg.regret(lqg.sample_argmin(noise, np.exp(logw - logw.max()), **kw), **kw)
    mean = lqg.weighted_expected_regret(P, H, a=a, r=10.0, sigma=sigma)
    assert mean == pytest.approx(
        lqg.expected_regret(P, H, a=a, r=10.0, sigma=sigma) * lqg.weighted_regret_ratio(H)
    )
    # the regret's spread is not exactly chi2_1 here; its sample SD gives the standard error
    assert abs(reg.mean() - mean) < 4 * reg.std(ddof=1) / np.sqrt(R)


def test_checks_are_the_closed_form_claims():
    """DEC-2, DEC-3 and DEC-5 test the simulated regret against closed forms (checks of our
    own machinery, counted apart from the findings); DEC-1 and DEC-4 are findings. No key
    number is a paired mean judged against a margin: ``n`` and ``margin`` stay unset."""
    summary = dec.summarize_lqg_regret(_synthetic(nbo_regret=1.0, pruned_slope=-1.0), MODEL)
    weighted = _summary(
        [
            {"a": 0.5, "H": 2, "method": "mc", "weighting": "likeliness", "P": p,
             "closed_form": 1.0 / p, "closed_kind": "asymptotic", "z": 0.5}
            for p in (100, 1000)
        ]
    )  # fmt: skip
    summary = pd.concat([summary, weighted], ignore_index=True)
    claims = dec_claims.lqg_claims(summary, dec.lqg_scaling(summary), MODEL)
    assert [c.id for c in claims] == ["DEC-1", "DEC-2", "DEC-3", "DEC-4", "DEC-5"]
    assert {c.id for c in claims if c.check} == {"DEC-2", "DEC-3", "DEC-5"}
    assert all(c.key.n is None and c.key.margin is None for c in claims)
