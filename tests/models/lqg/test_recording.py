"""The LQG tree recording, read back headless with rerun.chunk.RrdReader."""

from __future__ import annotations

import numpy as np
from rerun.chunk import RrdReader

from rsmhp.models.lqg.recording import record_lqg_tree


def entity_rows(path) -> dict[str, int]:
    counts: dict[str, int] = {}
    for chunk in RrdReader(path).store().stream():
        counts[chunk.entity_path] = counts.get(chunk.entity_path, 0) + chunk.num_rows
    return counts


def test_tree_recording_contents(tmp_path, paper_params):
    path = tmp_path / "tree.rrd"
    u = np.array([0.55, 0.17, 0.3, 0.3])
    logged = record_lqg_tree(path, paper_params, u, n_branch=4, max_keep=4, seed=1)
    reader = RrdReader(path)
    assert len(reader.recordings()) == 1 and len(reader.blueprints()) == 1
    rows = entity_rows(path)
    for entity, n in logged.items():
        assert rows["/" + entity] == n
    H = len(u)
    for k in range(1, H + 1):
        assert rows[f"/tree/level_{k}/kept"] == 1 and rows[f"/tree/level_{k}/nodes"] == 1
    # level 1 has N = 4 <= M nodes: nothing pruned; later levels have 16 > 4 children
    assert "/tree/level_1/pruned" not in rows
    assert all(rows[f"/tree/level_{k}/pruned"] == 1 for k in range(2, H + 1))
    # running estimates: one static series style + one value per step 0..H
    assert rows["/estimate/uniform"] == 1 + H + 1
    assert rows["/description"] == 1


def test_recording_is_deterministic(tmp_path, paper_params):
    u = np.array([0.5, 0.2, 0.1])
    a = record_lqg_tree(tmp_path / "a.rrd", paper_params, u, 3, 2, seed=5)
    b = record_lqg_tree(tmp_path / "b.rrd", paper_params, u, 3, 2, seed=5)
    assert a == b
    ids = {
        r.recording_id for p in ("a", "b") for r in RrdReader(tmp_path / f"{p}.rrd").recordings()
    }
    assert len(ids) == 1
