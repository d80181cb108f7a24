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
