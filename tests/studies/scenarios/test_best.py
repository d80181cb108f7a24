"""The best method per cell (rsmhp.studies.scenarios.best): the answer on synthetic data where it
is known (a clear best, two tied methods), the paired t interval against scipy by hand, the
refusals, the three groups' long tables, the table, the prose and the figure."""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from rsmhp.report.markdown import fmt_ci
from rsmhp.studies.scenarios.best import (
    BEST_COLUMNS,
    BEST_RUN_COLUMNS,
    BUDGET,
    HORIZON,
    PAIRED_COLUMNS,
    SCENARIO,
    best_family,
    best_runs,
    budget_runs,
    horizon_runs,
    scenario_runs,
)
from rsmhp.studies.scenarios.figures import best_figure, family_colour, short_label
from rsmhp.studies.scenarios.section import GROUP_NAMES, best_table, config_label


def _long(errors: dict[str, np.ndarray], group="horizon", model="paper", axis=6.0) -> pd.DataFrame:
    """One cell: ``errors[method][run]``."""
    return pd.DataFrame(
        [
            {"group": group, "model": model, "value": axis, "method": m, "run": r, "error": e}
            for m, x in errors.items()
            for r, e in enumerate(x)
        ]
    )


def _clear_cell(rng, n=30) -> dict[str, np.ndarray]:
    """A shared scenario part (SD 5 m) and small method noise: rsmhp 2 m below NBO, sigma
    1 m above rsmhp; every paired difference from rsmhp has SD ~0.3 m."""
    common = rng.normal(20.0, 5.0, n)
    return {
        "nbo": common + 2.0 + rng.normal(0, 0.2, n),
        "rsmhp_nt64": common + rng.normal(0, 0.2, n),
        "sigma": common + 1.0 + rng.normal(0, 0.2, n),
    }


def test_a_clearly_best_method_is_clear():
    b = best_family(_long(_clear_cell(np.random.default_rng(1))))
    assert list(b.cells.columns) == BEST_COLUMNS and list(b.paired.columns) == PAIRED_COLUMNS
    c = b.cells.iloc[0]
    assert (c.best, c.runner_up, c.runs, c.methods) == ("rsmhp_nt64", "sigma", 30, 3)
    assert c.clear and c.n_tied == 0 and c.tied == ""
    assert c.runner_up_diff == pytest.approx(1.0, abs=0.2) and c.runner_up_low > 0
    p = b.paired.set_index("method")
    assert list(p.index) == ["sigma", "nbo"]  # by mean, the runner-up first
    assert (p["low"] > 0).all() and not p["tied"].any()
    assert p.loc["nbo", "mean_diff"] == pytest.approx(2.0, abs=0.2)


def test_two_tied_methods_are_named_and_the_best_is_not_clear():
    # b − a over 8 runs: +1, −1, ... plus 0.1 on one run: mean 0.0125 > 0, CI contains 0;
    # c is 5 m above a on every run but one (SD > 0): clearly worse
    a = np.array([10.0, 12.0, 9.0, 11.0, 13.0, 8.0, 10.5, 11.5])
    b = a + np.array([1, -1, 1, -1, 1, -1, 1, -0.9])
    c = a + 5.0 + np.r_[np.zeros(7), 0.5]
    best = best_family(_long({"a": a, "b": b, "c": c}))
    r = best.cells.iloc[0]
    assert (r.best, r.runner_up, r.tied, r.n_tied, r.clear) == ("a", "b", "b", 1, False)
    assert r.runner_up_low < 0 < r.runner_up_high
    assert best.paired.set_index("method").loc["c", "low"] > 0
    # three tied: the list keeps the order of the means
    best3 = best_family(_long({"a": a, "b": b, "b2": b + 0.001, "c": c}))
    assert best3.cells.iloc[0].tied == "b;b2" and best3.cells.iloc[0].n_tied == 2


def test_the_interval_is_the_paired_student_t_interval_by_hand():
    rng = np.random.default_rng(7)
    n = 12
    x = {"nbo": rng.normal(30, 4, n), "dpw_s100": rng.normal(29, 4, n)}
    x["rqmc_nt256"] = x["dpw_s100"] - 0.5 + rng.normal(0, 1.0, n)
    b = best_family(_long(x))
    best = b.cells.iloc[0].best
    means = {m: v.mean() for m, v in x.items()}
    assert best == min(means, key=means.get)
    for r in b.paired.itertuples():
        d = x[r.method] - x[best]
        half = sps.t.ppf(0.975, n - 1) * d.std(ddof=1) / math.sqrt(n)
        assert r.mean_diff == pytest.approx(d.mean(), rel=1e-12)
        assert (r.low, r.high) == (pytest.approx(d.mean() - half, rel=1e-12),
                                   pytest.approx(d.mean() + half, rel=1e-12))  # fmt: skip
        assert r.tied == (d.mean() - half <= 0)
    # a 90% interval is narrower
    b90 = best_family(_long(x), level=0.9)
    assert (b90.paired["high"] - b90.paired["low"] < b.paired["high"] - b.paired["low"]).all()


def test_pairing_by_run_is_what_makes_a_small_difference_clear():
    """The shared scenario part (SD 10 m) dwarfs a 0.5 m difference; paired by run the
    difference has SD 0.1 m and its interval lies above 0. Shuffling one method's runs breaks
    the pairing: the interval then reaches 0."""
    rng = np.random.default_rng(3)
    common = rng.normal(50, 10, 40)
    x = {"a": common + rng.normal(0, 0.07, 40), "b": common + 0.5 + rng.normal(0, 0.07, 40)}
    assert best_family(_long(x)).cells.iloc[0].clear
    shuffled = {"a": x["a"], "b": x["b"][rng.permutation(40)]}
    assert not best_family(_long(shuffled)).cells.iloc[0].clear


def test_cells_are_separate_and_keep_their_order():
    rng = np.random.default_rng(2)
    parts = [_long(_clear_cell(rng), model=m, axis=h) for m in ("paper", "fp150") for h in (4, 2)]
    b = best_family(pd.concat(parts, ignore_index=True))
    assert list(zip(b.cells.model, b.cells.value, strict=True)) == [
        ("paper", 4.0), ("paper", 2.0), ("fp150", 4.0), ("fp150", 2.0)]  # fmt: skip
    assert len(b.paired) == 4 * 2


def test_equal_means_take_the_first_method():
    x = np.array([1.0, 2.0, 3.0])
    r = best_family(_long({"a": x, "b": x[::-1].copy()})).cells.iloc[0]
    assert r.best == "a" and r.tied == "b" and r.runner_up_diff == 0.0


def test_bad_input_is_refused_naming_it():
    ok = _long(_clear_cell(np.random.default_rng(4), n=5))
    with pytest.raises(ValueError, match=r"missing column\(s\) \['error'\]"):
        best_family(ok.drop(columns="error"))
    with pytest.raises(ValueError, match=r"runs \[3\] of 'sigma' are missing"):
        best_family(ok[~((ok.method == "sigma") & (ok.run == 3))])
    with pytest.raises(ValueError, match="has 1 run; a paired t interval needs at least 2"):
        best_family(ok[ok.run == 0])
    with pytest.raises(ValueError, match="run 2 of 'nbo' appears twice"):
        best_family(pd.concat([ok, ok[(ok.method == "nbo") & (ok.run == 2)]]))
    bad = ok.copy()
    bad.loc[bad.index[7], "error"] = np.nan
    with pytest.raises(ValueError, match="'error' is not a finite number at run 2 of 'rsmhp_nt64'"):
        best_family(bad)
    with pytest.raises(ValueError, match="has 1 method \\(nbo\\); a best needs at least 2"):
        best_family(ok[ok.method == "nbo"])
    with pytest.raises(ValueError, match="column 'value' must be numeric"):
        best_family(ok.assign(value="six"))
    with pytest.raises(ValueError, match="column 'model' has 15 missing"):
        best_family(ok.assign(model=np.nan))
    empty = best_family(pd.DataFrame(columns=BEST_RUN_COLUMNS))
    assert empty.cells.empty and list(empty.cells.columns) == BEST_COLUMNS


# ------------------------------------------------------------------ the groups' long tables

TUNED = {
    "chosen": {
        "fp150": {
            "0.5": {"rsmhp": {"member": "rsmhp_nt8", "maxiter": 6, "restarts": 0},
                    "dpw": {"member": "dpw_s10", "maxiter": None, "restarts": 0}},
            "2": {"rsmhp": {"member": "rsmhp_nt8", "maxiter": 6, "restarts": 1},
                  "sigma": {"member": "sigma", "maxiter": 6, "restarts": 1}},
        }
    }
}  # fmt: skip


def _confirm(rng, runs=4) -> pd.DataFrame:
    configs = [("nbo", "nbo"), ("rsmhp_nt8/it6/r0", "rsmhp_nt8"), ("dpw_s10", "dpw_s10"),
               ("rsmhp_nt8/it6/r1", "rsmhp_nt8"), ("sigma/it6/r1", "sigma")]  # fmt: skip
    common = rng.normal(40, 5, runs)
    return pd.DataFrame(
        [{"model": "fp150", "config": c, "member": m, "run": r,
          "mean_error": common[r] + k + rng.normal(0, 0.1)}
         for k, (c, m) in enumerate(configs) for r in range(runs)]
    )  # fmt: skip


def test_budget_runs_take_the_tuned_member_of_each_family_and_nbo_per_budget():
    runs = budget_runs(_confirm(np.random.default_rng(5)), TUNED, [0.5, 2.0])
    assert list(runs.columns) == BEST_RUN_COLUMNS and set(runs.group) == {BUDGET}
    per = runs.groupby("value")["method"].unique().map(list).to_dict()
    assert per == {0.5: ["nbo", "rsmhp_nt8/it6/r0", "dpw_s10"],
                   2.0: ["nbo", "rsmhp_nt8/it6/r1", "sigma/it6/r1"]}  # fmt: skip
    fam = dict(zip(runs.method, runs.family, strict=True))
    assert fam["dpw_s10"] == "dpw" and fam["sigma/it6/r1"] == "sigma" and fam["nbo"] == "nbo"
    b = best_family(runs)
    assert list(b.cells.value) == [0.5, 2.0] and (b.cells.best == "nbo").all()
    with pytest.raises(ValueError, match=r"'sigma/it6/r1' .* has no confirmatory runs"):
        c = _confirm(np.random.default_rng(5))
        budget_runs(c[c.config != "sigma/it6/r1"], TUNED, [0.5, 2.0])


def test_horizon_and_scenario_runs_and_absent_groups():
    closed = pd.DataFrame({"model": "paper", "H": [4, 4, 2, 2], "method": ["nbo", "sigma"] * 2,
                           "run": [0, 0, 0, 0], "mean_error": [1.0, 2.0, 3.0, 4.0]})  # fmt: skip
    h = horizon_runs(closed)
    assert list(h.value) == [2.0, 2.0, 4.0, 4.0] and set(h.group) == {HORIZON}
    m = pd.DataFrame({"cell": ["r0c0", "r1c0"], "row_value": [np.nan, 300.0],
                      "col_value": [1.0, 1.0], "method": "nbo", "run": 0,
                      "mean_error": [5.0, 6.0]})  # fmt: skip
    s = scenario_runs(m)
    assert list(s.model) == ["no footprint", "footprint 300 m"] and set(s.group) == {SCENARIO}
    both = best_runs(closed=closed, map_runs=m)
    assert list(dict.fromkeys(both.group)) == [HORIZON, SCENARIO]
    assert best_runs(confirm=None, closed=closed.iloc[:0], map_runs=None).empty
    with pytest.raises(ValueError, match="need the tuned document"):
        best_runs(confirm=_confirm(np.random.default_rng(1)))


# ------------------------------------------------------------------ table, prose and figure


def _three_groups(rng) -> pd.DataFrame:
    """A small table of every group: budget (1 model × 2 budgets), horizon (2 models × 2 H),
    scenario (2 footprints × 2 q)."""
    parts = [budget_runs(_confirm(rng), TUNED, [0.5, 2.0])]
    for model in ("paper", "footprint150"):
        for H in (2, 6):
            x = _clear_cell(rng, n=6)
            x["dpw_s100"] = x["rsmhp_nt64"] + rng.normal(0, 0.2, 6)  # tied with rsmhp
            parts.append(_long(x, HORIZON, model, H))
    for fp in ("no footprint", "footprint 120 m"):
        for q in (1.0, 4.0):
            parts.append(_long(_clear_cell(rng, n=6), SCENARIO, fp, q))
    runs = pd.concat(parts, ignore_index=True)
    runs["member"] = runs["member"].fillna(runs["method"])
    runs["family"] = runs["family"].fillna(runs["method"].str.split("_").str[0])
    return runs


def test_the_table_and_the_prose_come_from_the_best_table():
    from rsmhp.studies.scenarios.section import scenarios_section, scenarios_tables
    from rsmhp.studies.scenarios.summarise import improvement_summary, per_scenario
    from rsmhp.studies.scenarios.summarise import scenario_runs as improvement_runs
    from tests.studies.scenarios.test_scenarios import _tables

    b = best_family(_three_groups(np.random.default_rng(8)))
    table = best_table(b.cells, b.paired)
    assert table.count("\n") == len(b.cells) + 1
    assert "RS-MHP N_T=8 (it6/r1)" in table and f"| {GROUP_NAMES[BUDGET]}" in table
    h = b.cells[b.cells.group == HORIZON].iloc[0]
    assert fmt_ci(h.runner_up_low, h.runner_up_high, signed=True) in table
    assert config_label("sigma/it6/r1", "sigma") == "sigma points (it6/r1)"
    runs = improvement_runs(*_tables(np.random.default_rng(4)))
    s = improvement_summary(runs, n_boot=100, seed=0)
    tables = scenarios_tables(s, per_scenario(runs), b.cells, b.paired)
    sec = scenarios_section(s, tables, b.cells)
    assert sec.figures == ["scenarios_best", "scenarios_improvement"]
    assert tables["scenarios_best"] in sec.appendix
    n_h = len(b.cells[b.cells.group == HORIZON])
    clear_h = int(b.cells[b.cells.group == HORIZON].clear.sum())
    assert f"{GROUP_NAMES[HORIZON]} ({n_h} cells of 6 runs): " in sec.body
    if clear_h:
        assert f"a clear best in {clear_h} (" in sec.body
    assert sec.body.index(GROUP_NAMES[HORIZON]) < sec.body.index("P(a method's closed-loop run")
    assert "](figures/scenarios_best.png)" in sec.appendix


def test_the_figure_draws_one_panel_per_group():
    b = best_family(_three_groups(np.random.default_rng(9)))
    fig = best_figure(b.cells)
    try:
        assert len(fig.axes) == 3
        assert [t.get_text() for t in fig.axes[1].get_yticklabels()] == [
            "paper\n6 runs",
            "footprint150\n6 runs",
        ]
        texts = {t.get_text() for ax in fig.axes for t in ax.texts}
        assert "clear" in texts and any(t.startswith("tied with ") for t in texts)
        assert {short_label(m) for m in b.cells.best_member} <= texts
    finally:
        plt.close(fig)
    one = best_figure(b.cells[b.cells.group == SCENARIO])
    try:
        assert len(one.axes) == 1
    finally:
        plt.close(one)
    with pytest.raises(ValueError, match="empty"):
        best_figure(b.cells.iloc[:0])


def test_short_labels_and_family_colours():
    assert short_label("rsmhp_nt256") == "RS-MHP 256"
    assert short_label("tree_n4_m256") == "pruned 4×256"
    assert short_label("dpw_s300_ka2_ko0p5_ao0") == "tree search 300"
    assert short_label("rsmhp_nt16h") == "RS-MHP 16H"
    assert short_label("not_a_method") == "not_a_method"
    # every member of a family has the family's colour, unshaded
    assert family_colour("rsmhp", "rsmhp_nt256") == family_colour("rsmhp", "rsmhp_nt16")
    assert family_colour("tree") != family_colour("nbo")


def test_the_prose_counts_families_and_names_every_family_on_a_tie():
    from rsmhp.studies.scenarios.section import scenarios_section

    rng = np.random.default_rng(10)
    a = _clear_cell(rng)  # rsmhp clearly best
    # rsmhp_nt256 − sigma alternates +0.3, −0.25: mean 0.025 m, its interval reaches 0
    b = {"nbo": a["nbo"], "sigma": a["rsmhp_nt64"],
         "rsmhp_nt256": a["rsmhp_nt64"] + np.tile([0.3, -0.25], 15)}  # fmt: skip
    runs = pd.concat([_long(a, model="paper", axis=2), _long(b, model="paper", axis=4)])
    runs["family"] = runs["method"].map({"nbo": "nbo", "rsmhp_nt64": "rsmhp",
                                         "rsmhp_nt256": "rsmhp", "sigma": "sigma"})  # fmt: skip
    best = best_family(runs).cells
    assert list(best.best) == ["rsmhp_nt64", "sigma"] and list(best.clear) == [True, False]
    empty = pd.DataFrame(columns=["group", "method", "p_improve", "scenarios", "low", "high"])
    tables = {"scenarios_best": "", "scenarios_improvement": "", "scenarios_per_scenario": ""}
    body = scenarios_section(empty, tables, best).body
    assert (
        "long horizons, per H (2 cells of 30 runs): a clear best in 1 (RS-MHP in 1), tied in 1 "
        "(with 1 other method), most often best: RS-MHP and sigma points (1 of 2 each)."
    ) in body
