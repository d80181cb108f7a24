r"""RS-MHP with a pruned tree (paper Fig. 1a, shared draws): level 0 draws ``N`` initial states,
levels 1..H draw ``N`` process-noise values shared by all nodes, and after every level only the
``M`` most likely trajectories survive (:func:`rsmhp.models.uav.target.pruned_tree`); the cost
averages the survivors with equal weights. Config: ``tree: [{N: 8, M: 100}]``, one method per entry,
named ``tree_n<N>_m<M>``."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from rsmhp.core import guards
from rsmhp.models.uav import target
from rsmhp.models.uav.methods import register
from rsmhp.models.uav.methods.base import Hypotheses, Method
from rsmhp.models.uav.planner import Belief

__all__ = ["PrunedTree"]


@register
@dataclass(frozen=True)
class PrunedTree(Method):
    """Pruned tree with ``n_branch`` = N draws per level, keeping ``max_keep`` = M."""

    n_branch: int
    max_keep: int

    family: ClassVar[str] = "tree"
    schema: ClassVar[dict[str, Any]] = {
        "description": "Pruned-tree ablations (N draws per level, keep the M most likely).",
        "type": "array",
        "maxItems": 10,
        "items": {
            "type": "object",
            "additionalProperties": False,
            "required": ["N", "M"],
            "properties": {
                "N": {"type": "integer", "minimum": 1, "maximum": 1000},
                "M": {"type": "integer", "minimum": 1, "maximum": 100000},
            },
        },
    }
    default: ClassVar[Any] = []
    family_label: ClassVar[str] = "pruned tree"
    colour_key: ClassVar[str] = "pruned"  # the palette's "tree" is the unpruned tree's
    order: ClassVar[int] = 2
    closed_loop: ClassVar[str] = "drawn"
    name_pattern: ClassVar[str] = r"tree_n(\d+)_m(\d+)"

    def __post_init__(self) -> None:
        object.__setattr__(self, "n_branch", guards.positive_int("n_branch (N)", self.n_branch))
        object.__setattr__(self, "max_keep", guards.positive_int("max_keep (M)", self.max_keep))

    @classmethod
    def from_config(cls, value: Any, path: str) -> list[Method]:
        guards.instance_of(path, value, (list, tuple))
        out: list[Method] = []
        for i, t in enumerate(value):
            guards.instance_of(f"{path}[{i}]", t, Mapping)
            n = guards.positive_int(f"{path}[{i}].N", t["N"])
            m = guards.positive_int(f"{path}[{i}].M", t["M"])
            out.append(cls(n, m))
        return out

    @classmethod
    def config_problems(cls, value: Any, path: str, uav: Mapping[str, Any]) -> list[str]:
        """M at most the tree's N^(H+1) leaves."""
        horizon = (uav.get("planner", {}) or {}).get("horizon")
        problems = []
        for i, tree in enumerate(value or []):
            if horizon is not None and isinstance(tree, Mapping) and {"N", "M"} <= tree.keys():
                leaves = tree["N"] ** (horizon + 1)
                if tree["M"] > leaves:
                    problems.append(
                        f"{path}[{i}].M: {tree['M']} is greater than the tree's N^(H+1) = "
                        f"{leaves} leaves (allowed: 1 <= M <= N^(H+1))"
                    )
        return problems

    @property
    def name(self) -> str:
        return f"tree_n{self.n_branch}_m{self.max_keep}"

    @property
    def n_traj(self) -> int:  # type: ignore[override]
        return self.max_keep

    def columns(self) -> dict[str, int]:
        return {"N_T": self.max_keep, "N": self.n_branch, "M": self.max_keep}

    def job_key(self) -> dict[str, Any]:
        return {"method": self.name, "N_T": self.max_keep, "N": self.n_branch, "M": self.max_keep}

    def label(self) -> str:
        return f"pruned tree N={self.n_branch} M={self.max_keep}"

    def hypotheses(self, belief: Belief, setup: Any, rng: np.random.Generator) -> Hypotheses:
        states, _ = target.pruned_tree(
            belief.x_hat,
            belief.P_hat,
            setup.planner.horizon,
            self.n_branch,
            self.max_keep,
            setup.target,
            rng,
            check=False,
        )
        return Hypotheses.equal(states, check=False)
