"""Rule horizon_uav_closed_merge: the closed-loop chunks of every model variant and horizon,
checked and merged into one table each (the unsplit ones, row for row)."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.horizon.chunks import merge_closed, per_unit

with rule_logging(snakemake) as log:
    p = snakemake.params
    for (model, H, jobs), paths, path in zip(
        p.units, per_unit(snakemake.input, p.units), snakemake.output, strict=True
    ):
        closed = merge_closed(paths, p.cfg, model, H, jobs)
        write_csv(closed, path)
        log.info("%s H=%d: %d rows from %d chunks", model, H, len(closed), jobs)
