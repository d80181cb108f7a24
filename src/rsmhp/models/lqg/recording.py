"""Rerun recordings of sampled trajectory trees (open with ``rerun <file>.rrd``).

Layout of a tree recording (timeline ``step``, one tick per tree level):

* ``tree/level_<k>/kept``    LineStrips2D: edges (k-1, x_parent) -> (k, x_child) that survived
  pruning (orange, the pruned tree's colour of :mod:`rsmhp.report.palette`); every level is its own
  entity so earlier levels stay visible
* ``tree/level_<k>/pruned``  LineStrips2D: edges dropped by pruning (thin, grey)
* ``tree/level_<k>/nodes``   Points2D: children; radius and colour (viridis, bright = likely)
  encode the trajectory likeliness within the level; pruned nodes are drawn grey
* ``pruning``                TextLog: per level, children, kept, and the likeliness cut-off
* ``estimate/uniform``, ``estimate/weighted``  Scalars: running estimate of J after level k
* ``estimate/exact``, ``estimate/nbo``  Scalars: the closed-form references
* ``description``  TextDocument (static): parameters and how to read the view

The *running estimate* after level ``k`` averages, over the kept nodes, the exact conditional
expected cost-to-go from that node, :math:`\\sum_{j<k}u_j^2 + E[g | x_k]`, which equals J at
``k = 0`` and the MHP estimate of the (pruned) tree at ``k = H``.
"""

from __future__ import annotations

import os
import uuid
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from rsmhp.core.cost_estimators import likeliness_weights
from rsmhp.core.sampling import sample_tree
from rsmhp.core.seeding import canonical_job_id, job_rng
from rsmhp.models.lqg import oven as lqg
from rsmhp.report.palette import method_rgb

__all__ = ["record_lqg_tree", "tree_blueprint"]

#: kept edges in the pruned tree's method colour (rsmhp.report.palette, as in every figure); dropped
#: edges and nodes grey; the running estimates: pruned tree (uniform), a lighter shade of it
#: (weighted), NBO in its method colour, the exact J light grey (the viewer is dark)
KEPT = method_rgb("pruned")
PRUNED = (150, 150, 150, 120)
ROOT = (230, 230, 230)
SERIES = {
    "exact": (230, 230, 230),
    "nbo": method_rgb("nbo"),
    "uniform": method_rgb("pruned"),
    "weighted": (240, 196, 120),
}


def tree_blueprint() -> rrb.Blueprint:
    """Tree on the left, running estimates and the description on the right."""
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Spatial2DView(origin="/tree", name="sampled tree: state x_k vs step k"),
            rrb.Vertical(
                rrb.TimeSeriesView(origin="/estimate", name="running estimate of J"),
                rrb.TextLogView(origin="/pruning", name="pruning log"),
                rrb.TextDocumentView(origin="/description", name="about"),
                row_shares=[3, 1, 1],
            ),
            column_shares=[3, 2],
        ),
        rrb.TimePanel(state="expanded"),
        collapse_panels=False,
    )


def _cost_to_go(x: np.ndarray, k: int, u: np.ndarray, params: lqg.LQGModel) -> np.ndarray:
    """:math:`\\sum_{j<k}u_j^2 + E[r(x_H-T)^2 + \\sum_{j>=k}u_j^2 | x_k]` for each node."""
    spent = float(np.dot(u[:k], u[:k]))
    if k == len(u):
        return spent + params.r * (x - params.target) ** 2
    kw = {"a": params.a, "r": params.r, "target": params.target, "sigma": params.sigma}
    return np.array([spent + lqg.exact_cost(u[k:], x0=float(xi), **kw) for xi in x])


def record_lqg_tree(
    path: str | os.PathLike,
    params: lqg.LQGModel,
    u: np.ndarray,
    n_branch: int,
    max_keep: int | None,
    seed: int,
    experiment: str = "lqg_recording",
) -> dict[str, int]:
    """Sample one LQG tree (N = ``n_branch`` per step, pruned to ``max_keep``) and record it.

    Returns entity path -> number of logged rows (for checks). The tree's random stream is
    ``job_rng(seed, experiment, ...)``; the recording id is derived from the same job id, so a
    rerun writes the same data.
    """
    u = np.asarray(u, dtype=float)
    horizon = len(u)
    job = {
        "a": params.a,
        "sigma": params.sigma,
        "r": params.r,
        "target": params.target,
        "x0": params.x0,
        "u": u,
        "N": n_branch,
        "M": max_keep,
    }
    rng = job_rng(seed, experiment, **job)
    tree = sample_tree(params, [params.x0], u, n_branch, rng, max_keep=max_keep, keep_history=True)
    rec_id = uuid.uuid5(uuid.NAMESPACE_URL, canonical_job_id(experiment, seed=seed, **job))
    rec = rr.RecordingStream("rsmhp_lqg_tree", recording_id=str(rec_id))
    rec.set_log_time_enabled(False)  # only the deterministic `step` timeline
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    rec.save(path, default_blueprint=tree_blueprint())
    rows: dict[str, int] = {}

    def log(entity: str, data, static: bool = False) -> None:
        rec.log(entity, data, static=static)
        rows[entity] = rows.get(entity, 0) + 1

    j_exact = lqg.exact_cost(u, **params.closed_form_args())
    j_nbo = lqg.nbo_cost(u, x0=params.x0, a=params.a, r=params.r, target=params.target)
    text = (
        f"# RS-MHP tree, LQG oven problem\n\n"
        f"a={params.a:g}, r={params.r:g}, T={params.target:g}, sigma={params.sigma:g}, "
        f"x0={params.x0:g}, u={np.array2string(u, precision=3)}\n\n"
        f"N={n_branch} draws per step (shared by all nodes of a level), H={horizon}, "
        f"pruned to M={max_keep} most likely trajectories.\n\n"
        "Orange (the pruned tree's colour in every figure): kept branches; grey: pruned. "
        "Node radius and colour (viridis, bright = likely): trajectory likeliness within its "
        "level; the `pruning` log states each cut. Estimates: pruned tree uniform (orange), "
        "weighted (light orange), NBO (vermilion), exact J (light grey). "
        "Scrub the `step` timeline to grow the tree."
    )
    log("description", rr.TextDocument(text, media_type="text/markdown"), static=True)
    for name in ("exact", "nbo", "uniform", "weighted"):
        log(
            f"estimate/{name}",
            rr.SeriesLines(names=name, widths=1.5, colors=[SERIES[name]]),
            static=True,
        )
    rec.set_time("step", sequence=0)
    log("tree/level_0/nodes", rr.Points2D([[0.0, params.x0]], radii=0.08, colors=[ROOT]))
    kept_x = np.array([params.x0])
    for name, val in (("exact", j_exact), ("nbo", j_nbo)):
        log(f"estimate/{name}", rr.Scalars(val))
    log("estimate/uniform", rr.Scalars(j_exact))
    log("estimate/weighted", rr.Scalars(j_exact))
    for k, level in enumerate(tree.history, start=1):
        rec.set_time("step", sequence=k)
        x_child = level.states[:, 0]
        x_par = kept_x[level.parent]
        segs = np.stack(
            [
                np.column_stack([np.full_like(x_par, k - 1), x_par]),
                np.column_stack([np.full_like(x_child, k), x_child]),
            ],
            axis=1,
        )
        kept, pruned = level.kept, ~level.kept
        log(f"tree/level_{k}/kept", rr.LineStrips2D(segs[kept], colors=[KEPT], radii=0.02))
        if pruned.any():
            log(
                f"tree/level_{k}/pruned",
                rr.LineStrips2D(segs[pruned], colors=[PRUNED], radii=0.008),
            )
        q = likeliness_weights(level.log_likeliness)  # mean 1 within the level
        radii = 0.03 + 0.05 * q / q.max()
        shade = (q / q.max())[:, None]
        viridis = np.array([[68, 1, 84], [33, 145, 140], [253, 231, 37]], dtype=float)
        likely = np.where(
            shade < 0.5,
            viridis[0] + 2 * shade * (viridis[1] - viridis[0]),
            viridis[1] + (2 * shade - 1) * (viridis[2] - viridis[1]),
        )
        colors = np.where(kept[:, None], likely, np.array(PRUNED[:3])).astype(np.uint8)
        cut = level.log_likeliness[kept].min()
        log(
            "pruning",
            rr.TextLog(
                f"level {k}: {kept.size} children, kept {int(kept.sum())}, dropped "
                f"{int((~kept).sum())}; kept log-likeliness >= {cut:.3f}"
            ),
        )
        points = np.column_stack([np.full_like(x_child, k), x_child])
        log(f"tree/level_{k}/nodes", rr.Points2D(points, radii=radii, colors=colors))
        kept_x = x_child[kept]
        ctg = _cost_to_go(kept_x, k, u, params)
        w = likeliness_weights(level.log_likeliness[kept])
        log("estimate/uniform", rr.Scalars(float(np.mean(ctg))))
        log("estimate/weighted", rr.Scalars(float(np.mean(w * ctg))))
        for name, val in (("exact", j_exact), ("nbo", j_nbo)):
            log(f"estimate/{name}", rr.Scalars(val))
    rec.disconnect()
    return rows
