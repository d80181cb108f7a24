"""Rule frontier_confirm_merge: the chunks of one model's confirmatory runs, checked and
merged into results/frontier/confirm/<model>.csv (the unsplit table, row for row)."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.protocol import Configuration
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.frontier.chunks import merge_confirm

with rule_logging(snakemake) as log:
    p = snakemake.params
    configs = [Configuration.from_spec(c) for c in p.plan]
    table = merge_confirm(list(snakemake.input), configs, p.runs, p.jobs, snakemake.wildcards.model)
    write_csv(table, snakemake.output[0])
    log.info("%d rows from %d chunks", len(table), len(snakemake.input))
