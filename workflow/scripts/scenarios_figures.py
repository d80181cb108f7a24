"""Rule scenarios_figures: the probability of beating NBO per method and group of scenarios
(PNG + PDF)."""

from pathlib import Path

from rsmhp.pipeline.io import read_table
from rsmhp.pipeline.script import rule_logging
from rsmhp.report.figures import save_figure
from rsmhp.studies.scenarios.figures import improvement_figure
from rsmhp.studies.scenarios.summarise import SUMMARY_COLUMNS

with rule_logging(snakemake):
    outdir = Path(snakemake.output[0]).parent
    summary = read_table(snakemake.input[0], SUMMARY_COLUMNS)
    save_figure(improvement_figure(summary), outdir / "scenarios_improvement")
