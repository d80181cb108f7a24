"""Rule decisions_uav: open-loop regret of every method's plan at belief states."""

from rsmhp.experiments.decisions_uav import run_uav_regret
from rsmhp.io import write_csv
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    df = run_uav_regret(
        snakemake.params.uav, snakemake.params.cfg, snakemake.params.seed, snakemake.threads
    )
    write_csv(df, snakemake.output[0])
