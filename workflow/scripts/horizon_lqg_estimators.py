"""Rule horizon_lqg_estimators: the oven LQG's cost estimators at long horizons (exact J)."""

from rsmhp.experiments.horizon_lqg import run_lqg_estimators
from rsmhp.io import write_csv
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    p = snakemake.params
    write_csv(run_lqg_estimators(p.cfg, p.model, p.seed, snakemake.threads), snakemake.output[0])
