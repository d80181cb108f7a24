"""Rule horizon_lqg_regret: the oven LQG's decision regret at long horizons (exact argmins)."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.horizon.simulate_lqg import run_lqg_regret

with rule_logging(snakemake):
    p = snakemake.params
    write_csv(run_lqg_regret(p.cfg, p.model, p.seed, snakemake.threads), snakemake.output[0])
