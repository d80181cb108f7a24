"""Rule uav_simulate: one method, one chunk of Monte-Carlo runs -> runs CSV + steps Parquet."""

from rsmhp.experiments.uav import run_chunk
from rsmhp.io import write_csv, write_parquet
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    runs, steps = run_chunk(
        snakemake.params.uav,
        snakemake.params.method,
        snakemake.params.runs,
        snakemake.params.seed,
        n_jobs=snakemake.threads,
    )
    write_csv(runs, snakemake.output.runs)
    write_parquet(steps, snakemake.output.steps)
