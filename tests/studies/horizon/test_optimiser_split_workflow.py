"""The optimiser split in the workflow: rules horizon_optimiser (jobs of runs per model and
H), horizon_optimiser_merge, horizon_optimiser_summary and horizon_optimiser_figures, the
config section horizon.optimiser, the report section and the figure, and what the
long-horizon section and HZ-3 say about the regret they show.

Oracles: every number of the section body is recomputed here from the split rows (means by
hand, the ranges over methods, the shares of plans at 0 iterations and converged) and must
appear in the text; the summary's extra column is the share counted by hand; bad config values
are refused naming the field; the tiny workflow's dry run lists the configured jobs per (model,
H) and its run (the session's ``run_j2``) writes tables that meet their contracts and a section
whose numbers are the summary's.
"""

from __future__ import annotations

import copy
import json
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from rsmhp.pipeline.config import ConfigError, check_config
from rsmhp.pipeline.contracts import read_checked
from rsmhp.report.figures import save_figure
from rsmhp.report.markdown import fmt, range_text
from rsmhp.studies.horizon.checks import optimiser_problems as config_problems
from rsmhp.studies.horizon.chunks import units
from rsmhp.studies.horizon.claims import _hz3, budget_text
from rsmhp.studies.horizon.figures_optimiser import budget_label, largest_budget, optimiser_figure
from rsmhp.studies.horizon.section_optimiser import (
    KEY,
    ORDER,
    SUMMARY_COLUMNS,
    TITLE,
    horizon_note,
    optimiser_section,
    optimiser_summary,
    optimiser_tables,
    removing_budget,
)
from rsmhp.studies.horizon.simulate_optimiser import (
    RULE,
    SPLIT_COLUMNS,
    split_contract,
)
from rsmhp.studies.horizon.summarise_optimiser import summarize_split

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
TINY = ROOT / "tests" / "config" / "tiny.yaml"
PLANNER = {"maxiter": 30, "maxfun": 60, "restarts": 0}
BUDGETS = ((30, 60, 0), (300, 601, 0), (1000, 2001, 8))
CFG = {
    "H": [6, 12, 24],
    "runs": 4,
    "steps": [0, 20],
    "methods": {"nbo": True, "rsmhp_nt": [256], "sigma": True},
    "budgets": [{"maxiter": it, "maxfun": f, "restarts": r} for it, f, r in BUDGETS],
    "polish_starts": 8,
    "polish_maxiter": 2000,
}
METHODS = (("nbo", "nbo"), ("rsmhp_nt256", "monte_carlo"), ("sigma", "sigma"))


def _table(seed: int = 1, removed: bool = True) -> pd.DataFrame:
    """Split rows with stuck plans (0 iterations, converged, large optimisation regret) at the
    budgets without restarts, and an optimisation part of 0 (``removed``) or above the
    approximation part at the budget with restarts."""
    rng = np.random.default_rng(seed)
    rows = []
    for model in ("paper", "footprint150"):
        for H in CFG["H"]:
            for run in range(CFG["runs"]):
                for step in CFG["steps"]:
                    for method, family in METHODS:
                        a = rng.uniform(0, 0.01) * H / 6
                        stuck = rng.random() < 0.6
                        for maxiter, maxfun, restarts in BUDGETS:
                            if restarts:
                                o = 0.0 if removed else a + 0.01
                                nit = int(rng.integers(50, 900))
                            elif stuck:
                                o, nit = rng.uniform(0.05, 0.4) * H / 24, 0
                            else:
                                o, nit = rng.uniform(0, 0.02), int(rng.integers(1, maxiter + 1))
                            rows.append(
                                {
                                    "model": model, "H": H, "run": run, "step": step,
                                    "method": method, "family": family, "maxiter": maxiter,
                                    "maxfun": maxfun, "restarts": restarts, "nit": nit,
                                    "converged": bool(stuck or nit < maxiter),
                                    "work": 10 * (nit + 1), "own_cost": 1.0,
                                    "eval_cost": 100.0 * (1 + a + o), "ref_cost": 100.0,
                                    "regret": a + o, "approx_regret": a, "optim_regret": o,
                                    "star_own_cost": 0.9,
                                    "star_source": "polish" if rng.random() < 0.3 else "budget",
                                }
                            )  # fmt: skip
    return pd.DataFrame(rows, columns=SPLIT_COLUMNS)


@pytest.fixture(scope="module")
def table() -> pd.DataFrame:
    return _table()


@pytest.fixture(scope="module")
def summary(table) -> pd.DataFrame:
    return optimiser_summary(table)


def _pct(x) -> str:
    return f"{range_text(np.asarray(x, dtype=float), 2)}%"


def test_summary_adds_the_share_of_plans_at_zero_iterations(table, summary):
    assert list(summary.columns) == SUMMARY_COLUMNS
    pd.testing.assert_frame_equal(summary[summary.columns[:-1]], summarize_split(table))
    keys = ["model", "H", "method", "maxiter", "restarts"]
    by_hand = table.groupby(keys)["nit"].apply(lambda n: float((n == 0).mean()))
    got = summary.set_index(keys)["zero_nit_share"]
    pd.testing.assert_series_equal(got.sort_index(), by_hand.sort_index(), check_names=False)
    assert (summary.loc[summary["restarts"] > 0, "zero_nit_share"] == 0).all()


def test_section_numbers_come_from_the_split_rows(table, summary):
    section = optimiser_section(summary, optimiser_tables(summary), CFG, PLANNER)
    body = section.body
    assert (section.key, section.title, section.order) == (KEY, TITLE, ORDER)
    assert ORDER == 34 and section.claims == [] and section.figures == ["horizon_optimiser"]
    assert not re.search(r"\b(nan|inf)\b", body + section.appendix, re.IGNORECASE)
    cells = table.groupby(["model", "H", "method", "maxiter", "restarts"], sort=False)
    means = 100 * cells[["regret", "approx_regret", "optim_regret"]].mean()
    first, big = (30, 0), (1000, 8)
    for model in ("paper", "footprint150"):
        for H in CFG["H"]:
            m = means.xs((model, H, *first), level=["model", "H", "maxiter", "restarts"])
            want = (
                f"H = {H}: R {_pct(m['regret'])}, A {_pct(m['approx_regret'])}, O "
                f"{_pct(m['optim_regret'])}"
            )
            assert want in body, want
        m = means.xs((model, 24, *big), level=["model", "H", "maxiter", "restarts"])
        assert f"with {budget_label(big)} at H = 24: R {_pct(m['regret'])}" in body
    d = table[(table["maxiter"] == 30) & (table["restarts"] == 0)]
    zero = 100 * float((d["nit"] == 0).mean())
    conv = 100 * float(d["converged"].mean())
    assert f"{fmt(zero, 2)}% of the plans stopped at 0 iterations" in body
    assert f"reported convergence for {fmt(conv, 2)}% of the plans" in body
    assert "'Converged' is therefore no sign of a good plan" in body
    nit = d.groupby(["model", "H", "method"])["nit"].mean()
    assert f"used {range_text(nit.to_numpy(), 2)} iterations" in body
    plain = [means.xs((it, 0), level=["maxiter", "restarts"]) for it in (30, 300)]
    assert (
        f"Raising maxiter from 30 to 300 (restarts 0) moves the mean optimisation part over "
        f"the cells from {fmt(float(plain[0]['optim_regret'].mean()), 2)}% to "
        f"{fmt(float(plain[1]['optim_regret'].mean()), 2)}%"
    ) in body
    # which budget removes it: the budget with restarts (O = 0 there, A >= 0)
    assert removing_budget(summary) == big
    assert f"every (model, H, method) cell is {budget_label(big)}" in body
    # the definitions, the setting and the per-budget table are in the appendix
    assert "uav.planner's, the budget of every closed-loop study" in section.appendix
    assert "maxiter 1000 + 8 restarts (maxfun 2001)" in section.appendix
    full = section.appendix.split("\n\n")[-1]  # the last table: one row per summary row
    assert all(line.startswith("|") for line in full.splitlines())
    assert section.appendix.count("\n| paper ") + section.appendix.count(
        "\n| footprint150 "
    ) == len(summary)


def test_section_when_no_budget_removes_it_and_the_planner_differs():
    s = optimiser_summary(_table(seed=2, removed=False))
    assert removing_budget(s) is None
    section = optimiser_section(s, optimiser_tables(s), CFG, {**PLANNER, "maxiter": 50})
    g = s[(s["maxiter"] == 1000) & (s["restarts"] == 8)]
    assert (
        f"No configured budget brings the optimisation part down to the approximation part "
        f"in every (model, H, method) cell; the largest, maxiter 1000 + 8 restarts, does so in "
        f"0 of {len(g)} cells, its largest optimisation part is "
        f"{fmt(float(g['optim_pct'].max()), 2)}%"
    ) in section.body
    assert "uav.planner's (maxiter 50, maxfun 60)" in section.appendix
    with pytest.raises(ValueError, match="empty"):
        optimiser_section(s.iloc[:0], {}, CFG, PLANNER)


def test_budget_helpers():
    assert largest_budget([(30, 0), (1000, 0), (300, 8), (1000, 8)]) == (1000, 8)
    assert largest_budget([(30, 0), (100, 2), (300, 0)]) == (100, 2)  # 300 each: more restarts
    assert budget_label((30, 0)) == "maxiter 30"
    assert budget_label((20, 1)) == "maxiter 20 + 1 restart"
    assert budget_text(PLANNER) == "maxiter 30, maxfun 60, no restarts"
    assert budget_text({**PLANNER, "restarts": 2}) == "maxiter 30, maxfun 60, 2 restarts"
    assert budget_text(None) == ""


def test_the_horizon_section_says_which_regret_it_shows(summary):
    note = horizon_note(summary)
    g = summary[(summary["H"] == 24) & (summary["maxiter"] == 30) & (summary["restarts"] == 0)]
    assert f"At H = 24 and maxiter 30 (section '{TITLE}')" in note
    assert f"optimisation part of the open-loop regret is {_pct(g['optim_pct'])}" in note
    assert f"approximation part {_pct(g['approx_pct'])}" in note
    assert ("dominates in every case" in note) == bool((g["optim_pct"] > g["approx_pct"]).all())
    assert horizon_note(None) == (
        f"How much of it is optimisation error rather than approximation is in section '{TITLE}'."
    )
    # HZ-3: its measured text names the budget; its rule is unchanged
    rng = np.random.default_rng(8)
    rows = [
        {"model": "m", "H": H, "method": meth, "family": meth[:5], "run": r,
         "mean_error": 100.0 + rng.normal(), "final_error": 0.0, "plan_ms": 1.0}
        for H in (2, 24) for meth in ("nbo", "rsmhp_nt256") for r in range(6)
    ]  # fmt: skip
    closed = pd.DataFrame(rows)
    with_budget = _hz3(closed, "m", "rsmhp_nt256", 2, 24, 1, 200, PLANNER)
    without = _hz3(closed, "m", "rsmhp_nt256", 2, 24, 1, 200)
    assert "both planners ran at the optimiser budget of uav.planner (maxiter 30, maxfun 60, " \
        "no restarts) at every H" in with_budget.measured  # fmt: skip
    assert f"section '{TITLE}'" in with_budget.measured
    assert with_budget.rule == without.rule and with_budget.key == without.key
    assert with_budget.verdict == without.verdict


def test_figure_draws_on_a_synthetic_summary(summary, tmp_path):
    fig = optimiser_figure(summary)
    assert [ax.get_title() for ax in fig.axes] == ["paper", "footprint150"]
    labels = [t.get_text() for t in fig.axes[-1].get_legend().get_texts()]
    assert "total, maxiter 30 (default)" in labels and "approximation part" in labels
    assert "total, maxiter 1000 + 8 restarts" in labels
    png, pdf = save_figure(fig, tmp_path / "horizon_optimiser")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and pdf.read_bytes()[:5] == b"%PDF-"
    with pytest.raises(ValueError, match="empty"):
        optimiser_figure(summary.iloc[:0])


# ------------------------------------------------------------------------------ config


def _with(edit) -> dict:
    cfg = copy.deepcopy(CONFIG)
    edit(cfg["horizon"]["optimiser"])
    return cfg


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (lambda o: o.update(H=[6, 0]), r"horizon\.optimiser\.H\[1\]: 0 .*\[1, 48\]"),
        (lambda o: o.update(H=[6, 49]), r"horizon\.optimiser\.H\[1\]: 49 .*\[1, 48\]"),
        (lambda o: o.update(runs=1), r"horizon\.optimiser\.runs: 1 .*\[2, 1000\]"),
        (lambda o: o.update(steps=[-1]), r"horizon\.optimiser\.steps\[0\]: -1"),
        (lambda o: o.update(budgets=[]), r"horizon\.optimiser\.budgets"),
        (lambda o: o.update(budgets=[{"maxiter": 0}]), r"optimiser\.budgets\[0\]\.maxiter: 0"),
        (lambda o: o.update(budgets=[{"restarts": 1}]), r"horizon\.optimiser\.budgets\[0\]"),
        (lambda o: o.update(budgets=[{"maxiter": 5, "it": 1}]), r"budgets\[0\]\.it: unknown key"),
        (lambda o: o.update(polish_maxiter=0), r"horizon\.optimiser\.polish_maxiter: 0"),
        (lambda o: o.update(polish_starts=-1), r"horizon\.optimiser\.polish_starts: -1"),
        (lambda o: o.update(bogus=1), r"horizon\.optimiser\.bogus: unknown key"),
        (lambda o: o["methods"].update(rsmhp_nt=[0]), r"horizon\.optimiser\.methods\.rsmhp_nt"),
    ],
)  # fmt: skip
def test_bad_optimiser_config_is_refused_naming_the_field(edit, expected):
    with pytest.raises(ConfigError, match=expected):
        check_config(_with(edit))


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (
            lambda o: o.update(steps=[0, 60]),
            "horizon.optimiser.steps: [60] not before the run's last step (allowed: 0 <= step "
            "< uav.scenario.steps = 60)",
        ),
        (
            lambda o: o.update(models=["paper", "nosuch"]),
            "horizon.optimiser.models: ['nosuch'] not model(s) of uav_models",
        ),
        (
            lambda o: o.update(budgets=[{"maxiter": 30}, {"maxiter": 30, "maxfun": 5}]),
            "horizon.optimiser.budgets: (maxiter, restarts) [(30, 0)] appear twice (allowed: ",
        ),
        (
            lambda o: o.update(methods={"nbo": False, "dpw": [{"sims": 10}]}),
            "horizon.optimiser.methods: no method with an own cost",
        ),
    ],
)
def test_cross_field_problems_name_the_field(edit, expected):
    assert expected in "\n".join(config_problems(_with(edit)))
    assert config_problems(CONFIG) == []
    tiny = yaml.safe_load(TINY.read_text())["horizon"]["optimiser"]
    assert config_problems({**CONFIG, "horizon": {**CONFIG["horizon"], "optimiser": tiny}}) == []


def test_split_contract_names_the_rule():
    assert split_contract(CFG, "paper", 6).rule == RULE == "horizon_optimiser"
    assert (ROOT / "workflow" / "scripts" / f"{RULE}.py").is_file()


# ----------------------------------------------------------------------------- workflow


def test_dry_run_lists_the_jobs_of_every_model_and_horizon(tiny_dry_run):
    """The session's dry run of the tiny config's default target, ``all`` (no job runs)."""
    tiny = yaml.safe_load(TINY.read_text())
    out = tiny_dry_run
    stats = dict(re.findall(r"^(\w+)\s+(\d+)$", out.split("Job stats:", 1)[1], flags=re.M))
    # split.horizon_optimiser jobs of runs per (model, H) at the largest H, fewer below
    opt = tiny["horizon"]["optimiser"]
    layout = units(tiny["horizon"]["uav"]["models"], opt["H"], tiny["split"][RULE], opt["runs"])
    assert len(layout) == len(tiny["horizon"]["uav"]["models"]) * len(opt["H"])
    assert stats["horizon_optimiser"] == str(sum(j for *_, j in layout))
    assert stats["horizon_optimiser_merge"] == "1"  # every (model, H) table in one job
    assert stats["horizon_optimiser_summary"] == stats["horizon_optimiser_figures"] == "1"
    for h in tiny["horizon"]["optimiser"]["H"]:
        assert f"results/horizon/optimiser/paper_H{h}.csv" in out
    assert "results/report/horizon_optimiser.json" in out


@pytest.mark.workflow
def test_tiny_run_of_the_new_rules(run_j2):
    """The rules' outputs in the session's tiny run (``run_j2``, which made
    results/report/horizon_optimiser.json and results/figures/horizon_optimiser.png among
    everything else): tables meet their contracts, the summary is the split rows', the
    section's numbers are the summary's."""
    tiny = yaml.safe_load(TINY.read_text())
    opt = tiny["horizon"]["optimiser"]
    cfg = {**CONFIG["horizon"]["optimiser"], **opt, "methods": {
        **CONFIG["horizon"]["optimiser"]["methods"], **opt["methods"]}}  # fmt: skip
    table = pd.concat(
        [
            read_checked(
                run_j2 / f"results/horizon/optimiser/paper_H{h}.csv",
                split_contract(cfg, "paper", h),
            )
            for h in opt["H"]
        ],
        ignore_index=True,
    )
    summary = pd.read_csv(run_j2 / "results/horizon/optimiser_summary.csv")
    want = optimiser_summary(table)
    pd.testing.assert_frame_equal(summary[SUMMARY_COLUMNS], want, check_dtype=False)
    section = json.loads((run_j2 / "results/report/horizon_optimiser.json").read_text())
    assert section["key"] == KEY and section["order"] == ORDER and section["claims"] == []
    d = want[(want["maxiter"] == opt["budgets"][0]["maxiter"]) & (want["restarts"] == 0)]
    for h in opt["H"]:
        g = d[d["H"] == h]
        assert f"H = {h}: R {_pct(g['regret_pct'])}, A {_pct(g['approx_pct'])}" in section["body"]
    assert (run_j2 / "results/tables/horizon_optimiser.md").read_text().startswith("| model")
    png = (run_j2 / "results/figures/horizon_optimiser.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    assert "done in" in (run_j2 / "results/logs/horizon_optimiser_summary.log").read_text()
