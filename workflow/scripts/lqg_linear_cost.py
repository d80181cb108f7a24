"""Rule lqg_linear_cost: Prop. 3 on its own setting (linear dynamics, linear cost)."""

from rsmhp.experiments.lqg import run_linear_cost
from rsmhp.io import write_csv
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    write_csv(run_linear_cost(snakemake.params.lqg, snakemake.params.seed), snakemake.output[0])
