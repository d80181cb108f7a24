"""Rule estimators_ablation: one job of the grid's cells, every scheme x weighting x size,
seeded per cell and replicate."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.estimators.chunks import run_ablation_chunk

with rule_logging(snakemake):
    p = snakemake.params
    df = run_ablation_chunk(
        p.estimators,
        p.model,
        p.seed,
        p.jobs,
        int(snakemake.wildcards.chunk),
        n_jobs=snakemake.threads,
    )
    write_csv(df, snakemake.output[0])
