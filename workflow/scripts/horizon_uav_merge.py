"""Rule horizon_uav_merge: the chunks of every model variant and horizon of the UAV horizon
study, checked and merged into their cost-approximation and regret tables (the unsplit ones,
row for row)."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.horizon.chunks import merge_horizon, per_unit

with rule_logging(snakemake) as log:
    p, inp, out = snakemake.params, snakemake.input, snakemake.output
    for (model, H, jobs), a_in, r_in, a_out, r_out in zip(
        p.units,
        per_unit(inp.approx, p.units),
        per_unit(inp.regret, p.units),
        out.approx,
        out.regret,
        strict=True,
    ):
        approx, regret = merge_horizon(a_in, r_in, p.cfg, model, H, jobs)
        write_csv(approx, a_out)
        write_csv(regret, r_out)
        log.info("%s H=%d: %d + %d rows from %d chunks", model, H, len(approx), len(regret), jobs)
