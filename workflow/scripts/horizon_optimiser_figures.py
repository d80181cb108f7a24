"""Rule horizon_optimiser_figures: the optimiser split against the horizon (PNG + PDF)."""

from pathlib import Path

from rsmhp.figures import save_figure
from rsmhp.figures.optimiser_split import optimiser_figure
from rsmhp.io import read_table
from rsmhp.narrative.optimiser_split import SUMMARY_COLUMNS
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    outdir = Path(snakemake.output[0]).parent
    summary = read_table(snakemake.input[0], SUMMARY_COLUMNS)
    save_figure(optimiser_figure(summary), outdir / "hz_optimiser")
