"""The tuning's candidate table and what depth buys (rsmhp.studies.frontier.tuning), on
constructed tuning rows whose means and paired differences are known."""

import numpy as np
import pandas as pd
import pytest

from rsmhp.core.stats import mean_ci
from rsmhp.pipeline.protocol import Configuration, budget_cost
from rsmhp.studies.frontier.tuning import candidate_table, depth_table


def _rows():
    rng = np.random.default_rng(7)
    n = 12
    common = rng.normal(10.0, 2.0, n)
    spec = {  # config: (error shift, closed-loop ms, timed ms, plan depth, depth-1 share)
        "nbo": (0.0, 0.1, 0.1, np.nan, np.nan),
        "pursuit": (-1.0, 0.05, 0.05, 0.0, np.nan),
        "dpw_s30": (-1.5, 0.6, 0.5, 1.2, 0.98),
        "dpw_s300_ka1_aa0p1_ko0p5_ao0": (-2.0, 1.5, 1.4, 4.5, 0.05),
        "rsmhp_nt16/it30/r0/pursuit": (-0.5, 0.4, 0.2, np.nan, np.nan),
    }
    q, t = [], []
    for name, (shift, loop, timed, depth, f1) in spec.items():
        noise = 0.1 * rng.standard_normal(n)
        for r in range(n):
            q.append({"model": "m", "config": name, "run": r,
                      "mean_error": common[r] + shift + noise[r], "plan_ms": loop,
                      "work_per_step": 10.0, "plan_depth": depth, "frac_depth1": f1})  # fmt: skip
        for k in range(3):
            t.append({"model": "m", "config": name, "ms": timed * (1 + 0.01 * k)})
    configs = [Configuration("nbo"), Configuration("pursuit"), Configuration("dpw_s30"),
               Configuration("dpw_s300_ka1_aa0p1_ko0p5_ao0"),
               Configuration("rsmhp_nt16", 30, 0, "pursuit")]  # fmt: skip
    return pd.DataFrame(q), pd.DataFrame(t), configs


def test_candidate_table_is_what_the_rule_compares():
    q, t, configs = _rows()
    c = candidate_table(q, t, configs).set_index("config")
    assert list(c.index) == [x.name for x in configs]
    r = c.loc["rsmhp_nt16/it30/r0/pursuit"]
    assert r["start"] == "pursuit" and r["restarts"] == 0 and r["maxiter"] == 30
    # cost: the larger of the timed median (0.202) and the closed loop's mean (0.4)
    assert r["cost_ms"] == pytest.approx(float(budget_cost(0.202, 0.4)))
    want = q[q.config == "dpw_s30"]["mean_error"].mean()
    assert c.loc["dpw_s30", "mean_error"] == pytest.approx(want)
    assert c.loc["dpw_s30", "plan_depth"] == pytest.approx(1.2)
    assert c.loc["dpw_s30", "cost_ms"] == pytest.approx(0.6)


def test_depth_table_pairs_each_tree_search_with_the_pursuit_policy():
    q, t, configs = _rows()
    d = depth_table(q, candidate_table(q, t, configs))
    assert list(d["config"]) == ["pursuit", "dpw_s30", "dpw_s300_ka1_aa0p1_ko0p5_ao0"]
    assert list(d["plan_depth"]) == pytest.approx([0.0, 1.2, 4.5])
    w = q.pivot(index="run", columns="config", values="mean_error")
    for name in ("dpw_s30", "dpw_s300_ka1_aa0p1_ko0p5_ao0"):
        row = d.set_index("config").loc[name]
        m, lo, hi = mean_ci((w[name] - w["pursuit"]).to_numpy())
        assert (row["diff_pursuit"], row["diff_low"], row["diff_high"]) == pytest.approx(
            (m, lo, hi)
        )
    assert d.set_index("config").loc["pursuit", "diff_pursuit"] == 0.0
    assert d.set_index("config").loc["dpw_s30", "frac_depth1"] == pytest.approx(0.98)
