"""Rule horizon_lqg_regret: the oven LQG's decision regret at long horizons (exact argmins)."""

from rsmhp.experiments.horizon_lqg import run_lqg_regret
from rsmhp.io import write_csv
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    p = snakemake.params
    write_csv(run_lqg_regret(p.cfg, p.model, p.seed, snakemake.threads), snakemake.output[0])
