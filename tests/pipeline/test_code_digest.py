"""rsmhp.pipeline.code_digest: the digest of the code a rule script can import (static, transitive,
normalised), and its use by the workflow (every rule's `code` param)."""

from __future__ import annotations

import re
import shutil
import textwrap
from pathlib import Path

import pytest

from rsmhp.pipeline import code_digest as cd
from rsmhp.pipeline.code_digest import DIGEST_LENGTH, code_digest, describe, workflow_src

ROOT = Path(__file__).resolve().parents[2]

PACKAGE = {
    "__init__.py": '"""The package."""\n',
    "a.py": "from rsmhp.b import g\n\n\ndef f(x):\n    return g(x) + 1  # plus one\n",
    "b.py": "from . import c\n\n\ndef g(x):\n    return c.h(x)\n",
    "c.py": "def h(x):\n    return 2 * x\n",
    "d.py": "def unused():\n    return 'never imported'\n",
    "lazy.py": "def late():\n    from rsmhp.sub import e\n\n    return e.E\n",
    "sub/__init__.py": "",
    "sub/e.py": "E = 3\n",
    "reg/__init__.py": (
        "import importlib\nimport pkgutil\n\n"
        "for info in pkgutil.iter_modules(__path__):\n"
        "    importlib.import_module(f'{__name__}.{info.name}')\n"
    ),
    "reg/one.py": "ONE = 1\n",
    "reg/two.py": "TWO = 2\n",
}


def _write(root: Path, files: dict[str, str]) -> None:
    for rel, text in files.items():
        path = root / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)


@pytest.fixture
def tree(tmp_path) -> tuple[Path, Path]:
    """A small rsmhp package under tmp/src and a script importing part of it."""
    src = tmp_path / "src"
    _write(src / "rsmhp", PACKAGE)
    script = tmp_path / "workflow" / "scripts" / "rule_a.py"
    script.parent.mkdir(parents=True)
    script.write_text("from rsmhp.a import f\nimport rsmhp.lazy\n\nprint(f(1))\n")
    return script, src


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new))


def test_transitive_closure_follows_absolute_relative_and_lazy_imports(tree):
    script, src = tree
    d = describe(script, src)
    assert set(d.modules) == {
        "rule_a.py",
        "rsmhp",  # a parent package's __init__ runs on import
        "rsmhp.a",
        "rsmhp.b",  # from rsmhp.a
        "rsmhp.c",  # relative import in rsmhp.b
        "rsmhp.lazy",
        "rsmhp.sub",
        "rsmhp.sub.e",  # imported inside a function
    }
    assert re.fullmatch(rf"[0-9a-f]{{{DIGEST_LENGTH}}}", d.digest)
    assert str(d) == d.digest == code_digest(script, src)


def test_a_registry_that_imports_by_computed_name_counts_as_importing_its_package(tree):
    script, src = tree
    script.write_text("from rsmhp import reg\n")
    assert set(describe(script, src).modules) == {
        "rule_a.py",
        "rsmhp",
        "rsmhp.reg",
        "rsmhp.reg.one",
        "rsmhp.reg.two",
    }
    before = code_digest(script, src)
    _edit(src / "rsmhp/reg/two.py", "TWO = 2", "TWO = 22")
    assert code_digest(script, src) != before


def test_comments_and_formatting_keep_the_digest(tree):
    script, src = tree
    before = describe(script, src)
    _edit(src / "rsmhp/a.py", "# plus one", "# add one (a comment only)")
    _edit(src / "rsmhp/c.py", "return 2 * x", "return (\n        2\n        * x  # split\n    )")
    _edit(src / "rsmhp/d.py", "'never imported'", '"never imported"')
    _edit(script, "print(f(1))\n", "\n# a comment\nprint( f( 1 ) )\n")
    assert describe(script, src) == before


@pytest.mark.parametrize(
    ("rel", "old", "new", "module"),
    [
        ("c.py", "2 * x", "3 * x", "rsmhp.c"),  # code, two imports away
        ("c.py", "def h", "def helper():\n    return 0\n\n\ndef h", "rsmhp.c"),  # new function
        ("__init__.py", "The package.", "The package, documented.", "rsmhp"),  # a docstring
        ("sub/e.py", "E = 3", "E = 4", "rsmhp.sub.e"),  # reached through a lazy import only
    ],
)
def test_a_change_of_imported_code_changes_the_digest(tree, rel, old, new, module):
    script, src = tree
    before = describe(script, src)
    _edit(src / "rsmhp" / rel, old, new)
    after = describe(script, src)
    assert after.digest != before.digest
    assert {m for m in after.modules if after.modules[m] != before.modules[m]} == {module}


def test_a_module_the_script_does_not_import_leaves_the_digest(tree):
    script, src = tree
    before = code_digest(script, src)
    _edit(src / "rsmhp/d.py", "'never imported'", "'still never imported, now edited'")
    (src / "rsmhp/new_module.py").write_text("X = 1\n")
    assert code_digest(script, src) == before


def test_the_digest_does_not_depend_on_where_the_checkout_is(tree, tmp_path):
    script, src = tree
    copy = tmp_path / "elsewhere"
    shutil.copytree(src.parent, copy)
    assert code_digest(copy / "workflow/scripts/rule_a.py", copy / "src") == code_digest(
        script, src
    )
    assert workflow_src(copy / "workflow/scripts") == (copy / "src").resolve()


def test_the_disk_cache_is_keyed_by_content(tree, monkeypatch):
    """A second process (simulated: empty in-process caches) reads the analysis from
    src/rsmhp/__pycache__; an edit is analysed again, never served from the cache."""
    script, src = tree
    before = code_digest(script, src)
    assert list((src / "rsmhp/__pycache__").glob("code_digest.*.json"))
    monkeypatch.setattr(cd, "_DISK", {})
    cd._analyse_source.cache_clear()
    calls = []
    real = cd._analyse_source.__wrapped__
    monkeypatch.setattr(cd, "_analyse_source", lambda *a: calls.append(a[1]) or real(*a))
    assert code_digest(script, src) == before and calls == []
    _edit(src / "rsmhp/c.py", "2 * x", "5 * x")
    assert code_digest(script, src) != before and calls == ["rsmhp.c"]


def test_a_missing_script_is_named(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"no_such_script\.py"):
        code_digest(tmp_path / "no_such_script.py", tmp_path)


# ------------------------------------------------------------------ the workflow's use


def _rule_blocks() -> dict[str, str]:
    return cd.rule_blocks(ROOT / "workflow")


def test_every_rule_with_a_script_carries_the_digest_of_that_script():
    """A rule that runs package code without a `code` param would never rerun on a change; a
    rule that restricts its digest to some method families passes the same families as its
    `families` param (the job checks its code with them)."""
    blocks = _rule_blocks()
    scripted = {r: b for r, b in blocks.items() if "script:" in b}
    assert len(scripted) >= 20
    restricted = 0
    for rule, block in scripted.items():
        script = re.search(r'script:\s*\n\s*"\.\./scripts/(\w+\.py)"', block).group(1)
        whole = f'code=code_digest("workflow/scripts/{script}")' in block
        m = re.search(
            r'code=(?:lambda wc: )?code_digest\(\s*"workflow/scripts/'
            + re.escape(script)
            + r'",\s*(.+?)\s*\),\n',
            block,
            re.S,
        )
        assert whole or m, rule
        if m:
            restricted += 1
            fams = re.search(r"families=(?:lambda wc: )?(.+?),\n", block)
            assert fams and fams.group(1).strip() == m.group(1).strip(), rule
    assert restricted >= 10  # every rule that runs UAV planners


def test_every_rule_script_hands_the_snakemake_object_to_rule_logging():
    """rule_logging(snakemake) checks the inputs' code and stamps the outputs."""
    for script in sorted((ROOT / "workflow/scripts").glob("*.py")):
        assert "with rule_logging(snakemake)" in script.read_text(), script.name


def test_the_real_scripts_import_only_what_they_need():
    """The LQG and estimator rules (simulations, summaries, figures, recordings) do not depend
    on the UAV model (editing it reruns none of them), and every script depends on the io
    layer that stamps its outputs."""
    src = ROOT / "src"
    for name in (
        "lqg_convergence", "lqg_nbo_error", "lqg_summary", "lqg_figures", "tree_recording",
        "estimators_ablation", "estimators_summary", "estimators_figures", "decisions_lqg",
    ):  # fmt: skip
        mods = describe(ROOT / f"workflow/scripts/{name}.py", src).modules
        assert not any(m.startswith("rsmhp.models.uav") for m in mods), name
        assert "rsmhp.pipeline.io" in mods and "rsmhp.pipeline.script" in mods
    uav = describe(ROOT / "workflow/scripts/uav_simulate.py", src).modules
    assert "rsmhp.models.uav.kinematics" in uav and "rsmhp.analysis" not in uav


def test_an_import_docstring_example_in_a_module_is_not_an_import(tmp_path):
    """Only import statements and import calls count, not text that looks like one."""
    src = tmp_path / "src"
    _write(src / "rsmhp", {"__init__.py": "", "x.py": '"""import rsmhp.y"""\n', "y.py": ""})
    script = tmp_path / "s.py"
    script.write_text(textwrap.dedent("import rsmhp.x\n"))
    assert set(describe(script, src).modules) == {"s.py", "rsmhp", "rsmhp.x"}


def test_only_restricts_a_dynamic_registry_to_the_named_modules(tree):
    """A job that runs some method families counts only their modules of the registry:
    adding or editing another family's module leaves its digest alone."""
    _, src = tree
    script = src.parent / "workflow/scripts/rule_reg.py"
    script.write_text("from rsmhp import reg\n")
    only = {"rsmhp.reg": ["rsmhp.reg.one"]}
    full, restricted = describe(script, src), describe(script, src, only)
    assert {"rsmhp.reg.one", "rsmhp.reg.two"} <= set(full.modules)
    assert "rsmhp.reg.one" in restricted.modules and "rsmhp.reg.two" not in restricted.modules
    (src / "rsmhp/reg/three.py").write_text("THREE = 3\n")
    _edit(src / "rsmhp/reg/two.py", "TWO = 2", "TWO = 22")
    assert describe(script, src, only).digest == restricted.digest
    assert describe(script, src).digest != full.digest
    _edit(src / "rsmhp/reg/one.py", "ONE = 1", "ONE = 11")
    assert describe(script, src, only).digest != restricted.digest
    with pytest.raises(ValueError, match="not modules of it"):
        describe(script, src, {"rsmhp.reg": ["rsmhp.other"]})
    assert cd.method_only(["nbo", "monte_carlo"]) == {
        cd.METHOD_REGISTRY: [f"{cd.METHOD_REGISTRY}.monte_carlo", f"{cd.METHOD_REGISTRY}.nbo"]
    }
    assert cd.split_stamp_rule("uav_simulate+monte_carlo,nbo") == (
        "uav_simulate",
        ["monte_carlo", "nbo"],
    )
    assert cd.split_stamp_rule("report") == ("report", None)


def test_a_template_counts_for_the_modules_that_render_it(tree):
    """A Markdown template beside a module is code of the modules naming it (rendering it),
    not of the other modules of that folder: a prose edit reruns no simulation."""
    _, src = tree
    _write(
        src / "rsmhp",
        {
            "st/__init__.py": "",
            "st/simulate.py": "def run():\n    return 1\n",
            "st/section.py": "from rsmhp.st import simulate\n\nNAME = 'section.md'\n",
            "st/section.md": "The {{ value }} of the study.\n",
        },
    )
    scripts = src.parent / "workflow/scripts"
    sim, summary = scripts / "sim.py", scripts / "summary.py"
    sim.write_text("from rsmhp.st import simulate\n")
    summary.write_text("from rsmhp.st import section\n")
    before_sim, before_summary = describe(sim, src), describe(summary, src)
    assert "rsmhp.st/section.md" in before_summary.modules
    assert not any(k.endswith(".md") for k in before_sim.modules)
    _edit(src / "rsmhp/st/section.md", "The {{ value }}", "A {{ value }}")
    assert describe(sim, src).digest == before_sim.digest
    assert describe(summary, src).digest != before_summary.digest


def test_module_lookups_see_a_module_added_or_removed_after_them(tree):
    """_locate remembers its answers while the directories they depend on keep their
    modification times: adding or removing a module (or turning it into a package) is seen."""
    import os

    script, src = tree
    script.write_text("import rsmhp.sub.late\n")
    assert "rsmhp.sub.late" not in describe(script, src).modules  # not there yet

    def bump(path: Path) -> None:  # file systems with coarse clocks: make the change visible
        st = os.stat(path)
        os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 10_000_000))

    (src / "rsmhp/sub/late.py").write_text("L = 1\n")
    bump(src / "rsmhp/sub")
    assert "rsmhp.sub.late" in describe(script, src).modules
    (src / "rsmhp/sub/late.py").unlink()
    bump(src / "rsmhp/sub")
    (src / "rsmhp/sub/late").mkdir()
    (src / "rsmhp/sub/late/__init__.py").write_text("P = 2\n")
    bump(src / "rsmhp/sub")
    found = cd._locate("rsmhp.sub.late", src)
    assert found == (src / "rsmhp/sub/late/__init__.py", True)
    shutil.rmtree(src / "rsmhp/sub/late")
    bump(src / "rsmhp/sub")
    assert cd._locate("rsmhp.sub.late", src) is None
    assert "rsmhp.sub.late" not in describe(script, src).modules
