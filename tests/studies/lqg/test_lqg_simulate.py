"""LQG experiment drivers: table shape and closed-form columns."""

from __future__ import annotations

import numpy as np
import pytest

from rsmhp.models.lqg import oven as lqg
from rsmhp.studies.lqg.simulate import (
    CONVERGENCE_COLUMNS,
    NBO_ERROR_COLUMNS,
    p_grid,
    run_convergence,
    run_nbo_error,
)
from tests.core.test_seeding import BASE


def test_p_grid_is_inclusive():
    assert p_grid({"start": 100, "stop": 500, "step": 100}) == [100, 200, 300, 400, 500]
    assert p_grid({"start": 100, "stop": 10000, "step": 100})[-1] == 10000


def test_convergence_table():
    df = run_convergence(BASE, seed=1)
    assert list(df.columns) == CONVERGENCE_COLUMNS
    assert len(df) == 3 * 4
    assert sorted(df["P"].unique()) == [20, 40, 60]
    u = np.array(BASE["convergence"]["u"])
    kw = BASE["model"]
    assert np.allclose(df["J_exact"], lqg.exact_cost(u, **kw))
    assert np.allclose(df["J_nbo"], lqg.nbo_cost(u, x0=0.0, a=0.5, r=10.0, target=1.0))
    assert df["u"].iloc[0] == "0.55;0.17"
    assert df["J_mhp"].nunique() == len(df)


def test_nbo_error_table():
    df = run_nbo_error(BASE, seed=1)
    assert list(df.columns) == NBO_ERROR_COLUMNS
    assert len(df) == 2 * 2 * 3
    for (a, H), grp in df.groupby(["a", "H"]):
        closed = lqg.nbo_error(int(H), a=a, r=10.0, sigma=1.0)
        assert np.allclose(grp["nbo_error_closed"], closed)
        np.testing.assert_allclose(grp["nbo_error_sim"], grp["J_mhp"] - grp["J_nbo"])
        assert (grp["nbo_error_se"] > 0).all()


def test_bad_model_rejected_before_sampling():
    bad = {**BASE, "model": {**BASE["model"], "a": 1.2}}
    with pytest.raises(ValueError, match="a must lie"):
        run_convergence(bad, seed=1)
