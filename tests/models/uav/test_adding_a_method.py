"""The worked example of a new planning method in docs/methods.md, run end to end.

The block between the ``example:method`` markers of docs/methods.md is executed here as it
stands, registering a toy family (nominal future plus weighted samples); it then runs through a
closed-loop run, the open-loop scoring of the decision study, the per-method summary and the
paired table, and the palette, without any other file knowing about it.
"""

from __future__ import annotations

import copy
import re
import sys
import types
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from rsmhp.models.uav import methods
from rsmhp.models.uav.planner import Belief
from rsmhp.models.uav.scoring import belief_states, score_state
from rsmhp.models.uav.simulation import UAVSetup, simulate_run
from rsmhp.pipeline.config import check_config
from rsmhp.report.palette import method_colour, method_label
from rsmhp.studies.uav.summarise import paired_differences, summarize_methods

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


@pytest.fixture(scope="module")
def mix():
    text = (ROOT / "docs" / "methods.md").read_text(encoding="utf-8")
    block = re.search(
        r"<!-- example:method:begin -->\s*```python\n(.*?)```\s*<!-- example:method:end -->",
        text,
        re.S,
    )
    assert block, "docs/methods.md: the example:method block is missing"
    module = types.ModuleType("docs_nominal_mix")
    sys.modules[module.__name__] = module  # dataclasses look their module up
    exec(compile(block.group(1), "docs/methods.md:example:method", "exec"), module.__dict__)
    yield module.NominalMix
    methods.unregister("mix")
    del sys.modules[module.__name__]


def _short_uav():
    uav = copy.deepcopy(CONFIG["uav"])
    uav["scenario"]["steps"] = 6
    uav["planner"].update(horizon=4, maxiter=6, maxfun=12)
    uav["methods"] = {"nbo": True, "rsmhp_nt": [8], "tree": [], "mix_nt": [8]}
    return uav


def test_the_config_accepts_and_checks_the_new_key(mix):
    cfg = copy.deepcopy(CONFIG)
    cfg["uav"]["methods"]["mix_nt"] = [50]
    check_config(cfg)  # the family's schema fragment is part of the config schema now
    cfg["uav"]["methods"]["mix_nt"] = [0]
    with pytest.raises(ValueError, match=r"uav\.methods\.mix_nt\[0\]: 0 is invalid"):
        check_config(cfg)
    got = methods.from_config(_short_uav()["methods"])
    assert list(got) == ["nbo", "rsmhp_nt8", "mix_nt8"]  # the family's order: last


def test_closed_loop_scoring_summary_and_colour(mix):
    uav = _short_uav()
    setup = UAVSetup.from_config(uav)
    members = methods.from_config(uav["methods"])
    new = members["mix_nt8"]
    belief = Belief(np.array([0.0, 0.0, 20.0, 0.0]), np.array([200.0, 0.0, 5.0, 0.0]), setup.P0)
    hyp = new.hypotheses(belief, setup, np.random.default_rng(0))
    assert hyp.weights[0] == 0.5 and hyp.states.shape[0] == 9  # genuinely weighted

    runs = []
    for run in range(4):
        for m in members.values():
            summary, steps = simulate_run(setup, m, seed=3, run=run)
            assert len(steps) == 6
            runs.append(summary)
    runs = pd.DataFrame(runs)
    mine = runs[runs["method"] == "mix_nt8"]
    assert (mine["family"] == "mix").all() and (mine["N_T"] == 8).all()
    assert np.isfinite(mine["mean_error"]).all()

    state = belief_states(setup, "paper", 3, [0], [2])[0]
    scoring = {"n_eval": 64, "polish": 1, "random_starts": 1, "eval_maxiter": 5, "n_random": 8}
    rows = score_state(state, setup, members, scoring, 3)
    row = next(r for r in rows if r["method"] == "mix_nt8")
    assert row["family"] == "mix" and row["regret"] >= -1e-9 * row["best_cost"]

    summary = summarize_methods(runs, seed=3, n_boot=200)
    assert summary["method"].tolist() == ["nbo", "rsmhp_nt8", "mix_nt8"]
    assert summary.set_index("method").loc["mix_nt8", "label"] == "nominal mix N_T=8"
    paired = paired_differences(runs, seed=3, n_boot=200)
    vs = paired[(paired["method"] == "mix_nt8") & (paired["baseline"] == "nbo")]
    assert len(vs) == 1 and vs["n_runs"].iloc[0] == 4
    assert method_colour("mix_nt8") == "#7a5195"
    assert method_label("mix_nt8") == "nominal mix N_T=8"
