"""Rule decisions_uav: open-loop regret of every method's plan at belief states."""

from rsmhp.models.uav.scoring import run_uav_regret
from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging

with rule_logging(snakemake):
    df = run_uav_regret(
        snakemake.params.uav, snakemake.params.cfg, snakemake.params.seed, snakemake.threads
    )
    write_csv(df, snakemake.output[0])
