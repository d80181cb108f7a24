"""Rule estimators_ablation: every scheme x weighting x size, seeded per cell and replicate."""

from rsmhp.models.lqg.ablation import run_ablation
from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging

with rule_logging(snakemake):
    df = run_ablation(
        snakemake.params.estimators,
        snakemake.params.model,
        snakemake.params.seed,
        n_jobs=snakemake.threads,
    )
    write_csv(df, snakemake.output[0])
