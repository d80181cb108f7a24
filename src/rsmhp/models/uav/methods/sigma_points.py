r"""RS-MHP over sigma points: the spherical-radial cubature set of the joint Gaussian of the
planning step's uncertainty, :math:`(x_0 - \hat x, w_1, \dots, w_H) \sim \mathcal N(0,
\mathrm{diag}(\hat P, Q, \dots, Q))` of dimension :math:`n = 4(H+1)`: the :math:`2n` points
:math:`\pm\sqrt n\, e_k` in standard-normal coordinates, mapped by
:func:`rsmhp.models.uav.target.from_normals`, each of weight :math:`1/(2n)` (the unscented transform
with :math:`\kappa = 0`; all weights positive). The weighted mean of the points is 0 and their
weighted covariance the identity, so the hypotheses' initial states and process noises have
exactly the belief's mean and covariance, and every target state :math:`x_j` (linear in them)
too. Deterministic: no random numbers. 56 hypotheses at the paper's H = 6 (the number follows
the horizon; the tables' ``N_T`` column holds ``0`` for it). Config: ``sigma: true``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from rsmhp.core import designs, guards
from rsmhp.models.uav.methods import register
from rsmhp.models.uav.methods.base import Hypotheses, OnOffMethod, from_design
from rsmhp.models.uav.planner import Belief

__all__ = ["SigmaPoints", "n_points"]


def n_points(horizon: int) -> int:
    """The number of sigma points at ``horizon``: :math:`2 \\cdot 4 (H + 1)`."""
    return 8 * (guards.positive_int("horizon", horizon) + 1)


@register
@dataclass(frozen=True)
class SigmaPoints(OnOffMethod):
    """The cubature sigma points of the joint belief (no fields)."""

    family: ClassVar[str] = "sigma"
    description: ClassVar[str] = (
        "Run RS-MHP over the 8(H+1) cubature sigma points of the joint belief."
    )
    default: ClassVar[Any] = False
    family_label: ClassVar[str] = "sigma points"
    colour_key: ClassVar[str] = "cubature"
    order: ClassVar[int] = 5
    closed_loop: ClassVar[str] = "drawn"
    uses_rng: ClassVar[bool] = False
    #: the tables' N_T: 0, "set by the horizon" (n_points(H) hypotheses)
    n_traj: ClassVar[int] = 0

    def hypotheses(self, belief: Belief, setup: Any, rng: np.random.Generator | None) -> Hypotheses:
        return from_design(belief, setup, designs.cubature)
