"""Rule frontier_confirm_figures: the confirmatory ladder figure (PNG + PDF)."""

from pathlib import Path

from rsmhp.analysis.frontier import LADDER_COLUMNS
from rsmhp.figures import save_figure
from rsmhp.figures.frontier import confirm_figure
from rsmhp.io import read_table
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    outdir = Path(snakemake.output[0]).parent
    lad = read_table(snakemake.input.ladder, LADDER_COLUMNS)
    save_figure(confirm_figure(lad), outdir / "dec_confirm")
