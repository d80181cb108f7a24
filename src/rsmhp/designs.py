r"""Noise designs on a fixed budget of ``n`` trajectories, beyond the paper's plain Monte Carlo.

Every design returns ``(noise, weights)``: noise sequences of shape ``(n, H, d)`` for
:func:`rsmhp.sampling.rollout` and weights (summing to 1) for the cost average
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

import numpy as np
from numpy.polynomial.hermite_e import hermegauss
from scipy import special
from scipy.stats import qmc

from rsmhp import guards

__all__ = [
    "DETERMINISTIC",
    "STOCHASTIC",
    "antithetic",
    "cubature",
    "gauss_hermite",
    "gauss_hermite_order",
    "monte_carlo",
    "sobol",
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


def sobol(rng: np.random.Generator, n: int, H: int, chol: np.ndarray):
    """The first ``n`` points of a scrambled Sobol' sequence (``n`` a power of 2 keeps its
    balance properties), mapped to normals by :math:`\\Phi^{-1}`; uniform weights."""
    n = guards.positive_int("n", n)
    if n & (n - 1):
        raise ValueError(f"Sobol' sampling needs n a power of 2, got {n}")
    H, chol = _check(H, chol)
    guards.generator("rng", rng)
    D = H * chol.shape[0]
    engine = qmc.Sobol(d=D, scramble=True, rng=rng)
    u = engine.random(n)
    # scrambled points never hit 0 or 1 exactly, but guard the quantile anyway
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
