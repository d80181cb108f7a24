"""Rule decisions_figures: decision-study figures (PNG + PDF)."""

from pathlib import Path

from rsmhp.analysis.decisions import LQG_SUMMARY_COLUMNS
from rsmhp.figures import decisions as figs
from rsmhp.figures import save_figure
from rsmhp.io import read_table
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake.log[0], snakemake.rule):
    summary = read_table(snakemake.input.lqg, LQG_SUMMARY_COLUMNS)
    outdir = Path(snakemake.output[0]).parent
    save_figure(figs.lqg_regret_figure(summary), outdir / "dec_lqg_regret")
