r"""RS-MHP with Latin-hypercube-stratified hypotheses: ``N_T`` futures whose standard-normal
coordinates are stratified per dimension.

A planning step of horizon H draws ``N_T`` points of a Latin hypercube in :math:`[0,
1)^{4(H+1)}` (:class:`scipy.stats.qmc.LatinHypercube`, randomised: each point uniform within
its cell): in every dimension the ``N_T`` values fall one in each stratum :math:`[k/N_T,
(k+1)/N_T)`, the strata of the dimensions paired by independent random permutations. The
normal quantile :math:`\Phi^{-1}` maps them to standard normals ``z`` (N_T, H + 1, 4), and
:func:`rsmhp.models.uav.target.from_normals` to the initial deviation :math:`L_P z_0` and the
H process noises :math:`L_Q z_j` (:func:`rsmhp.models.uav.methods.base.from_design`, as the
built-in RQMC family does); weights :math:`1/N_T`.

Each hypothesis is marginally an exact draw of the belief's future, so the cost estimate is
unbiased, as plain Monte Carlo's (``rsmhp_nt<N_T>``); the stratification removes the
one-dimensional (additive) part of its variance (McKay, Beckman & Conover 1979; Stein 1987),
and its variance is never more than :math:`N_T/(N_T-1)` times Monte Carlo's (Owen 1997). Unlike
scrambled Sobol' points (``rqmc_nt``), any ``N_T`` is allowed.

The random numbers come from the step's own stream (the ``rng`` the closed loop keys on the
run, the step and :meth:`Method.job_key`: the name and ``N_T``), so the family's draws are
reproducible and independent of every other method's. Config: ``lhs_nt: [16, 64]``, one
method per ``N_T``, named ``lhs_nt<N_T>``, labelled ``LHS N_T=<N_T>``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from rsmhp.core import guards
from rsmhp.models.uav.methods import register
from rsmhp.models.uav.methods.base import Hypotheses, NTrajMethod, from_design
from rsmhp.models.uav.planner import Belief

__all__ = ["Stratified", "latin_hypercube", "lhs_design"]

#: the quantile's guard: no stratum is moved (1e-15 < 1/N_T for every allowed N_T)
_EPS = 1e-15


def latin_hypercube(rng: np.random.Generator, n: int, d: int) -> np.ndarray:
    """``n`` points of a randomised Latin hypercube in :math:`[0, 1)^d` (n, d), drawn from
    ``rng``: column ``j`` holds one value in each stratum :math:`[k/n, (k+1)/n)`."""
    n = guards.positive_int("n", n)
    d = guards.positive_int("d", d)
    guards.generator("rng", rng)
    # scipy.stats is imported when first used: the registry imports every plugin in every job
    from scipy.stats import qmc

    return qmc.LatinHypercube(d=d, scramble=True, rng=rng).random(n)


def lhs_design(
    rng: np.random.Generator, n: int, H: int, chol: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A design in the convention of :mod:`rsmhp.core.designs`: ``n`` Latin-hypercube points
    in :math:`[0, 1)^{H d}` through :math:`\\Phi^{-1}`, reshaped to (n, H, d) and mapped by
    the square root ``chol`` (d, d); weights ``1/n``."""
    chol = np.asarray(chol, dtype=float)
    d = chol.shape[0]
    u = latin_hypercube(rng, n, H * d)
    from scipy import special

    z = special.ndtri(np.clip(u, _EPS, 1.0 - _EPS))  # the normal quantile, Phi^-1
    return z.reshape(n, H, d) @ chol.T, np.full(n, 1.0 / n)


@register
@dataclass(frozen=True)
class Stratified(NTrajMethod):
    """RS-MHP with ``n_traj`` = N_T Latin-hypercube-stratified hypotheses.

    An :class:`NTrajMethod` (members are values of N_T): from its ``family`` it takes the
    config key ``lhs_nt``, the names ``lhs_nt<N_T>`` and their pattern, and the labels
    ``LHS N_T=<N_T>``; it reads a config list of N_T (positive ints) with ``from_config``."""

    family: ClassVar[str] = "lhs"
    schema: ClassVar[dict[str, Any]] = {
        "description": "N_T values of RS-MHP with Latin-hypercube-stratified hypotheses.",
        "type": "array",
        "maxItems": 20,
        "uniqueItems": True,
        "items": {"type": "integer", "minimum": 1, "maximum": 100000},
    }
    #: no member unless configured: installing the plugin changes no existing run
    default: ClassVar[Any] = []
    family_label: ClassVar[str] = "LHS"
    colour_key: ClassVar[str] = "#4d7c0f"  # olive: a colour rsmhp's palette does not use
    order: ClassVar[int] = 7  # after the built-in families

    def hypotheses(self, belief: Belief, setup: Any, rng: np.random.Generator) -> Hypotheses:
        return from_design(belief, setup, lhs_design, rng, self.n_traj)
