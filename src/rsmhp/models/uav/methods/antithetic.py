r"""RS-MHP with antithetic hypotheses: ``N_T/2`` independent standard-normal vectors
:math:`z \in \mathbb R^{4(H+1)}` and their negatives, mapped to the initial deviation and the H
process noises (:func:`rsmhp.models.uav.target.from_normals`); weights :math:`1/N_T`. Each
hypothesis
is marginally an exact draw (the cost estimate is unbiased); within a pair the parts of the
cost that are odd in the noise cancel exactly. ``N_T`` must be even. Config:
``antithetic_nt: [16, 32, 64, 128, 256]``, named ``antithetic_nt<N_T>``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from rsmhp.core import designs, guards
from rsmhp.models.uav.methods import register
from rsmhp.models.uav.methods.base import Hypotheses, NTrajMethod, from_design
from rsmhp.models.uav.planner import Belief

__all__ = ["Antithetic"]


@register
@dataclass(frozen=True)
class Antithetic(NTrajMethod):
    """Antithetic pairs, ``n_traj`` = N_T hypotheses (even)."""

    family: ClassVar[str] = "antithetic"
    schema: ClassVar[dict[str, Any]] = {
        "description": "N_T values (even) of RS-MHP with antithetic pairs of hypotheses.",
        "type": "array",
        "maxItems": 20,
        "uniqueItems": True,
        "items": {"type": "integer", "minimum": 2, "maximum": 100000, "multipleOf": 2},
    }
    default: ClassVar[Any] = []
    family_label: ClassVar[str] = "antithetic"
    order: ClassVar[int] = 4
    closed_loop: ClassVar[str] = "drawn"

    @classmethod
    def check_n_traj(cls, name: str, value: Any) -> int:
        n = guards.integer(name, value, minimum=2)
        if n % 2:
            raise ValueError(f"{name} must be even (pairs z, -z), got {n}")
        return n

    def hypotheses(self, belief: Belief, setup: Any, rng: np.random.Generator) -> Hypotheses:
        return from_design(belief, setup, designs.antithetic, rng, self.n_traj)
