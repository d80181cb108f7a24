"""rsmhp.core.numba_cache: numba's cache of a module is dropped when a module it inlines changes."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from rsmhp.core import numba_cache

DEP = "from numba import njit\n\n@njit(inline='always')\ndef k():\n    return {value}\n"
USER = textwrap.dedent(
    """
    from numba import njit
    import dep
    from rsmhp.core import numba_cache

    @njit(cache=True)
    def run():
        return dep.k()

    numba_cache.invalidate_if_changed(run, [dep])
    print(run())
    """
)


def _run(tmp: Path) -> str:
    env_path = f"{tmp}:{Path(numba_cache.__file__).parents[2]}"
    out = subprocess.run(
        [sys.executable, "-c", "import user"],
        cwd=tmp,
        env={"PYTHONPATH": env_path, "PATH": "/usr/bin:/bin"},
        capture_output=True,
        text=True,
        check=True,
    )
    return out.stdout.strip()


@pytest.mark.compile
def test_an_edit_of_an_inlined_module_recompiles_the_cached_caller(tmp_path):
    """Without the stamp numba would load the cached run() and print the old value."""
    (tmp_path / "dep.py").write_text(DEP.format(value=1))
    (tmp_path / "user.py").write_text(USER)
    assert _run(tmp_path) == "1"
    assert _run(tmp_path) == "1"  # loaded from the cache
    cached = list((tmp_path / "__pycache__").glob("user.*.nb[ic]"))
    assert cached, "numba wrote no cache"
    (tmp_path / "dep.py").write_text(DEP.format(value=2))
    assert _run(tmp_path) == "2"
    assert (tmp_path / "__pycache__" / "user.deps").is_file()


def test_no_cache_directory_is_a_no_op():
    class Plain:
        _cache = None

    assert numba_cache.invalidate_if_changed(Plain(), [numba_cache]) is False
