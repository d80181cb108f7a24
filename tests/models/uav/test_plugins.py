"""Method plugins: families that installed packages register through the entry-point group
``rsmhp.methods`` (``rsmhp.models.uav.methods.load_plugins``, run when the registry is built).

Each test installs toy distributions the way pip does (a ``*.dist-info`` directory with
``METADATA`` and ``entry_points.txt`` and their modules, in a directory put first on
``sys.path``), so ``importlib.metadata.entry_points(group="rsmhp.methods")`` finds them; the
registry is restored afterwards.

* an entry point naming a module that registers its family with ``@register``, or naming a
  ``Method`` subclass, adds the family: listed by ``plugins()`` with its distribution and
  version, inert unless configured, accepted in the config's ``methods`` blocks and passing
  ``check_method``;
* a family or config key that is taken is refused with a ``ValueError`` naming both packages
  (the plugin's distribution and ``rsmhp``, or the other plugin's distribution);
* a plugin that fails to import, registers nothing or is not inert raises ``PluginError``
  naming the entry point and the distribution, and registers nothing; importing the registry
  with it installed fails with that message as the last line;
* the example plugin (``examples/rsmhp-plugin-example``) is found when installed, also when
  its module is imported before the registry.
"""

from __future__ import annotations

import copy
import importlib.metadata
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
import yaml

from rsmhp.models.uav import methods
from rsmhp.models.uav.methods import PluginError
from rsmhp.pipeline.config import ConfigError, check_config
from rsmhp.testing import check_method

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


def toy_module(family: str, key: str, *, register: bool = True, default: str = "[]") -> str:
    """Source of a plugin module defining the family ``family`` (config key ``key``): Monte
    Carlo under other names, decorated with ``@register`` unless ``register`` is False."""
    return textwrap.dedent(
        f'''
        from dataclasses import dataclass
        from typing import Any, ClassVar

        from rsmhp.models.uav.methods import register
        from rsmhp.models.uav.methods.monte_carlo import MonteCarlo


        @dataclass(frozen=True)
        class ToyPlug(MonteCarlo):
            family: ClassVar[str] = "{family}"
            config_key: ClassVar[str] = "{key}"
            default: ClassVar[Any] = {default}
            family_label: ClassVar[str] = "toy plugin"
            colour_key: ClassVar[str] = "#7a5195"
            order: ClassVar[int] = 95
            name_pattern: ClassVar[str] = r"{family}_nt(\\d+)"

            @property
            def name(self) -> str:
                return f"{family}_nt{{self.n_traj}}"


        if {register}:
            ToyPlug = register(ToyPlug)
        '''
    )


@pytest.fixture
def install(tmp_path, monkeypatch):
    """``install(name, entry_points, modules)``: a toy distribution ``name`` 0.3 with the
    ``rsmhp.methods`` entry points ``{name: value}`` and the modules ``{module: source}``.
    The registry, its plugins and ``sys.modules`` are restored afterwards."""
    saved = (
        dict(methods._FAMILIES),
        dict(methods._PLUGINS),
        list(methods._ENTRY_POINTS),
    )
    before = methods.families()
    modules_before = set(sys.modules)
    monkeypatch.syspath_prepend(str(tmp_path))

    def install(name: str, entry_points: dict[str, str], modules: dict[str, str]) -> None:
        info = tmp_path / f"{name.replace('-', '_')}-0.3.dist-info"
        info.mkdir()
        (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: 0.3\n")
        lines = "".join(f"{k} = {v}\n" for k, v in entry_points.items())
        (info / "entry_points.txt").write_text(f"[rsmhp.methods]\n{lines}")
        for module, source in modules.items():
            (tmp_path / f"{module}.py").write_text(source)

    yield install
    for registry, old in zip(
        (methods._FAMILIES, methods._PLUGINS, methods._ENTRY_POINTS), saved, strict=True
    ):
        registry.clear()
        registry.update(old) if isinstance(registry, dict) else registry.extend(old)
    for name in set(sys.modules) - modules_before:
        if name.startswith("rsmhp_toy"):
            del sys.modules[name]
    assert methods.families() == before


def test_an_entry_point_naming_a_module_registers_its_family(install):
    install("rsmhp-toy-plugin", {"toy": "rsmhp_toy_a"}, {"rsmhp_toy_a": toy_module("ta", "ta_nt")})
    assert "ta" not in {c.family for c in methods.families()}
    found = {p.family: p for p in methods.load_plugins()}
    plugin = found["ta"]
    assert (plugin.distribution, plugin.version) == ("rsmhp-toy-plugin", "0.3")
    assert plugin.entry_point == "toy = rsmhp_toy_a" and plugin.config_key == "ta_nt"
    assert plugin.cls in methods.families() and plugin.cls.__module__ == "rsmhp_toy_a"
    # inert unless configured; then built, named and checked like a built-in family
    assert not any(m.family == "ta" for m in methods.from_config({}).values())
    assert list(methods.from_config({"nbo": True, "ta_nt": [4]})) == ["nbo", "ta_nt4"]
    assert methods.from_name("ta_nt4") == plugin.cls(4)
    check_method(plugin.cls)
    # loading again changes nothing
    assert methods.load_plugins() == methods.plugins()


def test_the_config_accepts_a_plugin_key_in_its_methods_blocks(install):
    install("rsmhp-toy-plugin", {"toy": "rsmhp_toy_b"}, {"rsmhp_toy_b": toy_module("tb", "tb_nt")})
    methods.load_plugins()
    cfg = copy.deepcopy(CONFIG)
    cfg["uav"]["methods"]["tb_nt"] = [8]
    cfg["decisions"]["uav"]["methods"]["tb_nt"] = [8]
    check_config(cfg)
    cfg["uav"]["methods"]["tb_nt"] = [0]
    with pytest.raises(ConfigError, match=r"uav\.methods\.tb_nt\[0\]: 0 is invalid"):
        check_config(cfg)


def test_an_entry_point_naming_a_method_class_registers_it(install):
    source = toy_module("tc", "tc_nt", register=False)
    install("rsmhp-toy-plugin", {"toy": "rsmhp_toy_c:ToyPlug"}, {"rsmhp_toy_c": source})
    found = {p.family: p for p in methods.load_plugins()}
    assert found["tc"].entry_point == "toy = rsmhp_toy_c:ToyPlug"
    assert found["tc"].cls.__name__ == "ToyPlug" and found["tc"].cls in methods.families()


def test_a_taken_config_key_is_refused_naming_both_packages(install):
    source = toy_module("td", "rsmhp_nt")
    install("rsmhp-toy-plugin", {"toy": "rsmhp_toy_d"}, {"rsmhp_toy_d": source})
    with pytest.raises(ValueError) as info:
        methods.load_plugins()
    message = str(info.value)
    assert not isinstance(info.value, PluginError)
    assert "distribution 'rsmhp-toy-plugin' (entry point 'toy = rsmhp_toy_d')" in message
    assert "clashes with the registered MonteCarlo ('rsmhp', 'rsmhp_nt') of package 'rsmhp'" in (
        message
    )
    assert "td" not in {c.family for c in methods.families()}


def test_a_family_taken_by_another_plugin_is_refused_naming_both_distributions(install):
    install("rsmhp-toy-first", {"first": "rsmhp_toy_e1"}, {"rsmhp_toy_e1": toy_module("te", "e1")})
    second = toy_module("te", "e2")  # the same class name and family, another package
    install("rsmhp-toy-second", {"second": "rsmhp_toy_e2"}, {"rsmhp_toy_e2": second})
    with pytest.raises(ValueError, match="clashes") as info:
        methods.load_plugins()  # by distribution name: first, then second
    message = str(info.value)
    assert "of distribution 'rsmhp-toy-second' (entry point 'second = rsmhp_toy_e2')" in message
    assert "of distribution 'rsmhp-toy-first' (entry point 'first = rsmhp_toy_e1')" in message
    assert methods.plugins()[-1].distribution == "rsmhp-toy-first"  # the first one stays


@pytest.mark.parametrize(
    "value,source,cause",
    [
        ("rsmhp_toy_missing", None, r"ModuleNotFoundError: No module named 'rsmhp_toy_missing'"),
        ("rsmhp_toy_f", "raise RuntimeError('boom')", r"RuntimeError: boom"),
        ("rsmhp_toy_f:Nothing", "x = 1", r"AttributeError: .*Nothing"),
        ("rsmhp_toy_f:x", "x = 1", r"TypeError: it names 1, neither a module nor a Method"),
        ("rsmhp_toy_f", "x = 1", r"TypeError: it registers no method family"),
    ],
    ids=["missing module", "import raises", "missing class", "not a class", "registers nothing"],
)
def test_a_plugin_that_fails_to_load_names_its_entry_point_and_distribution(
    install, value, source, cause
):
    install(
        "rsmhp-toy-broken", {"broken": value}, {} if source is None else {"rsmhp_toy_f": source}
    )
    where = rf"method plugin entry point 'broken = {value}' \(group 'rsmhp\.methods'\) of "
    where += r"distribution 'rsmhp-toy-broken' 0\.3 failed to load: "
    with pytest.raises(PluginError, match=where + cause + r".*pip uninstall rsmhp-toy-broken"):
        methods.load_plugins()


def test_a_failed_plugin_registers_nothing(install):
    """A module that registers one family and then fails leaves the registry as it was."""
    source = toy_module("tg", "tg_nt") + "\nraise RuntimeError('late failure')\n"
    install("rsmhp-toy-broken", {"broken": "rsmhp_toy_g"}, {"rsmhp_toy_g": source})
    with pytest.raises(PluginError, match="late failure"):
        methods.load_plugins()
    assert "tg" not in {c.family for c in methods.families()}
    assert "tg" not in {p.family for p in methods.plugins()}


def test_a_plugin_family_must_be_inert_unless_configured(install):
    source = toy_module("th", "th_nt", default="[4]")
    install("rsmhp-toy-plugin", {"toy": "rsmhp_toy_h"}, {"rsmhp_toy_h": source})
    with pytest.raises(PluginError, match=r"a plugin family's default must configure no member"):
        methods.load_plugins()
    assert "th" not in {c.family for c in methods.families()}


def test_a_broken_plugin_stops_the_registry_import_with_a_clear_last_line(tmp_path):
    info = tmp_path / "rsmhp_toy_broken-0.3.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: rsmhp-toy-broken\nVersion: 0.3\n")
    (info / "entry_points.txt").write_text("[rsmhp.methods]\nbroken = rsmhp_toy_nowhere\n")
    env = {"PYTHONPATH": str(tmp_path), "PATH": "/usr/bin:/bin"}
    res = subprocess.run(
        [sys.executable, "-c", "import rsmhp.models.uav.methods"],
        capture_output=True,
        text=True,
        env=env,
        check=False,
    )
    assert res.returncode != 0
    last = res.stderr.strip().splitlines()[-1]
    assert last.startswith("rsmhp.models.uav.methods.PluginError: method plugin entry point ")
    assert "'broken = rsmhp_toy_nowhere'" in last and "'rsmhp-toy-broken' 0.3" in last
    assert "No module named 'rsmhp_toy_nowhere'" in last


def _example_installed() -> bool:
    try:
        importlib.metadata.distribution("rsmhp-plugin-example")
    except importlib.metadata.PackageNotFoundError:
        return False
    return True


needs_example = pytest.mark.skipif(
    not _example_installed(),
    reason="the example plugin is not installed in this environment "
    "(pip install -e examples/rsmhp-plugin-example; make test installs it)",
)


@needs_example
def test_the_installed_example_plugin_is_found():
    found = {p.family: p for p in methods.plugins()}
    plugin = found["lhs"]
    assert plugin.distribution == "rsmhp-plugin-example" and plugin.config_key == "lhs_nt"
    assert plugin.entry_point == "example = rsmhp_plugin_example.stratified"
    assert plugin.cls.__module__ == "rsmhp_plugin_example.stratified"
    assert plugin.cls.default == []
    # inert: the paper's methods are what they were
    got = methods.from_config(CONFIG["uav"]["methods"], "uav.methods")
    assert list(got) == ["nbo", "rsmhp_nt50", "rsmhp_nt100", "rsmhp_nt250", "tree_n8_m100"]
    cfg = copy.deepcopy(CONFIG)
    cfg["uav"]["methods"]["lhs_nt"] = [64]
    check_config(cfg)
    assert methods.from_name("lhs_nt64").label() == "LHS N_T=64"


@needs_example
def test_the_example_plugin_module_imported_first_is_still_its_distributions():
    """Importing the plugin's module before the registry (which then loads the entry point
    while the module is still being imported) attributes the family all the same."""
    code = (
        "import rsmhp_plugin_example.stratified as s\n"
        "from rsmhp.models.uav import methods\n"
        "p = {p.family: p for p in methods.plugins()}['lhs']\n"
        "assert p.cls is s.Stratified and methods.from_name('lhs_nt8') == s.Stratified(8)\n"
        "print(p.distribution)\n"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert res.returncode == 0, res.stderr[-2000:]
    assert res.stdout.strip() == "rsmhp-plugin-example"
