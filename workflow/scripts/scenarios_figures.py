"""Rule scenarios_figures: the probability of beating NBO per method and group of scenarios
(PNG + PDF)."""

from pathlib import Path

from rsmhp.analysis.scenarios import SUMMARY_COLUMNS
from rsmhp.figures import save_figure
from rsmhp.figures.scenarios import improvement_figure
from rsmhp.io import read_table
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    outdir = Path(snakemake.output[0]).parent
    summary = read_table(snakemake.input[0], SUMMARY_COLUMNS)
    save_figure(improvement_figure(summary), outdir / "scn_improvement")
