"""Rule uav_simulate: one method, one chunk of Monte-Carlo runs -> runs CSV + steps Parquet."""

from rsmhp.pipeline.io import write_csv, write_parquet
from rsmhp.pipeline.runstore import open_store, report_line
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.uav.simulate import run_chunk

with rule_logging(snakemake) as log:
    store = open_store(snakemake.config["run_store"])
    runs, steps = run_chunk(
        snakemake.params.uav,
        snakemake.params.method,
        snakemake.params.runs,
        snakemake.params.seed,
        n_jobs=snakemake.threads,
        store=store,
    )
    log.info(report_line(store))
    write_csv(runs, snakemake.output.runs)
    write_parquet(steps, snakemake.output.steps)
