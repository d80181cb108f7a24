r"""The pursuit policy alone: no search and no optimisation, the baseline that shows what a
planner adds to "steer to the estimate and close the range". Its plan at a belief is the
pursuit policy :math:`\pi` (:mod:`rsmhp.models.uav.dpw`) on the nominal propagation from the
belief, :math:`u_j = \pi(s_j, \hat x_j)`, :math:`s_{j+1} = f(s_j, u_j)`,
:math:`\hat x_{j+1} = F \hat x_j` (:func:`rsmhp.models.uav.dpw.pursuit_plan`): exactly the tree
search's tail from its root, i.e. the tree search with no simulation. It ignores the warm
start and draws no random number. Config: ``pursuit: true``; member ``pursuit``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from rsmhp.models.uav import dpw, kinematics, target
from rsmhp.models.uav.methods import register
from rsmhp.models.uav.methods.base import Hypotheses, OnOffMethod
from rsmhp.models.uav.planner import Belief, PlanningProblem, PlanResult
from rsmhp.models.uav.stepper import Stepper

__all__ = ["Pursuit", "PursuitPlanner"]


class PursuitPlanner:
    r"""The :class:`rsmhp.models.uav.planner.Planner` of the pursuit policy: ``plan(belief,
    warm_start, rng)`` returns the pursuit plan (controls: the normalised plan of
    :func:`rsmhp.models.uav.dpw.pursuit_plan` times the control scale; ``warm_start`` and
    ``rng`` are not read), the planned UAV states, ``nit`` 0, ``converged`` ``None`` (no
    optimiser), no hypotheses, ``work`` = the H - 1 nominal propagations of the plan (model
    steps, :attr:`rsmhp.models.uav.dpw.SearchResult.work`) and ``diagnostics``
    ``{"plan_depth": 0.0, "tail_steps": H - 1}`` (the tree search's, with no tree).

    ``cost``: the policy estimates none; reported is the plan's cost under NBO's nominal
    hypothesis, :math:`\sum_{j=1}^H \mathrm{tr}\,P_j` with the target at
    :math:`F^j \hat x` (m², comparable with NBO's own ``cost``): one kernel call
    (``n_kernel_calls`` 1) of H model steps, not counted in ``work`` (the plan does not
    depend on it). ``cost_warm``: NaN (no warm start)."""

    def __init__(self, setup: Any) -> None:
        self.setup = setup
        self.stepper = Stepper(setup.uav, setup.target, setup.sensor)
        self.scale = np.asarray(setup.uav.control_scale, dtype=float)

    def plan(
        self, belief: Belief, warm_start: np.ndarray, rng: np.random.Generator | None
    ) -> PlanResult:
        setup = self.setup
        H = setup.planner.horizon
        r = dpw.pursuit_search(belief.uav, belief.x_hat, belief.P_hat, self.stepper, self.scale, H)
        controls = r.plan * self.scale
        state = np.asarray(belief.uav, dtype=float)
        path = np.empty((H, 4))
        for j, u in enumerate(controls):
            state = kinematics.step(state, u, setup.uav)
            path[j] = state
        nominal = target.nominal(belief.x_hat, H, setup.target, check=False)
        problem = PlanningProblem(
            belief.uav, belief.P_hat, nominal[..., :2], setup.uav, setup.target, setup.sensor,
            setup.planner, check=False,
        )  # fmt: skip
        cost = float(problem.costs(r.plan.reshape(1, -1))[0])
        return PlanResult(
            controls=controls,
            cost=cost,
            cost_warm=float("nan"),
            nit=0,
            n_kernel_calls=problem.n_kernel_calls,
            uav_path=path,
            hypotheses=None,
            diagnostics={"plan_depth": float(r.plan_depth), "tail_steps": float(r.tail_steps)},
            work=r.work,
            converged=None,
        )


@register
@dataclass(frozen=True)
class Pursuit(OnOffMethod):
    """The pursuit policy as a planning method (no fields)."""

    family: ClassVar[str] = "pursuit"
    description: ClassVar[str] = (
        "Run the pursuit policy alone (the tree search's tail from the root: no search, no "
        "optimisation)."
    )
    default: ClassVar[Any] = False
    family_label: ClassVar[str] = "pursuit policy"
    colour_key: ClassVar[str] = "#8b1e3f"  # the palette has no pursuit colour
    order: ClassVar[int] = 8  # after the tree search (6); 7 is the example plugin's (lhs)
    uses_rng: ClassVar[bool] = False
    estimates_cost: ClassVar[bool] = False
    #: the tables' N_T: 0 (no hypotheses)
    n_traj: ClassVar[int] = 0

    def hypotheses(self, belief: Belief, setup: Any, rng: np.random.Generator) -> Hypotheses:
        raise NotImplementedError(
            "the pursuit policy plans over no hypotheses (it follows the estimate)"
        )

    def planner(self, setup: Any) -> PursuitPlanner:
        return PursuitPlanner(setup)
