"""Library guards of rsmhp.core: every public entry point refuses bad arguments up front.

A parametrised matrix of bad calls to the core modules (designs, sampling, cost_estimators,
stats, seeding; each asserts the exception type and that the message names the argument), then
valid edge inputs that must keep working (unchanged numbers). The matrices of the models live
beside their tests (tests/models/lqg/test_guards.py, tests/models/uav/test_guards.py);
test_matrix_size checks the union.
"""

from __future__ import annotations

import numpy as np
import pytest

from rsmhp.core import cost_estimators, designs, seeding, stats
from rsmhp.core.sampling import (
    GaussianNoise,
    rollout,
    rollout_cost,
    sample_independent,
    sample_tree,
    sample_tree_batch,
    top_m,
)
from rsmhp.models.lqg import oven as lqg
from rsmhp.models.lqg.linear_quadratic import LinearQuadratic
from rsmhp.models.uav import methods as uav_methods
from rsmhp.models.uav import sensor
from rsmhp.models.uav.kinematics import UAVParams
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.models.uav.sensor import SensorModel

LQG = {"x0": 0.0, "a": 0.5, "r": 10.0, "target": 1.0, "sigma": 1.0}
U = np.array([0.55, 0.17])
MODEL_LQG = lqg.LQGModel(a=0.5, r=10.0, target=1.0, sigma=1.0)
LQ = LinearQuadratic.scalar_lqg(U, **LQG)
QF = LQ.quadratic_form
CHOL = np.array([[1.0]])
LOGISTIC = SensorModel(0.05, 0.10, 100.0, footprint_radius=200.0, detection="logistic")
NAN = float("nan")
INF = float("inf")


def _rng() -> np.random.Generator:
    return np.random.default_rng(0)


V, T = ValueError, TypeError


# (id, call, exception, regex the message must match: it names the argument)
BAD = [
    # ---- the cases reported by the user --------------------------------------------------
    (
        "sample_independent 2-D x0",
        lambda: sample_independent(MODEL_LQG, [[0.2], [0.3]], U, 5, _rng()),
        V,
        r"^x0 must have 0 or 1 dimension",
    ),
    (
        "GaussianNoise(nan)",
        lambda: GaussianNoise(NAN),
        V,
        r"^noise covariance cov must be finite, got nan",
    ),
    (
        "monte_carlo n=0",
        lambda: designs.monte_carlo(_rng(), 0, 2, CHOL),
        V,
        r"^n must be >= 1, got 0",
    ),
    # ---- designs -----------------------------------------------------------------------------
    (
        "monte_carlo H=0",
        lambda: designs.monte_carlo(_rng(), 4, 0, CHOL),
        V,
        r"^H must be >= 1, got 0",
    ),
    (
        "monte_carlo chol nan",
        lambda: designs.monte_carlo(_rng(), 4, 2, np.array([[NAN]])),
        V,
        r"^chol must be finite",
    ),
    (
        "monte_carlo rng None",
        lambda: designs.monte_carlo(None, 4, 2, CHOL),
        T,
        r"^rng must be a Generator",
    ),
    (
        "antithetic n=0",
        lambda: designs.antithetic(_rng(), 0, 2, CHOL),
        V,
        r"^n must be >= 2, got 0",
    ),
    ("sobol n=3", lambda: designs.sobol(_rng(), 3, 2, CHOL), V, r"needs n a power of 2, got 3"),
    (
        "cubature chol not square",
        lambda: designs.cubature(2, np.ones((2, 3))),
        V,
        r"^chol must be a square",
    ),
    (
        "gauss_hermite q=0",
        lambda: designs.gauss_hermite(0, 2, CHOL),
        V,
        r"^q \(Gauss-Hermite nodes per dimension\) must be >= 1, got 0",
    ),
    (
        "gauss_hermite_order D=0",
        lambda: designs.gauss_hermite_order(16, 0),
        V,
        r"^D must be >= 1, got 0",
    ),
    # ---- sampling ----------------------------------------------------------------------------
    (
        "GaussianNoise not square",
        lambda: GaussianNoise(np.ones((2, 3))),
        V,
        r"^noise covariance cov must be a non-empty square matrix",
    ),
    (
        "GaussianNoise asymmetric",
        lambda: GaussianNoise(np.array([[1.0, 0.5], [0.0, 1.0]])),
        V,
        r"^noise covariance cov must be symmetric",
    ),
    (
        "GaussianNoise not PD",
        lambda: GaussianNoise(np.array([[1.0, 2.0], [2.0, 1.0]])),
        np.linalg.LinAlgError,
        r"^noise covariance cov must be positive definite, got smallest eigenvalue -1",
    ),
    (
        "GaussianNoise inf",
        lambda: GaussianNoise(np.diag([1.0, INF])),
        V,
        r"^noise covariance cov must be finite, got inf at index \(1, 1\)",
    ),
    (
        "sample_independent n=0",
        lambda: sample_independent(MODEL_LQG, [0.0], U, 0, _rng()),
        V,
        r"^n \(number of trajectories\) must be >= 1, got 0",
    ),
    (
        "sample_independent x0=nan",
        lambda: sample_independent(MODEL_LQG, [NAN], U, 3, _rng()),
        V,
        r"^x0 must be finite",
    ),
    (
        "sample_independent rng int",
        lambda: sample_independent(MODEL_LQG, [0.0], U, 3, 7),
        T,
        r"^rng must be a Generator, got int 7",
    ),
    (
        "sample_tree N=2.5",
        lambda: sample_tree(MODEL_LQG, [0.0], U, 2.5, _rng()),
        V,
        r"^N \(draws per step\) must be an integer >= 1, got 2\.5",
    ),
    (
        "sample_tree M=0",
        lambda: sample_tree(MODEL_LQG, [0.0], U, 3, _rng(), max_keep=0),
        V,
        r"^M \(trajectories kept\) must be >= 1, got 0",
    ),
    (
        "sample_tree level_noise not noise",
        lambda: sample_tree(MODEL_LQG, [0.0], U, 2, _rng(), level_noise=[1.0, 1.0]),
        T,
        r"^level_noise\[0\] must be a GaussianNoise",
    ),
    (
        "sample_tree_batch rngs[1] None",
        lambda: sample_tree_batch(LQ, LQ.x0, LQ.u, 2, [_rng(), None]),
        T,
        r"^rngs\[1\] must be a Generator",
    ),
    (
        "sample_tree_batch x0 wrong size",
        lambda: sample_tree_batch(LQ, [0.0, 1.0], LQ.u, 2, [_rng()]),
        V,
        r"^x0 must have 1 entries",
    ),
    (
        "rollout u nan",
        lambda: rollout(MODEL_LQG, [0.0], [NAN, 0.1], np.zeros((3, 2, 1))),
        V,
        r"^u must be finite",
    ),
    (
        "rollout_cost x0 2-D",
        lambda: rollout_cost(MODEL_LQG, np.zeros((2, 2)), U, np.zeros((3, 2, 1))),
        V,
        r"^x0 must have 0 or 1 dimension",
    ),
    ("top_m M=2.5", lambda: top_m(np.zeros(4), 2.5), V, r"^M must be an integer >= 1, got 2\.5"),
    # ---- estimators ----------------------------------------------------------------------------
    (
        "uniform_estimate nan",
        lambda: cost_estimators.uniform_estimate([1.0, NAN]),
        V,
        r"^cost must be finite, got nan at index 1",
    ),
    (
        "uniform_estimate bad axis",
        lambda: cost_estimators.uniform_estimate(np.ones(3), axis=2),
        V,
        r"^axis must be a valid axis of cost",
    ),
    (
        "likeliness_weights nan",
        lambda: cost_estimators.likeliness_weights([0.0, NAN]),
        V,
        r"^log_likeliness must be finite or -inf",
    ),
    (
        "likeliness_weights all -inf",
        lambda: cost_estimators.likeliness_weights([-INF, -INF]),
        V,
        r"^log_likeliness must not be -inf for every trajectory",
    ),
    (
        "weighted_estimate shape mismatch",
        lambda: cost_estimators.weighted_estimate(np.ones(5), np.zeros(1)),
        V,
        r"^cost and log_likeliness must have the same shape",
    ),
    (
        "nbo_estimate empty u",
        lambda: cost_estimators.nbo_estimate(MODEL_LQG, [0.0], []),
        V,
        r"control sequence u must have at least one step",
    ),
    # ---- stats ---------------------------------------------------------------------------------
    (
        "mean_ci level=1.5",
        lambda: stats.mean_ci(np.ones(3), level=1.5),
        V,
        r"^level must lie in the open interval \(0, 1\), got 1\.5",
    ),
    ("mean_ci x nan", lambda: stats.mean_ci([1.0, NAN, 2.0]), V, r"^x must be finite"),
    ("binomial_ci k > n", lambda: stats.binomial_ci(5, 3), V, r"^k must be in \[0, 3\], got 5"),
    ("binomial_ci n=0", lambda: stats.binomial_ci(0, 0), V, r"^n must be >= 1, got 0"),
    ("rmse_ci empty", lambda: stats.rmse_ci([]), V, r"err for an RMSE, got 0"),
    (
        "loglog_slope length mismatch",
        lambda: stats.loglog_slope([1.0, 2.0, 3.0], [1.0, 2.0]),
        V,
        r"^x and y must have the same length",
    ),
    (
        "loglog_slope y nan",
        lambda: stats.loglog_slope([1.0, 2.0, 3.0], [1.0, NAN, 2.0]),
        V,
        r"^y must be finite",
    ),
    # ---- seeding -------------------------------------------------------------------------------
    (
        "job_rng root_seed=True",
        lambda: seeding.job_rng(True, "e"),
        T,
        r"^root_seed must be an integer >= 0, got bool True",
    ),
    (
        "job_rng root_seed=1.5",
        lambda: seeding.job_rng(1.5, "e"),
        V,
        r"^root_seed must be an integer >= 0, got 1\.5",
    ),
    (
        "job_rng param nan",
        lambda: seeding.job_rng(1, "e", q=NAN),
        V,
        r"^job identifier parameter q: .*finite, got nan",
    ),
    (
        "canonical_job_id experiment=5",
        lambda: seeding.canonical_job_id(5),
        T,
        r"^experiment must be a non-empty string, got int 5",
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


def test_matrix_size():
    """The whole matrix (core, LQG and UAV files together) stays large, with unique ids."""
    from tests.models.lqg.test_guards import BAD as BAD_LQG
    from tests.models.uav.test_guards import BAD as BAD_UAV

    every = BAD + BAD_LQG + BAD_UAV
    assert len(every) >= 70
    assert len({c[0] for c in every}) == len(every)


# --------------------------------------------------------------------------------------------
# valid edge inputs keep working, with the same numbers


def test_whole_number_floats_are_normalised():
    """3.0 counts as 3 (as in rsmhp.core.seeding's job ids); the result equals the int's."""
    assert lqg.state_variance(3.0, a=0.4, sigma=1.0) == lqg.state_variance(3, a=0.4, sigma=1.0)
    w, wt = designs.monte_carlo(np.random.default_rng(1), 8.0, 2, CHOL)
    w2, wt2 = designs.monte_carlo(np.random.default_rng(1), 8, 2, CHOL)
    np.testing.assert_array_equal(w, w2)
    np.testing.assert_array_equal(wt, wt2)
    assert MonteCarlo(3.0).n_traj == 3
    assert "rsmhp_nt3" in uav_methods.from_config({"nbo": False, "rsmhp_nt": [3.0], "tree": []})


def test_edge_bounds_are_allowed():
    # equal speed bounds: a constant-speed aircraft
    UAVParams(1.0, 9.81, 3.0, 0.7, 20.0, 20.0, 100.0)
    assert sensor.detected(np.zeros(2), np.ones(2), LOGISTIC, 0.0)  # u = 0 in [0, 1]
    assert stats.binomial_ci(0, 5)[0] == 0.0 and stats.binomial_ci(5, 5)[1] == 1.0
    assert QF.prefix_covariance(0) == 0.0 and QF.prefix_covariance(2) == pytest.approx(
        QF.variance()
    )
    # -inf log-likeliness is a zero weight, not an error
    np.testing.assert_array_equal(cost_estimators.likeliness_weights([0.0, -np.inf]), [2.0, 0.0])
    assert seeding.job_rng(np.uint32(3), "e").random() == seeding.job_rng(3, "e").random()
