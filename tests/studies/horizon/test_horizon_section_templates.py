"""The report prose of the long-horizon study as Markdown templates beside its code
(``src/rsmhp/studies/horizon/*.md``, rendered by :func:`rsmhp.report.templates.render`).

Oracles, on small synthetic data that reaches every paragraph: (1) every name a template
uses is a value its section module passes, and every value passed is used (static, with
:func:`jinja2.meta.find_undeclared_variables`); (2) leaving out any one value either raises
:class:`jinja2.UndefinedError` (StrictUndefined) or, where the branch taken does not use it,
changes nothing: a missing value never turns into silent text; (3) the rendered Markdown holds
no template syntax and no ``nan``; (4) every template beside the code is rendered."""

from __future__ import annotations

import re
from pathlib import Path

import jinja2
import numpy as np
import pandas as pd
import pytest
from jinja2 import meta

from rsmhp.report import templates
from rsmhp.studies.horizon import claims, section, section_optimiser
from rsmhp.studies.horizon.section import HorizonInputs, horizon_section, horizon_tables
from rsmhp.studies.horizon.section_optimiser import (
    horizon_note,
    optimiser_section,
    optimiser_summary,
    optimiser_tables,
)
from rsmhp.studies.horizon.simulate_optimiser import SPLIT_COLUMNS
from rsmhp.studies.horizon.summarise_uav import (
    lqg_horizon_table,
    summarize_approx,
    summarize_closed,
)

PACKAGE = "rsmhp.studies.horizon"
HERE = Path(section.__file__).parent
ENV = templates._environment(PACKAGE)
PLANNER = {"maxiter": 30, "maxfun": 60, "restarts": 0}
UAV_CFG = {
    "H": [4, 24],
    "models": ["m"],
    "runs": 12,
    "plans": 4,
    "n_ref": 500,
    "replicates": 1,
    "closed_runs": 12,
    "bootstrap": 200,
    "claims": {"tree": "tree_n4_m256", "monte_carlo": "rsmhp_nt256", "closed_model": "m"},
}
LQG_CFG = {"eps": 0.01}
BUDGETS = ((30, 60, 0), (300, 601, 0), (1000, 2001, 8))
OPT_CFG = {
    "H": [6, 24],
    "runs": 3,
    "steps": [0, 20],
    "budgets": [{"maxiter": i, "maxfun": f, "restarts": r} for i, f, r in BUDGETS],
    "polish_starts": 4,
    "polish_maxiter": 200,
}
METHODS = {"nbo": "nbo", "tree_n4_m256": "tree", "rsmhp_nt256": "rsmhp"}
SYNTAX = re.compile(r"\{\{|\}\}|\{%|%\}|\{#|#\}")


def _approx(rng: np.random.Generator) -> pd.DataFrame:
    """Cost-approximation rows: estimate = reference x (1 + e), e growing with H for NBO."""
    rows = []
    for H, sd in ((4, 0.01), (24, 0.03)):
        for method, family in METHODS.items():
            for run in range(UAV_CFG["runs"]):
                for plan in range(UAV_CFG["plans"]):
                    e = rng.normal(0.02 if method == "nbo" and H == 24 else 0.0, sd)
                    rows.append({"model": "m", "H": H, "run": run, "step": 0,
                                 "method": method, "family": family, "replicate": 0,
                                 "plan": plan, "estimate": 100.0 * (1 + e),
                                 "reference": 100.0, "reference_se": 0.1})  # fmt: skip
    return pd.DataFrame(rows)


def _closed(rng: np.random.Generator) -> pd.DataFrame:
    base = rng.normal(100.0, 30.0, UAV_CFG["closed_runs"])
    rows = []
    for H, adv in ((4, -2.0), (24, -10.0)):
        for method, family in METHODS.items():
            e = base + (0.0 if method == "nbo" else adv) + rng.normal(0.0, 4.0, base.size)
            rows += [{"model": "m", "H": H, "method": method, "family": family, "run": r,
                      "mean_error": e[r], "final_error": 0.0, "plan_ms": 1.0 + r}
                     for r in range(base.size)]  # fmt: skip
    return pd.DataFrame(rows)


def _regret_summary() -> pd.DataFrame:
    return pd.DataFrame(
        [
            {"model": "m", "H": H, "method": m, "states": 12, "regret_pct": 1.0 * H,
             "regret_methods_pct": 0.5 * H, "plan_ms": 0.1 * H * (k + 1)}
            for H in UAV_CFG["H"]
            for k, m in enumerate(METHODS)
        ]
    )  # fmt: skip


def _lqg_summaries() -> tuple[pd.DataFrame, pd.DataFrame]:
    """Estimator and regret summaries of the simulated oven LQG at a = 0.5, H = 2 and 24:
    Monte Carlo, RQMC, NBO, a pruned tree; uniform and likeliness-weighted Monte Carlo regret
    (one weighted cell far from its closed form)."""
    est = []
    for H in (2, 24):
        for scheme, weighting, N, rmse in (("mc", "uniform", 0, 0.16), ("sobol", "uniform", 0,
                                           0.04), ("nbo", "nominal", 0, 0.84),
                                           ("pruned", "uniform", 4, 0.6)):  # fmt: skip
            est.append({"a": 0.5, "H": H, "scheme": scheme, "weighting": weighting, "N": N,
                        "n_trajectories": 64, "rel_bias": 0.0, "rel_rmse": rmse * (1 + H / 100),
                        "rel_rmse_low": rmse, "rel_rmse_high": 1.2 * rmse,
                        "rel_rmse_theory": np.nan})  # fmt: skip
    reg = []
    for H in (2, 24):
        for weighting, kind, z in (
            ("uniform", "exact", 0.1),
            ("likeliness", "asymptotic", -5.0 if H == 24 else 0.2),
        ):
            for P in (16, 256):
                reg.append({"a": 0.5, "H": H, "method": "mc", "weighting": weighting, "P": P,
                            "n": 100, "closed_kind": kind,
                            "mean": 1.0 / P, "ci_low": 0.5 / P, "ci_high": 1.5 / P,
                            "closed_form": 1.1 / P, "limit": 1.2 / P, "z": z,
                            "rel_mean": 0.01})  # fmt: skip
    return pd.DataFrame(est), pd.DataFrame(reg)


def _split_table(rng: np.random.Generator) -> pd.DataFrame:
    """Optimiser split rows: some plans stuck at the warm start (0 iterations) at the budgets
    without restarts; no optimisation part at the budget with restarts."""
    rows = []
    for H in OPT_CFG["H"]:
        for run in range(OPT_CFG["runs"]):
            for step in OPT_CFG["steps"]:
                for method, family in (("nbo", "nbo"), ("rsmhp_nt256", "monte_carlo")):
                    a = rng.uniform(0, 0.01)
                    stuck = rng.random() < 0.5
                    for maxiter, maxfun, restarts in BUDGETS:
                        o = 0.0 if restarts else (0.2 if stuck else rng.uniform(0, 0.02))
                        nit = 0 if stuck and not restarts else int(rng.integers(1, maxiter))
                        rows.append({"model": "m", "H": H, "run": run, "step": step,
                                     "method": method, "family": family, "maxiter": maxiter,
                                     "maxfun": maxfun, "restarts": restarts, "nit": nit,
                                     "converged": True, "work": 10 * (nit + 1),
                                     "own_cost": 1.0, "eval_cost": 100.0 * (1 + a + o),
                                     "ref_cost": 100.0, "regret": a + o, "approx_regret": a,
                                     "optim_regret": o, "star_own_cost": 0.9,
                                     "star_source": "polish"})  # fmt: skip
    return pd.DataFrame(rows, columns=SPLIT_COLUMNS)


@pytest.fixture(scope="module")
def opt_summary() -> pd.DataFrame:
    return optimiser_summary(_split_table(np.random.default_rng(3)))


@pytest.fixture(scope="module")
def inputs(opt_summary) -> HorizonInputs:
    rng = np.random.default_rng(2)
    approx, closed = _approx(rng), _closed(rng)
    a_sum, r_sum = summarize_approx(approx), _regret_summary()
    c_sum = summarize_closed(closed)
    lqg_table = lqg_horizon_table([0.3, 0.5], [6, 24], r=10.0, sigma=1.0, eps=0.01)
    est_sum, reg_sum = _lqg_summaries()
    return HorizonInputs(
        approx=approx,
        approx_summary=a_sum,
        regret_summary=r_sum,
        tables=horizon_tables(a_sum, r_sum, lqg_table, c_sum, est_sum, reg_sum),
        cfg=UAV_CFG,
        seed=5,
        lqg_table=lqg_table,
        lqg_cfg=LQG_CFG,
        a_model=0.5,
        closed=closed,
        closed_summary=c_sum,
        lqg_est_summary=est_sum,
        lqg_regret_summary=reg_sum,
        planner=PLANNER,
        optimiser=opt_summary,
    )


@pytest.fixture
def calls(monkeypatch) -> list[tuple[str, dict]]:
    """Every (template, values) the section modules render, rendered as they would be."""
    out: list[tuple[str, dict]] = []

    def spy(package: str, template: str, /, **values):
        assert package == PACKAGE
        out.append((template, values))
        return templates.render(package, template, **values)

    monkeypatch.setattr(section, "render", spy)
    monkeypatch.setattr(section_optimiser, "render", spy)
    return out


def _names(template: str) -> set[str]:
    source = ENV.loader.get_source(ENV, template)[0]
    return meta.find_undeclared_variables(ENV.parse(source))


def _check_calls(calls: list[tuple[str, dict]]) -> None:
    for template, values in calls:
        assert set(values) == _names(template), template
        full = templates.render(PACKAGE, template, **values)
        for name in values:
            rest = {k: v for k, v in values.items() if k != name}
            try:
                text = templates.render(PACKAGE, template, **rest)
            except jinja2.UndefinedError as exc:
                assert name in str(exc), (template, name, str(exc))
            else:  # the branch taken does not use it
                assert text == full, (template, name)
        with pytest.raises(jinja2.UndefinedError):
            templates.render(PACKAGE, template)


def _check_text(*texts: str) -> None:
    for text in texts:
        assert text and not SYNTAX.search(text), text
        assert not re.search(r"\bnan\b", text, re.IGNORECASE)
        assert not text.endswith("\n") or text.endswith(".*\n")  # no file's final newline


def test_horizon_section_templates_are_complete(inputs, calls):
    s = horizon_section(inputs)
    assert {t for t, _ in calls} == {
        "section.md",
        "section_appendix.md",
        "lqg_limits.md",
        "horizon_note.md",
    }
    _check_calls(calls)
    _check_text(s.body, s.appendix)
    # every paragraph of the body and of the appendix is reached by the data
    for words in ("Claims HZ-1-m", "At H = 24 on 'm'", "runs at uav.planner's budget (maxiter 30",
                  "At H = 24 and maxiter 30", "CIs of HZ-1-m", "Oven LQG (closed forms, a = 0.50)",
                  "figures/horizon_lqg.png"):  # fmt: skip
        assert words in s.body, words
    for words in ("Runs needed", "Pruned tree, N = 4", "Decisions: uniform Monte Carlo",
                  "|z| > 3 in 2 of 4 cells", "Intervals of the claims",
                  inputs.tables["horizon_lqg"], "eps = 0.010 of L_1"):  # fmt: skip
        assert words in s.appendix, words
    assert s.body.split("\n\n")[0].startswith("H ∈ {4, 24} on 'm', belief states of 12 NBO")


def test_horizon_section_without_the_optional_inputs(inputs, calls):
    """No closed-loop counts, LQG simulation, planner or optimiser split: the absent
    paragraphs leave their empty lines, the LQG figure is left out."""
    bare = HorizonInputs(**{k: getattr(inputs, k) for k in (
        "approx", "approx_summary", "regret_summary", "tables", "cfg", "seed", "lqg_table",
        "lqg_cfg", "a_model")})  # fmt: skip
    s = horizon_section(bare)
    _check_calls(calls)
    _check_text(s.body, s.appendix)
    assert s.appendix.startswith("\n\n\n\nCost approximation per model")
    assert "horizon_lqg.png" not in s.body and s.body.endswith("by horizon.*\n")
    assert "runs at uav.planner's budget for every method" in s.body
    assert "is in section 'Optimiser error apart from approximation error'." in s.body


def test_optimiser_section_templates_are_complete(opt_summary, calls):
    s = optimiser_section(opt_summary, optimiser_tables(opt_summary), OPT_CFG, PLANNER)
    other = optimiser_section(opt_summary, optimiser_tables(opt_summary), OPT_CFG, None)
    note = horizon_note(opt_summary), horizon_note(None)
    assert {t for t, _ in calls} == {
        "section_optimiser.md",
        "section_optimiser_appendix.md",
        "horizon_note.md",
    }
    _check_calls(calls)
    _check_text(s.body, s.appendix, other.appendix, *note)
    assert "Already at the default budget" not in s.body
    assert "The first budget at which the optimisation part" in s.body  # the restarts remove it
    assert "of the plans stopped at 0 iterations, i.e. they are the warm start" in s.body
    assert "Raising maxiter from 30 to 300 (restarts 0)" in s.body
    assert "The first budget is uav.planner's" in s.appendix
    assert "The first budget is the default the others are compared with." in other.appendix
    assert "budgets maxiter 30 (maxfun 60); maxiter 300 (maxfun 601)" in s.appendix


def test_every_template_beside_the_code_is_rendered():
    """The .md files beside the section modules are exactly the templates the tests above
    render (a stale template would still count in the code digests), and the words of the
    claims module (``claims.md``: :class:`rsmhp.report.templates.Words`, rendered by the
    claims' tests)."""
    words = {claims.WORDS.template} if claims.WORDS.package == PACKAGE else set()
    assert words == {"claims.md"}
    assert {p.name for p in HERE.glob("*.md")} - words == {
        "section.md",
        "section_appendix.md",
        "lqg_limits.md",
        "horizon_note.md",
        "section_optimiser.md",
        "section_optimiser_appendix.md",
    }


def test_every_macro_of_the_claims_template_is_used():
    """The claims' words (``claims.md``, :data:`rsmhp.studies.horizon.claims.WORDS`) hold no
    macro that neither the claims module nor one of its specs nor another macro uses."""
    from tests.studies.uav.test_uav_claims import unused_macros

    assert claims.WORDS.package == PACKAGE
    assert unused_macros(claims) == set()


@pytest.mark.parametrize("template", sorted(p.name for p in HERE.glob("*.md")))
def test_template_lines_are_wrapped(template):
    """Long lines are continued with a backslash, so a diff shows the sentence that changed."""
    source = (HERE / template).read_text(encoding="utf-8")
    assert [line for line in source.split("\n") if len(line) > 100] == []
