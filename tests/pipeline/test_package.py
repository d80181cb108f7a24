"""The package docstring lists every module (help(rsmhp) is the map of the library)."""

from __future__ import annotations

import pkgutil
import re

import rsmhp


def test_package_docstring_lists_every_module():
    """Every sub-package and module of the layers and every study is named in the map."""
    listed = set(re.findall(r"^\s{2}(\w+)\s{2,}", rsmhp.__doc__, flags=re.M))
    top = {m.name for m in pkgutil.iter_modules(rsmhp.__path__)}
    assert top <= listed, sorted(top - listed)
    words = set(re.findall(r"\w+", rsmhp.__doc__))
    for pkg in ("core", "models.lqg", "models.uav", "pipeline", "report", "studies"):
        mod = __import__(f"rsmhp.{pkg}", fromlist=["_"])
        for sub in pkgutil.iter_modules(mod.__path__):
            assert sub.name in words, f"rsmhp.{pkg}.{sub.name}"


def test_docs_library_example_runs_and_prints_what_the_docs_say():
    """The example of docs/methods.md's "Using the library" prints what the page shows."""
    import contextlib
    import io
    import os
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    text = (root / "docs" / "methods.md").read_text(encoding="utf-8")
    section = text.split("## Using the library", 1)[1]
    code = section.split("```python\n", 1)[1].split("```", 1)[0]
    printed = section.split("which prints", 1)[1].split("```\n", 1)[1].split("```", 1)[0]
    out = io.StringIO()
    cwd = os.getcwd()
    try:
        os.chdir(root)
        with contextlib.redirect_stdout(out):
            exec(compile(code, "docs/methods.md", "exec"), {})
    finally:
        os.chdir(cwd)
    assert out.getvalue() == printed
