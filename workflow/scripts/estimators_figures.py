"""Rule estimators_figures: RMSE, tree variance, weighting, pruning, CPU frontier (PNG + PDF)."""

from pathlib import Path

from rsmhp.pipeline.io import read_table
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.estimators import figures as figs
from rsmhp.studies.estimators.summarise import SUMMARY_COLUMNS, problems_from_config

with rule_logging(snakemake):
    s = read_table(snakemake.input.summary, SUMMARY_COLUMNS)
    problems = problems_from_config({"problems": snakemake.params.problems}, snakemake.params.model)
    figs.save_all(s, problems, Path(snakemake.output[0]).parent, n_jobs=snakemake.threads)
