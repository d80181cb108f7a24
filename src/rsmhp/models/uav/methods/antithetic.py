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
from rsmhp.models.uav.methods.base import Hypotheses, Method, from_design
from rsmhp.models.uav.planner import Belief

__all__ = ["Antithetic"]


def _even(name: str, value: Any) -> int:
    n = guards.integer(name, value, minimum=2)
    if n % 2:
        raise ValueError(f"{name} must be even (pairs z, -z), got {n}")
    return n


@register
@dataclass(frozen=True)
class Antithetic(Method):
    """Antithetic pairs, ``n_traj`` = N_T hypotheses (even)."""

    n_traj: int

    family: ClassVar[str] = "antithetic"
    config_key: ClassVar[str] = "antithetic_nt"
    schema: ClassVar[dict[str, Any]] = {
        "description": "N_T values (even) of RS-MHP with antithetic pairs of hypotheses.",
        "type": "array",
        "maxItems": 20,
        "uniqueItems": True,
        "items": {"type": "integer", "minimum": 2, "maximum": 100000, "multipleOf": 2},
    }
    default: ClassVar[Any] = []
    family_label: ClassVar[str] = "antithetic"
    colour_key: ClassVar[str] = "antithetic"
    order: ClassVar[int] = 4
    closed_loop: ClassVar[str] = "drawn"
    name_pattern: ClassVar[str] = r"antithetic_nt(\d+)"

    def __post_init__(self) -> None:
        object.__setattr__(self, "n_traj", _even("n_traj (N_T)", self.n_traj))

    @classmethod
    def from_config(cls, value: Any, path: str) -> list[Method]:
        guards.instance_of(path, value, (list, tuple))
        return [cls(_even(f"{path}[{i}]", n)) for i, n in enumerate(value)]

    @property
    def name(self) -> str:
        return f"antithetic_nt{self.n_traj}"

    def label(self) -> str:
        return f"antithetic N_T={self.n_traj}"

    def shade_size(self) -> int:
        return self.n_traj

    def hypotheses(self, belief: Belief, setup: Any, rng: np.random.Generator) -> Hypotheses:
        return from_design(belief, setup, designs.antithetic, rng, self.n_traj)
