"""The FR claims against every other member of the comparator's family in the run
(:func:`rsmhp.studies.frontier.claims.comparator_members`): a reader sees whether the sign of
a claim depends on which member of the comparator's family it is compared with."""

import numpy as np
import pytest
from scipy import stats

from rsmhp.pipeline.protocol import Configuration
from rsmhp.studies.frontier.claims import Comparison, comparator_members, confirm_claims
from rsmhp.studies.frontier.summarise import ladder, summarize_configs
from tests.pipeline.test_protocol import PREREG, _confirm_tables


def _paired_t(a: np.ndarray, b: np.ndarray) -> tuple[float, float, float]:
    """Mean of a − b with its 95% t interval (the oracle)."""
    d = a - b
    h = stats.t.ppf(0.975, d.size - 1) * d.std(ddof=1) / np.sqrt(d.size)
    return float(d.mean()), float(d.mean() - h), float(d.mean() + h)


def test_the_tree_search_against_each_other_monte_carlo_member():
    # dpw (-1.1 m) is worse than the chosen 2 ms member rsmhp_nt64/r1 (made -1.7 m) but
    # better than the 0.5 ms member rsmhp_nt16 (-1.0 m): the sign depends on the comparator
    runs, timing, chosen = _confirm_tables(shift_dpw=-0.1, noise=0.05)
    runs.loc[runs["config"] == "rsmhp_nt64/it30/r1", "mean_error"] -= 0.5
    summary = summarize_configs(runs, timing).set_index(["model", "config"])
    c = Comparison("FR-3", "m", PREREG["claims"]["FR-3"], 2.0,
                   Configuration("dpw_s30"), Configuration("rsmhp_nt64", 30, 1),
                   ("tree search", "RS-MHP"), "f" * 64)  # fmt: skip
    members = comparator_members(c, runs, summary, "not supported")
    assert [m["label"] for m in members] == [Configuration("rsmhp_nt16", 30, 0).label()]
    (m,) = members
    w = runs.pivot(index="run", columns="config", values="mean_error")
    mean, lo, hi = _paired_t(w["dpw_s30"].to_numpy(), w["rsmhp_nt16/it30/r0"].to_numpy())
    assert mean == pytest.approx(-0.1, abs=0.03)  # its shift, within 2 SE of the noise
    assert m["better"]
    assert m["loop_ms"] == pytest.approx(0.3) and not m["over"]
    assert hi < 0 and m["opposite"]  # CI below 0 where the verdict says "above 0"
    assert float(m["diff"]) == pytest.approx(mean, abs=5e-4)
    ci = [float(v) for v in m["ci"].strip("[]").split(",")]
    assert ci == pytest.approx([lo, hi], abs=5e-4)
    # the claim carries it as contrary evidence, labelled post hoc
    lad = ladder(runs, summarize_configs(runs, timing), chosen, [0.5, 2.0])
    claims = {x.id: x for x in confirm_claims(runs, summarize_configs(runs, timing), lad,
                                              PREREG, chosen, "abc123" * 6)}  # fmt: skip
    fr3 = claims["FR-3-m"]
    assert fr3.verdict == "not supported"
    assert "post hoc" in fr3.contrary and "the difference is -0.0" in fr3.contrary


def test_a_member_on_the_verdicts_side_is_not_contrary_and_over_budget_is_flagged():
    runs, timing, _ = _confirm_tables(shift_dpw=3.0, noise=0.05)
    # the 0.5 ms member spends 2.5 ms per step in its closed loop: over the 2 ms budget
    sel = runs["config"] == "rsmhp_nt16/it30/r0"
    runs.loc[sel, "plan_ms"] = 2.5
    summary = summarize_configs(runs, timing).set_index(["model", "config"])
    c = Comparison("FR-3", "m", PREREG["claims"]["FR-3"], 2.0,
                   Configuration("dpw_s30"), Configuration("rsmhp_nt64", 30, 1),
                   ("tree search", "RS-MHP"), "f" * 64)  # fmt: skip
    (m,) = comparator_members(c, runs, summary, "not supported")
    assert m["over"] and m["loop_ms"] == pytest.approx(2.5)
    assert not m["better"] and not m["opposite"]  # +2 m worse: on the verdict's side


def test_preregistered_secondaries_replace_the_post_hoc_list():
    """With a version-3 ``secondaries`` block the claim shows the comparator's tuned members
    at the listed budgets and the listed families' members at the headline budget, labelled
    preregistered, and nothing post hoc."""
    from rsmhp.studies.frontier.claims import preregistered_secondaries

    runs, timing, chosen = _confirm_tables(shift_dpw=-0.1, noise=0.05)
    summary = summarize_configs(runs, timing).set_index(["model", "config"])
    sec = {"against_comparator_budgets_ms": [0.5, 2.0], "against_families": ["nbo", "sigma"]}
    chosen_nbo = {b: {**fams, "nbo": Configuration("nbo")} for b, fams in chosen["m"].items()}
    c = Comparison("FR-3", "m", PREREG["claims"]["FR-3"], 2.0,
                   Configuration("dpw_s30"), Configuration("rsmhp_nt64", 30, 1),
                   ("tree search", "RS-MHP"), "f" * 64, sec, chosen_nbo)  # fmt: skip
    got = preregistered_secondaries(c, runs, summary, "inconclusive")
    # the 0.5 ms RS-MHP member (the 2 ms one is the claim's own comparator), then NBO and sigma
    assert [g["label"] for g in got] == [
        Configuration("rsmhp_nt16", 30, 0).label(),
        Configuration("nbo").label(),
        Configuration("sigma", 30, 0).label(),
    ]
    w = runs.pivot(index="run", columns="config", values="mean_error")
    mean, _, _ = _paired_t(w["dpw_s30"].to_numpy(), w["nbo"].to_numpy())
    assert float(got[1]["diff"]) == pytest.approx(mean, rel=5e-3)  # three significant digits
    lad = ladder(runs, summarize_configs(runs, timing), chosen, [0.5, 2.0])
    prereg = {**PREREG, "secondaries": sec}
    fr3 = {x.id: x for x in confirm_claims(runs, summarize_configs(runs, timing), lad,
                                           prereg, chosen, "abc123" * 6)}["FR-3-m"]  # fmt: skip
    assert "preregistered secondary results (no verdict): against RS-MHP N_T=16" in fr3.measured
    assert "post hoc" not in fr3.measured + fr3.contrary
    # a listed member without confirmatory runs is refused, naming it
    missing = {
        **chosen_nbo,
        "0.5": {**chosen_nbo["0.5"], "rsmhp": Configuration("rsmhp_nt256", 30, 0)},
    }
    c2 = Comparison("FR-3", "m", PREREG["claims"]["FR-3"], 2.0, Configuration("dpw_s30"),
                    Configuration("rsmhp_nt64", 30, 1), ("t", "r"), "f" * 64, sec,
                    missing)  # fmt: skip
    with pytest.raises(ValueError, match=r"rsmhp_nt256/it30/r0.*no confirmatory runs"):
        preregistered_secondaries(c2, runs, summary, "inconclusive")


def test_a_member_over_the_tolerance_leaves_the_claim_without_a_verdict():
    """Version 3: a compared member whose closed-loop time per step exceeds the budget by more
    than the preregistered tolerance makes the claim "over budget", with no p-value (so it is
    outside Holm's family); within the tolerance the rule decides as before."""
    from rsmhp.report.ledger import OVER_BUDGET

    runs, timing, chosen = _confirm_tables(shift_dpw=3.0, noise=0.05)
    lad = ladder(runs, summarize_configs(runs, timing), chosen, [0.5, 2.0])
    prereg = {**PREREG, "budget_tolerance": 0.2}
    within = {x.id: x for x in confirm_claims(runs, summarize_configs(runs, timing), lad,
                                              prereg, chosen, "abc123" * 6)}  # fmt: skip
    assert within["FR-3-m"].verdict == "not supported" and within["FR-3-m"].key.p_value < 0.05
    assert "exceeds 2.4 ms (the budget plus the preregistered tolerance of 20%)" in (
        within["FR-3-m"].rule
    )
    # the tree search spends 2.5 ms per step in closed loop: over 2 ms x 1.2 = 2.4 ms
    runs.loc[runs["config"] == "dpw_s30", "plan_ms"] = 2.5
    s = summarize_configs(runs, timing)
    over = {x.id: x for x in confirm_claims(runs, s, ladder(runs, s, chosen, [0.5, 2.0]),
                                            prereg, chosen, "abc123" * 6)}  # fmt: skip
    assert over["FR-3-m"].verdict == OVER_BUDGET and over["FR-3-m"].key.p_value is None
    assert over["FR-1-m"].verdict == within["FR-1-m"].verdict  # the others are untouched
    # at 2.3 ms it is within the tolerance again
    runs.loc[runs["config"] == "dpw_s30", "plan_ms"] = 2.3
    s = summarize_configs(runs, timing)
    again = {x.id: x for x in confirm_claims(runs, s, ladder(runs, s, chosen, [0.5, 2.0]),
                                             prereg, chosen, "abc123" * 6)}  # fmt: skip
    assert again["FR-3-m"].verdict == "not supported"
