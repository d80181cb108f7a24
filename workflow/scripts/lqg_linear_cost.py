"""Rule lqg_linear_cost: Prop. 3 on its own setting (linear dynamics, linear cost)."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.lqg.simulate import run_linear_cost

with rule_logging(snakemake):
    write_csv(run_linear_cost(snakemake.params.lqg, snakemake.params.seed), snakemake.output[0])
