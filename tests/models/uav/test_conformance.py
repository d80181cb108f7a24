"""The conformance check of UAV planning-method families (rsmhp.testing.check_method).

* every registered family passes it, with its default members (derived from its schema) and
  with members configured by value or given directly; the registry's families include those of
  installed plugins (entry points ``rsmhp.methods``, e.g. ``examples/rsmhp-plugin-example``),
  so an installed plugin's family is checked here too;
* it refuses faulty families, each with a message naming the family and the property: a
  toy family that passes is broken in one place at a time (weights that miss one by 1e-10,
  an unknown colour key or a malformed hex colour, an invalid schema or default, an order
  that is no int (which the registry refuses first), a name of
  another family, a job key without the name, a missing column, hypotheses that read the
  global random state, ignore the stream or are not made by their noise, controls out of
  bounds, a planner that keeps state between plans, a step that reports no work or less than
  one cost evaluation, a planner that drops or swaps its hypotheses, a parse that raises on
  another family's name, an unregistered class);
* the planner protocol of a family without hypotheses (``estimates_cost`` False, as the tree
  search): a toy random-shooting planner conforms, and breaking it in one place is refused
  (hypotheses returned, hypotheses() answering, the default planner kept, the stream ignored,
  a planner seeded from a counter shared between planners);
* the toy families are registered only for the test that uses them: the registry is the
  same before and after.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import pytest

from rsmhp.models.uav import kinematics, methods, target
from rsmhp.models.uav.methods import Hypotheses, Method
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.models.uav.methods.tree_search import TreeSearch
from rsmhp.models.uav.planner import PlanResult
from rsmhp.testing import CheckReport, check_method, example_setup


@pytest.mark.parametrize("family", methods.families(), ids=lambda c: c.family)
def test_every_registered_family_conforms(family):
    report = check_method(family)
    assert isinstance(report, CheckReport) and report.family == family.family
    assert report.members and set(report.plan_seconds) == set(report.members)
    assert all(s > 0 for s in report.plan_seconds.values())
    assert set(report.plan_work) == set(report.members)
    assert all(w > 0 for w in report.plan_work.values())
    expected = {
        "class attributes",
        "round trip",
        "job_key",
        "config schema",
        "plan",
        "time per step",
        "planner protocol",
        "plan determinism",
        "plan independence",
    }
    if family.estimates_cost:
        expected |= {"hypotheses", "determinism", "stream independence"}
    assert expected <= set(report.checks)


def test_members_by_value_or_given():
    assert check_method(MonteCarlo, value=[16, 3]).members == ("rsmhp_nt16", "rsmhp_nt3")
    member = TreeSearch(5, k_o=1.0, alpha_o=0.1, rollout="warm")
    report = check_method(TreeSearch, [member], setup=example_setup(horizon=3))
    assert report.members == ("dpw_s5_ko1_ao0p1_rwarm",)
    with pytest.raises(AssertionError, match=r"\[config\] members must be instances of"):
        check_method(TreeSearch, [MonteCarlo(4)])
    with pytest.raises(AssertionError, match=r"\[config\] \[0\] is not valid against the schema"):
        check_method(MonteCarlo, value=[0])


def test_the_global_random_state_is_left_as_it_was():
    state = np.random.get_state()[1].copy()  # noqa: NPY002
    check_method(MonteCarlo, value=[4])
    np.testing.assert_array_equal(np.random.get_state()[1], state)  # noqa: NPY002


# ------------------------------------------------------------------------ faulty families


@dataclass(frozen=True)
class Toy(MonteCarlo):
    """A conforming toy family: Monte Carlo under other names (each fault below breaks it in
    one place); its config key ``toy_nt`` and names ``toy_nt<N_T>`` follow from its family."""

    family: ClassVar[str] = "toy"
    family_label: ClassVar[str] = "toy"
    colour_key: ClassVar[str] = "rsmhp"
    order: ClassVar[int] = 90


class BadWeights(Toy):
    def hypotheses(self, belief, setup, rng) -> Hypotheses:
        h = super().hypotheses(belief, setup, rng)
        w = h.weights.copy()
        w[0] += 1e-10  # accepted by the Hypotheses constructor (1e-9), not by the contract
        return Hypotheses(h.states, w, h.noise)


class UnknownColour(Toy):
    colour_key: ClassVar[str] = "no_such_colour"


class ShortHex(Toy):
    colour_key: ClassVar[str] = "#7a51"


class OwnColour(Toy):
    """A family the palette does not know, with its own hex colour."""

    colour_key: ClassVar[str] = "#7a5195"


class BadSchema(Toy):
    schema: ClassVar[dict[str, Any]] = {"type": "arrray"}


class BadDefault(Toy):
    default: ClassVar[Any] = [0]


class BadOrder(Toy):
    order: ClassVar[Any] = "90"


class OthersName(Toy):
    """Names of the Monte-Carlo family."""

    name_pattern: ClassVar[str] = r"toy(\d+)"

    @property
    def name(self) -> str:
        return f"rsmhp_nt{self.n_traj}"


class KeyWithoutName(Toy):
    def job_key(self) -> dict[str, Any]:
        return {"N_T": self.n_traj, "N": None, "M": None}


class MissingColumn(Toy):
    def columns(self) -> dict[str, int]:
        return {"N_T": self.n_traj, "N": 0}


class GlobalSeeded(Toy):
    """Jitters its hypotheses with numbers keyed on numpy's global seed."""

    def hypotheses(self, belief, setup, rng) -> Hypotheses:
        h = super().hypotheses(belief, setup, rng)
        seed = int(np.random.get_state()[1][0])  # noqa: NPY002
        jitter = np.random.default_rng(seed).standard_normal(h.states.shape)
        return Hypotheses.equal(h.states + 1e-6 * jitter)


class IgnoresStream(Toy):
    def hypotheses(self, belief, setup, rng) -> Hypotheses:
        return super().hypotheses(belief, setup, np.random.default_rng(0))


class NoiseMismatch(Toy):
    """Hypotheses whose states are not made by their noise."""

    def hypotheses(self, belief, setup, rng) -> Hypotheses:
        h = super().hypotheses(belief, setup, rng)
        states = target.nominal(belief.x_hat, setup.planner.horizon, setup.target)
        return Hypotheses(np.repeat(states, h.n, axis=0), h.weights, h.noise)


class _Shifted:
    """A planner whose controls leave the box."""

    def __init__(self, inner, scale) -> None:
        self.inner, self.scale = inner, scale

    def plan(self, belief, warm_start, rng):
        res = self.inner.plan(belief, warm_start, rng)
        res.controls = res.controls + 2.0 * self.scale
        return res


class OutOfBounds(Toy):
    def planner(self, setup):
        return _Shifted(super().planner(setup), setup.uav.control_scale)


class _Counting:
    """A planner that carries a counter from plan to plan."""

    def __init__(self, inner) -> None:
        self.inner, self.calls = inner, 0

    def plan(self, belief, warm_start, rng):
        self.calls += 1
        res = self.inner.plan(belief, warm_start, rng)
        res.cost += 1e-9 * self.calls
        return res


class Stateful(Toy):
    def planner(self, setup):
        return _Counting(super().planner(setup))


class _Edited:
    """A planner whose results are edited by ``edit(result)``."""

    def __init__(self, inner, edit) -> None:
        self.inner, self.edit = inner, edit

    def plan(self, belief, warm_start, rng):
        res = self.inner.plan(belief, warm_start, rng)
        self.edit(res)
        return res


class NoWork(Toy):
    def planner(self, setup):
        return _Edited(super().planner(setup), lambda r: setattr(r, "work", 0))


class TooLittleWork(Toy):
    def planner(self, setup):
        return _Edited(super().planner(setup), lambda r: setattr(r, "work", 1))


class DropsHypotheses(Toy):
    def planner(self, setup):
        return _Edited(super().planner(setup), lambda r: setattr(r, "hypotheses", None))


class SwapsHypotheses(Toy):
    """Plans over the hypotheses of another stream than its hypotheses() of the step's."""

    def planner(self, setup):
        def draw(belief, rng):
            return self.hypotheses(belief, setup, np.random.default_rng(rng.integers(2**32)))

        from rsmhp.models.uav.planner import SampledCostPlanner

        return SampledCostPlanner(draw, setup.uav, setup.target, setup.sensor, setup.planner)


class RaisingParse(Toy):
    @classmethod
    def parse(cls, name):
        if not name.startswith("toy_nt"):
            raise ValueError(f"not a toy name: {name!r}")
        return super().parse(name)


FAULTS = [
    (BadWeights, r"\[weights\] weights sum to one: sum is 1\.0000000001"),
    (UnknownColour, r"\[colour_key\] 'no_such_colour' is neither a key of .*METHOD_COLOURS"),
    (ShortHex, r"\[colour_key\] '#7a51' is neither a key of .* nor a hex colour '#rrggbb'"),
    (BadSchema, r"\[schema\] not a valid JSON Schema"),
    (BadDefault, r"\[default\] \[0\] is not valid against the schema"),
    (OthersName, r"\[names\] the name is also a name of family 'rsmhp'"),
    (KeyWithoutName, r"\[job_key\] job_key\(\)\['method'\] must be the name 'toy_nt4'"),
    (MissingColumn, r"\[columns\] columns\(\) must have exactly the keys \['N_T', 'N', 'M'\]"),
    (GlobalSeeded, r"\[stream independence\] the hypotheses depend on numpy's or Python's"),
    (IgnoresStream, r"\[determinism\] uses_rng is True but another stream seed gives identical"),
    (NoiseMismatch, r"\[hypotheses\] noise does not reproduce the states"),
    (OutOfBounds, r"\[plan\] controls leave the bounds"),
    (Stateful, r"\[plan determinism\] planning again .* changed \['cost'\]"),
    (NoWork, r"\[time per step\] work .* must be reported: an int in \[1, 2\*\*63\), got 0"),
    (TooLittleWork, r"\[time per step\] work 1 is less than one cost evaluation of its 4"),
    (DropsHypotheses, r"\[planner protocol\] a family with a cost estimate .* got None"),
    (SwapsHypotheses, r"\[planner protocol\] the plan's hypotheses are not the member's"),
    (RaisingParse, r"\[names\] parse\(''\) raised ValueError"),
]


@pytest.fixture
def local_registry():
    """Register toy families for one test only; the registry is restored afterwards."""
    before = methods.families()
    added: list[str] = []

    def register(cls):
        methods.register(cls)
        added.append(cls.family)
        return cls

    yield register
    for family in added:
        methods.unregister(family)
    assert methods.families() == before


def test_the_toy_family_conforms(local_registry):
    report = check_method(local_registry(Toy))
    assert report.members == ("toy_nt4", "toy_nt8")


def test_a_family_with_its_own_hex_colour_conforms(local_registry):
    check_method(local_registry(OwnColour))


@pytest.mark.parametrize("cls,message", FAULTS, ids=[c.__name__ for c, _ in FAULTS])
def test_a_fault_is_refused_naming_the_family_and_the_property(local_registry, cls, message):
    local_registry(cls)
    with pytest.raises(AssertionError, match=rf"'{cls.__name__}' \(family 'toy'\).*{message}"):
        check_method(cls)


def test_a_family_the_registry_refuses_is_refused_by_the_check_too():
    with pytest.raises(TypeError, match=r"class BadOrder .*'order' must be an int, got '90'"):
        methods.register(BadOrder)
    with pytest.raises(
        AssertionError, match=r"\[class attributes\] order must be an int, got '90'"
    ):
        check_method(BadOrder)


def test_an_unregistered_family_is_refused():
    with pytest.raises(AssertionError, match=r"'Toy' \(family 'toy'\): \[registry\] .*register"):
        check_method(Toy)
    with pytest.raises(AssertionError, match=r"\[class attributes\] expected a subclass"):
        check_method(dict)


# ------------------------------------------------ the protocol of a planner without hypotheses


class _Shooting:
    """Random shooting: ``n`` control sequences uniform in the box drawn from the step's
    stream, the one ending nearest the nominal target wins; no hypotheses (a planner of the
    tree search's kind). ``cost``: that distance (m); ``work``: n H model steps."""

    def __init__(self, n, setup, hypotheses=False) -> None:
        self.n, self.setup, self.hypotheses = n, setup, hypotheses

    def plan(self, belief, warm_start, rng):
        H, uav = self.setup.planner.horizon, self.setup.uav
        scale = np.asarray(uav.control_scale, dtype=float)
        u = rng.uniform(-1.0, 1.0, (self.n, H, 2)) * scale
        paths = kinematics.rollout(np.asarray(belief.uav, dtype=float), u, uav)
        goal = target.nominal(belief.x_hat, H, self.setup.target)[0, -1, :2]
        dist = np.linalg.norm(paths[:, -1, :2] - goal, axis=1)
        best = int(np.argmin(dist))
        hyp = None
        if self.hypotheses:
            hyp = Hypotheses.equal(target.nominal(belief.x_hat, H, self.setup.target))
        return PlanResult(
            controls=u[best],
            cost=float(dist[best]),
            cost_warm=float("nan"),
            nit=self.n,
            n_kernel_calls=0,
            uav_path=paths[best],
            hypotheses=hyp,
            diagnostics={"best": float(best)},
            work=self.n * H,
        )


@dataclass(frozen=True)
class Shooting(Method):
    """A conforming toy family without a cost estimate (``estimates_cost`` False)."""

    n: int

    family: ClassVar[str] = "toyshoot"
    config_key: ClassVar[str] = "toyshoot"
    schema: ClassVar[dict[str, Any]] = {
        "type": "array",
        "items": {"type": "integer", "minimum": 1, "maximum": 1000},
    }
    default: ClassVar[Any] = []
    family_label: ClassVar[str] = "shooting"
    colour_key: ClassVar[str] = "#7a5195"
    order: ClassVar[int] = 91
    name_pattern: ClassVar[str] = r"toyshoot_n(\d+)"
    n_traj: ClassVar[int] = 0
    estimates_cost: ClassVar[bool] = False

    @classmethod
    def from_config(cls, value, path):
        return [cls(int(n)) for n in value]

    @property
    def name(self) -> str:
        return f"toyshoot_n{self.n}"

    def job_key(self) -> dict[str, Any]:
        return {"method": self.name, "N_T": 0, "N": None, "M": None}

    def hypotheses(self, belief, setup, rng) -> Hypotheses:
        raise NotImplementedError("random shooting plans without hypotheses")

    def planner(self, setup):
        return _Shooting(self.n, setup)


class ShootingWithHypotheses(Shooting):
    def planner(self, setup):
        return _Shooting(self.n, setup, hypotheses=True)


class ShootingAnswersHypotheses(Shooting):
    def hypotheses(self, belief, setup, rng) -> Hypotheses:
        return Hypotheses.equal(target.nominal(belief.x_hat, setup.planner.horizon, setup.target))


class ShootingDefaultPlanner(Shooting):
    planner = Method.planner


class ShootingIgnoresStream(Shooting):
    def planner(self, setup):
        inner = _Shooting(self.n, setup)

        class Fixed:
            def plan(self, belief, warm_start, rng):
                return inner.plan(belief, warm_start, np.random.default_rng(0))

        return Fixed()


class _Numbered(_Shooting):
    """Seeded at construction from a counter shared by every planner (state across planners)."""

    made = 0

    def __init__(self, n, setup) -> None:
        super().__init__(n, setup)
        _Numbered.made += 1
        self.number = _Numbered.made

    def plan(self, belief, warm_start, rng):
        res = super().plan(belief, warm_start, rng)
        res.cost += 1e-9 * self.number
        return res


class ShootingSharedCounter(Shooting):
    def planner(self, setup):
        return _Numbered(self.n, setup)


SEARCH_FAULTS = [
    (ShootingWithHypotheses, r"must plan with hypotheses=None .* got Hypotheses"),
    (ShootingAnswersHypotheses, r"hypotheses\(\) must raise NotImplementedError"),
    (ShootingDefaultPlanner, r"must override Method\.planner"),
    (ShootingIgnoresStream, r"uses_rng is True but planning with another stream seed gives"),
    (ShootingSharedCounter, r"\[plan independence\] a fresh planner .* changed \['cost'\]"),
]


def test_a_planner_without_hypotheses_conforms(local_registry):
    report = check_method(local_registry(Shooting))
    assert report.members == ("toyshoot_n4", "toyshoot_n8")
    assert report.plan_work == {"toyshoot_n4": 4 * 4, "toyshoot_n8": 8 * 4}
    assert "hypotheses" not in report.checks and "planner protocol" in report.checks


@pytest.mark.parametrize("cls,message", SEARCH_FAULTS, ids=[c.__name__ for c, _ in SEARCH_FAULTS])
def test_the_protocol_without_hypotheses_is_enforced(local_registry, cls, message):
    local_registry(cls)
    with pytest.raises(AssertionError, match=rf"'{cls.__name__}' \(family 'toyshoot'\).*{message}"):
        check_method(cls)
