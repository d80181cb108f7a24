r"""NBO (nominal belief-state optimisation): one hypothesis, the noise-free prediction
:math:`x_j = F^j \hat x` (:func:`rsmhp.models.uav.target.nominal`), weight 1. The baseline of every
comparison. Config: ``nbo: true``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from rsmhp.models.uav import target
from rsmhp.models.uav.methods import register
from rsmhp.models.uav.methods.base import Hypotheses, OnOffMethod
from rsmhp.models.uav.planner import Belief

__all__ = ["NBO"]

_ONE = np.ones(1)
_ONE.flags.writeable = False


@register
@dataclass(frozen=True)
class NBO(OnOffMethod):
    """The nominal-belief planner (no fields)."""

    family: ClassVar[str] = "nbo"
    description: ClassVar[str] = "Run the NBO planner (the baseline of every comparison)."
    default: ClassVar[Any] = True
    family_label: ClassVar[str] = "NBO"
    order: ClassVar[int] = 0
    closed_loop: ClassVar[str] = "nominal"
    baseline: ClassVar[bool] = True
    uses_rng: ClassVar[bool] = False
    n_traj: ClassVar[int] = 1

    def hypotheses(self, belief: Belief, setup: Any, rng: np.random.Generator | None) -> Hypotheses:
        H = setup.planner.horizon
        states = target.nominal(belief.x_hat, H, setup.target, check=False)
        return Hypotheses(states, _ONE, np.zeros((1, H + 1, 4)), check=False)
