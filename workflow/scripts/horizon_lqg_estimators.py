"""Rule horizon_lqg_estimators: the oven LQG's cost estimators at long horizons (exact J)."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.horizon.simulate_lqg import run_lqg_estimators

with rule_logging(snakemake):
    p = snakemake.params
    write_csv(run_lqg_estimators(p.cfg, p.model, p.seed, snakemake.threads), snakemake.output[0])
