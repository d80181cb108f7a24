"""A tree search named by its measured plan depth (:mod:`rsmhp.report.naming`)."""

import math

import pandas as pd
import pytest

from rsmhp.report.naming import ROLLOUT_DEPTH, depth_name
from rsmhp.studies.scenarios.best import best_family


def test_below_a_depth_of_two_it_is_a_one_step_rollout():
    assert depth_name("tree search 30 sims", 1.2) == (
        "tree search 30 sims (plan depth 1.20: a one-step rollout over the pursuit policy)"
    )
    assert depth_name("tree search", 1.99, rollout="warm") == (
        "tree search (plan depth 1.99: a one-step rollout over the warm start)"
    )
    # decided on the depth as printed: 1.999 reads 2.00 and is no rollout
    assert depth_name("tree search", 1.999) == "tree search (plan depth 2.00)"
    assert (
        depth_name("tree search 100 sims", ROLLOUT_DEPTH)
        == "tree search 100 sims (plan depth 2.00)"
    )
    assert depth_name("tree search 100 sims", 4.2) == "tree search 100 sims (plan depth 4.20)"
    assert (
        depth_name("tree search 30", 1.2, short=True)
        == "tree search 30, depth 1.20: one-step rollout"
    )
    assert depth_name("tree search 30", 4.2, short=True) == "tree search 30, depth 4.20"


@pytest.mark.parametrize("depth", [None, math.nan])
def test_without_a_measured_depth_the_name_is_kept(depth):
    assert depth_name("RS-MHP N_T=64", depth) == "RS-MHP N_T=64"


def test_bad_depth_or_rollout_is_refused():
    with pytest.raises(ValueError, match=r"plan_depth: -1\.0"):
        depth_name("x", -1.0)
    with pytest.raises(ValueError, match="rollout: 'random'"):
        depth_name("x", 1.0, rollout="random")


def test_the_best_method_per_cell_carries_its_mean_depth():
    # a cell of 3 runs: the tree search (depths 1, 1, 1.6 per run: mean 1.2) beats NBO
    rows = []
    for r, (e_t, e_n, d) in enumerate([(1.0, 3.0, 1.0), (1.5, 3.2, 1.0), (1.2, 3.1, 1.6)]):
        rows.append(
            {
                "group": "horizon",
                "model": "paper",
                "value": 6,
                "method": "dpw_s30",
                "family": "dpw",
                "run": r,
                "error": e_t,
                "plan_depth": d,
            }
        )
        rows.append({"group": "horizon", "model": "paper", "value": 6, "method": "nbo",
                     "family": "nbo", "run": r, "error": e_n, "plan_depth": math.nan})  # fmt: skip
    cells = best_family(pd.DataFrame(rows)).cells
    (c,) = cells.itertuples(index=False)
    assert c.best == "dpw_s30" and c.best_depth == pytest.approx(1.2)
    assert c.best_label == "tree search 30, depth 1.20: one-step rollout"
    # NBO best (no depth): its label alone
    flipped = pd.DataFrame(rows).assign(error=lambda t: -t["error"])
    assert best_family(flipped).cells["best_label"].iloc[0] == "NBO"


def test_the_depth_phrase_is_found_in_a_claims_words():
    from rsmhp.report.naming import depth_of

    words = f"On 'paper', the tuned {depth_name('tree search', 1.2)} member tracks better"
    assert depth_of(words) == "plan depth 1.20: a one-step rollout over the pursuit policy"
    assert depth_of("the tuned RQMC member tracks better") == ""


def test_the_pursuit_policy_alone_is_not_named_by_a_depth():
    # it reports plan depth 0 (no tree): it keeps its name
    methods = (("pursuit", 1.0, 0.0), ("nbo", 3.0, math.nan))
    rows = [{"group": "horizon", "model": "paper", "value": 6, "method": m, "family": m,
             "run": r, "error": e + r, "plan_depth": d}
            for r in range(3) for m, e, d in methods]  # fmt: skip
    assert best_family(pd.DataFrame(rows)).cells["best_label"].iloc[0] == "pursuit policy"


def test_a_setup_label_carries_a_tree_search_claims_depth():
    from rsmhp.report.findings import named_setup
    from rsmhp.report.ledger import Claim, KeyNumber

    words = f"On 'paper', the tuned {depth_name('tree search', 1.2)} member tracks better"
    c = Claim("FR-3-paper", words, "p", KeyNumber("d", -1.0, -2.0, -0.5, null=0.0),
              "supported", "rule: supported if the CI lies below 0")  # fmt: skip
    assert named_setup("UAV paper", c) == (
        "UAV paper (plan depth 1.20: a one-step rollout over the pursuit policy)"
    )
    other = Claim("FR-1-paper", "tuned RQMC tracks better", "p",
                  KeyNumber("d", -1.0, -2.0, -0.5, null=0.0), "supported", "rule")  # fmt: skip
    assert named_setup("UAV paper", other) == "UAV paper"
