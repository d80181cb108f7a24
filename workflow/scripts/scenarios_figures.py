"""Rule scenarios_figures: the best method per cell (scenarios_best) and the probability of
beating NBO per method and group of scenarios (scenarios_improvement), PNG + PDF."""

from pathlib import Path

from rsmhp.pipeline.io import read_table
from rsmhp.pipeline.script import rule_logging
from rsmhp.report.figures import save_figure
from rsmhp.studies.scenarios.best import BEST_COLUMNS
from rsmhp.studies.scenarios.figures import best_figure, improvement_figure
from rsmhp.studies.scenarios.summarise import SUMMARY_COLUMNS

with rule_logging(snakemake):
    outdir = Path(snakemake.output[0]).parent
    summary = read_table(snakemake.input.summary, SUMMARY_COLUMNS)
    best = read_table(snakemake.input.best, BEST_COLUMNS)
    save_figure(best_figure(best), outdir / "scenarios_best")
    save_figure(improvement_figure(summary), outdir / "scenarios_improvement")
