"""Rule decisions_uav_merge: the jobs of the UAV open-loop study, checked and merged into
results/decisions/uav_regret.csv (the unsplit table, row for row)."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.decisions.chunks import merge_regret

with rule_logging(snakemake) as log:
    p = snakemake.params
    df = merge_regret(list(snakemake.input), p.cfg, p.jobs)
    write_csv(df, snakemake.output[0])
    log.info("%d rows from %d jobs", len(df), len(snakemake.input))
