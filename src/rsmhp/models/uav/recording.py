"""Rerun recordings of UAV runs, every method side by side (open with ``rerun <file>.rrd``).

One recording per run ``r`` (``results/recordings/uav_run<r>.rrd``), timeline ``step``.
For each method ``<m>`` (entity per method, its own 2-D view), drawn in the method's colour
``c_m = rsmhp.report.palette.method_rgb(m)`` (the same colour as in every figure):

* ``<m>/map/uav_path``      LineStrips2D in ``c_m``: the UAV's path up to step k
* ``<m>/map/uav``           Points2D in ``c_m``: the UAV now
* ``<m>/map/plan``          LineStrips2D in ``c_m`` (translucent, thinner): the H-step UAV path
  planned at step k (from the position before the step)
* ``<m>/map/hypotheses``    LineStrips2D in ``c_m`` (faint): the target hypotheses the planner
  used at step k (at most ``max_hypotheses`` of them, the first ones drawn)
* ``<m>/map/target_path``, ``<m>/map/target``  the true target (identical for every method),
  in :data:`TRUE_C` (lime)
* ``<m>/map/estimate``, ``<m>/map/ellipse``  the tracker's estimate and its 2-sigma position
  ellipse (closed polygon of :math:`\\hat p + 2 L (\\cos t, \\sin t)`, :math:`L L^T` the
  position block of :math:`\\hat P`; ``Ellipses2D`` has no rotation), in :data:`EST_C`
  (magenta)
* ``<m>/map/footprint``    LineStrips2D (model variants with a sensor footprint only): the
  footprint circle around the UAV, in ``c_m`` when the step measured, faint when it did not
* ``error/<m>``, ``trace/<m>``  Scalars in ``c_m``: :math:`\\|\\hat p_k - p_k\\|` and
  :math:`\\mathrm{tr}\\,\\hat P_k` (one time-series view each, methods overlaid)
* ``about``  TextDocument (static, optional): which run this is and why it was chosen

Target and estimate colours differ from every method colour of :mod:`rsmhp.report.palette` (RGB
distance > 100), so they cannot be mistaken for a method.

The recording id is derived from the job identifier: reruns write the same data.
"""

from __future__ import annotations

import os
import uuid
from pathlib import Path

import numpy as np
import pandas as pd
import rerun as rr
import rerun.blueprint as rrb

from rsmhp.core import guards
from rsmhp.core.seeding import canonical_job_id
from rsmhp.models.uav.methods import Method
from rsmhp.models.uav.simulation import StepInfo, UAVSetup, draw_scenario, simulate_run
from rsmhp.report.palette import method_rgb

__all__ = [
    "EST_C",
    "TRUE_C",
    "check_replay",
    "ellipse_polygon",
    "record_checked_run",
    "record_uav_run",
    "uav_blueprint",
]

#: the true target (path and position): lime, unlike any method colour
TRUE_C = (120, 230, 0)
#: the tracker's estimate and its ellipse: magenta, unlike any method colour
EST_C = (230, 0, 230)
#: alpha of the plan, the hypotheses and a footprint that did not measure (method colour)
PLAN_ALPHA, HYP_ALPHA, MISSED_ALPHA = 170, 70, 70


def ellipse_polygon(mean: np.ndarray, cov: np.ndarray, n_sigma: float = 2.0, n: int = 48):
    """Closed polygon (n + 1, 2) of the ``n_sigma`` ellipse of a 2-D Gaussian: ``mean``
    finite (2,), ``cov`` finite symmetric positive definite (2, 2), ``n_sigma`` > 0,
    ``n`` >= 3 polygon sides."""
    guards.finite_array("mean", mean, shape=(2,))
    guards.spd_matrix("cov", cov, size=2)
    guards.real("n_sigma", n_sigma, lo=0.0, lo_open=True)
    n = guards.integer("n", n, minimum=3)
    L = np.linalg.cholesky(0.5 * (cov + cov.T))
    t = np.linspace(0.0, 2 * np.pi, n + 1)
    return np.asarray(mean)[None, :] + n_sigma * np.column_stack([np.cos(t), np.sin(t)]) @ L.T


class _MethodLogger:
    """Observer of :func:`rsmhp.models.uav.simulation.simulate_run` that logs one method's
    entities."""

    def __init__(
        self,
        rec,
        log,
        name: str,
        uav_start: np.ndarray,
        max_hypotheses: int,
        footprint: float | None = None,
    ) -> None:
        self.rec, self.log, self.name, self.max_hyp = rec, log, name, max_hypotheses
        self.footprint = footprint
        self.base = f"{name}/map"
        self.rgb = method_rgb(name)
        self.uav_path = [np.asarray(uav_start, dtype=float).copy()]
        self.tgt_path: list[np.ndarray] = []

    def __call__(self, info: StepInfo) -> None:
        log, base = self.log, self.base
        self.rec.set_time("step", sequence=info.step)
        plan = np.vstack([self.uav_path[-1], info.plan_path[:, :2]])
        self.uav_path.append(info.uav[:2].copy())
        self.tgt_path.append(info.target[:2].copy())
        c = self.rgb
        log(f"{base}/plan", rr.LineStrips2D([plan], colors=[(*c, PLAN_ALPHA)], radii=1.0))
        log(f"{base}/uav_path", rr.LineStrips2D([np.array(self.uav_path)], colors=[c], radii=1.5))
        log(f"{base}/uav", rr.Points2D([info.uav[:2]], colors=[c], radii=6.0))
        hyp = info.hypotheses[: self.max_hyp, :, :2]
        log(f"{base}/hypotheses", rr.LineStrips2D(list(hyp), colors=[(*c, HYP_ALPHA)], radii=0.5))
        log(f"{base}/target_path", rr.LineStrips2D([np.array(self.tgt_path)], colors=[TRUE_C]))
        log(f"{base}/target", rr.Points2D([info.target[:2]], colors=[TRUE_C], radii=4.0))
        log(f"{base}/estimate", rr.Points2D([info.estimate[:2]], colors=[EST_C], radii=4.0))
        ell = ellipse_polygon(info.estimate[:2], info.covariance[:2, :2])
        log(f"{base}/ellipse", rr.LineStrips2D([ell], colors=[EST_C], radii=0.8))
        if self.footprint is not None:
            t = np.linspace(0.0, 2 * np.pi, 73)
            ring = info.uav[:2] + self.footprint * np.column_stack([np.cos(t), np.sin(t)])
            color = c if info.detected else (*c, MISSED_ALPHA)
            log(f"{base}/footprint", rr.LineStrips2D([ring], colors=[color], radii=1.0))
        log(f"error/{self.name}", rr.Scalars(info.error))
        log(f"trace/{self.name}", rr.Scalars(info.trace))


def uav_blueprint(methods: list[str], note: bool = False) -> rrb.Blueprint:
    """One 2-D map per method (grid) above the error and tr P time series (and, with
    ``note``, the text document ``about`` that says which run this is and why)."""
    series = [
        rrb.TimeSeriesView(origin="/error", name="target location error (m)"),
        rrb.TimeSeriesView(origin="/trace", name="tr P"),
    ]
    if note:
        series.append(rrb.TextDocumentView(origin="/about", name="this run"))
    return rrb.Blueprint(
        rrb.Vertical(
            rrb.Grid(*(rrb.Spatial2DView(origin=f"/{m}/map", name=m) for m in methods)),
            rrb.Horizontal(*series),
            row_shares=[3, 1],
        ),
        rrb.TimePanel(state="expanded"),
        collapse_panels=False,
    )


def record_uav_run(
    path: str | os.PathLike,
    setup: UAVSetup,
    methods: list[Method],
    seed: int,
    run: int,
    max_hypotheses: int = 50,
    note: str = "",
) -> tuple[dict[str, int], list[dict]]:
    """Simulate run ``run`` with every method and record it; a non-empty ``note`` (e.g. why
    this run was chosen) is logged as the static text document ``about``.

    Returns (entity path -> logged rows, the per-method summary rows of the simulations, which
    equal those of the Monte-Carlo study for the same run).
    """
    guards.instance_of("setup", setup, UAVSetup)
    methods = list(methods)
    if not methods:
        raise ValueError("methods must name at least one planning method, got none")
    for i, m in enumerate(methods):
        guards.instance_of(f"methods[{i}]", m, Method)
    seed = guards.nonneg_int("seed", seed)
    run = guards.nonneg_int("run", run)
    max_hypotheses = guards.nonneg_int("max_hypotheses", max_hypotheses)
    names = [m.name for m in methods]
    variant = {} if not setup.sensor.limited else {"footprint": setup.sensor.footprint_radius}
    job = canonical_job_id("uav_recording", seed=seed, run=run, methods=names, **variant)
    rec = rr.RecordingStream("rsmhp_uav", recording_id=str(uuid.uuid5(uuid.NAMESPACE_URL, job)))
    rec.set_log_time_enabled(False)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    rec.save(path, default_blueprint=uav_blueprint(names, note=bool(note)))
    rows: dict[str, int] = {}

    def log(entity: str, data, static: bool = False) -> None:
        rec.log(entity, data, static=static)
        rows[entity] = rows.get(entity, 0) + 1

    if note:
        log("about", rr.TextDocument(note), static=True)

    summaries = []
    for m in methods:
        style = rr.SeriesLines(names=m.name, colors=[method_rgb(m.name)], widths=1.5)
        log(f"error/{m.name}", style, static=True)
        log(f"trace/{m.name}", style, static=True)
        start = draw_scenario(setup, seed, run).uav[:2]
        footprint = setup.sensor.footprint_radius if setup.sensor.limited else None
        observer = _MethodLogger(rec, log, m.name, start, max_hypotheses, footprint)
        summary, _ = simulate_run(setup, m, seed, run, observer=observer)
        summaries.append(summary)
    rec.disconnect()
    return rows, summaries


def check_replay(summaries: list[dict], table: pd.DataFrame, rtol: float = 1e-9) -> None:
    """Refuse a recording whose replayed runs differ from the study's table rows of the same
    run (``table``: one row per method with ``method`` and ``mean_error``): the simulation is
    deterministic given (seed, run, method), so a difference means the table is stale or the
    code changed under it. Methods absent from the table are refused too."""
    rows = table.set_index("method")["mean_error"]
    for s in summaries:
        m = s["method"]
        if m not in rows.index:
            raise ValueError(f"recording: method {m!r} has no row of this run in the study table")
        want, got = float(rows.loc[m]), float(s["mean_error"])
        if not np.isclose(got, want, rtol=rtol, atol=0.0):
            raise ValueError(
                f"recording: the replay of {m} gives mean error {got!r} m, the study table "
                f"{want!r} m (allowed: equal to rtol {rtol:g}); rerun the study's rule"
            )


def record_checked_run(
    path: str | os.PathLike,
    setup: UAVSetup,
    methods: list[Method],
    table: pd.DataFrame,
    *,
    seed: int,
    run: int,
    max_hypotheses: int,
    note: str,
    log,
) -> None:
    """:func:`record_uav_run` of run ``run``, its replay checked against the study's rows of
    that run (``table``, :func:`check_replay`), each method's mean error and the logged
    entities written to ``log`` (a :class:`logging.Logger`)."""
    rows, summaries = record_uav_run(
        path, setup, methods, seed=seed, run=run, max_hypotheses=max_hypotheses, note=note
    )
    check_replay(summaries, table[table["run"] == run])
    for s in summaries:
        log.info(
            "%s: mean error %.2f m, detections %.0f%%",
            s["method"],
            s["mean_error"],
            100 * s.get("detect_rate", 1.0),
        )
    log.info("logged %d entities, %d rows", len(rows), sum(rows.values()))
