"""The summary across scenarios: the probability of improvement (rsmhp.core.stats) against its
normal-theory oracle and its bootstrap's coverage, the per-scenario and per-group tables
(rsmhp.studies.scenarios.summarise) against brute force, the section and the figure."""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import stats as sps

from rsmhp.core.stats import probability_of_improvement
from rsmhp.report.markdown import fmt
from rsmhp.report.palette import method_label
from rsmhp.studies.scenarios.best import BEST_RUN_COLUMNS, best_family
from rsmhp.studies.scenarios.figures import improvement_figure
from rsmhp.studies.scenarios.section import scenarios_section, scenarios_tables
from rsmhp.studies.scenarios.summarise import (
    ALL_GROUP,
    HORIZON_GROUP,
    MAP_GROUP,
    SUMMARY_COLUMNS,
    improvement_summary,
    per_scenario,
    scenario_runs,
)


def test_no_difference_is_one_half_with_a_degenerate_interval():
    x = np.arange(7.0)
    imp = probability_of_improvement([(x, x), (x[:3], x[:3])], n_boot=200)
    assert (imp.p, imp.low, imp.high, imp.scenarios) == (0.5, 0.5, 0.5, 2)
    assert imp.share_above_half == 0.0


@settings(max_examples=40, deadline=None)
@given(st.lists(st.lists(st.integers(-3, 3), min_size=1, max_size=8), min_size=1, max_size=5),
       st.integers(0, 2**31 - 1))  # fmt: skip
def test_swapping_the_methods_mirrors_the_probability(values, seed):
    rng = np.random.default_rng(seed)
    pairs = [(np.array(v, float), rng.integers(-3, 4, len(v)).astype(float)) for v in values]
    a = probability_of_improvement(pairs, n_boot=50, seed=seed)
    b = probability_of_improvement([(y, x) for x, y in pairs], n_boot=50, seed=seed)
    assert a.p + b.p == pytest.approx(1.0)
    assert 0.0 <= a.low <= a.p <= a.high <= 1.0 or a.low == a.high


def _scenarios(rng, shifts, n, sd=1.0):
    """Paired runs: a shared scenario part, x = common − shift + noise, y = common + noise:
    d = x − y ~ N(−shift, 2 sd²), so P(x < y) = Φ(shift / (sd √2))."""
    out = []
    for s in shifts:
        common = rng.normal(10.0, 5.0, n)
        out.append((common - s + rng.normal(0, sd, n), common + rng.normal(0, sd, n)))
    return out


def test_point_estimate_matches_the_normal_oracle_within_its_standard_error():
    rng = np.random.default_rng(11)
    shifts = [0.0, 0.5, 1.0, 2.0]
    n = 400
    want = np.mean([sps.norm.cdf(s / math.sqrt(2)) for s in shifts])
    # each p_s is a mean of n Bernoulli(p_s): SD of the average over S scenarios
    sd = math.sqrt(sum(p * (1 - p) for p in (sps.norm.cdf(s / math.sqrt(2)) for s in shifts))
                   / n) / len(shifts)  # fmt: skip
    imp = probability_of_improvement(_scenarios(rng, shifts, n), n_boot=500, seed=1)
    assert abs(imp.p - want) < 4 * sd
    # three scenarios lie far above 1/2 (p = 0.64, 0.76, 0.92 with SE <= 0.024); the
    # shift-0 one is 1/2 in expectation and falls on either side
    assert imp.share_above_half in (0.75, 1.0)


def test_stratified_bootstrap_interval_covers_the_truth():
    """200 replicate benchmarks of 3 scenarios x 30 runs: the 95% interval should cover the
    true average probability in 95% of them; with 200 replicates a coverage below 0.89 (3
    binomial SDs under 0.95) would be an error, not chance."""
    rng = np.random.default_rng(5)
    shifts = [0.3, 0.8, 1.5]
    truth = np.mean([sps.norm.cdf(s / math.sqrt(2)) for s in shifts])
    hits = 0
    reps = 200
    for k in range(reps):
        imp = probability_of_improvement(_scenarios(rng, shifts, 30), n_boot=400, seed=k)
        hits += imp.low <= truth <= imp.high
    assert hits / reps >= 0.95 - 3 * math.sqrt(0.95 * 0.05 / reps)


def test_bad_input_is_refused_naming_it():
    with pytest.raises(ValueError, match="no scenarios"):
        probability_of_improvement([])
    with pytest.raises(ValueError, match=r"pairs\[0\]: x and y must be 1-D of one length"):
        probability_of_improvement([(np.ones(3), np.ones(2))])
    with pytest.raises(ValueError, match=r"pairs\[1\]\[0\]"):
        probability_of_improvement([(np.ones(2), np.ones(2)), (np.array([np.nan]), np.ones(1))])


def _tables(rng):
    rows = []
    for cell, radius, q in (("r0c0", np.nan, 1.0), ("r1c0", 150.0, 1.0)):
        common = rng.normal(10, 3, 6)
        for method, shift in (("nbo", 0.0), ("rsmhp_nt100", -0.5), ("sigma", 0.3)):
            for r in range(6):
                rows.append({"cell": cell, "row_value": radius, "col_value": q,
                             "method": method, "run": r,
                             "mean_error": common[r] + shift + rng.normal(0, 0.4)})  # fmt: skip
    map_runs = pd.DataFrame(rows)
    rows = []
    for H in (2, 4, 6):
        common = rng.normal(10, 3, 5)
        for method, shift in (("nbo", 0.0), ("sigma", -0.2), ("dpw_s20", -1.0)):
            for r in range(5):
                rows.append({"model": "paper", "H": H, "method": method, "run": r,
                             "mean_error": common[r] + shift + rng.normal(0, 0.4)})  # fmt: skip
    return map_runs, pd.DataFrame(rows)


def test_per_scenario_and_summary_follow_brute_force():
    map_runs, closed = _tables(np.random.default_rng(2))
    runs = scenario_runs(map_runs, closed)
    assert set(runs["group"]) == {MAP_GROUP, HORIZON_GROUP}
    assert "r1c0: footprint 150 m, q 1" in set(runs["scenario"])
    assert "r0c0: no footprint, q 1" in set(runs["scenario"])
    per = per_scenario(runs)
    # brute force for one scenario
    m = map_runs[map_runs.cell == "r1c0"].pivot(index="run", columns="method", values="mean_error")
    want = np.mean((m["sigma"] < m["nbo"]) + 0.5 * (m["sigma"] == m["nbo"]))
    got = per[(per.scenario == "r1c0: footprint 150 m, q 1") & (per.method == "sigma")]
    assert got["p_improve"].item() == pytest.approx(want)
    assert got["mean_diff"].item() == pytest.approx(float((m["sigma"] - m["nbo"]).mean()))
    s = improvement_summary(runs, n_boot=300, seed=4)
    assert list(s.columns) == SUMMARY_COLUMNS
    # the sigma points ran in both groups: a row for all scenarios (5 of them), the mean of
    # the five per-scenario probabilities; the others ran in one group and have none
    sig = s[s.method == "sigma"].set_index("group")
    assert set(sig.index) == {MAP_GROUP, HORIZON_GROUP, ALL_GROUP}
    assert sig.loc[ALL_GROUP, "scenarios"] == 5
    assert sig.loc[ALL_GROUP, "p_improve"] == pytest.approx(
        per[per.method == "sigma"]["p_improve"].mean()
    )
    assert set(s[s.method == "dpw_s20"]["group"]) == {HORIZON_GROUP}
    assert (s["low"] <= s["p_improve"]).all() and (s["p_improve"] <= s["high"]).all()


def test_a_run_twice_in_a_scenario_is_refused():
    map_runs, closed = _tables(np.random.default_rng(3))
    with pytest.raises(ValueError, match="appears twice"):
        scenario_runs(pd.concat([map_runs, map_runs.iloc[:1]]), closed)
    assert scenario_runs(None, None).empty


def test_section_and_figure_read_the_summary():
    map_runs, closed = _tables(np.random.default_rng(4))
    runs = scenario_runs(map_runs, closed)
    s = improvement_summary(runs, n_boot=200, seed=0)
    empty = best_family(pd.DataFrame(columns=BEST_RUN_COLUMNS))
    tables = scenarios_tables(s, per_scenario(runs), empty.cells, empty.paired)
    sec = scenarios_section(s, tables, empty.cells)
    assert sec.key == "scenarios" and not sec.claims
    assert f"{MAP_GROUP} (2 scenarios): " in sec.body
    assert f"{HORIZON_GROUP} (3 scenarios): " in sec.body
    # every method with its probability and, beside it, its mean difference in metres (the
    # mean over scenarios of the scenario's paired mean difference) in the table's order
    per = per_scenario(runs)
    for r in s[s.group != ALL_GROUP].itertuples(index=False):
        mine = per[(per.method == r.method) & (per.group == r.group)]["mean_diff"]
        assert r.mean_diff == pytest.approx(mine.mean())
        assert r.worse_scenarios == int((mine > 0).sum())
        text = (f"{method_label(r.method)} {fmt(r.p_improve, 2)} [{fmt(r.low, 2)}, "
                f"{fmt(r.high, 2)}], {fmt(r.mean_diff, 3, True)} m")  # fmt: skip
        assert text in sec.body
    assert "highest" not in sec.body and "lowest" not in sec.body.split("Which")[-1]
    assert tables["scenarios_improvement"] in sec.appendix
    fig = improvement_figure(s)
    try:
        assert fig.axes[0].get_xlabel().startswith("P(run beats NBO")
    finally:
        plt.close(fig)
    with pytest.raises(ValueError, match="empty"):
        improvement_figure(s.iloc[:0])
