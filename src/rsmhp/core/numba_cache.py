"""Invalidate numba's on-disk cache of a module whose compiled code inlines another module's.

numba's cache (``cache=True``) is keyed on the source file of each cached function only: when
``rsmhp/models/uav/fused.py``'s compiled planning step inlines :func:`rsmhp.core.boxqn.minimise`,
an edit of ``boxqn.py`` leaves the cached planning step as it was, and every later process would run
the old optimiser without a word. :func:`invalidate_if_changed` closes that gap: it keeps, in
the cache directory, a digest of the dependencies' source files, and when the digest changes
removes the dependent module's cache files (index ``.nbi`` and data ``.nbc``) before anything
is compiled or loaded, so that numba recompiles from the current sources.

Concurrent processes (``snakemake -j2``) may both remove and rewrite: removal of a file
another process is about to load makes that process compile instead (numba treats a missing
cache entry as a miss), so the race costs time, never correctness.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path
from types import ModuleType

__all__ = ["invalidate_if_changed"]


def _digest(modules: list[ModuleType]) -> str:
    h = hashlib.blake2b(digest_size=16)
    for mod in modules:
        path = Path(mod.__file__ or "")
        h.update(path.name.encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def invalidate_if_changed(dispatcher, dependencies: list[ModuleType]) -> bool:
    """Remove the cache files of ``dispatcher``'s module when the sources of
    ``dependencies`` changed since the stamp was written (then rewrite the stamp). Returns
    whether files were removed. Call at import of the dependent module, before its first
    compiled call. A cache directory that cannot be written is left alone (numba then
    compiles in memory, or uses its user-wide cache, whose stamp this also maintains)."""
    cache = getattr(dispatcher, "_cache", None)
    cache_dir = getattr(cache, "_cache_path", None)
    if cache_dir is None:
        return False
    module = Path(dispatcher.py_func.__code__.co_filename).stem
    stamp = Path(cache_dir) / f"{module}.deps"
    digest = _digest(dependencies)
    try:
        if stamp.is_file() and stamp.read_text() == digest:
            return False
        removed = False
        for f in Path(cache_dir).glob(f"{module}.*.nb[ic]"):
            f.unlink(missing_ok=True)
            removed = True
        Path(cache_dir).mkdir(parents=True, exist_ok=True)
        tmp = stamp.with_suffix(f".deps.{os.getpid()}")
        tmp.write_text(digest)
        os.replace(tmp, stamp)
        return removed
    except OSError:
        return False
