"""Rule frontier_explore_figures: the planner frontier (PNG + PDF)."""

from pathlib import Path

from rsmhp.pipeline.io import read_table
from rsmhp.pipeline.script import rule_logging
from rsmhp.report.figures import save_figure
from rsmhp.studies.frontier.figures import frontier_figure
from rsmhp.studies.frontier.summarise import FRONTIER_SUMMARY_COLUMNS

with rule_logging(snakemake):
    outdir = Path(snakemake.output[0]).parent
    summary = read_table(snakemake.input.summary, FRONTIER_SUMMARY_COLUMNS)
    budget = float(snakemake.params.budget["ms_per_step"])
    save_figure(frontier_figure(summary, budget), outdir / "frontier_exploratory")
