"""Rule horizon_optimiser_figures: the optimiser split against the horizon (PNG + PDF)."""

from pathlib import Path

from rsmhp.pipeline.io import read_table
from rsmhp.pipeline.script import rule_logging
from rsmhp.report.figures import save_figure
from rsmhp.studies.horizon.figures_optimiser import optimiser_figure
from rsmhp.studies.horizon.section_optimiser import SUMMARY_COLUMNS

with rule_logging(snakemake):
    outdir = Path(snakemake.output[0]).parent
    summary = read_table(snakemake.input[0], SUMMARY_COLUMNS)
    save_figure(optimiser_figure(summary), outdir / "horizon_optimiser")
