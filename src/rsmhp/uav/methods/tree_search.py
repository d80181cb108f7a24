r"""Tree search with double progressive widening (PFT-DPW over Kalman beliefs,
:mod:`rsmhp.uav.dpw`): the belief-space planner of the continuous-POMDP literature, against
which the paper's sampled-cost planners are compared at equal compute. Unlike them it plans
over the tracker's own future beliefs (random detections and measurements, R at the estimate)
and its controls come from sampled actions rather than a gradient-based optimiser; its
budget is ``sims`` simulations per planning step. Config: ``dpw: [{sims: 200}, {sims:
1000}]``, named ``dpw_s<sims>``.

Search constants, chosen before any run and not tuned on our results: UCB constant
:data:`C_UCB` = 0.5 on per-step rewards normalised by the root's :math:`\mathrm{tr}\,\hat
P`, action widening :data:`K_A` = 4, :data:`ALPHA_A` = 0.25, observation widening
:data:`K_O` = 4, :data:`ALPHA_O` = 0.25.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from rsmhp import guards
from rsmhp.palette import METHOD_COLOURS
from rsmhp.uav import dpw, kinematics
from rsmhp.uav.methods import register
from rsmhp.uav.methods.base import Hypotheses, Method
from rsmhp.uav.planner import Belief, PlanResult
from rsmhp.uav.stepper import Stepper

__all__ = ["ALPHA_A", "ALPHA_O", "C_UCB", "K_A", "K_O", "TreeSearch", "TreeSearchPlanner"]

C_UCB = 0.5
K_A = 4.0
ALPHA_A = 0.25
K_O = 4.0
ALPHA_O = 0.25


class TreeSearchPlanner:
    """The :class:`rsmhp.uav.planner.Planner` of a tree-search member: ``plan(belief,
    warm_start (H, 2), rng)`` runs ``sims`` simulations of :func:`rsmhp.uav.dpw.search` and
    returns the most visited path's controls (H, 2), the search's estimate of their expected
    cost, ``nit`` = simulations, ``n_kernel_calls`` = belief nodes created, the planned UAV
    states and no hypotheses."""

    def __init__(self, sims: int, setup: Any) -> None:
        self.sims = guards.positive_int("sims", sims)
        self.setup = setup
        self.stepper = Stepper(setup.uav, setup.target, setup.sensor)
        self.scale = np.asarray(setup.uav.control_scale, dtype=float)

    def plan(self, belief: Belief, warm_start: np.ndarray, rng: np.random.Generator) -> PlanResult:
        warm = np.clip(np.asarray(warm_start, dtype=float) / self.scale, -1.0, 1.0)
        x, cost, n_b, n_a, n_root, n_chosen, best = dpw.search(
            belief.uav,
            belief.x_hat,
            belief.P_hat,
            warm,
            self.scale,
            self.sims,
            (C_UCB, K_A, ALPHA_A, K_O, ALPHA_O),
            self.stepper,
            rng,
        )
        controls = x * self.scale
        state = np.asarray(belief.uav, dtype=float)
        path = np.empty((controls.shape[0], 4))
        for j, u in enumerate(controls):
            state = kinematics.step(state, u, self.setup.uav)
            path[j] = state
        return PlanResult(
            controls=controls,
            cost=float(cost),
            cost_warm=float("nan"),
            nit=self.sims,
            n_kernel_calls=int(n_b),
            uav_path=path,
            hypotheses=None,
            diagnostics={
                "action_nodes": float(n_a),
                "root_actions": float(n_root),
                "chosen_visits": float(n_chosen),
                "best_root_cost": float(best),
            },
        )


@register
@dataclass(frozen=True)
class TreeSearch(Method):
    """PFT-DPW with ``sims`` simulations per planning step."""

    sims: int

    family: ClassVar[str] = "dpw"
    config_key: ClassVar[str] = "dpw"
    schema: ClassVar[dict[str, Any]] = {
        "description": "Tree-search planners (PFT-DPW over Kalman beliefs): simulations per step.",
        "type": "array",
        "maxItems": 10,
        "items": {
            "type": "object",
            "additionalProperties": False,
            "required": ["sims"],
            "properties": {"sims": {"type": "integer", "minimum": 1, "maximum": 1000000}},
        },
    }
    default: ClassVar[Any] = []
    family_label: ClassVar[str] = "tree search"
    colour: ClassVar[str] = METHOD_COLOURS["dpw"]
    order: ClassVar[int] = 6
    name_pattern: ClassVar[str] = r"dpw_s(\d+)"
    #: the tables' N_T: 0 (no fixed hypotheses; ``sims`` is the budget)
    n_traj: ClassVar[int] = 0
    estimates_cost: ClassVar[bool] = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "sims", guards.positive_int("sims", self.sims))

    @classmethod
    def from_config(cls, value: Any, path: str) -> list[Method]:
        guards.instance_of(path, value, (list, tuple))
        out: list[Method] = []
        for i, t in enumerate(value):
            guards.instance_of(f"{path}[{i}]", t, dict)
            out.append(cls(guards.positive_int(f"{path}[{i}].sims", t["sims"])))
        return out

    @property
    def name(self) -> str:
        return f"dpw_s{self.sims}"

    def label(self) -> str:
        return f"tree search {self.sims} sims"

    def job_key(self) -> dict[str, Any]:
        return {"method": self.name, "N_T": 0, "N": None, "M": None}

    def sort_key(self) -> tuple:
        return (self.order, self.sims, 0, 0, self.name)

    def hypotheses(self, belief: Belief, setup: Any, rng: np.random.Generator) -> Hypotheses:
        raise NotImplementedError(
            "a tree search plans over simulated beliefs, not over a fixed set of hypotheses"
        )

    def planner(self, setup: Any) -> TreeSearchPlanner:
        return TreeSearchPlanner(self.sims, setup)
