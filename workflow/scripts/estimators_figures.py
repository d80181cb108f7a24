"""Rule estimators_figures: RMSE, tree variance, weighting, pruning, CPU frontier (PNG + PDF)."""

from pathlib import Path

from rsmhp.analysis.estimators import SUMMARY_COLUMNS, problems_from_config
from rsmhp.figures import estimators as figs
from rsmhp.io import read_table
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    s = read_table(snakemake.input.summary, SUMMARY_COLUMNS)
    problems = problems_from_config({"problems": snakemake.params.problems}, snakemake.params.model)
    figs.save_all(s, problems, Path(snakemake.output[0]).parent, n_jobs=snakemake.threads)
