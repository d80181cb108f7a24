"""Rule estimators_figures: RMSE, tree variance, weighting, pruning, CPU frontier (PNG + PDF)."""

from pathlib import Path

from rsmhp.analysis.estimators import SUMMARY_COLUMNS, problems_from_config
from rsmhp.figures import estimators as figs
from rsmhp.figures import save_figure
from rsmhp.io import read_table
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake.log[0], snakemake.rule):
    s = read_table(snakemake.input.summary, SUMMARY_COLUMNS)
    problems = problems_from_config({"problems": snakemake.params.problems}, snakemake.params.model)
    out = Path(snakemake.output[0]).parent
    save_figure(figs.rmse_figure(s), out / "est_rmse_vs_n")
    save_figure(figs.bias_figure(s), out / "est_bias_vs_n")
    save_figure(figs.tree_variance_figure(s, problems), out / "est_tree_variance")
    save_figure(figs.weighted_vs_uniform_figure(s), out / "est_weighted_vs_uniform")
    save_figure(figs.pruning_heatmap(s), out / "est_pruning_heatmap")
    save_figure(figs.frontier_figure(s), out / "est_frontier")
