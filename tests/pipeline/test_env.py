"""The conda environment of the rules (``snakemake --use-conda``) holds every runtime
dependency of the package: a job run there imports what the project's virtual environment
has."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]


def _name(requirement: str) -> str:
    """The distribution name of a requirement (``numpy>=2.0,<3`` -> ``numpy``), with conda's
    ``-base`` variants mapped to their package (``matplotlib-base`` -> ``matplotlib``)."""
    name = re.split(r"[\s<>=!~\[;]", requirement.strip(), maxsplit=1)[0].lower()
    return name.removesuffix("-base")


def test_the_conda_environment_holds_every_runtime_dependency():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    needed = {_name(r) for r in project["dependencies"]} - {"snakemake"}  # the runner itself
    env = yaml.safe_load((ROOT / "workflow/envs/rsmhp.yaml").read_text())
    have = set()
    for dep in env["dependencies"]:
        if isinstance(dep, dict):
            have |= {_name(r) for r in dep.get("pip", [])}
        else:
            have.add(_name(dep))
    assert {"numpy", "numba", "jinja2", "filterpy"} <= needed
    assert needed <= have, sorted(needed - have)
