r"""The contract of a UAV planning method (one family per module of this package).

A *family* (NBO, Monte Carlo, pruned tree, ...) is a subclass of :class:`Method` decorated
with :func:`rsmhp.models.uav.methods.register`; an instance is one configured member (``RS-MHP
N_T=250``). The class declares everything the pipeline needs, so that simulation, decision
study, sensitivity map, palette, config checks and analysis iterate over the registry and never
name a family:

==================  ==========================================================================
``family``          identifier written in the ``family`` column of every table
``config_key``      its key in a ``methods`` block of the config (``uav.methods``,
                    ``decisions.uav.methods``, ``decisions.map.methods``); default: ``family``
``schema``          JSON Schema of that key's value (inserted into the config schema's
                    ``$defs/uav_methods``; written once, here)
``default``         the value when a ``methods`` block omits the key
``family_label``    human-readable family name
``colour_key``      the key of its colour in :data:`rsmhp.report.palette.METHOD_COLOURS`, or a
                    hex colour (``"#7a5195"``) for a family the palette does not know
                    (presentation lives in the palette: a colour edit reruns no simulation);
                    default: ``family`` (declare it where the palette has no such key)
``order``           position of the family in tables and figures (smaller first)
``name_pattern``    regular expression of the members' names, its groups the fields in order
                    (what the default :meth:`Method.parse` reads); not needed with an own
                    ``parse``
``n_traj``          N_T, the hypotheses the cost averages over (a field, a property or a
                    constant; the tables' ``N_T`` column)
``baseline``        True for the one family every comparison is made against (NBO)
``uses_rng``        False for a deterministic family (the planner gets no stream)
``estimates_cost``  False for a family that has no cost estimate of an arbitrary plan (a
                    tree search plans over simulated beliefs, not over hypotheses)
``closed_loop``     which closed loop runs it: ``"python"`` (default), or compiled with
                    ``"nominal"`` or ``"drawn"`` hypotheses (:mod:`rsmhp.models.uav.loop`)
==================  ==========================================================================

and per instance: :meth:`Method.name` (rule wildcard, table key), :meth:`Method.columns` (the
``N_T``, ``N``, ``M`` columns), :meth:`Method.job_key` (its part of the random-stream key:
changing it changes every draw), :meth:`Method.label`, :meth:`Method.shade_size`,
:meth:`Method.hypotheses` (the weighted hypotheses it plans over) and :meth:`Method.planner`
(a :class:`rsmhp.models.uav.planner.Planner`; by default the method's hypotheses and L-BFGS-B).

Derived attributes
------------------
A family class that leaves out ``config_key`` or ``colour_key`` gets them from its ``family``
when the class is created (:meth:`Method.derivations`; which ones it got:
``derived_attributes``); one that writes them keeps its own. A written value is inherited as
usual; a derived one follows the class's own ``family``: a subclass that writes another
``family`` gets its own config key, names and colour key unless it writes them. Two bases of a
common kind of family derive more:

* :class:`NTrajMethod`, a family whose members are numbers of hypotheses ``n_traj`` (config:
  a list of N_T, as ``rsmhp_nt: [50, 100]``): ``config_key`` ``<family>_nt``, members named
  ``<config_key><N_T>`` (``name_pattern`` accordingly) and labelled ``<family_label>
  N_T=<N_T>``, shaded by N_T, built by ``from_config`` with :meth:`NTrajMethod.check_n_traj`
  (default: a positive int; a family with its own rule, even or a power of 2, overrides it);
* :class:`OnOffMethod`, a family of one member with no fields, switched by a boolean
  (``nbo: true``): member named ``<config_key>`` (``name_pattern`` and ``parse``
  accordingly), ``schema`` ``{"description": <description>, "type": "boolean"}`` from the
  class attribute ``description``, ``from_config`` building the member for ``true``.

The rest (``family``, ``schema``, ``default``, ``family_label``, ``order``, ``n_traj``, the
flags) is written by the family; :func:`rsmhp.models.uav.methods.register` refuses a class
that lacks one of them, naming the class and the attribute.

Hypotheses
----------
:class:`Hypotheses` are ``T`` future target trajectories ``states`` (T, H, 4) with weights
:math:`\omega_i \ge 0`, :math:`\sum_i \omega_i = 1` (T,), and optionally the draws that made
them, ``noise`` (T, H + 1, 4): ``noise[:, 0]`` the initial-state deviation
:math:`x_0 - \hat x`, ``noise[:, j]`` the process noise :math:`w_j`. The planner's cost is
:math:`J(u) = \sum_i \omega_i \sum_{j=1}^H \mathrm{tr}\,P^i_j(u)`.
"""

from __future__ import annotations

import re
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import InitVar, asdict, dataclass, fields
from typing import Any, ClassVar

import numpy as np

from rsmhp.core import guards
from rsmhp.models.uav import target
from rsmhp.models.uav.planner import Belief, Planner, SampledCostPlanner

__all__ = ["COLUMNS", "Hypotheses", "Method", "NTrajMethod", "OnOffMethod", "from_design"]

#: the method columns of every UAV table: trajectories averaged, draws per level, kept
COLUMNS = ("N_T", "N", "M")


@dataclass(frozen=True)
class Hypotheses:
    """Weighted target hypotheses of one planning step (see the module docstring)."""

    states: np.ndarray
    weights: np.ndarray
    noise: np.ndarray | None = None
    #: ``False`` skips the shape and weight checks: for a generator whose output is valid by
    #: construction (NBO's single nominal hypothesis, planned at every closed-loop step)
    check: InitVar[bool] = True

    def __post_init__(self, check: bool) -> None:
        if not check:
            return
        s = np.asarray(self.states, dtype=float)
        if s.ndim != 3 or s.shape[0] == 0 or s.shape[2] != 4:
            raise ValueError(f"Hypotheses.states must have shape (T, H, 4), got {s.shape}")
        w = np.asarray(self.weights, dtype=float)
        if w.shape != (s.shape[0],):
            raise ValueError(f"Hypotheses.weights must have shape ({s.shape[0]},), got {w.shape}")
        if not np.isfinite(w).all() or (w < 0).any() or abs(w.sum() - 1.0) > 1e-9:
            raise ValueError(
                f"Hypotheses.weights must be finite, >= 0 and sum to 1, got sum {w.sum()!r}"
            )
        if self.noise is not None:
            n = np.asarray(self.noise, dtype=float)
            if n.shape != (s.shape[0], s.shape[1] + 1, 4):
                raise ValueError(
                    f"Hypotheses.noise must have shape (T, H + 1, 4) = "
                    f"({s.shape[0]}, {s.shape[1] + 1}, 4), got {n.shape}"
                )

    @classmethod
    def equal(
        cls, states: np.ndarray, noise: np.ndarray | None = None, *, check: bool = True
    ) -> Hypotheses:
        """``states`` with equal weights 1/T (``check=False``: a generator whose output is
        valid by construction, as the built-in families' are, skips the checks)."""
        n = np.shape(states)[0]
        return cls(states, np.full(n, 1.0 / n), noise, check=check)

    @property
    def n(self) -> int:
        return int(np.shape(self.states)[0])


#: the identity square root: a design of :mod:`rsmhp.core.designs` given it draws standard normals
_STANDARD = np.eye(4)
_STANDARD.flags.writeable = False


def from_design(belief: Belief, setup: Any, design, *args: Any) -> Hypotheses:
    """Hypotheses of a point set of :mod:`rsmhp.core.designs`: ``design(*args, H + 1, I_4)``
    gives standard-normal coordinates ``z`` (n, H + 1, 4) and weights, mapped to the initial
    deviation and the H process noises by :func:`rsmhp.models.uav.target.from_normals`. Unchecked
    (valid by construction), like every generator the closed loop calls."""
    z, weights = design(*args, setup.planner.horizon + 1, _STANDARD)
    states, noise = target.from_normals(belief.x_hat, belief.P_hat, z, setup.target, check=False)
    return Hypotheses(states, weights, noise, check=False)


def _written(cls: type, attr: str) -> bool:
    """Whether ``attr`` is written in the body of ``cls`` or of the base it inherits it from
    (not set there by :meth:`Method.derivations`)."""
    for k in cls.__mro__:
        if attr in vars(k):
            return attr not in vars(k).get("derived_attributes", ())
    return False


@dataclass(frozen=True)
class Method(ABC):
    """One configured planning method; subclasses are families (see the module docstring)."""

    family: ClassVar[str]
    #: default: ``family`` (:meth:`derivations`)
    config_key: ClassVar[str]
    schema: ClassVar[dict[str, Any]]
    default: ClassVar[Any]
    family_label: ClassVar[str]
    #: default: ``family`` (:meth:`derivations`)
    colour_key: ClassVar[str]
    order: ClassVar[int]
    #: the attributes this class got from :meth:`derivations` (written neither in its body nor
    #: in a base's)
    derived_attributes: ClassVar[frozenset[str]] = frozenset()
    baseline: ClassVar[bool] = False
    #: whether the planner draws random numbers; ``False`` (a deterministic method such as
    #: NBO) spares the closed loop building the step's stream, and the planner gets ``None``
    uses_rng: ClassVar[bool] = True
    #: whether :meth:`hypotheses` gives the cost estimate of any plan (False: a tree search)
    estimates_cost: ClassVar[bool] = True
    #: which closed loop runs the family (:mod:`rsmhp.models.uav.loop`): ``"nominal"`` (NBO's
    #: noise-free hypothesis, computed in compiled code), ``"drawn"`` (compiled; :meth:`hypotheses`
    #: is called from the compiled loop once per step) or ``"python"`` (the Python loop: the
    #: default, and the only choice for a family with its own :meth:`planner`)
    closed_loop: ClassVar[str] = "python"

    # ---------------------------------------------------------------- derived attributes
    @classmethod
    def derivations(cls) -> dict[str, Callable[[type[Method]], Any]]:
        """The class attributes a family may leave out and how each is derived from the
        class (in this order: a later one may read an earlier one): ``config_key`` and
        ``colour_key`` from ``family``. A base of a kind of family extends it."""
        return {"config_key": lambda c: c.family, "colour_key": lambda c: c.family}

    def __init_subclass__(cls, **kwargs: Any) -> None:
        """Set the :meth:`derivations` of the attributes written neither in the class's body
        nor in a base's, for a class with a ``family`` (an abstract base such as
        :class:`OnOffMethod` has none and derives nothing). A value derived for a base is
        derived again for the subclass, from its own ``family``."""
        super().__init_subclass__(**kwargs)
        derived: set[str] = set()
        if isinstance(getattr(cls, "family", None), str):
            for attr, derive in cls.derivations().items():
                if not _written(cls, attr):
                    try:
                        value = derive(cls)
                    except AttributeError:
                        continue  # what it needs is missing too: register names it
                    setattr(cls, attr, value)
                    derived.add(attr)
        cls.derived_attributes = frozenset(derived)

    # ---------------------------------------------------------------- construction
    @classmethod
    @abstractmethod
    def from_config(cls, value: Any, path: str) -> list[Method]:
        """The family's members from its config value (``path`` names the key in messages)."""

    @classmethod
    def config_problems(cls, value: Any, path: str, uav: Mapping[str, Any]) -> list[str]:
        """Cross-field problems of the family's config value given the ``uav`` section (e.g.
        more trajectories kept than a tree has leaves), as messages naming ``path``."""
        return []

    @classmethod
    def parse(cls, name: str) -> Method | None:
        """The member named ``name`` (:meth:`name`), or ``None`` if the name is not of this
        family. Default: names matching ``name_pattern`` with its groups as the fields."""
        m = re.fullmatch(cls.name_pattern, name)
        if m is None:
            return None
        return cls(*(int(g) for g in m.groups()))

    name_pattern: ClassVar[str]

    # ---------------------------------------------------------------- identity
    @property
    @abstractmethod
    def name(self) -> str:
        """Unique name: the rule wildcard and the ``method`` column of every table."""

    #: N_T, the number of hypotheses the cost averages over (a field or a property)
    n_traj: ClassVar[int]

    def columns(self) -> dict[str, int]:
        """The :data:`COLUMNS` of this method's table rows (0 where a field does not apply)."""
        return {"N_T": self.n_traj, "N": 0, "M": 0}

    def job_key(self) -> dict[str, Any]:
        """The method's part of its random-stream keys (``rsmhp.core.seeding.job_rng``)."""
        return {"method": self.name, "N_T": self.n_traj, "N": None, "M": None}

    def spec(self) -> dict[str, Any]:
        """JSON-ready description (rule params; :func:`rsmhp.models.uav.methods.from_spec`)."""
        return {"family": self.family, **asdict(self)}

    def label(self) -> str:
        """Human-readable name (figures and tables)."""
        return self.family_label

    def shade_size(self) -> int | None:
        """The size (hypotheses) that shades this member's colour in the palette
        (:func:`rsmhp.report.palette.method_colour`); ``None``: the family's colour."""
        return None

    def sort_key(self) -> tuple:
        """Position in tables and figures: family order, then the columns."""
        c = self.columns()
        return (self.order, c["N_T"], c["N"], c["M"], self.name)

    # ---------------------------------------------------------------- planning
    @abstractmethod
    def hypotheses(self, belief: Belief, setup: Any, rng: np.random.Generator) -> Hypotheses:
        """The weighted hypotheses this method plans over at ``belief`` (horizon
        ``setup.planner.horizon``; ``setup`` a :class:`rsmhp.models.uav.simulation.UAVSetup`),
        drawn from ``rng``. Unchecked: the closed loop checks its inputs once per run."""

    def planner(self, setup: Any) -> Planner:
        """The planner of this method for ``setup``: by default its hypotheses, the weighted
        covariance cost and L-BFGS-B (:class:`rsmhp.models.uav.planner.SampledCostPlanner`)."""

        def draw(belief: Belief, rng: np.random.Generator) -> Hypotheses:
            return self.hypotheses(belief, setup, rng)

        return SampledCostPlanner(draw, setup.uav, setup.target, setup.sensor, setup.planner)

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in fields(cls))


@dataclass(frozen=True)
class NTrajMethod(Method):
    """Base of a family whose members are numbers of hypotheses, ``n_traj`` = N_T (config: a
    list of N_T). Derives ``config_key`` ``<family>_nt`` and ``name_pattern``; provides
    ``from_config``, ``name`` (``<config_key><N_T>``), ``label`` (``<family_label>
    N_T=<N_T>``) and ``shade_size`` (N_T). A family writes ``family``, ``schema``,
    ``default``, ``family_label``, ``order`` and :meth:`hypotheses`."""

    n_traj: int

    @classmethod
    def derivations(cls) -> dict[str, Callable[[type[Method]], Any]]:
        return {
            **super().derivations(),
            "config_key": lambda c: f"{c.family}_nt",
            "name_pattern": lambda c: re.escape(c.config_key) + r"(\d+)",
        }

    @classmethod
    def check_n_traj(cls, name: str, value: Any) -> int:
        """``value`` as a valid N_T of the family (``name`` in messages): a positive int;
        whole-number floats become ints (1.0 and 1 already name the same random streams)."""
        return guards.positive_int(name, value)

    def __post_init__(self) -> None:
        object.__setattr__(self, "n_traj", self.check_n_traj("n_traj (N_T)", self.n_traj))

    @classmethod
    def from_config(cls, value: Any, path: str) -> list[Method]:
        guards.instance_of(path, value, (list, tuple))
        return [cls(cls.check_n_traj(f"{path}[{i}]", n)) for i, n in enumerate(value)]

    @property
    def name(self) -> str:
        return f"{self.config_key}{self.n_traj}"

    def label(self) -> str:
        return f"{self.family_label} N_T={self.n_traj}"

    def shade_size(self) -> int:
        return self.n_traj


@dataclass(frozen=True)
class OnOffMethod(Method):
    """Base of a family of one member without fields, switched on by a boolean config value
    (``nbo: true``). Derives ``name_pattern`` and ``schema`` (a boolean, described by the
    class attribute ``description``); provides ``from_config``, ``name`` (the config key)
    and ``parse``. A family writes ``family``, ``description``, ``default``,
    ``family_label``, ``order``, ``n_traj`` and :meth:`hypotheses`."""

    #: the schema's description of the switch
    description: ClassVar[str]

    @classmethod
    def derivations(cls) -> dict[str, Callable[[type[Method]], Any]]:
        return {
            **super().derivations(),
            "name_pattern": lambda c: re.escape(c.config_key),
            "schema": lambda c: {"description": c.description, "type": "boolean"},
        }

    @classmethod
    def from_config(cls, value: Any, path: str) -> list[Method]:
        guards.instance_of(path, value, (bool, np.bool_))
        return [cls()] if value else []

    @classmethod
    def parse(cls, name: str) -> Method | None:
        member = cls()
        return member if name == member.name else None

    @property
    def name(self) -> str:
        return self.config_key
