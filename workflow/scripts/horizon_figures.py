"""Rule horizon_figures: the long-horizon study's figures (PNG + PDF)."""

from pathlib import Path

from rsmhp.models.lqg.regret_summary import LQG_SUMMARY_COLUMNS
from rsmhp.pipeline.io import read_table
from rsmhp.pipeline.script import rule_logging
from rsmhp.report.figures import save_figure
from rsmhp.studies.horizon.figures import (
    horizon_closed_figure,
    horizon_error_figure,
    horizon_lqg_figure,
    horizon_time_figure,
)
from rsmhp.studies.horizon.summarise_lqg import LQG_ESTIMATOR_COLUMNS
from rsmhp.studies.horizon.summarise_uav import (
    APPROX_SUMMARY_COLUMNS,
    CLOSED_SUMMARY_COLUMNS,
    REGRET_SUMMARY_COLUMNS,
)

with rule_logging(snakemake):
    outdir = Path(snakemake.output[0]).parent
    approx = read_table(snakemake.input.approx, APPROX_SUMMARY_COLUMNS)
    regret = read_table(snakemake.input.regret, REGRET_SUMMARY_COLUMNS)
    save_figure(horizon_error_figure(approx), outdir / "horizon_uav_error")
    save_figure(horizon_time_figure(regret), outdir / "horizon_uav_time")
    closed = read_table(snakemake.input.closed, CLOSED_SUMMARY_COLUMNS)
    save_figure(horizon_closed_figure(closed), outdir / "horizon_uav_closed")
    est = read_table(snakemake.input.lqg_estimators, LQG_ESTIMATOR_COLUMNS)
    reg = read_table(snakemake.input.lqg_regret, [*LQG_SUMMARY_COLUMNS, "limit"])
    save_figure(horizon_lqg_figure(est, reg), outdir / "horizon_lqg")
