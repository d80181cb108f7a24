"""The worked example of docs/adding-a-study.md, run end to end on a copy of the workflow.

Every block of the guide marked ``<!-- study:file PATH -->`` is written to PATH in a copy of the
workflow under a temporary directory, and every block marked ``<!-- study:edit PATH -->`` goes
into PATH where the guide says (the schema's ``properties``, the end of config.yaml, before
config/README.md's method families, before the Snakefile's ``report.smk``). Then, with the
copy's src/ first on PYTHONPATH (so that ``rsmhp.studies.coinflip`` is importable):

* the new code is lint-clean (ruff, ruff format, snakefmt) and the templates keep to 100 columns;
* ``snakemake -n results/report/coinflip.json`` plans exactly the two new rules, and
  ``snakemake -j1 coinflip`` runs them: the section JSON holds claim COIN-1 with the verdict,
  numbers, rule and sentences the guide states, and the report's appendix renders it;
* the house rules hold on the copy: tests/pipeline/test_layout.py and the study's own tests
  pass there, ``rsmhp.pipeline.config.studies()`` finds the study's checks, and bad values of
  the new section are refused naming the field (the guide's overlay prints what it shows).

The study exists only in the guide and the copy.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest
import yaml

from rsmhp.report.templates import CONTINUATION

ROOT = Path(__file__).resolve().parents[2]
GUIDE = ROOT / "docs" / "adding-a-study.md"
STUDY = "coinflip"
pytestmark = pytest.mark.workflow

#: a marked block: its kind, its path and its text (the fence's body)
BLOCK = re.compile(r"<!-- study:(file|edit) (\S+) -->\n```[\w-]*\n(.*?)^```$", re.S | re.M)
#: the files the guide adds, and the existing files it edits
NEW_FILES = {
    *(
        f"src/rsmhp/studies/{STUDY}/{name}"
        for name in (
            "__init__.py",
            "checks.py",
            "simulate.py",
            "summarise.py",
            "claims.py",
            "claims.md",
            "section.py",
            "section.md",
        )
    ),
    f"workflow/rules/{STUDY}.smk",
    f"workflow/scripts/{STUDY}_simulate.py",
    f"workflow/scripts/{STUDY}_summary.py",
    f"tests/studies/{STUDY}/__init__.py",
    f"tests/studies/{STUDY}/test_{STUDY}_study.py",
}
EDITED = {
    "workflow/schemas/config.schema.yaml",
    "config/config.yaml",
    "config/README.md",
    "Snakefile",
}
RULES = {f"{STUDY}_simulate", f"{STUDY}_summary"}


def _text() -> str:
    return GUIDE.read_text(encoding="utf-8")


def _blocks() -> tuple[dict[str, str], dict[str, str]]:
    """(new files, edits): path -> text of the guide's marked blocks, each path once."""
    files: dict[str, str] = {}
    edits: dict[str, str] = {}
    for kind, path, body in BLOCK.findall(_text()):
        into = files if kind == "file" else edits
        assert path not in into, f"docs/adding-a-study.md: two blocks for {path}"
        into[path] = body
    return files, edits


def _marked(name: str) -> str:
    """The fenced block after ``<!-- study:<name> -->``."""
    m = re.search(rf"<!-- study:{name} -->\n```[\w-]*\n(.*?)^```$", _text(), re.S | re.M)
    assert m, f"docs/adding-a-study.md: the study:{name} block is missing"
    return m.group(1)


def _macro(template: str, name: str) -> str:
    """A macro's text as :class:`rsmhp.report.templates.Words` renders it (no values)."""
    m = re.search(rf"{{% macro {name}\(\) %}}\n(.*?){{% endmacro %}}", template, re.S)
    assert m, f"no macro {name} in claims.md"
    return CONTINUATION.sub(" ", m.group(1)).strip()


def _edit(wf: Path, path: str, block: str) -> None:
    """Add the guide's ``block`` to the copy's ``path`` where the guide says."""
    target = wf / path
    text = target.read_text(encoding="utf-8")
    if path == "workflow/schemas/config.schema.yaml":
        schema = yaml.safe_load(text)
        section = yaml.safe_load(textwrap.dedent(block))
        assert set(section) == {STUDY} and STUDY not in schema["properties"]
        schema["properties"].update(section)
        text = yaml.safe_dump(schema, sort_keys=False, allow_unicode=True, width=1000)
    elif path == "config/config.yaml":
        text = text.rstrip("\n") + "\n\n" + block
    elif path == "config/README.md":
        assert text.count("\n## Method families") == 1
        text = text.replace("\n## Method families", "\n" + block + "\n## Method families")
    elif path == "Snakefile":
        anchor = 'include: "workflow/rules/report.smk"'
        assert text.count(anchor) == 1
        text = text.replace(anchor, block + anchor)
    else:
        raise AssertionError(f"the test does not know where to add a block to {path}")
    target.write_text(text, encoding="utf-8")


def _env(wf: Path) -> dict[str, str]:
    """The environment with the copy's src/ first on the path."""
    path = [str(wf / "src"), *filter(None, [os.environ.get("PYTHONPATH")])]
    return {**os.environ, "PYTHONPATH": os.pathsep.join(path)}


def _run(wf: Path, *cmd: str | Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(c) for c in cmd], cwd=wf, env=_env(wf), capture_output=True, text=True, timeout=600
    )


def _tool(name: str) -> Path:
    """An executable of this environment (ruff, snakefmt)."""
    exe = Path(sys.executable).parent / name
    if not exe.is_file():
        pytest.skip(f"{name} is not installed next to {sys.executable}")
    return exe


@pytest.fixture(scope="module")
def wf(tmp_path_factory) -> Path:
    """A copy of the workflow (Snakefile, workflow/, config/, src/, the layout test and the
    study test folders) with the guide's files and edits applied."""
    wf = tmp_path_factory.mktemp("adding_a_study")
    for name in ("Snakefile", "pyproject.toml"):
        shutil.copy2(ROOT / name, wf / name)
    skip = shutil.ignore_patterns("*.pyc", "*.egg-info", "*.nbi", "*.nbc", ".snakemake")
    for d in ("workflow", "config", "src"):
        shutil.copytree(ROOT / d, wf / d, ignore=skip)
    for f in ("__init__.py", "conftest.py", "pipeline/__init__.py", "pipeline/test_layout.py"):
        (wf / "tests" / f).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / "tests" / f, wf / "tests" / f)
    (wf / "tests/studies").mkdir()
    shutil.copy2(ROOT / "tests/studies/__init__.py", wf / "tests/studies/__init__.py")
    for study in (ROOT / "tests/studies").iterdir():
        if study.is_dir() and study.name != "__pycache__":
            (wf / "tests/studies" / study.name).mkdir()  # the layout test looks at the names
    files, edits = _blocks()
    for path, body in files.items():
        assert not (wf / path).exists(), f"{path} exists already: the guide's study is not new"
        (wf / path).parent.mkdir(parents=True, exist_ok=True)
        (wf / path).write_text(body, encoding="utf-8")
    for path, body in edits.items():
        _edit(wf, path, body)
    return wf


def test_the_guide_marks_every_place_and_its_config_blocks_agree():
    files, edits = _blocks()
    assert set(files) == NEW_FILES
    assert set(edits) == EDITED
    section = yaml.safe_load(textwrap.dedent(edits["workflow/schemas/config.schema.yaml"]))[STUDY]
    values = yaml.safe_load(edits["config/config.yaml"])[STUDY]
    assert set(values) == set(section["properties"])
    readme = edits["config/README.md"]
    for key, spec in section["properties"].items():
        assert spec["minimum"] <= values[key] <= spec["maximum"]
        row = f"| `{STUDY}.{key}` | {spec['type']} | `{spec['default']}` |"
        assert row in readme, row
    assert not (ROOT / "src/rsmhp/studies" / STUDY).exists()  # it lives in the guide only


def test_the_new_code_is_lint_clean(wf):
    files, _ = _blocks()
    python = sorted(p for p in files if p.endswith(".py"))
    res = _run(wf, _tool("ruff"), "check", "--no-cache", *python)
    assert res.returncode == 0, res.stdout + res.stderr
    res = _run(wf, _tool("ruff"), "format", "--check", "--no-cache", *python)
    assert res.returncode == 0, res.stdout + res.stderr
    res = _run(wf, _tool("snakefmt"), "--check", f"workflow/rules/{STUDY}.smk")
    assert res.returncode == 0, res.stdout + res.stderr
    for path in (p for p in files if p.endswith(".md")):
        long = [n for n, line in enumerate(files[path].splitlines(), 1) if len(line) > 100]
        assert not long, f"{path}: lines {long} are longer than 100 characters"


def test_snakemake_plans_and_runs_the_new_rules_and_reports_the_claim(wf):
    section = f"results/report/{STUDY}.json"
    res = _run(wf, sys.executable, "-m", "snakemake", "-n", section)
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-3000:]
    stats = out.split("Job stats:", 1)[1].split("\ntotal", 1)[0]
    assert set(re.findall(r"^(\w+)\s+1$", stats, flags=re.M)) == RULES, stats

    res = _run(wf, sys.executable, "-m", "snakemake", "-j1", STUDY)
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-3000:]
    # the summary rule wrote the section the rule file registers for the report rule
    smk = (wf / f"workflow/rules/{STUDY}.smk").read_text(encoding="utf-8")
    assert f'REPORT_SECTIONS["{STUDY}"] = "{section}"' in smk
    data = json.loads((wf / section).read_text(encoding="utf-8"))
    assert data["key"] == STUDY and data["code"].startswith(f"{STUDY}_summary:")
    (claim,) = data["claims"]
    files, _ = _blocks()
    words = files[f"src/rsmhp/studies/{STUDY}/claims.md"]
    rule = f"{_macro(words, 'coin_1_rule_basis')}: supported if "
    rule += f"{_macro(words, 'coin_1_rule_supported')}; not supported otherwise"
    assert claim["id"] == "COIN-1" and claim["verdict"] == "supported"
    assert (claim["claim"], claim["paper"], claim["rule"]) == (
        _macro(words, "coin_1_claim"),
        _macro(words, "coin_1_paper"),
        rule,
    )
    assert (claim["part"], claim["check"]) == ("beyond", True)

    # the key number is the share of heads of the simulated table, and the guide says so
    table = pd.read_csv(wf / f"results/{STUDY}/flips.csv")
    assert table["flips"].sum() == 10000 and len(table) == 10
    key = claim["key"]
    assert key["value"] == table["heads"].sum() / table["flips"].sum()
    assert key["ci_low"] <= 0.5 <= key["ci_high"]
    guide = " ".join(_text().split())
    assert claim["measured"] in guide, claim["measured"]
    shown = f"{key['value']:.3f} [{key['ci_low']:.3f}, {key['ci_high']:.3f}]"
    assert shown in guide, shown

    # the report renders the section: the claim among the checks, and in detail
    code = (
        "from rsmhp.report.ledger import Section\n"
        "from rsmhp.report.render import render_appendix\n"
        f"print(render_appendix([Section.load({section!r})], {{}}, {{}}))\n"
    )
    res = _run(wf, sys.executable, "-c", code)
    assert res.returncode == 0, res.stderr[-3000:]
    assert "### COIN-1" in res.stdout and data["title"] in res.stdout


def test_the_house_rules_hold_on_the_copy(wf):
    res = _run(
        wf,
        sys.executable,
        "-m",
        "pytest",
        "-q",
        "-p",
        "no:cacheprovider",
        "tests/pipeline/test_layout.py",
        f"tests/studies/{STUDY}",
    )
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-2000:]
    assert re.search(r"\b\d+ passed\b", res.stdout) and "failed" not in res.stdout

    # the pipeline finds the study's checks; the schema refuses a bad value, naming it
    code = (
        "from rsmhp.pipeline.config import ConfigError, check_config, load_config_file, studies\n"
        "print(studies())\n"
        "config = load_config_file('config/config.yaml')\n"
        f"config[{STUDY!r}] = {{'flips': 5, 'chunks': 5}}\n"
        "try:\n"
        "    check_config(config)\n"
        "except ConfigError as exc:\n"
        "    print(exc)\n"
    )
    res = _run(wf, sys.executable, "-c", code)
    assert res.returncode == 0, res.stderr[-3000:]
    assert f"'{STUDY}'" in res.stdout.splitlines()[0]
    assert f"{STUDY}.flips: 5 is invalid" in res.stdout
    assert f"{STUDY}.chunks: unknown key" in res.stdout

    # the guide's bad overlay prints what the guide shows
    overlay = wf / "bad.yaml"
    overlay.write_text(_marked("bad-config"), encoding="utf-8")
    res = _run(wf, sys.executable, "-m", "rsmhp.pipeline.config", overlay)
    assert res.returncode == 1, res.stdout + res.stderr
    assert _marked("bad-config-output") in res.stderr, res.stderr
