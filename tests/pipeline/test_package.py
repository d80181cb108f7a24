"""The package docstring lists every module (help(rsmhp) is the map of the library)."""

from __future__ import annotations

import pkgutil
import re

import rsmhp


def test_package_docstring_lists_every_module():
    listed = set(re.findall(r"^\s{2}(\w+)\s{2,}", rsmhp.__doc__, flags=re.M))
    top = {m.name for m in pkgutil.iter_modules(rsmhp.__path__)}
    assert top <= listed, sorted(top - listed)
    for pkg in ("experiments", "analysis", "figures", "uav"):
        mod = __import__(f"rsmhp.{pkg}", fromlist=["_"])
        for sub in pkgutil.iter_modules(mod.__path__):
            assert sub.name in rsmhp.__doc__, f"rsmhp.{pkg}.{sub.name}"


def test_readme_library_example_runs_and_prints_what_the_readme_says():
    import contextlib
    import io
    import os
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    text = (root / "README.md").read_text()
    section = text.split("## Using the library", 1)[1]
    code = section.split("```python\n", 1)[1].split("```", 1)[0]
    printed = section.split("which prints", 1)[1].split("```\n", 1)[1].split("```", 1)[0]
    out = io.StringIO()
    cwd = os.getcwd()
    try:
        os.chdir(root)
        with contextlib.redirect_stdout(out):
            exec(compile(code, "README.md", "exec"), {})
    finally:
        os.chdir(cwd)
    assert out.getvalue() == printed
