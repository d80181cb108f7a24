"""Rule frontier_confirm_figures: the confirmatory ladder figure (PNG + PDF)."""

from pathlib import Path

from rsmhp.pipeline.io import read_table
from rsmhp.pipeline.script import rule_logging
from rsmhp.report.figures import save_figure
from rsmhp.studies.frontier.figures import confirm_figure
from rsmhp.studies.frontier.summarise import LADDER_COLUMNS

with rule_logging(snakemake):
    outdir = Path(snakemake.output[0]).parent
    lad = read_table(snakemake.input.ladder, LADDER_COLUMNS)
    save_figure(confirm_figure(lad), outdir / "frontier_confirm")
