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
        if _study(i) == study and i.split(".")[3].startswith(presentation)
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
