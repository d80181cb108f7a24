r"""Noise designs on a fixed budget of ``n`` trajectories, beyond the paper's plain Monte Carlo.

Every design returns ``(noise, weights)``: noise sequences of shape ``(n, H, d)`` for
:func:`rsmhp.core.sampling.rollout` and weights (summing to 1) for the cost average
:math:`\hat J = \sum_i \omega_i g_i`. The stacked noise :math:`w \in \mathbb R^{D}`,
:math:`D = Hd`, is :math:`\mathcal N(0, I_H \otimes \Sigma)`; with :math:`L L^\top = \Sigma`
each design produces standard normal :math:`z` and maps :math:`w_k = L z_k`.

* ``mc``            i.i.d. draws, :math:`\omega_i = 1/n` (the paper's non-overlapping MHP).
* ``antithetic``    :math:`n/2` draws and their negatives; unbiased, and for a quadratic cost
  the linear part cancels exactly within each pair.
* ``sobol``         scrambled Sobol' points (randomized QMC, :mod:`scipy.stats.qmc`), mapped
  through the normal quantile; unbiased, error :math:`O(n^{-1+\epsilon})` for smooth costs.
* ``cubature``      the :math:`2D` symmetric sigma points :math:`\pm\sqrt{D}\,e_j` (unscented /
  spherical-radial cubature, :math:`\kappa = 0`), :math:`\omega = 1/(2D)`; exact for every
  polynomial of degree <= 3, hence for the quadratic costs here. Deterministic.
* ``gauss_hermite`` tensor Gauss-Hermite rule with ``q`` nodes per dimension (:math:`q^D`
  points, probabilists' Hermite), exact to degree :math:`2q-1` per coordinate. Deterministic.
"""

from __future__ import annotations

import functools

import numpy as np
from numba import njit
from numpy.polynomial.hermite_e import hermegauss

from rsmhp.core import guards

__all__ = [
    "DETERMINISTIC",
    "STOCHASTIC",
    "antithetic",
    "cubature",
    "gauss_hermite",
    "gauss_hermite_order",
    "monte_carlo",
    "sobol",
    "sobol_points",
    "warm_up",
]

STOCHASTIC = ("mc", "antithetic", "sobol")
DETERMINISTIC = ("cubature", "gauss_hermite")


def _shape(z: np.ndarray, H: int, chol: np.ndarray) -> np.ndarray:
    """``z`` (n, H d) -> (n, H, d), :math:`w_k = L z_k`. For d = 1 an elementwise product
    (the same single rounding as the 1x1 matrix product, and much faster)."""
    d = chol.shape[0]
    if d == 1:
        return z.reshape(z.shape[0], H, 1) * chol[0, 0]
    return z.reshape(z.shape[0], H, d) @ chol.T


def _check(H: int, chol: np.ndarray) -> tuple[int, np.ndarray]:
    """The arguments every sampler shares: horizon ``H`` >= 1 and a finite square ``chol``
    (d, d), d >= 1 (a square root of the noise covariance). Returns ``(H, chol)`` (a float
    ndarray ``chol`` is returned as is)."""
    H = guards.positive_int("H", H)
    c = guards.finite_array("chol", chol, shape=("d", "d"), nonempty=True)
    if c.shape[0] != c.shape[1]:
        raise ValueError(f"chol must be a square (d, d) matrix, got shape {c.shape}")
    return H, c


def monte_carlo(rng: np.random.Generator, n: int, H: int, chol: np.ndarray):
    """``n`` i.i.d. sequences, uniform weights."""
    n = guards.positive_int("n", n)
    H, chol = _check(H, chol)
    guards.generator("rng", rng)
    z = rng.standard_normal((n, H * chol.shape[0]))
    return _shape(z, H, chol), np.full(n, 1.0 / n)


def antithetic(rng: np.random.Generator, n: int, H: int, chol: np.ndarray):
    """``n/2`` i.i.d. sequences followed by their negatives, uniform weights (``n`` even)."""
    n = guards.integer("n", n, minimum=2)
    if n % 2:
        raise ValueError(f"antithetic sampling needs an even n >= 2, got {n}")
    H, chol = _check(H, chol)
    guards.generator("rng", rng)
    z = rng.standard_normal((n // 2, H * chol.shape[0]))
    return _shape(np.concatenate([z, -z]), H, chol), np.full(n, 1.0 / n)


#: bits of scipy's Sobol' integers (its default)
SOBOL_BITS = 30
#: scipy's largest Sobol' dimension, ``qmc.Sobol.MAXDIM`` (tested equal)
SOBOL_MAXDIM = 21201


@functools.cache
def _direction_numbers(d: int) -> np.ndarray:
    """scipy's unscrambled Sobol' direction numbers (d, 30) as int64, read-only."""
    from scipy.stats import qmc  # here, not at import: scipy.stats costs every job ~0.4 s

    sv = np.asarray(qmc.Sobol(d, scramble=False)._sv, dtype=np.int64)
    sv.flags.writeable = False
    return sv


@njit(cache=True, nogil=True)
def _parity(x):  # pragma: no cover - compiled
    """Parity of the set bits of a non-negative int64."""
    x ^= x >> 32
    x ^= x >> 16
    x ^= x >> 8
    x ^= x >> 4
    x ^= x >> 2
    x ^= x >> 1
    return x & 1


@njit(cache=True, nogil=True)
def _scrambled_points(sv, ltm, shift, n):  # pragma: no cover - compiled
    """Linear matrix scramble of the direction numbers ``sv`` (d, b) by the lower-triangular
    bit matrices ``ltm`` (d, b, b) (entries above the diagonal ignored, diagonal taken as 1),
    then the first ``n`` points of the Gray-code sequence started at ``shift`` (d,), times
    2^-b: (n, d). The arithmetic of scipy's ``_cscramble`` and ``_draw`` (bit ``b-1-p`` of a
    scrambled direction number is the parity of row ``p`` AND the number), with each row
    packed into one integer so that a number costs b parities instead of b^2 bit products."""
    d, b = sv.shape
    rows = np.empty(b, np.int64)
    v = np.empty((d, b), np.int64)
    for k in range(d):
        for p in range(b):
            z = np.int64(0)
            for i in range(b):
                if i == p or (i < p and ltm[k, p, i] != 0):
                    z |= np.int64(1) << (b - 1 - i)
            rows[p] = z
        for j in range(b):
            t = np.int64(0)
            for p in range(b):
                t |= _parity(rows[p] & sv[k, j]) << (b - 1 - p)
            v[k, j] = t
    scale = 1.0 / (np.int64(1) << b)
    out = np.empty((n, d))
    quasi = shift.copy()
    for j in range(d):
        out[0, j] = quasi[j] * scale
    for i in range(1, n):
        g = i - 1  # position of the lowest zero bit of i - 1 (Gray-code step)
        pos = 0
        while g & 1:
            g >>= 1
            pos += 1
        for j in range(d):
            quasi[j] ^= v[j, pos]
            out[i, j] = quasi[j] * scale
    return out


def sobol_points(rng: np.random.Generator, n: int, d: int) -> np.ndarray:
    """The first ``n`` points of a Sobol' sequence in [0, 1)^d with scipy's linear matrix
    scramble and digital shift drawn from ``rng``: the same numbers, bit for bit, as
    ``qmc.Sobol(d, scramble=True, rng=rng).random(n)`` (tested), about 5x faster at d = 28
    (scipy spends most of a fresh scramble in a bit-by-bit matrix product)."""
    n = guards.positive_int("n", n)
    d = guards.positive_int("d", d)
    guards.generator("rng", rng)
    if d > SOBOL_MAXDIM:
        raise ValueError(f"Sobol' points: d must be at most {SOBOL_MAXDIM}, got {d}")
    b = SOBOL_BITS
    if n > 2**b:
        raise ValueError(f"Sobol' points: at most 2^{b} points, got n = {n}")
    # scipy's draws: a child generator spawned from rng's seed sequence (rng's own stream is
    # not advanced), then the shift's bits, then the matrices' bits
    rng = rng.spawn(1)[0]
    shift = rng.integers(2, size=(d, b), dtype=np.uint32).astype(np.int64) @ (
        np.int64(1) << np.arange(b, dtype=np.int64)
    )
    ltm = rng.integers(2, size=(d, b, b), dtype=np.uint32)
    return _scrambled_points(_direction_numbers(d), ltm, shift, n)


def sobol(rng: np.random.Generator, n: int, H: int, chol: np.ndarray):
    """The first ``n`` points of a scrambled Sobol' sequence (``n`` a power of 2 keeps its
    balance properties; :func:`sobol_points`), mapped to normals by :math:`\\Phi^{-1}`;
    uniform weights."""
    n = guards.positive_int("n", n)
    if n & (n - 1):
        raise ValueError(f"Sobol' sampling needs n a power of 2, got {n}")
    H, chol = _check(H, chol)
    guards.generator("rng", rng)
    D = H * chol.shape[0]
    u = sobol_points(rng, n, D)
    # scrambled points never hit 0 or 1 exactly, but guard the quantile anyway
    from scipy import special

    z = special.ndtri(np.clip(u, 1e-15, 1 - 1e-15))  # the normal quantile, Phi^-1
    return _shape(z, H, chol), np.full(n, 1.0 / n)


def cubature(H: int, chol: np.ndarray):
    """The ``2D`` points :math:`\\pm\\sqrt{D} e_j`, weights ``1/(2D)`` (deterministic)."""
    H, chol = _check(H, chol)
    D = H * chol.shape[0]
    eye = np.sqrt(D) * np.eye(D)
    return _shape(np.concatenate([eye, -eye]), H, chol), np.full(2 * D, 1.0 / (2 * D))


def gauss_hermite_order(n: int, D: int) -> int:
    """Largest nodes-per-dimension ``q`` with ``q**D <= n`` (0 if even q = 2 does not fit)."""
    n = guards.positive_int("n", n)
    D = guards.positive_int("D", D)
    q = int(np.floor(n ** (1.0 / D) + 1e-9))
    while q**D > n:
        q -= 1
    return q if q >= 2 else 0


def gauss_hermite(q: int, H: int, chol: np.ndarray):
    """Tensor Gauss-Hermite rule, ``q`` nodes per dimension, ``q**D`` points (deterministic)."""
    q = guards.positive_int("q (Gauss-Hermite nodes per dimension)", q)
    H, chol = _check(H, chol)
    D = H * chol.shape[0]
    x, w = hermegauss(q)
    w = w / np.sqrt(2 * np.pi)
    grids = np.meshgrid(*([x] * D), indexing="ij")
    z = np.stack([g.ravel() for g in grids], axis=1)
    wts = np.prod(np.meshgrid(*([w] * D), indexing="ij"), axis=0).ravel()
    return _shape(z, H, chol), wts


def warm_up() -> float:
    """Compile (or load from the cache) the scrambled Sobol' kernel; returns the seconds it
    took."""
    import time

    t0 = time.perf_counter()
    sobol_points(np.random.default_rng(0), 2, 2)
    return time.perf_counter() - t0
