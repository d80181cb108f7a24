"""Rule decisions_uav: open-loop regret of every method's plan at the belief states of one
model variant and chunk of runs."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.decisions.chunks import run_regret_chunk

with rule_logging(snakemake):
    p = snakemake.params
    df = run_regret_chunk(
        p.uav, p.cfg, snakemake.wildcards.model, p.runs, p.seed, snakemake.threads
    )
    write_csv(df, snakemake.output[0])
