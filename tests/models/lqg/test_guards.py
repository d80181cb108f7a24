"""Library guards of rsmhp.models.lqg: every public entry point refuses bad arguments up front.

A parametrised matrix of bad calls to the oven closed forms and LinearQuadratic (each asserts the
exception type and that the message names the argument), then valid edge inputs that must keep
working (unchanged numbers).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from rsmhp.core import guards
from rsmhp.models.lqg import oven as lqg
from rsmhp.models.lqg.linear_quadratic import LinearQuadratic

LQG = {"x0": 0.0, "a": 0.5, "r": 10.0, "target": 1.0, "sigma": 1.0}
KW = {"x0": 0.0, "a": 0.5, "r": 10.0, "target": 1.0}  # no sigma
U = np.array([0.55, 0.17])
LQ = LinearQuadratic.scalar_lqg(U, **LQG)
QF = LQ.quadratic_form
NAN = float("nan")
INF = float("inf")

V, T = ValueError, TypeError


# (id, call, exception, regex the message must match: it names the argument)
BAD = [
    # ---- the cases reported by the user --------------------------------------------------
    (
        "state_variance H=2.5",
        lambda: lqg.state_variance(2.5, a=0.5, sigma=1.0),
        V,
        r"^H must be an integer >= 1, got 2\.5",
    ),
    # ---- lqg closed forms --------------------------------------------------------------------
    (
        "state_variance H=0",
        lambda: lqg.state_variance(0, a=0.5, sigma=1.0),
        V,
        r"^H must be >= 1, got 0",
    ),
    (
        "state_variance H=-3",
        lambda: lqg.state_variance(-3, a=0.5, sigma=1.0),
        V,
        r"^H must be >= 1, got -3",
    ),
    (
        "state_variance H=True",
        lambda: lqg.state_variance(True, a=0.5, sigma=1.0),
        T,
        r"^H must be an integer >= 1, got bool True",
    ),
    (
        "state_variance H='3'",
        lambda: lqg.state_variance("3", a=0.5, sigma=1.0),
        T,
        r"^H must be an integer >= 1, got str '3'",
    ),
    (
        "state_variance a=nan",
        lambda: lqg.state_variance(2, a=NAN, sigma=1.0),
        V,
        r"^a must be finite and lie in the open interval \(0, 1\), got nan",
    ),
    (
        "state_variance sigma=inf",
        lambda: lqg.state_variance(2, a=0.5, sigma=INF),
        V,
        r"^sigma must be finite and >= 0, got inf",
    ),
    (
        "state_variance sigma<0",
        lambda: lqg.state_variance(2, a=0.5, sigma=-0.1),
        V,
        r"^sigma must be >= 0, got -0\.1",
    ),
    (
        "nbo_error r<0",
        lambda: lqg.nbo_error(2, a=0.5, r=-1.0, sigma=1.0),
        V,
        r"^r must be >= 0, got -1\.0",
    ),
    (
        "nbo_cost x0=nan",
        lambda: lqg.nbo_cost(U, **{**KW, "x0": NAN}),
        V,
        r"^x0 must be finite, got nan",
    ),
    (
        "exact_cost target=inf",
        lambda: lqg.exact_cost(U, **{**LQG, "target": INF}),
        V,
        r"^target must be finite, got inf",
    ),
    (
        "exact_cost a=1",
        lambda: lqg.exact_cost(U, **{**LQG, "a": 1.0}),
        V,
        r"^a must lie in the open interval \(0, 1\), got 1\.0",
    ),
    (
        "exact_cost u with nan",
        lambda: lqg.exact_cost([0.1, NAN], **LQG),
        V,
        r"^u must be finite, got nan at index 1",
    ),
    (
        "exact_cost u 2-D",
        lambda: lqg.exact_cost(np.zeros((2, 2)), **LQG),
        V,
        r"^u must be a non-empty 1-D control sequence",
    ),
    (
        "cost_variance r=-1",
        lambda: lqg.cost_variance(U, **{**LQG, "r": -1.0}),
        V,
        r"^r must be >= 0",
    ),
    ("mhp_variance P=0", lambda: lqg.mhp_variance(0, U, **LQG), V, r"^P must be >= 1, got 0"),
    (
        "mhp_variance P=2.5",
        lambda: lqg.mhp_variance(2.5, U, **LQG),
        V,
        r"^P must be integer\(s\) >= 1, got 2\.5",
    ),
    (
        "chebyshev_bound eps=nan",
        lambda: lqg.chebyshev_bound(10, NAN, U, **LQG),
        V,
        r"^eps must be finite",
    ),
    (
        "chebyshev_bound eps=0",
        lambda: lqg.chebyshev_bound(10, 0.0, U, **LQG),
        V,
        r"^eps must be > 0",
    ),
    (
        "optimal_controls H=2.5",
        lambda: lqg.optimal_controls(2.5, **KW),
        V,
        r"^H must be an integer >= 1, got 2\.5",
    ),
    ("regret_gain H=0", lambda: lqg.regret_gain(0, a=0.5, r=1.0), V, r"^H must be >= 1, got 0"),
    (
        "expected_regret n_eff=0",
        lambda: lqg.expected_regret(0, 2, a=0.5, r=1.0, sigma=1.0),
        V,
        r"^n_eff must be >= 1, got 0",
    ),
    (
        "sample_argmin target=nan",
        lambda: lqg.sample_argmin(np.zeros((3, 2)), np.ones(3), **{**KW, "target": NAN}),
        V,
        r"^target must be finite",
    ),
    (
        "LQGModel sigma=0",
        lambda: lqg.LQGModel(a=0.5, r=1.0, target=1.0, sigma=0.0),
        V,
        r"sigma must be > 0",
    ),
    (
        "LQGModel target=nan",
        lambda: lqg.LQGModel(a=0.5, r=1.0, target=NAN, sigma=1.0),
        V,
        r"^target must be finite",
    ),
    # ---- linear_quadratic --------------------------------------------------------------------
    (
        "scalar_lqg r<0",
        lambda: LinearQuadratic.scalar_lqg(U, **{**LQG, "r": -1.0}),
        V,
        r"^r must be >= 0, got -1\.0",
    ),
    (
        "scalar_lqg x0=nan",
        lambda: LinearQuadratic.scalar_lqg(U, **{**LQG, "x0": NAN}),
        V,
        r"^x0 must be finite",
    ),
    (
        "LinearQuadratic x0 wrong size",
        lambda: dataclasses.replace(LQ, x0=[0.0, 1.0]),
        V,
        r"^x0 must have 1 entries \(the state dimension\), got shape \(2,\)",
    ),
    (
        "LinearQuadratic Sigma not PSD",
        lambda: dataclasses.replace(LQ, Sigma=[[-1.0]]),
        guards.NotPositiveDefiniteError,
        r"^Sigma must be symmetric positive semidefinite",
    ),
    (
        "LinearQuadratic u nan",
        lambda: dataclasses.replace(LQ, u=[[NAN], [0.0]]),
        V,
        r"^u must be finite",
    ),
    ("QuadraticForm.tree_variance N=1", lambda: QF.tree_variance(1), V, r"^N must be >= 2, got 1"),
    (
        "QuadraticForm.antithetic_variance n=0",
        lambda: QF.antithetic_variance(0),
        V,
        r"^n must be >= 1, got 0",
    ),
    (
        "QuadraticForm.independent_variance n=2.5",
        lambda: QF.independent_variance(2.5),
        V,
        r"^n must be an integer >= 1, got 2\.5",
    ),
    (
        "QuadraticForm.pernode_tree_variance N=0",
        lambda: QF.pernode_tree_variance(0),
        V,
        r"^N must be >= 1, got 0",
    ),
    (
        "QuadraticForm.prefix_covariance m=5",
        lambda: QF.prefix_covariance(5),
        V,
        r"^m must be in \[0, 2\], got 5",
    ),
    ("QuadraticForm.mean scale<0", lambda: QF.mean(scale=-1.0), V, r"^scale must be >= 0"),
    (
        "QuadraticForm.grid_average weights<0",
        lambda: QF.grid_average([np.ones(2), np.ones(2)], [np.array([1.0, -1.0]), np.ones(2)]),
        V,
        r"^weights\[0\] must be >= 0 with a positive sum",
    ),
    (
        "QuadraticForm.evaluate wrong width",
        lambda: QF.evaluate(np.zeros((3, 5))),
        V,
        r"^w must have shape \(\.\.\., 2\)",
    ),
]


@pytest.mark.parametrize(("call", "exc", "match"), [c[1:] for c in BAD], ids=[c[0] for c in BAD])
def test_bad_call_is_refused_naming_the_argument(call, exc, match):
    with pytest.raises(exc, match=match) as info:
        call()
    # the exact type asked for (a TypeError is not accepted for a ValueError case and
    # vice versa; NotPositiveDefiniteError is a LinAlgError, hence a ValueError)
    assert isinstance(info.value, exc)
    assert not (exc is ValueError and isinstance(info.value, TypeError))
    assert not (exc is TypeError and isinstance(info.value, ValueError))


# --------------------------------------------------------------------------------------------
# valid edge inputs keep working, with the same numbers


def test_h_equal_one_and_numpy_integers():
    assert lqg.state_variance(1, a=0.5, sigma=2.0) == 4.0
    assert lqg.state_variance(np.int64(4), a=0.3, sigma=1.5) == lqg.state_variance(
        4, a=0.3, sigma=1.5
    )
    np.testing.assert_array_equal(
        lqg.optimal_controls(np.int32(3), **KW), lqg.optimal_controls(3, **KW)
    )
    assert lqg.mhp_variance(np.array([10, 100]), U, **LQG).shape == (2,)
    # guards return ints (and numpy ints) unchanged: the same object
    n = np.int64(7)
    assert guards.positive_int("n", n) is n


def test_sigma_zero_is_allowed_in_the_closed_forms():
    assert lqg.state_variance(3, a=0.5, sigma=0.0) == 0.0
    assert lqg.exact_cost(U, **{**LQG, "sigma": 0.0}) == lqg.nbo_cost(U, **KW)
