"""What a method family need not write (rsmhp.models.uav.methods.base: derived attributes,
NTrajMethod, OnOffMethod) and what the registry refuses.

* the built-in families' config keys, colour keys, name patterns and schemas, derived or
  written, are the ones every published run used (pinned here);
* a family declared with only the attributes it must write gets the derived ones from its
  ``family`` (``config_key``, ``colour_key``; an NTrajMethod also ``<family>_nt``, names,
  labels, shades and config reading), passes the conformance check, and can still write
  any of them; a subclass that writes another ``family`` derives them afresh, a written value
  is inherited;
* an on/off family round-trips config -> members -> name -> parse, through the family and
  through the registry;
* ``register`` refuses a class lacking an attribute of the contract, or with one of the
  wrong type, or with an abstract method left, naming the class and the attribute; the
  registry is unchanged afterwards.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import pytest

from rsmhp.models.uav import methods, target
from rsmhp.models.uav.methods import Hypotheses, Method, NTrajMethod, OnOffMethod
from rsmhp.models.uav.methods.antithetic import Antithetic
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.models.uav.methods.monte_carlo_per_step import MonteCarloPerStep
from rsmhp.models.uav.methods.nbo import NBO
from rsmhp.models.uav.methods.pruned_tree import PrunedTree
from rsmhp.models.uav.methods.pursuit import Pursuit
from rsmhp.models.uav.methods.rqmc import RQMC
from rsmhp.models.uav.methods.sigma_points import SigmaPoints
from rsmhp.models.uav.methods.tree_search import TreeSearch
from rsmhp.report.palette import member_colour, method_colour, size_shade
from rsmhp.testing import check_method

_KEYS, _PATTERN, _ON_OFF = {"config_key", "colour_key"}, {"name_pattern"}, {"schema"}
#: family -> (config_key, colour_key, name_pattern, derived attributes): the published values
BUILT_IN = {
    NBO: ("nbo", "nbo", "nbo", _KEYS | _PATTERN | _ON_OFF),
    MonteCarlo: ("rsmhp_nt", "rsmhp", r"rsmhp_nt(\d+)", _KEYS | _PATTERN),
    MonteCarloPerStep: ("rsmhp_nt_per_step", "rsmhp_per_step", r"rsmhp_nt(\d+)h", {"colour_key"}),
    PrunedTree: ("tree", "pruned", r"tree_n(\d+)_m(\d+)", {"config_key"}),
    RQMC: ("rqmc_nt", "sobol", r"rqmc_nt(\d+)", {"config_key"} | _PATTERN),
    Antithetic: ("antithetic_nt", "antithetic", r"antithetic_nt(\d+)", _KEYS | _PATTERN),
    SigmaPoints: ("sigma", "cubature", "sigma", {"config_key"} | _PATTERN | _ON_OFF),
    TreeSearch: ("dpw", "dpw", TreeSearch.name_pattern, _KEYS),
    Pursuit: ("pursuit", "#8b1e3f", "pursuit", {"config_key"} | _PATTERN | _ON_OFF),
}


@pytest.mark.parametrize("cls", list(BUILT_IN), ids=lambda c: c.family)
def test_built_in_families_keep_their_published_attributes(cls):
    key, colour, pattern, derived = BUILT_IN[cls]
    assert (cls.config_key, cls.colour_key, cls.name_pattern) == (key, colour, pattern)
    assert cls.derived_attributes == derived
    assert methods.schema()["properties"][key] is cls.schema


def test_the_on_off_families_schemas_and_the_n_traj_families():
    assert NBO.schema == {
        "description": "Run the NBO planner (the baseline of every comparison).",
        "type": "boolean",
    }
    assert list(SigmaPoints.schema) == ["description", "type"]
    assert SigmaPoints.schema["type"] == "boolean"
    assert all(issubclass(c, OnOffMethod) for c in (NBO, SigmaPoints))
    assert all(issubclass(c, NTrajMethod) for c in (MonteCarlo, RQMC, Antithetic))
    labels = [c(16).label() for c in (MonteCarlo, RQMC, Antithetic)]
    assert labels == ["RS-MHP N_T=16", "RQMC N_T=16", "antithetic N_T=16"]
    assert [NBO().label(), SigmaPoints().label()] == ["NBO", "sigma points"]


# ------------------------------------------------------------- a minimal family of each kind


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


def _independent(belief, setup, rng, n):
    states, noise = target.draw_independent(
        belief.x_hat, belief.P_hat, setup.planner.horizon, n, setup.target, rng
    )
    return Hypotheses.equal(states, noise)


@dataclass(frozen=True)
class Minimal(NTrajMethod):
    """Only what an N_T family must write."""

    family: ClassVar[str] = "minimal"
    schema: ClassVar[dict[str, Any]] = {
        "type": "array",
        "items": {"type": "integer", "minimum": 1, "maximum": 1000},
    }
    default: ClassVar[Any] = []
    family_label: ClassVar[str] = "minimal"
    colour_key: ClassVar[str] = "#7a5195"  # the palette has no key "minimal"
    order: ClassVar[int] = 90

    def hypotheses(self, belief, setup, rng) -> Hypotheses:
        return _independent(belief, setup, rng, self.n_traj)


def test_a_minimal_n_traj_family_gets_the_derived_attributes(local_registry):
    assert Minimal.derived_attributes == {"config_key", "name_pattern"}
    assert (Minimal.config_key, Minimal.name_pattern) == ("minimal_nt", r"minimal_nt(\d+)")
    local_registry(Minimal)
    got = methods.from_config({"nbo": False, "minimal_nt": [16, 4]})
    assert list(got) == ["minimal_nt4", "minimal_nt16"]
    m = got["minimal_nt16"]
    assert m == Minimal(16) and methods.from_name("minimal_nt16") == m
    assert m.label() == "minimal N_T=16" and m.shade_size() == 16
    assert m.columns() == {"N_T": 16, "N": 0, "M": 0}
    assert m.job_key() == {"method": "minimal_nt16", "N_T": 16, "N": None, "M": None}
    assert m.spec() == {"family": "minimal", "n_traj": 16}
    assert methods.from_spec(m.spec()) == m
    assert member_colour(m) == method_colour("minimal_nt16") == size_shade("#7a5195", 16)
    assert Minimal(4.0).n_traj == 4 and type(Minimal(4.0).n_traj) is int
    with pytest.raises(ValueError, match=r"methods\.minimal_nt\[1\] must be >= 1, got 0"):
        methods.from_config({"minimal_nt": [4, 0]})
    with pytest.raises(TypeError, match=r"methods\.minimal_nt must be a list or tuple"):
        Minimal.from_config(4, "methods.minimal_nt")
    assert check_method(Minimal).members == ("minimal_nt4", "minimal_nt8")


def test_a_minimal_family_gets_its_config_key_and_colour_key_from_its_family(local_registry):
    @dataclass(frozen=True)
    class Nominal(Method):
        """Only what a general family must write: one member planning on the nominal future
        with a weight field."""

        w: int

        family: ClassVar[str] = "rsmhp_per_step"  # a palette key: its colour_key is derived
        schema: ClassVar[dict[str, Any]] = {"type": "array", "items": {"type": "integer"}}
        default: ClassVar[Any] = []
        family_label: ClassVar[str] = "nominal"
        order: ClassVar[int] = 92
        name_pattern: ClassVar[str] = r"nominal_w(\d+)"
        n_traj: ClassVar[int] = 1
        uses_rng: ClassVar[bool] = False

        @classmethod
        def from_config(cls, value, path):
            return [cls(int(w)) for w in value]

        @property
        def name(self) -> str:
            return f"nominal_w{self.w}"

        def hypotheses(self, belief, setup, rng) -> Hypotheses:
            H = setup.planner.horizon
            return Hypotheses.equal(target.nominal(belief.x_hat, H, setup.target))

    assert Nominal.derived_attributes == {"config_key", "colour_key"}
    assert (Nominal.config_key, Nominal.colour_key) == ("rsmhp_per_step", "rsmhp_per_step")
    # a family id of a built-in family: refused, naming both
    with pytest.raises(
        ValueError, match=r"'rsmhp_per_step' .*Nominal.*clashes with .*MonteCarloPerStep"
    ):
        methods.register(Nominal)

    class Renamed(Nominal):
        family = "nominal"
        colour_key = "#7a5195"

    # derived afresh from the subclass's family; written values inherited
    assert (Renamed.config_key, Renamed.colour_key) == ("nominal", "#7a5195")
    assert Renamed.derived_attributes == {"config_key"}
    assert Renamed.name_pattern == r"nominal_w(\d+)"
    local_registry(Renamed)
    assert methods.from_name("nominal_w3") == Renamed(3)


def test_written_attributes_win_and_are_inherited():
    @dataclass(frozen=True)
    class Own(MonteCarlo):
        family: ClassVar[str] = "own"
        config_key: ClassVar[str] = "own_samples"
        colour_key: ClassVar[str] = "sobol"

    assert Own.derived_attributes == {"name_pattern"}
    assert Own(8).name == "own_samples8" and Own.parse("own_samples8") == Own(8)
    assert Own.parse("rsmhp_nt8") is None and MonteCarlo.parse("own_samples8") is None

    class Sub(Own):
        family = "sub"

    # config_key and colour_key written by Own: inherited; name_pattern follows config_key
    assert (Sub.config_key, Sub.colour_key) == ("own_samples", "sobol")
    assert Sub.parse("own_samples8") == Sub(8)
    assert MonteCarlo.config_key == "rsmhp_nt"  # the base is left as it was


# ------------------------------------------------------------------------ on/off families


@dataclass(frozen=True)
class Switch(OnOffMethod):
    """Only what an on/off family must write: NBO's nominal future under another name."""

    family: ClassVar[str] = "switch"
    description: ClassVar[str] = "Run the switch planner."
    default: ClassVar[Any] = False
    family_label: ClassVar[str] = "switch"
    colour_key: ClassVar[str] = "#7a5195"
    order: ClassVar[int] = 93
    n_traj: ClassVar[int] = 1
    uses_rng: ClassVar[bool] = False

    def hypotheses(self, belief, setup, rng) -> Hypotheses:
        H = setup.planner.horizon
        return Hypotheses(
            target.nominal(belief.x_hat, H, setup.target), np.ones(1), np.zeros((1, H + 1, 4))
        )


def test_an_on_off_family_round_trips_config_members_and_names(local_registry):
    assert Switch.derived_attributes == {"config_key", "name_pattern", "schema"}
    assert Switch.schema == {"description": "Run the switch planner.", "type": "boolean"}
    assert (Switch.config_key, Switch.name_pattern) == ("switch", "switch")
    assert Switch.from_config(True, "m.switch") == [Switch()]
    assert Switch.from_config(np.bool_(False), "m.switch") == []
    with pytest.raises(TypeError, match=r"m\.switch must be a bool or bool, got str 'yes'"):
        Switch.from_config("yes", "m.switch")
    (m,) = Switch.from_config(True, "m.switch")
    assert m.name == "switch" and Switch.parse(m.name) == m
    assert Switch.parse("switch1") is None and Switch.parse("nbo") is None
    assert m.label() == "switch" and m.shade_size() is None and m.spec() == {"family": "switch"}

    local_registry(Switch)
    assert methods.schema()["properties"]["switch"] is Switch.schema
    assert "switch" not in methods.from_config({})  # default False: off
    got = methods.from_config({"switch": True})
    assert list(got) == ["nbo", "switch"] and methods.count({"switch": True}) == 2
    assert methods.from_name("switch") == got["switch"] == methods.from_spec(m.spec())
    assert check_method(Switch).members == ("switch",)


# ------------------------------------------------------------------ what register refuses


def _family(base: type[Method] = NTrajMethod, **attrs: Any) -> type[Method]:
    """A dataclass family ``Broken`` on ``base`` with Minimal's attributes, then ``attrs``
    (a value ``...`` leaves the attribute out)."""
    body = {k: getattr(Minimal, k) for k in ("schema", "default", "family_label", "order")}
    body |= {"family": "broken", "colour_key": "#7a5195", "hypotheses": Minimal.hypotheses}
    body["__module__"] = __name__
    body |= attrs
    body = {k: v for k, v in body.items() if v is not ...}
    return dataclass(frozen=True)(type("Broken", (base,), body))


@pytest.mark.parametrize(
    "attrs,message",
    [
        ({"order": ...}, r"class attribute missing: 'order' \(the family's position"),
        ({"family": ...}, r"missing: 'family' \(.*\); 'config_key' \(derived from family"),
        ({"schema": ..., "default": ...}, r"attributes missing: 'schema' \(.*\); 'default'"),
        ({"family_label": ...}, r"missing: 'family_label'"),
        ({"hypotheses": ...}, r"abstract method\(s\) \['hypotheses'\] not implemented"),
        ({"family": "bad family"}, r"'family' must be a non-empty string of \[A-Za-z0-9_\]"),
        ({"config_key": ""}, r"'config_key' must be a non-empty string"),
        ({"order": 1.5}, r"'order' must be an int, got 1\.5"),
        ({"order": True}, r"'order' must be an int, got True"),
        ({"uses_rng": 1}, r"'uses_rng' must be a bool, got 1"),
        ({"schema": [1]}, r"'schema' must be a mapping"),
        ({"family_label": " "}, r"'family_label' must be a non-empty string"),
        ({"colour_key": None}, r"'colour_key' must be a string"),
        ({"name_pattern": "broken_nt(\\d+"}, r"'name_pattern' 'broken_nt\(\\\\d\+': missing \)"),
    ],
    ids=lambda x: str(x)[:40],
)
def test_register_names_the_class_and_the_attribute(attrs, message):
    before = methods.families()
    cls = _family(**attrs)
    with pytest.raises(
        TypeError,
        match=r"method family class Broken \(module tests\.models\.uav\.test_method_defaults\): .*"
        + message,
    ):
        methods.register(cls)
    assert methods.families() == before


def test_register_asks_for_what_a_general_or_on_off_family_must_write(local_registry):
    before = methods.families()
    # a general family: n_traj, and name_pattern unless it parses names itself
    reads = classmethod(lambda c, value, path: [])
    general = _family(Method, from_config=reads, name="broken")
    with pytest.raises(TypeError, match=r"missing: 'n_traj' \(.*\); 'name_pattern' \(.*own parse"):
        methods.register(general)
    # an on/off family without description has no schema
    switch = {k: getattr(Switch, k) for k in ("default", "n_traj", "hypotheses")}
    with pytest.raises(TypeError, match=r"missing: 'schema' \(.*OnOffMethod writes description"):
        methods.register(_family(OnOffMethod, **switch, schema=...))
    assert methods.families() == before
    # with n_traj and its own parse, nothing is missing
    parses = classmethod(lambda c, name: None)
    local_registry(_family(Method, n_traj=0, from_config=reads, name="b", parse=parses))
