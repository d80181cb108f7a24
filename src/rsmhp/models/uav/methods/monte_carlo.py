r"""RS-MHP with non-overlapping trajectories (plain Monte Carlo): ``N_T`` independent futures,
:math:`x_0^i \sim \mathcal N(\hat x, \hat P)`, :math:`x_j^i = F x_{j-1}^i + w_j^i`, each of
weight :math:`1/N_T` (:func:`rsmhp.models.uav.target.draw_independent`). Config: ``rsmhp_nt: [50,
100, 250]``, one method per N_T, named ``rsmhp_nt<N_T>``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from rsmhp.models.uav import target
from rsmhp.models.uav.methods import register
from rsmhp.models.uav.methods.base import Hypotheses, NTrajMethod
from rsmhp.models.uav.planner import Belief

__all__ = ["MonteCarlo"]


@register
@dataclass(frozen=True)
class MonteCarlo(NTrajMethod):
    """RS-MHP with ``n_traj`` = N_T independent hypotheses."""

    family: ClassVar[str] = "rsmhp"
    schema: ClassVar[dict[str, Any]] = {
        "description": "N_T values of non-overlapping RS-MHP (independent hypotheses).",
        "type": "array",
        "maxItems": 20,
        "uniqueItems": True,
        "items": {"type": "integer", "minimum": 1, "maximum": 100000},
    }
    default: ClassVar[Any] = []
    family_label: ClassVar[str] = "RS-MHP"
    order: ClassVar[int] = 1
    closed_loop: ClassVar[str] = "drawn"

    def hypotheses(self, belief: Belief, setup: Any, rng: np.random.Generator) -> Hypotheses:
        states, noise = target.draw_independent(
            belief.x_hat,
            belief.P_hat,
            setup.planner.horizon,
            self.n_traj,
            setup.target,
            rng,
            check=False,
        )
        return Hypotheses.equal(states, noise, check=False)
