r"""RS-MHP whose number of independent futures grows with the horizon: :math:`N_T = k H` for a
configured :math:`k` (hypotheses per planning step), otherwise plain Monte Carlo
(:mod:`rsmhp.models.uav.methods.monte_carlo`, :func:`rsmhp.models.uav.target.draw_independent`,
weights
:math:`1/N_T`).

A fixed :math:`N_T` spreads the same number of futures over a longer window as H grows; this
member keeps the futures per step constant, so the cost of one cost evaluation grows like
:math:`H^2` (N_T futures of H steps) instead of H. Config: ``rsmhp_nt_per_step: [16]``, one
method per k, named ``rsmhp_nt<k>h`` (16 hypotheses per step: 96 at H = 6, 384 at H = 24);
the tables' ``N_T`` column holds ``0`` ("set by the horizon", like the sigma points)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from rsmhp.core import guards
from rsmhp.models.uav import target
from rsmhp.models.uav.methods import register
from rsmhp.models.uav.methods.base import Hypotheses, Method
from rsmhp.models.uav.planner import Belief

__all__ = ["MonteCarloPerStep"]


@register
@dataclass(frozen=True)
class MonteCarloPerStep(Method):
    """RS-MHP with :math:`N_T = k H` independent hypotheses, ``per_step`` = k."""

    per_step: int

    family: ClassVar[str] = "rsmhp_per_step"
    config_key: ClassVar[str] = "rsmhp_nt_per_step"
    schema: ClassVar[dict[str, Any]] = {
        "description": (
            "Hypotheses per planning step k of RS-MHP with N_T = k H independent hypotheses "
            "(N_T grows with the horizon)."
        ),
        "type": "array",
        "maxItems": 10,
        "uniqueItems": True,
        "items": {"type": "integer", "minimum": 1, "maximum": 10000},
    }
    default: ClassVar[Any] = []
    family_label: ClassVar[str] = "RS-MHP N_T ∝ H"
    order: ClassVar[int] = 1
    closed_loop: ClassVar[str] = "drawn"
    name_pattern: ClassVar[str] = r"rsmhp_nt(\d+)h"
    #: the tables' N_T: 0, "set by the horizon" (n_traj_at(H) hypotheses)
    n_traj: ClassVar[int] = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "per_step", guards.positive_int("per_step (k)", self.per_step))

    @classmethod
    def from_config(cls, value: Any, path: str) -> list[Method]:
        guards.instance_of(path, value, (list, tuple))
        return [cls(guards.positive_int(f"{path}[{i}]", k)) for i, k in enumerate(value)]

    @property
    def name(self) -> str:
        return f"rsmhp_nt{self.per_step}h"

    def label(self) -> str:
        return f"RS-MHP N_T={self.per_step}H"

    def job_key(self) -> dict[str, Any]:
        return {"method": self.name, "N_T": None, "N": None, "M": None, "per_step": self.per_step}

    def sort_key(self) -> tuple:
        # after every fixed-N_T member of the Monte-Carlo family (same order)
        return (self.order, np.inf, self.per_step, 0, self.name)

    def n_traj_at(self, horizon: int) -> int:
        """:math:`N_T = k H` at ``horizon``."""
        return self.per_step * guards.positive_int("horizon", horizon)

    def hypotheses(self, belief: Belief, setup: Any, rng: np.random.Generator) -> Hypotheses:
        H = setup.planner.horizon
        states, noise = target.draw_independent(
            belief.x_hat, belief.P_hat, H, self.per_step * H, setup.target, rng, check=False
        )
        return Hypotheses.equal(states, noise, check=False)
