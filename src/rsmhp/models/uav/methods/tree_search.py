r"""Tree search with double progressive widening (PFT-DPW over Kalman beliefs,
:mod:`rsmhp.models.uav.dpw`): the belief-space planner of the continuous-POMDP literature, against
which the paper's sampled-cost planners are compared at equal compute. Unlike them it plans
over the tracker's own future beliefs (random detections and measurements, R at the estimate)
and its controls come from sampled actions rather than a gradient-based optimiser; its
budget is ``sims`` simulations per planning step.

Config: ``dpw: [{sims: 200}, {sims: 1000, k_o: 1, alpha_o: 0.1}]``. Every search constant is
a field of the member: UCB constant ``c``, action widening ``k_a``, ``alpha_a``, observation
widening ``k_o``, ``alpha_o`` and the ``rollout`` policy (``"pursuit"`` or ``"warm"``, see
:mod:`rsmhp.models.uav.dpw`). The defaults are the constants fixed before any run and not tuned on
our results: :data:`C_UCB` = 0.5 (on per-step rewards normalised by the root's
:math:`\mathrm{tr}\,\hat P`), :data:`K_A` = 4, :data:`ALPHA_A` = 0.25, :data:`K_O` = 4,
:data:`ALPHA_O` = 0.25, and rollout :data:`ROLLOUT` = ``"pursuit"``; any tuning of them
happens elsewhere (a study that configures members), never by changing these defaults.

Names: ``dpw_s<sims>`` when every constant is the default (the name of every earlier result),
otherwise the non-default fields are appended in the order ``c``, ``k_a``, ``alpha_a``,
``k_o``, ``alpha_o``, ``rollout`` as ``_c``, ``_ka``, ``_aa``, ``_ko``, ``_ao`` followed by
the number with its decimal point written ``p`` (the shortest decimal that gives the float
back: ``0.1`` is ``0p1``, ``4.0`` is ``4``), and ``_rwarm``: ``dpw_s300_ko1_ao0p1``.
:meth:`TreeSearch.parse` inverts :attr:`TreeSearch.name` exactly and refuses any other
spelling. The name is the random-stream key (:meth:`TreeSearch.job_key`), so members that
differ in any constant draw different streams, and the default members draw what they drew.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from decimal import Decimal
from typing import Any, ClassVar

import numpy as np

from rsmhp.core import guards
from rsmhp.models.uav import dpw, kinematics
from rsmhp.models.uav.methods import register
from rsmhp.models.uav.methods.base import Hypotheses, Method
from rsmhp.models.uav.planner import Belief, PlanResult
from rsmhp.models.uav.stepper import Stepper

__all__ = [
    "ALPHA_A",
    "ALPHA_O",
    "C_UCB",
    "K_A",
    "K_O",
    "ROLLOUT",
    "TreeSearch",
    "TreeSearchPlanner",
]

C_UCB = 0.5
K_A = 4.0
ALPHA_A = 0.25
K_O = 4.0
ALPHA_O = 0.25
ROLLOUT = "pursuit"

#: the real constants: field -> (name token, default, guard bounds for rsmhp.core.guards.real)
_REALS: dict[str, tuple[str, float, dict[str, Any]]] = {
    "c": ("c", C_UCB, {"lo": 0.0, "lo_open": True, "hi": 100.0}),
    "k_a": ("ka", K_A, {"lo": 0.0, "lo_open": True, "hi": 100.0}),
    "alpha_a": ("aa", ALPHA_A, {"lo": 0.0, "hi": 1.0}),
    "k_o": ("ko", K_O, {"lo": 0.0, "lo_open": True, "hi": 100.0}),
    "alpha_o": ("ao", ALPHA_O, {"lo": 0.0, "hi": 1.0}),
}
_NUM = r"(\d+(?:p\d+)?)"
_PATTERN = (
    r"dpw_s(\d+)"
    + "".join(f"(?:_{token}{_NUM})?" for token, _, _ in _REALS.values())
    + r"(?:_r(warm|pursuit))?"
)


def _number(x: float) -> str:
    """``x`` (>= 0) in a name: the shortest decimal that reads back as ``x``, point as ``p``,
    no exponent, no trailing ``.0``."""
    text = format(Decimal(repr(float(x))), "f")
    if text.endswith(".0"):
        text = text[:-2]
    return text.replace(".", "p")


def _schema_real(lo: float, lo_open: bool, hi: float) -> dict[str, Any]:
    return {"type": "number", ("exclusiveMinimum" if lo_open else "minimum"): lo, "maximum": hi}


class TreeSearchPlanner:
    """The :class:`rsmhp.models.uav.planner.Planner` of a tree-search member: ``plan(belief,
    warm_start (H, 2), rng)`` runs ``sims`` simulations of :func:`rsmhp.models.uav.dpw.search` with
    the member's constants and returns the plan (H, 2: the most visited path, then the tail),
    the search's estimate of the chosen root action's expected cost, ``nit`` = simulations,
    ``n_kernel_calls`` = belief nodes created, ``work`` = calls of the generative model plus
    the tail's nominal propagations (model steps), the planned UAV states, no hypotheses and
    these ``diagnostics``:

    ==================  =====================================================================
    ``max_depth``       depth of the deepest belief node of the tree (root = 0)
    ``mean_end_depth``  mean depth at which a simulation left the tree (expanded a new belief:
                        1 = a child of a root action), over the simulations that left it
    ``frac_depth1``     fraction of the simulations that expanded at depth 1
    ``frac_horizon``    fraction that reached depth H inside the tree (expanded nothing)
    ``root_actions``    actions of the root; ``chosen_visits``: visits of the chosen one
    ``plan_depth``      steps of the plan from the tree's most visited path (the rest is the
                        tail: the warm start, or the pursuit policy's nominal continuation)
    ``tail_steps``      nominal propagations spent on the tail (part of ``work``)
    ``action_nodes``    action nodes created
    ``best_root_cost``  the lowest estimated cost of any visited root action (m²)
    ==================  ====================================================================="""

    def __init__(
        self,
        sims: int,
        setup: Any,
        params: tuple[float, float, float, float, float] = (C_UCB, K_A, ALPHA_A, K_O, ALPHA_O),
        rollout: str = ROLLOUT,
    ) -> None:
        self.sims = guards.positive_int("sims", sims)
        self.setup = setup
        self.params = tuple(float(p) for p in params)
        self.rollout = guards.one_of("rollout", rollout, dpw.ROLLOUTS)
        self.stepper = Stepper(setup.uav, setup.target, setup.sensor)
        self.scale = np.asarray(setup.uav.control_scale, dtype=float)

    def plan(self, belief: Belief, warm_start: np.ndarray, rng: np.random.Generator) -> PlanResult:
        warm = np.clip(np.asarray(warm_start, dtype=float) / self.scale, -1.0, 1.0)
        r = dpw.search(
            belief.uav,
            belief.x_hat,
            belief.P_hat,
            warm,
            self.scale,
            self.sims,
            self.params,
            self.stepper,
            rng,
            self.rollout,
        )
        controls = r.plan * self.scale
        state = np.asarray(belief.uav, dtype=float)
        path = np.empty((controls.shape[0], 4))
        for j, u in enumerate(controls):
            state = kinematics.step(state, u, self.setup.uav)
            path[j] = state
        hist = np.asarray(r.end_depths)
        left = int(hist[1:].sum())
        mean_end = float(np.arange(1, hist.size) @ hist[1:]) / left if left else float("nan")
        return PlanResult(
            controls=controls,
            cost=float(r.cost),
            cost_warm=float("nan"),
            nit=self.sims,
            n_kernel_calls=int(r.belief_nodes),
            uav_path=path,
            hypotheses=None,
            diagnostics={
                "max_depth": float(r.max_depth),
                "mean_end_depth": mean_end,
                "frac_depth1": float(hist[1]) / self.sims if hist.size > 1 else 0.0,
                "frac_horizon": float(hist[0]) / self.sims,
                "root_actions": float(r.root_actions),
                "chosen_visits": float(r.chosen_visits),
                "plan_depth": float(r.plan_depth),
                "tail_steps": float(r.tail_steps),
                "action_nodes": float(r.action_nodes),
                "best_root_cost": float(r.best_root_cost),
            },
            work=r.work,
            converged=None,
        )


@register
@dataclass(frozen=True)
class TreeSearch(Method):
    """PFT-DPW with ``sims`` simulations per planning step and the search constants ``c``,
    ``k_a``, ``alpha_a``, ``k_o``, ``alpha_o``, ``rollout`` (module docstring)."""

    sims: int
    c: float = C_UCB
    k_a: float = K_A
    alpha_a: float = ALPHA_A
    k_o: float = K_O
    alpha_o: float = ALPHA_O
    rollout: str = ROLLOUT

    family: ClassVar[str] = "dpw"
    schema: ClassVar[dict[str, Any]] = {
        "description": (
            "Tree-search planners (PFT-DPW over Kalman beliefs): simulations per step and, "
            "optionally, search constants (defaults: the constants fixed before any run)."
        ),
        "type": "array",
        "maxItems": 20,
        "items": {
            "type": "object",
            "additionalProperties": False,
            "required": ["sims"],
            "properties": {
                "sims": {"type": "integer", "minimum": 1, "maximum": 1000000},
                **{
                    f: _schema_real(b["lo"], b.get("lo_open", False), b["hi"])
                    for f, (_, _, b) in _REALS.items()
                },
                "rollout": {"enum": list(dpw.ROLLOUTS[::-1])},
            },
        },
    }
    default: ClassVar[Any] = []
    family_label: ClassVar[str] = "tree search"
    order: ClassVar[int] = 6
    name_pattern: ClassVar[str] = _PATTERN
    #: the tables' N_T: 0 (no fixed hypotheses; ``sims`` is the budget)
    n_traj: ClassVar[int] = 0
    estimates_cost: ClassVar[bool] = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "sims", guards.positive_int("sims", self.sims))
        for f, (_, _, bounds) in _REALS.items():
            # float (1 and 1.0 are one member), -0.0 -> 0.0 (one name)
            object.__setattr__(self, f, float(guards.real(f, getattr(self, f), **bounds)) + 0.0)
        guards.one_of("rollout", self.rollout, dpw.ROLLOUTS)

    @classmethod
    def from_config(cls, value: Any, path: str) -> list[Method]:
        guards.instance_of(path, value, (list, tuple))
        out: list[Method] = []
        allowed = cls.field_names()
        for i, t in enumerate(value):
            where = f"{path}[{i}]"
            guards.instance_of(where, t, Mapping)
            unknown = sorted(set(t) - set(allowed))
            if unknown:
                raise ValueError(f"{where}: unknown key(s) {unknown} (allowed: {list(allowed)})")
            if "sims" not in t:
                raise ValueError(f"{where}.sims is required")
            kw: dict[str, Any] = {"sims": guards.positive_int(f"{where}.sims", t["sims"])}
            for f, (_, _, bounds) in _REALS.items():
                if f in t:
                    kw[f] = guards.real(f"{where}.{f}", t[f], **bounds)
            if "rollout" in t:
                kw["rollout"] = guards.one_of(f"{where}.rollout", t["rollout"], dpw.ROLLOUTS)
            out.append(cls(**kw))
        return out

    @classmethod
    def parse(cls, name: str) -> Method | None:
        """The member called ``name``, or ``None`` if ``name`` is not the exact name of one
        (a default written out, ``dpw_s100_ko4``, or ``0p10`` for ``0p1`` are not)."""
        m = re.fullmatch(_PATTERN, name)
        if m is None:
            return None
        sims, *reals, rollout = m.groups()
        kw: dict[str, Any] = {"sims": int(sims)}
        for f, g in zip(_REALS, reals, strict=True):
            if g is not None:
                kw[f] = float(g.replace("p", "."))
        if rollout is not None:
            kw["rollout"] = rollout
        member = cls(**kw)
        return member if member.name == name else None

    def _changed(self) -> list[str]:
        """The fields whose value is not the default, in name order."""
        out = [f for f, (_, d, _) in _REALS.items() if getattr(self, f) != d]
        return out + (["rollout"] if self.rollout != ROLLOUT else [])

    @property
    def name(self) -> str:
        parts = [f"dpw_s{self.sims}"]
        for f in self._changed():
            if f == "rollout":
                parts.append(f"r{self.rollout}")
            else:
                parts.append(f"{_REALS[f][0]}{_number(getattr(self, f))}")
        return "_".join(parts)

    def label(self) -> str:
        base = f"tree search {self.sims} sims"
        changed = [
            (
                f"{self.rollout} rollout"
                if f == "rollout"
                else f"{f}={_number(getattr(self, f)).replace('p', '.')}"
            )
            for f in self._changed()
        ]
        return f"{base} ({', '.join(changed)})" if changed else base

    def spec(self) -> dict[str, Any]:
        """``{"family": "dpw", "sims": ...}`` and the non-default constants (a default
        member's spec, and so its rule params, is what it was before the constants were
        fields)."""
        return {
            "family": self.family,
            "sims": self.sims,
            **{f: getattr(self, f) for f in self._changed()},
        }

    def job_key(self) -> dict[str, Any]:
        return {"method": self.name, "N_T": 0, "N": None, "M": None}

    def sort_key(self) -> tuple:
        return (self.order, self.sims, 0, 0, self.name)

    def hypotheses(self, belief: Belief, setup: Any, rng: np.random.Generator) -> Hypotheses:
        raise NotImplementedError(
            "a tree search plans over simulated beliefs, not over a fixed set of hypotheses"
        )

    def planner(self, setup: Any) -> TreeSearchPlanner:
        params = (self.c, self.k_a, self.alpha_a, self.k_o, self.alpha_o)
        return TreeSearchPlanner(self.sims, setup, params, self.rollout)
