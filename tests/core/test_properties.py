"""Property-based tests (hypothesis) of the UAV covariance kernels, the samplers, the
estimators and the trajectory sampling, over adversarial inputs.

Geometry and scales are drawn to hurt: the target exactly below the UAV (zero horizontal
range, bearing undefined), within a micrometre of it, 1e5 m away; prior covariances from
1e-8 to 1e8 with eigenvalue spreads up to 1e16 (numerically singular); sensor noise
fractions from 1e-6 to 1 per metre (R up to 1e12 times more precise across-range than along
it), altitudes 1..1000 m; footprints from 1 to 1000 m with logistic widths 0.1..100 m, so
detection probabilities are exactly 0 (missed detections), exactly 1 and anything between.

Tolerances are derived from float64 rounding, never fitted to the outputs:

* ``U`` is the unit roundoff 2**-53 and ``C_OPS = 128`` bounds the rounding of one Kalman
  step: the longest dependency chain of one predict + update has about 20 rounded
  operations (4 in the prediction, 1 in S, 3 in det S, 3 in the adjugate products, 3 in
  K S K^T, 1 in the subtraction), and entrywise errors of a 4x4 matrix bound its spectral
  norm within a factor 4; 20 * 4 = 80 <= 128.
* One step of the conventional update P+ = P- - p K S K^T (the kernels' form) has a
  spectral-norm error of at most ``U * C_OPS * kappa(S) * ||P-||``: the 2x2 inverse is
  formed from det S = s11 s22 - s12^2, whose relative error is <= 3 U kappa(S) (for a 2x2
  SPD matrix s11 s22 + s12^2 <= lambda_max^2), and every product carrying that error is
  bounded by ||P-|| because K S K^T <= P- (Loewner).  With a footprint, p_d itself carries
  rounding: its argument (rho - rho0) / w has error <= 2 U (rho + rho0) / w and
  dp/darg = -p (1 - p), adding ``4 U p (1 - p) (rho + rho0) / w * ||P-||``.
* Errors made at earlier steps propagate through the first-order map of one step,
  dP+ = (1 - p) dP- + p E dP- E^T (E = I - K H, the optimal-gain identity stated in
  rsmhp.models.uav.fused), composed with dP- = F dP F^T: a factor ``||F||^2 max(1, ||E||^2)``.
  The accumulated bound ``tau_j`` bounds ||computed P_j - exact P_j|| (spectral), so the
  computed P_j has eigenvalues >= -tau_j and its trace is within 4 tau_j of the exact one.

These bounds are upper bounds: on the examples below the observed errors stay below a few
per cent of them. ``test_kernel_posterior_psd_relative_to_its_own_scale`` records where
the bound is all the kernels promise: there the computed posterior is not PSD relative to
its own size (a known-failing case, see its docstring).
"""

from __future__ import annotations

import dataclasses
import math
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from rsmhp.core import designs
from rsmhp.core.cost_estimators import likeliness_weights, uniform_estimate, weighted_estimate
from rsmhp.core.sampling import rollout, rollout_cost, sample_independent, sample_tree
from rsmhp.models.lqg.linear_quadratic import LinearQuadratic
from rsmhp.models.uav import fused, kernel
from rsmhp.models.uav.kinematics import UAVParams
from rsmhp.models.uav.sensor import (
    GROWTHS,
    SensorModel,
    detected,
    detection_probability,
    measurement_cov,
    measurement_noise,
)
from rsmhp.models.uav.target import TargetModel
from rsmhp.models.uav.tracker import MEASUREMENT_MATRIX, Tracker

U = np.finfo(float).eps / 2  # unit roundoff of float64
C_OPS = 128  # rounded operations of one Kalman step, times 4 for norms (module docstring)

# Same examples on every run (derandomize), no example database, no per-example deadline
# (the first call of a compiled kernel in a process loads it from numba's cache).
BASE = settings(
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)

UAV = UAVParams(
    dt=1.0, g=9.81, accel_max=3.0, bank_max=math.pi / 4, speed_min=10, speed_max=35, altitude=100
)
MODES = ("below", "near", "mid", "far")


# --------------------------------------------------------------------------------------------
# strategies


def exp10(lo: float, hi: float) -> st.SearchStrategy[float]:
    """10**e for e uniform-ish in [lo, hi] (hypothesis also tries the end points)."""
    return st.floats(lo, hi).map(lambda e: 10.0**e)


@st.composite
def covariances(draw, scale=(-8.0, 8.0), spread=16.0) -> np.ndarray:
    """Symmetric PSD 4x4: V diag(s 10**e_k) V^T, s in 1e-8..1e8, e_k in [-spread, 0]
    (eigenvalue spread up to 1e16: numerically singular), V a random rotation or I."""
    s = draw(exp10(*scale))
    e = np.array(draw(st.lists(st.floats(-spread, 0.0), min_size=4, max_size=4)))
    if draw(st.booleans()):
        seed = draw(st.integers(0, 2**32 - 1))
        V = np.linalg.qr(np.random.default_rng(seed).standard_normal((4, 4)))[0]
    else:
        V = np.eye(4)
    P = (V * (s * 10.0**e)) @ V.T
    return 0.5 * (P + P.T)


@st.composite
def sensors(draw, footprint: bool | None = None) -> SensorModel:
    """Every variant: noise fractions 1e-6..1 (isotropic or up to 1e6 apart, so cond R up
    to 1e12), altitude 1..1000 m, linear/quadratic growth, no footprint or a footprint of
    1..1000 m with width 0.1..100 m and hard/logistic truth detection."""
    f_r = draw(exp10(-6, 0))
    f_c = f_r if draw(st.booleans()) else draw(exp10(-6, 0))
    limited = draw(st.booleans()) if footprint is None else footprint
    return SensorModel(
        sigma_r_per_m=f_r,
        sigma_c_per_m=f_c,
        altitude=draw(exp10(0, 3)),
        noise_growth=draw(st.sampled_from(GROWTHS)),
        reference_distance=draw(exp10(0, 3)),
        footprint_radius=draw(exp10(0, 3)) if limited else float("inf"),
        footprint_width=draw(exp10(-1, 2)),
        detection=draw(st.sampled_from(("hard", "logistic"))),
    )


target_models = st.builds(TargetModel, dt=st.floats(0.1, 2.0), q=exp10(-4, 2))


def place_targets(uav_xy: np.ndarray, modes, rng, near=(-6.0, 0.0)) -> np.ndarray:
    """Targets (T, H, 2) relative to the path ``uav_xy`` (H, 2): exactly below it, at
    10**U(near) m from it, anywhere within 500 m of the origin, or 1e5 m away."""
    T = len(modes) // len(uav_xy)
    out = np.empty((T, len(uav_xy), 2))
    for k, mode in enumerate(modes):
        i, j = divmod(k, len(uav_xy))
        bearing = rng.uniform(-np.pi, np.pi)
        unit = np.array([np.cos(bearing), np.sin(bearing)])
        if mode == "below":
            out[i, j] = uav_xy[j]
        elif mode == "near":
            out[i, j] = uav_xy[j] + 10.0 ** rng.uniform(*near) * unit
        elif mode == "mid":
            out[i, j] = rng.uniform(-500.0, 500.0, 2)
        else:
            out[i, j] = uav_xy[j] + 1e5 * unit
    return out


@st.composite
def kalman_cases(draw, max_h=6, footprint=None):
    """(P0, model, sensor, uav_xy (C, H, 2), target_xy (T, H, 2)); the targets are placed
    relative to candidate 0's positions."""
    H = draw(st.integers(1, max_h))
    C = draw(st.integers(1, 3))
    T = draw(st.integers(1, 3))
    modes = draw(st.lists(st.sampled_from(MODES), min_size=T * H, max_size=T * H))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    uav_xy = rng.uniform(-500.0, 500.0, (C, H, 2))
    target_xy = place_targets(uav_xy[0], modes, rng)
    return draw(covariances()), draw(target_models), draw(sensors(footprint)), uav_xy, target_xy


# --------------------------------------------------------------------------------------------
# rounding budgets (see the module docstring)


def norm2(M: np.ndarray) -> np.ndarray:
    """Spectral norm over the last two axes (inf for a matrix with non-finite entries)."""
    M = np.asarray(M)
    finite = np.isfinite(M).all(axis=(-2, -1))
    if finite.all():
        return np.linalg.norm(M, 2, axis=(-2, -1))
    out = np.full(finite.shape, np.inf)
    out[finite] = np.linalg.norm(M[finite], 2, axis=(-2, -1))
    return out


def cond_spd(S: np.ndarray) -> np.ndarray:
    """lambda_max / lambda_min of symmetric S; inf where S is not numerically positive
    definite (then no float64 evaluation of the update is bounded, nor is our budget)."""
    ev = np.linalg.eigvalsh(S)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(ev[..., 0] > 0, ev[..., -1] / ev[..., 0], np.inf)


def initial_negativity(P0: np.ndarray) -> np.ndarray:
    """How far the given (rounded) P0 is below PSD, plus eigvalsh's own error."""
    return np.maximum(0.0, -np.linalg.eigvalsh(P0)[..., 0]) + C_OPS * U * norm2(P0)


def gain_and_complement(prior: np.ndarray, S: np.ndarray):
    """K = P- H^T S^-1 (..., 4, 2) and E = I - K H (..., 4, 4), by the 2x2 adjugate (inf or
    nan entries only where S is singular; the budget is infinite there anyway)."""
    det = S[..., 0, 0] * S[..., 1, 1] - S[..., 0, 1] * S[..., 1, 0]
    adj = np.stack(
        [np.stack([S[..., 1, 1], -S[..., 0, 1]], -1), np.stack([-S[..., 1, 0], S[..., 0, 0]], -1)],
        -2,
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        K = prior[..., :, :2] @ (adj / det[..., None, None])
    return K, np.eye(4) - K @ MEASUREMENT_MATRIX


def kernel_budget(P0, covs, uav_xy, target_xy, model, sensor):
    """For the covariances ``covs`` (C, T, H, 4, 4) the numpy kernel computed from ``P0``:
    the prior of every step recomputed from the kernel's previous posterior (C, T, H, 4, 4),
    the local error bound ``eps`` of that step and the accumulated bound ``tau`` (C, T, H)."""
    F, Q = model.F, model.Q
    nF2 = norm2(F) ** 2
    R = measurement_cov(uav_xy[:, None], target_xy[None], sensor)  # (C, T, H, 2, 2)
    pd = detection_probability(uav_xy[:, None], target_xy[None], sensor)
    rho = np.hypot(*np.moveaxis(target_xy[None] - uav_xy[:, None], -1, 0))
    prev = np.broadcast_to(P0, (*covs.shape[:2], 4, 4))
    tau = initial_negativity(prev)
    priors = np.empty_like(covs)
    eps = np.empty(covs.shape[:3])
    taus = np.empty(covs.shape[:3])
    for j in range(covs.shape[2]):
        prior = F @ prev @ F.T + Q
        S = prior[..., :2, :2] + R[:, :, j]
        _, E = gain_and_complement(prior, S)
        scale = np.maximum(norm2(prior), nF2 * norm2(prev))
        lam = 0.0
        if sensor.limited:
            p = pd[:, :, j]
            lam = p * (1 - p) * (rho[:, :, j] + sensor.footprint_radius) / sensor.footprint_width
        with np.errstate(invalid="ignore", over="ignore"):
            eps_j = U * (C_OPS * cond_spd(S) + 4 * lam + 4) * scale
            growth = nF2 * np.maximum(1.0, norm2(E) ** 2)
            tau = eps_j + growth * tau
        eps[:, :, j] = np.where(np.isnan(eps_j), np.inf, eps_j)
        taus[:, :, j] = np.where(np.isnan(tau), np.inf, tau)
        priors[:, :, j] = prior
        prev = covs[:, :, j]
    return priors, eps, taus


# --------------------------------------------------------------------------------------------
# 1a. the numpy kernel: symmetric, PSD, finite; the update never increases the covariance


@settings(BASE, max_examples=150)
@given(case=kalman_cases())
def test_kernel_covariances_symmetric_psd_finite_and_below_the_prior(case):
    P0, model, sensor, uav_xy, txy = case
    traces, covs = kernel.covariance_traces(
        P0, uav_xy, txy, model.dt, model.Q, sensor, return_cov=True
    )
    assert np.all(np.isfinite(covs)) and np.all(np.isfinite(traces))
    # symmetric exactly: the kernel carries the 10 distinct entries only
    np.testing.assert_array_equal(covs, np.swapaxes(covs, -1, -2))
    # the traces are the traces of these covariances, summed in the same order
    np.testing.assert_array_equal(traces, np.trace(covs, axis1=-2, axis2=-1))
    priors, eps, tau = kernel_budget(P0, covs, uav_xy, txy, model, sensor)
    # PSD up to the accumulated rounding bound
    assert np.all(np.linalg.eigvalsh(covs)[..., 0] >= -tau)
    # one (expected) update never increases the covariance: P- - P+ = p K S K^T >= 0
    assert np.all(np.linalg.eigvalsh(priors - covs)[..., 0] >= -eps)
    # traces are non-negative up to the same bound (trace <= 4 x spectral norm)
    assert np.all(traces >= -4 * tau)
    # a missed detection (p_d = 0 exactly, e.g. 1e5 m outside the footprint) is a
    # prediction only
    pd = detection_probability(uav_xy[:, None], txy[None], sensor)
    miss = pd == 0.0
    diff = np.abs(covs - priors).max(axis=(-2, -1))
    assert np.all(diff[miss] <= eps[miss])


@settings(BASE, max_examples=80)
@given(
    P0=covariances(),
    model=target_models,
    sensor=sensors(footprint=True),
    seed=st.integers(0, 2**32 - 1),
    mode=st.sampled_from(MODES),
)
def test_expected_update_lies_between_the_full_update_and_the_prior(P0, model, sensor, seed, mode):
    """P+ = P- - p_d K S K^T with 0 <= p_d <= 1: full update <= expected update <= prior
    (Loewner), one step from the same prior, same R."""
    rng = np.random.default_rng(seed)
    uav_xy = rng.uniform(-500.0, 500.0, (1, 1, 2))
    txy = place_targets(uav_xy[0], [mode], rng)
    unlimited = dataclasses.replace(sensor, footprint_radius=float("inf"))
    _, exp_cov = kernel.covariance_traces(
        P0, uav_xy, txy, model.dt, model.Q, sensor, return_cov=True
    )
    _, full_cov = kernel.covariance_traces(
        P0, uav_xy, txy, model.dt, model.Q, unlimited, return_cov=True
    )
    priors, eps, _ = kernel_budget(P0, exp_cov, uav_xy, txy, model, sensor)
    _, eps_full, _ = kernel_budget(P0, full_cov, uav_xy, txy, model, unlimited)
    assert np.linalg.eigvalsh(priors - exp_cov).min() >= -eps.max()
    assert np.linalg.eigvalsh(exp_cov - full_cov).min() >= -(eps + eps_full).max()


# --------------------------------------------------------------------------------------------
# 1b. the compiled kernel equals the numpy kernel


@settings(BASE, max_examples=120)
@given(case=kalman_cases())
def test_fused_traces_equal_numpy_kernel(case):
    """Both kernels run the same recursion (same block formulas, same operation order); they
    can differ only where library functions round differently (exp, hypot vs sqrt in p_d).
    Each is within 4 tau of the exact traces, so they are within 8 tau of each other. A
    flat relative tolerance (say 1e-9) would not be justified: with kappa(S) up to 1e12 and
    P- up to 1e8 a one-ulp change of p_d moves a posterior trace of 1e-3 by ~1e-8."""
    P0, model, sensor, uav_xy, txy = case
    ref, covs = kernel.covariance_traces(
        P0, uav_xy, txy, model.dt, model.Q, sensor, return_cov=True
    )
    ours = fused.covariance_traces(P0, uav_xy, txy, model.dt, model.Q, sensor)
    assert ours.shape == ref.shape and np.all(np.isfinite(ours))
    _, _, tau = kernel_budget(P0, covs, uav_xy, txy, model, sensor)
    # in benign cases 8 tau is ~1e-13 of the trace, tighter than a relative 1e-9
    assert np.all(np.abs(ours - ref) <= 8 * tau)


@st.composite
def planning_cases(draw, max_h=6, smooth=False):
    """(x (2H,), UAV state, P0, model, sensor, target_xy (T, H, 2)); targets placed relative
    to the compiled path of x. ``smooth``: no target exactly below the UAV unless R and p_d
    are smooth there (isotropic noise, no footprint), none within 1 m otherwise."""
    H = draw(st.integers(1, max_h))
    T = draw(st.integers(1, 3))
    sensor = draw(sensors())
    x = np.array(draw(st.lists(st.floats(-0.99, 0.99), min_size=2 * H, max_size=2 * H)))
    state = np.array(
        [0.0, 0.0, draw(st.floats(UAV.speed_min, UAV.speed_max)), draw(st.floats(-4.0, 4.0))]
    )
    modes = draw(st.lists(st.sampled_from(MODES), min_size=T * H, max_size=T * H))
    if smooth and (sensor.limited or sensor.sigma_r_per_m != sensor.sigma_c_per_m):
        modes = ["near" if m == "below" else m for m in modes]
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    model = draw(target_models)
    P0 = draw(covariances())
    probe = fused.Frozen(state, UAV, P0, np.zeros((1, H, 2)), model.dt, model.Q, sensor)
    path = fused.path(x, probe)
    txy = place_targets(path[:, :2], modes, rng, near=(0.0, 1.0) if smooth else (-6.0, 0.0))
    return x, state, P0, model, sensor, txy


@settings(BASE, max_examples=80)
@given(case=planning_cases())
def test_fused_cost_equals_numpy_objective_and_every_entry_point_agrees(case):
    x, state, P0, model, sensor, txy = case
    frozen = fused.Frozen(state, UAV, P0, txy, model.dt, model.Q, sensor)
    uav_xy = fused.path(x, frozen)[None, :, :2]  # compiled kinematics, shared by both
    ref, covs = kernel.covariance_traces(
        P0, uav_xy, txy, model.dt, model.Q, sensor, return_cov=True
    )
    _, _, tau = kernel_budget(P0, covs, uav_xy, txy, model, sensor)
    c = fused.cost(x, state, UAV, P0, txy, model.dt, model.Q, sensor)
    assert np.isfinite(c[0])
    # the objective is the mean over hypotheses of the summed traces: error <= mean sum 8 tau
    assert abs(c[0] - ref[0].sum(axis=1).mean()) <= 8 * tau[0].sum(axis=1).mean()
    cg, g = fused.cost_and_grad(x, state, UAV, P0, txy, model.dt, model.Q, sensor)
    ev, _ = fused.evaluate(x[None], frozen, want_grad=False)
    # the same compiled arithmetic: bit for bit, with or without the gradient pass
    np.testing.assert_array_equal(cg, c)
    np.testing.assert_array_equal(ev, c)
    assert g.shape == (1, x.size) and np.all(np.isfinite(g))


# --------------------------------------------------------------------------------------------
# 1c. the exact gradient against central differences


@settings(BASE, max_examples=60)
@given(case=planning_cases(smooth=True))
def test_fused_gradient_matches_central_differences(case):
    """Step h = 1e-5 (controls are normalised, O(1)): central differences have truncation
    error a h^2 (a ~ J''' / 6) and rounding error <= err_J / h, where err_J bounds the
    rounding of J (mean over hypotheses of 4 tau summed over steps); h ~ (3 U)^(1/3)
    balances the two when J''' ~ J. With the Richardson estimate a h^2 ~ (D_2h - D_h) / 3
    (whose own rounding is <= 1.5 err_J / h) the exact gradient lies within
    |D_2h - D_h| / 3 + 2.5 err_J / h of D_h; we allow twice that.

    Kinks are kept away: the speed clip (every pre-clip speed at least 10 h a_max dt from
    both bounds, beyond what the 2h steps can move it), the control box (|x| <= 0.99),
    and the overhead point (only with isotropic noise and no footprint, where R and p_d are
    smooth in the UAV position; else every target at least 1 m off the path)."""
    x, state, P0, model, sensor, txy = case
    h = 1e-5
    frozen = fused.Frozen(state, UAV, P0, txy, model.dt, model.Q, sensor)
    path = fused.path(x, frozen)
    # pre-clip speeds s_j + a_j dt of every step
    v = np.concatenate([[state[2]], path[:-1, 2]]) + x[0::2] * UAV.accel_max * UAV.dt
    margin = np.minimum(np.abs(v - UAV.speed_min), np.abs(v - UAV.speed_max)).min()
    assume(margin > 10 * h * UAV.accel_max * UAV.dt)
    f0, g = fused.evaluate(x[None], frozen, want_grad=True)
    uav_xy = path[None, :, :2]
    _, covs = kernel.covariance_traces(P0, uav_xy, txy, model.dt, model.Q, sensor, return_cov=True)
    _, _, tau = kernel_budget(P0, covs, uav_xy, txy, model, sensor)
    err_j = 4 * tau[0].sum(axis=1).mean()
    n = x.size
    steps = np.concatenate([np.eye(n) * h, -np.eye(n) * h, np.eye(n) * 2 * h, -np.eye(n) * 2 * h])
    f = fused.evaluate(x[None] + steps, frozen, want_grad=False)[0].reshape(4, n)
    d1 = (f[0] - f[1]) / (2 * h)
    d2 = (f[2] - f[3]) / (4 * h)
    tol = 2 * (np.abs(d2 - d1) / 3 + 2.5 * err_j / h)
    assert np.all(np.isfinite(g)) and np.isfinite(f0[0])
    assert np.all(np.abs(g[0] - d1) <= tol), (g[0], d1, tol)


# --------------------------------------------------------------------------------------------
# 1d. the sensor model


@settings(BASE, max_examples=200)
@given(
    sensor=sensors(),
    seed=st.integers(0, 2**32 - 1),
    mode=st.sampled_from(MODES),
)
def test_measurement_covariance_is_the_rotated_diagonal_and_never_singular(sensor, seed, mode):
    """R = G diag(sr^2, sc^2) G^T: symmetric exactly, eigenvalues (f_r D)^2, (f_c D)^2 with
    D^2 = d^2 (linear) or d^4 / d0^2 (quadratic), to <= 32 U lambda_max (<= 12 roundings in
    an entry, each relative to a term <= lambda_max, <= 4 in our own expected values, and
    eigvalsh's backward error of a few U, doubled for the norm), positive even overhead;
    the noise factor reproduces it to the same bound."""
    rng = np.random.default_rng(seed)
    uav = rng.uniform(-500.0, 500.0, 2)
    tgt = place_targets(uav[None], [mode], rng)[0, 0]
    R = measurement_cov(uav, tgt, sensor)
    assert np.all(np.isfinite(R)) and R[0, 1] == R[1, 0]
    rho = float(np.hypot(*(tgt - uav)))
    d2 = rho**2 + sensor.altitude**2
    D2 = d2 * d2 / sensor.reference_distance**2 if sensor.noise_growth == "quadratic" else d2
    expected = np.sort([sensor.sigma_r_per_m**2 * D2, sensor.sigma_c_per_m**2 * D2])
    ev = np.linalg.eigvalsh(R)
    np.testing.assert_allclose(ev, expected, rtol=0, atol=32 * U * expected[1])
    # f_r / f_c <= 1e6, so lambda_min / lambda_max >= 1e-12 >> 32 U: never singular
    assert ev[0] > 0
    if rho == 0.0:  # bearing undefined: taken as 0, R diagonal
        assert R[0, 1] == 0.0
    L = np.column_stack([measurement_noise(uav, tgt, sensor, e) for e in np.eye(2)])
    np.testing.assert_allclose(L @ L.T, R, rtol=0, atol=32 * U * expected[1])


@settings(BASE, max_examples=200)
@given(
    sensor=sensors(),
    rho=st.one_of(st.just(0.0), exp10(-6, 5)),
    drho=exp10(-6, 5),
    u=st.floats(0.0, 1.0, exclude_max=True),
)
def test_detection_probability_and_truth_detection(sensor, rho, drho, u):
    """p_d in [0, 1], never NaN, 1 without a footprint, 1/2 on the footprint edge,
    non-increasing in the range, exactly 0 far outside (missed detection); truth: hard
    detects exactly inside the radius, logistic exactly when u < p_d."""
    uav = np.array([3.0, -4.0])
    tgt = uav + np.array([rho, 0.0])
    far = uav + np.array([rho + drho, 0.0])
    p, p_far = detection_probability(uav, tgt, sensor), detection_probability(uav, far, sensor)
    # exp is monotone up to its last-ulp rounding: allow 2 ulp
    assert 0.0 <= p <= 1.0 and 0.0 <= p_far <= p * (1 + 4 * U)
    if not sensor.limited:
        assert p == 1.0 and detected(uav, tgt, sensor, u)
        return
    origin = np.zeros(2)  # exactly on the edge: argument 0, p = 1 / (1 + 1)
    assert detection_probability(origin, np.array([sensor.footprint_radius, 0.0]), sensor) == 0.5
    # 1e5 m out: (rho - rho0) / w >= (1e5 - 1e3) / 100 > 710, exp overflows, p_d = 0 exactly
    assert detection_probability(uav, uav + np.array([1e5, 0.0]), sensor) == 0.0
    rho_c = float(np.hypot(*(tgt - uav)))  # the range as the sensor computes it
    if sensor.detection == "hard":
        assert detected(uav, tgt, sensor, u) == (rho_c <= sensor.footprint_radius)
    else:
        assert detected(uav, tgt, sensor, u) == (u < p)


# --------------------------------------------------------------------------------------------
# 1e. the tracker (filterpy, Joseph form)


def joseph_bound(prior: np.ndarray, R: np.ndarray) -> tuple[float, np.ndarray]:
    """(eps_J, E) of filterpy's Joseph update from ``prior`` with ``R`` (see the tracker
    test's docstring): the update's rounding plus the second-order effect of its gain's
    error, ||computed P+ - exact update of sym(prior)|| <= eps_J."""
    gamma = 10 * U / (1 - 10 * U)
    sym_prior = 0.5 * (prior + prior.T)
    S = sym_prior[:2, :2] + R
    K, E = gain_and_complement(sym_prior, S)
    lam_min = np.linalg.eigvalsh(S)[0]
    with np.errstate(divide="ignore"):
        asym = norm2(0.5 * (prior - prior.T)) * (1 + norm2(K)) / np.where(lam_min > 0, lam_min, 0.0)
    dK = C_OPS * U * cond_spd(S) * norm2(K) + asym
    joseph = np.abs(E) @ np.abs(prior) @ np.abs(E).T + np.abs(K) @ np.abs(R) @ np.abs(K).T
    return float(norm2(2 * gamma * joseph) + dK**2 * norm2(S)), E


@settings(BASE, max_examples=100)
@given(case=kalman_cases(), seed=st.integers(0, 2**32 - 1))
def test_tracker_covariances_stay_psd_and_below_the_prior(case, seed):
    """The simulation's filter over the same geometry, misses decided by the sensor's truth
    detection. Bounds (entrywise |.| products, gamma_10 = 10 U / (1 - 10 U) for the 4-term
    dot products and sums, doubled for two different evaluation orders):

    * predict = F P F^T + Q within 2 gamma_10 (|F||P||F|^T + |Q|);
    * the Joseph update P+ = E P- E^T + K R K^T has rounding eps_J = 2 gamma_10 (|E||P-||E|^T
      + |K||R||K|^T); its gain is off the optimal one for sym(P-) by dK (the inverse's
      rounding C_OPS U kappa(S) ||K||, and the prior's asymmetry ||P_a|| (1 + ||K||) /
      lambda_min(S)); Joseph's value for a gain K + dK is P+ + dK S dK^T, which is PSD
      and exceeds the prior's update by at most ||dK||^2 ||S||.
    * errors accumulate as in the kernels' budget (factor ||F||^2 per prediction, ||E||^2
      per update); the computed P is within tau of the exact one, so its asymmetric part
      is below tau and its symmetric part has eigenvalues >= -tau.

    With an unlimited sensor its traces equal the numpy kernel's within both bounds."""
    P0, model, sensor, uav_xy, txy = case
    uav, F, Q = uav_xy[0], model.F, model.Q
    gamma = 10 * U / (1 - 10 * U)
    nF2 = norm2(F) ** 2
    rng = np.random.default_rng(seed)
    trk = Tracker(np.zeros(4), P0, model)
    tau = float(initial_negativity(P0))
    traces = []
    for j in range(uav.shape[0]):
        prev = trk.P
        trk.predict()
        pred_err = 2 * gamma * (np.abs(F) @ np.abs(prev) @ np.abs(F).T + np.abs(Q))
        assert np.all(np.abs(trk.P - (F @ prev @ F.T + Q)) <= pred_err)
        tau = nF2 * tau + norm2(pred_err)
        R = measurement_cov(uav[j], txy[0, j], sensor)
        if detected(uav[j], txy[0, j], sensor, rng.uniform()):
            prior = trk.P
            trk.update(np.zeros(2), R)
            post = trk.P
            assert np.all(np.isfinite(post))
            eps, E = joseph_bound(prior, R)
            sym_prior = 0.5 * (prior + prior.T)
            sym = 0.5 * (post + post.T)
            # eigvalsh's own error, C_OPS U ||.||, as in initial_negativity (the BLAS path of
            # filterpy's products differs with the thread settings other tests leave behind)
            diff = sym_prior - sym
            assert np.linalg.eigvalsh(diff)[0] >= -eps - C_OPS * U * norm2(diff)
            tau = eps + norm2(E) ** 2 * tau
            assert np.abs(post - post.T).max() <= tau
            assert np.linalg.eigvalsh(sym)[0] >= -tau - C_OPS * U * norm2(sym)
        traces.append(np.trace(trk.P))
    if not sensor.limited:
        ref, covs = kernel.covariance_traces(
            P0, uav[None], txy[:1], model.dt, Q, sensor, return_cov=True
        )
        _, _, tau_k = kernel_budget(P0, covs, uav[None], txy[:1], model, sensor)
        assert np.all(np.abs(np.array(traces) - ref[0, 0]) <= 4 * tau_k[0, 0] + 4 * tau)


# --------------------------------------------------------------------------------------------
# 1f. a former failure: the update A- - A- S^-1 A- lost PSD when R << U kappa(S) ||P-||


def _exact_one_step(P0, R, F, Q):
    """One predict + full update in exact rational arithmetic (inputs taken as exact)."""

    def exact(M):
        return [[Fraction(float(v)) for v in row] for row in np.asarray(M)]

    def tr(A):
        return [[A[i][j] for i in range(len(A))] for j in range(len(A[0]))]

    def mm(A, B):
        return [[sum(a * b for a, b in zip(r, c, strict=True)) for c in tr(B)] for r in A]

    Fm = exact(F)
    FPF = mm(mm(Fm, exact(P0)), tr(Fm))
    Pm = [[a + b for a, b in zip(r, q, strict=True)] for r, q in zip(FPF, exact(Q), strict=True)]
    S = [[Pm[i][j] + Fraction(float(R[i, j])) for j in range(2)] for i in range(2)]
    det = S[0][0] * S[1][1] - S[0][1] * S[1][0]
    Si = [[S[1][1] / det, -S[0][1] / det], [-S[1][0] / det, S[0][0] / det]]
    PH = [row[:2] for row in Pm]
    X = mm(mm(PH, Si), tr(PH))
    return np.array([[float(Pm[i][j] - X[i][j]) for j in range(4)] for i in range(4)])


def _minimal_case():
    """Minimal case found by the properties above: one step, one candidate, one hypothesis.

    Prior position variance 1e8 m^2 along 30 degrees and 1 m^2 across it, velocity variance
    0.01 (m/s)^2; NCV model dt = 1 s, q = 0.01; sensor f_r = 0.01, f_c = 1e-6 per metre at
    1 m altitude; target exactly below the UAV, so R = diag(1e-4, 1e-12) m^2. All valid.
    Returns the kernels' arguments, R and the exact posterior."""
    model = TargetModel(1.0, 0.01)
    c, s = math.cos(math.pi / 6), math.sin(math.pi / 6)
    V = np.array([[c, -s], [s, c]])
    P0 = np.zeros((4, 4))
    P0[:2, :2] = V @ np.diag([1e8, 1.0]) @ V.T
    P0[2:, 2:] = 0.01 * np.eye(2)
    sensor = SensorModel(0.01, 1e-6, 1.0)
    uav_xy, txy = np.zeros((1, 1, 2)), np.zeros((1, 1, 2))
    R = measurement_cov(uav_xy[0, 0], txy[0, 0], sensor)
    return P0, model, sensor, uav_xy, txy, R, _exact_one_step(P0, R, model.F, model.Q)


def test_minimal_case_exact_posterior_is_psd_and_filterpy_reproduces_it():
    """The oracle of the known failure below: the exact posterior is PSD (smallest
    eigenvalue ~1e-12 > 0) with trace 0.039878, and the simulation's tracker (Joseph form)
    reproduces it within its a-priori rounding bound (5e-3 of the trace; observed: 1e-9)."""
    P0, model, _, _, _, R, exact = _minimal_case()
    assert np.linalg.eigvalsh(exact)[0] > 0
    assert np.trace(exact) == pytest.approx(0.039878, rel=1e-4)
    F, Q = model.F, model.Q
    trk = Tracker(np.zeros(4), P0, model)
    trk.predict()
    prior = trk.P
    pred_err = norm2(20 * U * (np.abs(F) @ np.abs(P0) @ np.abs(F).T + np.abs(Q)))
    trk.update(np.zeros(2), R)
    eps, E = joseph_bound(prior, R)
    bound = eps + norm2(E) ** 2 * pred_err  # the prediction's error, through E dP E^T
    np.testing.assert_allclose(trk.P, exact, rtol=0, atol=bound)


def test_kernel_posterior_psd_relative_to_its_own_scale():
    """Regression test of a defect these properties found (see ``_minimal_case``). With the
    update evaluated as A+ = A- - A- S^-1 A-, both kernels returned trace -0.2726 (the
    planner's cost of this step was negative) and a posterior with eigenvalue -0.33 against
    a largest of 0.02, where the exact trace is 0.039878: an error of 0.3, within the
    a-priori bound U C_OPS kappa(S) ||P-|| (kappa(S) ~ 1e8, ||P-|| ~ 1e8) of that form.
    The kernels now evaluate A+ = R S^-1 A- and B+ = R S^-1 B- (equal, as S - A- = R),
    which has no cancellation. Thresholds: 1e-6 relative; the problem itself is well
    conditioned (one-ulp changes of P0 and R move the exact posterior by < 1e-10
    relative), and filterpy's Joseph form meets 1e-6 with ~3 orders to spare."""
    P0, model, sensor, uav_xy, txy, _, exact = _minimal_case()
    traces, covs = kernel.covariance_traces(P0, uav_xy, txy, 1.0, model.Q, sensor, return_cov=True)
    fused_trace = fused.covariance_traces(P0, uav_xy, txy, 1.0, model.Q, sensor)[0, 0, 0]
    P = covs[0, 0, 0]
    assert np.linalg.eigvalsh(P)[0] >= -1e-6 * np.abs(P).max()
    assert traces[0, 0, 0] == pytest.approx(np.trace(exact), rel=1e-6)
    assert fused_trace == pytest.approx(np.trace(exact), rel=1e-6)


# --------------------------------------------------------------------------------------------
# 2. samplers


@st.composite
def cholesky_factors(draw, max_d=3) -> np.ndarray:
    """Random lower-triangular L with positive diagonal, entries over six decades."""
    d = draw(st.integers(1, max_d))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    L = np.tril(rng.standard_normal((d, d))) * draw(exp10(-3, 3))
    L[np.diag_indices(d)] = np.abs(L[np.diag_indices(d)]) + draw(exp10(-3, 0))
    return L


def check_rule(noise, weights, n, H, L, weight_roundings=1):
    """Shape (n, H, d), finite, weights >= 0 summing to 1: a sum of n non-negative terms
    rounds by <= n U, and each weight carries ``weight_roundings`` roundings of its own."""
    d = L.shape[0]
    assert noise.shape == (n, H, d) and weights.shape == (n,)
    assert np.all(np.isfinite(noise)) and np.all(weights >= 0)
    assert abs(weights.sum() - 1.0) <= 2 * (n + weight_roundings) * U


@settings(BASE, max_examples=100)
@given(
    L=cholesky_factors(),
    H=st.integers(1, 6),
    k=st.integers(1, 64),
    seed=st.integers(0, 2**32 - 1),
)
def test_stochastic_samplers_shapes_weights_and_antithetic_pairs(L, H, k, seed):
    rng = np.random.default_rng(seed)
    noise, w = designs.monte_carlo(rng, k, H, L)
    check_rule(noise, w, k, H, L)
    noise, w = designs.antithetic(rng, 2 * k, H, L)
    check_rule(noise, w, 2 * k, H, L)
    # pairs: L z and L (-z). Each entry is a d-term dot product, within d U (|L| |z|) of
    # exact, whichever BLAS path computes it; both: 2 d U (|L| |z|); z recovered by a solve
    # (to a relative ~kappa(L) U), another factor 2
    d = L.shape[0]
    z = np.linalg.solve(L, noise[:k].reshape(-1, d).T).T
    bound = 4 * d * U * (np.abs(z) @ np.abs(L).T).reshape(k, H, d)
    assert np.all(np.abs(noise[:k] + noise[k:]) <= bound)
    m = 2 ** (k % 7)
    noise, w = designs.sobol(rng, m, H, L)
    check_rule(noise, w, m, H, L)


def moments_exact(noise, w, L, tol_scale):
    """Weighted mean 0 and covariance I_H (x) L L^T, to tol_scale * ||L||_F^2."""
    n, H, d = noise.shape
    flat = noise.reshape(n, H * d)
    Sigma = L @ L.T
    scale = np.sum(L * L)
    mean = w @ flat
    cov = (flat * w[:, None]).T @ flat
    np.testing.assert_allclose(mean, 0.0, atol=tol_scale * math.sqrt(scale))
    np.testing.assert_allclose(cov, np.kron(np.eye(H), Sigma), rtol=0, atol=tol_scale * scale)


@settings(BASE, max_examples=100)
@given(L=cholesky_factors(), H=st.integers(1, 5), q=st.integers(1, 5))
def test_deterministic_rules_reproduce_the_first_two_moments(L, H, q):
    """Cubature (2D points) and Gauss-Hermite (q**D points) integrate every polynomial of
    degree <= 3 exactly; the computed moments carry rounding <= n_points U ||L||_F^2
    (n-term weighted sums of products), below 1e-12 here: 1e-10 is safe, and any
    structural error (a wrong node or weight) is O(1)."""
    d = L.shape[0]
    D = H * d
    noise, w = designs.cubature(H, L)
    check_rule(noise, w, 2 * D, H, L)
    moments_exact(noise, w, L, 1e-10)
    # symmetric points: odd moments vanish exactly in pairs
    np.testing.assert_array_equal(noise[:D], -noise[D:])
    q = min(q, designs.gauss_hermite_order(4096, D) or 1)
    noise, w = designs.gauss_hermite(q, H, L)
    # each weight: a product of D one-dimensional weights, each normalised by numpy and
    # divided by sqrt(2 pi): <= q + 4 roundings each
    check_rule(noise, w, q**D, H, L, weight_roundings=D * (q + 4))
    if q >= 2:  # q = 1 is the single node 0: exact for degree 1 only
        moments_exact(noise, w, L, 1e-10)
    if q >= 3:  # exact to degree 2q - 1 >= 5: the fourth moments too, E w^4 = 3 Sigma_kk^2
        var = np.tile(np.diag(L @ L.T), H)
        fourth = w @ noise.reshape(len(w), D) ** 4
        np.testing.assert_allclose(fourth, 3 * var**2, rtol=1e-10)


# --------------------------------------------------------------------------------------------
# 3. estimators


finite_ll = st.floats(allow_nan=False, allow_infinity=False)


# ll - max(ll) overflows to -inf for ranges beyond the float range: the right limit (weight
# 0), but numpy warns
@pytest.mark.filterwarnings("ignore:overflow encountered in subtract:RuntimeWarning")
@settings(BASE, max_examples=200)
@given(data=st.data(), n=st.integers(1, 60))
def test_weighted_estimate_is_a_convex_combination_for_any_log_likeliness(data, n):
    """Any finite log-likeliness (the full float range, so differences overflow to -inf),
    with -inf entries (zero likeliness) as long as one is finite: weights non-negative, no
    NaN, sum n (q / n sums to 1, relative rounding <= (n + 3) U), and the estimate within
    [min g, max g] up to the rounding of an n-term weighted mean, 2 (n + 3) U max |g|."""
    ll = np.array(data.draw(st.lists(finite_ll | st.just(-np.inf), min_size=n, max_size=n)))
    assume(np.isfinite(ll).any())
    g = np.array(data.draw(st.lists(st.floats(-1e300, 1e300), min_size=n, max_size=n)))
    q = likeliness_weights(ll)
    assert not np.isnan(q).any() and np.all(q >= 0)
    assert abs(q.sum() - n) <= 2 * (n + 3) * U * n
    assert np.all(q[ll == -np.inf] == 0)
    est = weighted_estimate(g, ll)
    slack = 2 * (n + 3) * U * np.abs(g).max()
    assert g.min() - slack <= est <= g.max() + slack
    uni = uniform_estimate(g)
    assert g.min() - slack <= uni <= g.max() + slack


@settings(BASE, max_examples=200)
@given(
    data=st.data(),
    n=st.integers(1, 60),
    shift=st.floats(-1e6, 1e6),
)
def test_weights_invariant_to_a_constant_log_likeliness_shift(data, n, shift):
    """q(ll + c) = q(ll), in float64 up to rounding: ll_i + c and the max subtraction move
    each exponent by <= Delta = 4 U (max |ll| + |c|), exp adds 2 U and the normalisation
    (n + 3) U, so every weight moves by a relative <= 2 (Delta + 2 U) + 2 (n + 3) U (both
    sides), or is below 1e-300 on both."""
    ll = np.array(data.draw(st.lists(st.floats(-1e4, 1e4), min_size=n, max_size=n)))
    g = np.array(data.draw(st.lists(st.floats(-1e6, 1e6), min_size=n, max_size=n)))
    q0, q1 = likeliness_weights(ll), likeliness_weights(ll + shift)
    rtol = 2 * (4 * U * (np.abs(ll).max() + abs(shift)) + 2 * U) + 2 * (n + 3) * U
    np.testing.assert_allclose(q1, q0, rtol=rtol, atol=n * 1e-300)
    e0, e1 = weighted_estimate(g, ll), weighted_estimate(g, ll + shift)
    assert abs(e1 - e0) <= (rtol + 4 * (n + 3) * U) * np.abs(g).max()
    # equal likeliness: the weighted estimate is the plain mean
    assert weighted_estimate(g, np.full(n, ll[0])) == pytest.approx(
        uniform_estimate(g), rel=0, abs=2 * (n + 3) * U * np.abs(g).max()
    )


@settings(BASE, max_examples=100)
@given(
    data=st.data(),
    n=st.integers(1, 40),
    offset=st.sampled_from([1e300, -1e300, 1.7e308, -1.7e308]),
)
def test_huge_log_likeliness_offsets_give_no_nan(data, n, offset):
    ll = offset + np.array(data.draw(st.lists(st.floats(-1e3, 1e3), min_size=n, max_size=n)))
    g = np.array(data.draw(st.lists(st.floats(0.0, 1e6), min_size=n, max_size=n)))
    q = likeliness_weights(ll)
    assert np.all(np.isfinite(q)) and np.all(q >= 0)
    assert abs(q.sum() - n) <= 2 * (n + 3) * U * n
    est = weighted_estimate(g, ll)
    assert np.isfinite(est) and g.min() * (1 - 2 * (n + 3) * U) <= est <= g.max() * (
        1 + 2 * (n + 3) * U
    )


# --------------------------------------------------------------------------------------------
# 3b. trajectory sampling


class _AbsSystem:
    """The system with every input replaced by its absolute value: its cost is the classic
    bound f_abs of forward error analysis, |fl(f) - f| <= gamma_depth f_abs for a polynomial
    f evaluated with + and * at operation depth ``depth``."""

    def __init__(self, sys: LinearQuadratic) -> None:
        self.A, self.B = np.abs(sys.A), np.abs(sys.B)
        self.Q, self.R, self.Qf = np.abs(sys.Q), np.abs(sys.R), np.abs(sys.Qf)
        self.t = np.abs(sys.target)
        self.noise = sys.noise

    def step(self, x, u_k, w):
        return x @ self.A.T + np.abs(np.asarray(u_k)) @ self.B.T + np.abs(w)

    def stage_cost(self, x, u_k):
        u_k = np.abs(np.asarray(u_k))
        return np.einsum("ni,ij,nj->n", x, self.Q, x) + float(u_k @ self.R @ u_k)

    def terminal_cost(self, x):
        e = x + self.t
        return np.einsum("ni,ij,nj->n", e, self.Qf, e)


@st.composite
def lq_systems(draw, max_h=4):
    """A random linear-quadratic system: d in 1..3, m in 1..2, H in 1..max_h."""
    d, m, H = draw(st.integers(1, 3)), draw(st.integers(1, 2)), draw(st.integers(1, max_h))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    L = np.tril(rng.standard_normal((d, d)))
    L[np.diag_indices(d)] = np.abs(L[np.diag_indices(d)]) + 0.1
    W, V = rng.standard_normal((d, d)), rng.standard_normal((d, d))
    return LinearQuadratic(
        A=rng.standard_normal((d, d)) * draw(st.floats(0.1, 1.5)) / math.sqrt(d),
        B=rng.standard_normal((d, m)),
        Sigma=L @ L.T * draw(exp10(-4, 2)),
        Q=W @ W.T,
        R=np.eye(m),
        Qf=V @ V.T,
        target=rng.standard_normal(d) * 10,
        x0=rng.standard_normal(d) * 10,
        u=rng.standard_normal((H, m)),
    )


def cost_bound(sys, noise):
    """2 gamma_n f_abs: two evaluations (different batch sizes may round the d-term matrix
    products differently), depth n <= H (2d + 2m + 2) + 2d + 2 + H + 1."""
    H, d, m = sys.H, sys.d, sys.B.shape[1]
    depth = H * (2 * d + 2 * m + 2) + 2 * d + 2 + H + 1
    f_abs = rollout_cost(_AbsSystem(sys), np.abs(sys.x0), sys.u, np.abs(noise))
    return 2 * depth * U / (1 - depth * U) * f_abs


@settings(BASE, max_examples=80)
@given(sys=lq_systems(), n=st.integers(1, 50), seed=st.integers(0, 2**32 - 1))
def test_rollout_cost_is_the_cost_of_rollout(sys, n, seed):
    noise, _ = designs.monte_carlo(np.random.default_rng(seed), n, sys.H, sys.noise.chol)
    traj = rollout(sys, sys.x0, sys.u, noise)
    np.testing.assert_array_equal(rollout_cost(sys, sys.x0, sys.u, noise), traj.cost)
    assert traj.states.shape == (n, sys.H + 1, sys.d)
    np.testing.assert_array_equal(traj.states[:, 0], np.broadcast_to(sys.x0, (n, sys.d)))
    assert np.all(np.isfinite(traj.cost)) and np.all(np.isfinite(traj.log_likeliness))
    ind = sample_independent(sys, sys.x0, sys.u, n, np.random.default_rng(seed))
    assert len(ind) == n and ind.noise.shape == (n, sys.H, sys.d)
    np.testing.assert_array_equal(ind.cost, rollout_cost(sys, sys.x0, sys.u, ind.noise))


@settings(BASE, max_examples=80)
@given(
    sys=lq_systems(),
    N=st.integers(1, 5),
    M=st.none() | st.integers(1, 200),
    shared=st.booleans(),
    seed=st.integers(0, 2**32 - 1),
)
def test_tree_leaf_count_and_leaf_costs(sys, N, M, shared, seed):
    """N**H leaves without pruning, min(M, N**H) with; every leaf's cost is the cost of its
    noise path (to the forward-error bound), the weighted estimate is within the leaves'
    cost range, and the log-likeliness is the sum of the path's log-densities."""
    tree = sample_tree(
        sys, sys.x0, sys.u, N, np.random.default_rng(seed), max_keep=M, shared_draws=shared
    )
    leaves = tree.leaves
    full = N**sys.H
    assert len(leaves) == (full if M is None else min(M, full))
    assert leaves.noise.shape == (len(leaves), sys.H, sys.d)
    replay = rollout_cost(sys, sys.x0, sys.u, leaves.noise)
    assert np.all(np.abs(replay - leaves.cost) <= cost_bound(sys, leaves.noise))
    # log-likeliness: sum over steps of log_norm - |y|^2 / 2 with L y = w. Evaluated in
    # batches of other sizes a solve may round differently: |y|^2 / 2 within (4 d kappa(L) +
    # 2 d) U of itself, log_norm exact, and the H-term sum within H U of the terms' sizes;
    # twice (two evaluations).
    steps = sys.noise.logpdf(leaves.noise)  # (n, H)
    quad = sys.noise.log_norm - steps  # |y|^2 / 2 >= 0
    kap = np.linalg.cond(sys.noise.chol)
    mag = (4 * sys.d * kap + 2 * sys.d + sys.H) * quad + sys.H * abs(sys.noise.log_norm)
    bound = 2 * U * mag.sum(axis=1)
    assert np.all(np.abs(steps.sum(axis=1) - leaves.log_likeliness) <= bound)
    est = weighted_estimate(leaves.cost, leaves.log_likeliness)
    slack = 2 * (len(leaves) + 3) * U * np.abs(leaves.cost).max()
    assert leaves.cost.min() - slack <= est <= leaves.cost.max() + slack
