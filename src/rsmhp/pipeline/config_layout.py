"""What changed in the config's layout, apart from the checks (:mod:`rsmhp.pipeline.config`)
so that the report's provenance can use it without importing them: keys that moved
(:data:`MOVED`), keys added with the value the code used before (:data:`ADDED`), and the view
of a config its hash is taken of (:func:`hash_view`).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from typing import Any

__all__ = ["ADDED", "MOVED", "hash_view"]

#: config keys that moved, with where they went: a config that still has one is refused with a
#: message saying so (before the schema, which would only call the key unknown)
MOVED = {
    ("decisions", "uav", "models"): "uav_models (the UAV model variants every UAV study reads)",
}


#: config keys added after version 4 whose value was fixed in the code before: a config that
#: has this value hashes as if the key did not exist (:func:`hash_view`)
ADDED = {("scenarios", "bootstrap"): 2000}


def hash_view(config: Mapping[str, Any]) -> dict[str, Any]:
    """The config as its hash (``config sha256``, :mod:`rsmhp.report.provenance`; what ``make
    verify`` compares) sees it: keys of :data:`MOVED` back at their old place and keys of
    :data:`ADDED` that hold their old fixed value left out, so that a change of the config's
    layout alone is no change of configuration and the committed reference still compares.
    Any other value, and any changed value of these keys, changes the hash as before."""
    view = copy.deepcopy(dict(config))
    for old, where in MOVED.items():
        new = where.split(" ", 1)[0].split(".")
        node: Any = view
        for key in new[:-1]:
            node = node.get(key) if isinstance(node, Mapping) else None
        if not isinstance(node, dict) or new[-1] not in node:
            continue
        value = node.pop(new[-1])
        target = view
        for key in old[:-1]:
            target = target.setdefault(key, {})
        target[old[-1]] = value
    for path, value in ADDED.items():
        node = view
        for key in path[:-1]:
            node = node.get(key) if isinstance(node, Mapping) else None
        if isinstance(node, dict) and node.get(path[-1]) == value:
            del node[path[-1]]
            parent = view
            for key in path[:-2]:
                parent = parent[key]
            if not node:
                del parent[path[-2]]
    return view
