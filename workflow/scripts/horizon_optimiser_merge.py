"""Rule horizon_optimiser_merge: the chunks of the optimiser split of every model variant and
horizon, checked and merged into one table each (the unsplit ones, row for row)."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.horizon.chunks import merge_optimiser, per_unit

with rule_logging(snakemake) as log:
    p = snakemake.params
    for (model, H, jobs), paths, path in zip(
        p.units, per_unit(snakemake.input, p.units), snakemake.output, strict=True
    ):
        table = merge_optimiser(paths, p.cfg, model, H, jobs)
        write_csv(table, path)
        log.info("%s H=%d: %d rows from %d chunks", model, H, len(table), jobs)
