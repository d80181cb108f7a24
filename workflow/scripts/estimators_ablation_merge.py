"""Rule estimators_ablation_merge: the ablation's jobs, checked and merged into
results/estimators/ablation.csv in table order (the unsplit table, row for row)."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.estimators.chunks import merge_ablation

with rule_logging(snakemake) as log:
    p = snakemake.params
    df = merge_ablation(list(snakemake.input), p.estimators, p.model, p.jobs)
    write_csv(df, snakemake.output[0])
    log.info("%d rows from %d jobs", len(df), len(snakemake.input))
