r"""RS-MHP with randomised quasi-Monte-Carlo hypotheses: the first ``N_T`` points of a Sobol'
sequence in :math:`[0, 1)^{4(H+1)}`, scrambled afresh at every planning step from the run's
random stream (scipy's linear matrix scramble and digital shift, computed by
:func:`rsmhp.core.designs.sobol_points` bit for bit as :class:`scipy.stats.qmc.Sobol` does, about
10x faster), mapped to standard normals by the quantile :math:`\Phi^{-1}` and then to the
initial deviation and the H process noises (:func:`rsmhp.models.uav.target.from_normals`); weights
:math:`1/N_T`. Each point is marginally an exact draw of the belief's future (the cost
estimate is unbiased), while the set fills the space more evenly than independent draws.
``N_T`` must be a power of 2 (the Sobol' balance property). Config: ``rqmc_nt: [16, 32, 64,
128, 256]``, one method per N_T, named ``rqmc_nt<N_T>``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from rsmhp.core import designs, guards
from rsmhp.models.uav.methods import register
from rsmhp.models.uav.methods.base import Hypotheses, NTrajMethod, from_design
from rsmhp.models.uav.planner import Belief

__all__ = ["RQMC"]


@register
@dataclass(frozen=True)
class RQMC(NTrajMethod):
    """Scrambled-Sobol' hypotheses, ``n_traj`` = N_T points (a power of 2)."""

    family: ClassVar[str] = "rqmc"
    schema: ClassVar[dict[str, Any]] = {
        "description": "N_T values (powers of 2) of RS-MHP with scrambled Sobol' hypotheses.",
        "type": "array",
        "maxItems": 20,
        "uniqueItems": True,
        "items": {"type": "integer", "minimum": 1, "maximum": 65536},
    }
    default: ClassVar[Any] = []
    family_label: ClassVar[str] = "RQMC"
    colour_key: ClassVar[str] = "sobol"
    order: ClassVar[int] = 3
    closed_loop: ClassVar[str] = "drawn"

    @classmethod
    def check_n_traj(cls, name: str, value: Any) -> int:
        n = guards.positive_int(name, value)
        if n & (n - 1):
            raise ValueError(f"{name} must be a power of 2 (Sobol' points), got {n}")
        return n

    @classmethod
    def config_problems(cls, value: Any, path: str, uav: Any) -> list[str]:
        return [
            f"{path}[{i}]: {n} is not a power of 2 (allowed: 1, 2, 4, ..., 65536; "
            "Sobol' points keep their balance only in powers of 2)"
            for i, n in enumerate(value or [])
            if isinstance(n, int) and n >= 1 and n & (n - 1)
        ]

    def hypotheses(self, belief: Belief, setup: Any, rng: np.random.Generator) -> Hypotheses:
        return from_design(belief, setup, designs.sobol, rng, self.n_traj)
