"""The house rules of the package layout, checked on the real import graph (every ``import``
and ``from ... import`` of every module, at module level or inside functions, parsed with
:mod:`ast`; nothing is imported):

* a study (``rsmhp.studies.<study>``) never imports another study;
* inside a study, ``simulate*`` never imports its ``claims*``, ``section*`` or ``figures*``;
* ``rsmhp.core`` imports nothing of rsmhp outside core, and the models never import a study;
* one name per study: its package, its rule file ``workflow/rules/<study>.smk`` and its test
  folder ``tests/studies/<study>/``.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src"
STUDIES = sorted(p.name for p in (SRC / "rsmhp/studies").iterdir() if (p / "__init__.py").is_file())


def _module_name(path: Path) -> str:
    parts = path.relative_to(SRC).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports_of(path: Path) -> set[str]:
    """Every rsmhp module or name ``path`` imports (``from a.b import c`` gives ``a.b`` and
    ``a.b.c``; relative imports resolved)."""
    name = _module_name(path)
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join([*package[: len(package) - node.level + 1], *filter(None, [base])])
            out.add(base)
            out.update(f"{base}.{a.name}" for a in node.names)
    return {m for m in out if m.split(".")[0] == "rsmhp"}


GRAPH = {_module_name(p): imports_of(p) for p in sorted((SRC / "rsmhp").rglob("*.py"))}


def _study(module: str) -> str | None:
    parts = module.split(".")
    return parts[2] if len(parts) > 2 and parts[1] == "studies" else None


def test_the_graph_is_real():
    """The parser sees what is there: a known edge in each direction of interest."""
    assert "rsmhp.models.uav.simulation" in GRAPH["rsmhp.studies.uav.simulate"]
    assert "rsmhp.studies.uav.summarise" in GRAPH["rsmhp.studies.uav.section"]
    assert len(STUDIES) >= 7 and len(GRAPH) > 90


def test_no_study_imports_another_study():
    crossing = sorted(
        f"{m} -> {i}"
        for m, imports in GRAPH.items()
        if (s := _study(m))
        for i in imports
        if (t := _study(i)) and t != s
    )
    assert not crossing, "a study imports another study:\n" + "\n".join(crossing)


@pytest.mark.parametrize("study", STUDIES)
def test_simulation_never_imports_claims_section_or_figures(study):
    presentation = ("claims", "section", "figures")
    bad = sorted(
        f"{m} -> {i}"
        for m, imports in GRAPH.items()
        if m.startswith(f"rsmhp.studies.{study}.simulate")
        for i in imports
        if _study(i) == study and len(i.split(".")) > 3 and i.split(".")[3].startswith(presentation)
    )
    assert not bad, bad


def test_core_and_models_stay_below_the_studies():
    bad = sorted(
        f"{m} -> {i}"
        for m, imports in GRAPH.items()
        for i in imports
        if (m.startswith("rsmhp.core") and not i.startswith("rsmhp.core") and i != "rsmhp")
        or (m.startswith("rsmhp.models") and _study(i))
    )
    assert not bad, bad


def test_a_study_keeps_one_name():
    """Package, rule file and test folder carry the study's name."""
    rules = {p.stem for p in (ROOT / "workflow/rules").glob("*.smk")}
    tests = {p.name for p in (ROOT / "tests/studies").iterdir() if p.is_dir()}
    assert set(STUDIES) <= rules, set(STUDIES) - rules
    assert set(STUDIES) <= tests, set(STUDIES) - tests


def test_the_rules_catch_a_crossing(tmp_path):
    """The checks can fail: a planted cross-study import is seen by the parser."""
    planted = tmp_path / "src/rsmhp/studies/uav/x.py"
    planted.parent.mkdir(parents=True)
    planted.write_text("def f():\n    from rsmhp.studies.lqg import claims\n    return claims\n")
    global SRC
    saved, SRC = SRC, tmp_path / "src"
    try:
        found = imports_of(planted)
    finally:
        SRC = saved
    assert "rsmhp.studies.lqg.claims" in found and _study("rsmhp.studies.lqg.claims") == "lqg"


# ------------------------------------------------------------------ a study's code in its folder


def test_the_layers_below_never_import_a_study():
    """core, models, pipeline and report never import a study by name: the pipeline finds the
    studies' checks by package (rsmhp.pipeline.config.studies), as the registry finds families."""
    below = ("rsmhp.core", "rsmhp.models", "rsmhp.pipeline", "rsmhp.report")
    bad = sorted(
        f"{m} -> {i}"
        for m, imports in GRAPH.items()
        if m.startswith(below)
        for i in imports
        if _study(i)
    )
    assert not bad, bad


def test_every_study_with_cross_field_checks_owns_them():
    """A study's config checks live in its package (``checks.config_problems``); the
    pipeline's config module names no study section in its messages, only the shared ones
    (``uav``, the UAV model every UAV study builds on, and ``uav_models``) and the keys that
    moved."""
    from rsmhp.pipeline.config import studies

    found = studies()
    assert set(found) == set(STUDIES) - {"scenarios"}, found  # scenarios: the schema suffices
    tree = ast.parse((SRC / "rsmhp/pipeline/config.py").read_text(encoding="utf-8"))
    named = sorted(
        {
            f"{s}: {node.value[:60]!r}"
            for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str)
            for s in STUDIES
            if s != "uav" and f"{s}." in node.value and "moved" not in node.value
        }
    )
    assert not named, named
    resources = (SRC / "rsmhp/pipeline/resources.py").read_text(encoding="utf-8")
    assert "rsmhp.studies" not in "".join(i for i in GRAPH["rsmhp.pipeline.resources"])
    assert "working_sets" in resources


def _users(module: str) -> tuple[set[str], set[str]]:
    """(studies, other modules outside ``module``) that import ``module`` or a name in it."""
    studies, others = set(), set()
    for m, imports in GRAPH.items():
        if module in imports or any(
            i.rpartition(".")[0] == module and i not in GRAPH for i in imports
        ):
            if s := _study(m):
                studies.add(s)
            elif not m.startswith(module):
                others.add(m)
    return studies, others


#: model modules that the method registry imports by name (every study reaches them through it)
_REGISTERED = "rsmhp.models.uav.methods."


def _model_modules() -> list[str]:
    return [
        m
        for m in GRAPH
        if m.startswith("rsmhp.models.")
        and not (SRC / (m.replace(".", "/") + "/__init__.py")).is_file()  # not a package
        and not m.startswith(_REGISTERED)
    ]


@pytest.mark.parametrize("module", _model_modules())
def test_a_model_module_lives_where_its_users_are(module):
    """A model module that one study alone uses belongs in that study; one that several
    studies use stays below them, and its docstring names each of them."""
    studies, others = _users(module)
    if len(studies) == 1 and not others:
        pytest.fail(f"{module} is used by the {studies.pop()} study alone: move it into that study")
    if len(studies) >= 2:
        doc = (
            ast.get_docstring(ast.parse((SRC / (module.replace(".", "/") + ".py")).read_text()))
            or ""
        )
        missing = sorted(s for s in studies if f"rsmhp.studies.{s}" not in doc)
        assert not missing, f"{module}'s docstring does not name its users {missing}"


# ------------------------------------------------------------------ rule files share explicitly

RULES = ROOT / "workflow/rules"
_ASSIGNED = re.compile(r"^([A-Z][A-Z0-9_]*)\s*=", re.M)
_USED = re.compile(r"\b([A-Z][A-Z0-9_]{2,})\b")


def _globals(path: Path) -> set[str]:
    return set(_ASSIGNED.findall(path.read_text(encoding="utf-8")))


def _strip_strings(text: str) -> str:
    """The text without comments and docstring lines (names there are prose, not reads)."""
    lines = [line.split("#", 1)[0] for line in text.splitlines()]
    return "\n".join(line for line in lines if not line.strip().startswith(('"""', "'")))


def test_a_rule_file_reads_only_its_own_and_the_shared_globals():
    """What several rule files need is defined once in common.smk (included first); no rule
    file reads a global that another study's rule file defines, so the include order of the
    study files does not matter."""
    files = sorted(RULES.glob("*.smk"))
    defined = {f.name: _globals(f) for f in files}
    shared = defined["common.smk"]
    owner = {n: f for f, names in defined.items() if f != "common.smk" for n in names}
    bad = sorted(
        f"{f.name} reads {n} of {owner[n]}"
        for f in files
        if f.name != "common.smk"
        for n in set(_USED.findall(_strip_strings(f.read_text(encoding="utf-8"))))
        if n in owner and owner[n] != f.name and n not in shared
    )
    assert not bad, bad
    clash = sorted(n for n, f in owner.items() if n in shared)
    assert not clash, f"defined both in common.smk and a study's rule file: {clash}"
    snakefile = (ROOT / "Snakefile").read_text(encoding="utf-8")
    includes = re.findall(r'include: "workflow/rules/(\w+)\.smk"', snakefile)
    assert includes[0] == "common", includes


def test_no_rule_file_reads_a_file_when_parsed():
    """A rule file reads published files (paper/) as a rule's input, never when the workflow
    is parsed (no open, json.load or read_text). The one exception is a package function:
    make compare's pre-flight check of the published reference
    (rsmhp.studies.frontier.reference.compare_problems), which refuses a comparison that would
    not pair before any job."""
    bad = sorted(
        f"{f.name}: {pat}"
        for f in RULES.glob("*.smk")
        for pat in ("open(", "json.load", "read_text(", "load_reference(", "yaml.safe_load")
        if pat in _strip_strings(f.read_text(encoding="utf-8"))
    )
    assert not bad, bad


def test_the_rule_file_check_can_fail(tmp_path):
    """The parser sees a planted cross-file read."""
    a = tmp_path / "a.smk"
    a.write_text("FOO_JOBS = [1]\n")
    b = tmp_path / "b.smk"
    b.write_text('rule x:\n    input: expand("{j}", j=FOO_JOBS)\n')
    assert "FOO_JOBS" in _globals(a) and "FOO_JOBS" in _USED.findall(_strip_strings(b.read_text()))


def _rsmhp_imports(paths) -> set[str]:
    """The rsmhp modules the files ``paths`` import at their top level (``from``/``import``)."""
    found: set[str] = set()
    for path in paths:
        found |= set(re.findall(r"^(?:from|import) (rsmhp[\w.]*)", path.read_text(), re.M))
    return found


def _loaded_by_importing(modules: set[str], heavy: tuple[str, ...]) -> str:
    """Which of ``heavy`` a fresh Python process has loaded after importing ``modules`` (the
    sorted list as printed)."""
    import subprocess
    import sys

    code = (
        f"import importlib, sys\nfor m in {sorted(modules)!r}: importlib.import_module(m)\n"
        f"print(sorted(m for m in {heavy!r} if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return out.stdout.strip()


#: the UAV simulation rules: their scripts' imports leave scipy.stats and scipy.optimize out
UAV_SIMULATION_SCRIPTS = (
    "uav_simulate", "uav_recording", "decisions_uav", "decisions_map_cell", "frontier_confirm",
    "frontier_confirm_timing", "frontier_explore", "frontier_explore_timing", "horizon_uav",
    "horizon_uav_closed", "horizon_optimiser",
)  # fmt: skip


def test_a_uav_simulation_job_does_not_import_scipy_stats_or_optimize():
    """What a UAV simulation job imports leaves scipy.stats and scipy.optimize unloaded, the
    example plugin included (each costs every job ~0.4 s at start; the planner's scipy
    oracle, the Sobol' direction numbers and Spearman's rho import them when first used)."""
    scripts = [ROOT / "workflow" / "scripts" / f"{name}.py" for name in UAV_SIMULATION_SCRIPTS]
    modules = _rsmhp_imports(scripts)
    assert "rsmhp.studies.uav.simulate" in modules, modules
    assert _loaded_by_importing(modules, ("scipy.stats", "scipy.optimize")) == "[]"


def test_parsing_the_workflow_imports_no_plotting_or_scipy_submodule():
    """What the Snakefile and the rule files import when Snakemake parses them leaves
    matplotlib, seaborn and scipy's stats, optimize and integrate unloaded (about 1.2 s a
    parse, paid by every snakemake command and by every job of a cluster run): a rule file
    takes its outputs' names from its study's package, not from its figure or section code."""
    rules = sorted((ROOT / "workflow" / "rules").glob("*.smk"))
    modules = _rsmhp_imports([ROOT / "Snakefile", *rules])
    assert {"rsmhp.studies.frontier", "rsmhp.pipeline.config"} <= modules, modules
    heavy = ("matplotlib", "seaborn", "scipy.stats", "scipy.optimize", "scipy.integrate")
    assert _loaded_by_importing(modules, heavy) == "[]"


def test_the_import_check_can_fail():
    """The check above sees a heavy module that an import brings along."""
    assert _loaded_by_importing({"rsmhp.studies.frontier.figures"}, ("seaborn",)) == "['seaborn']"
