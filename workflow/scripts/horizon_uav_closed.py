"""Rule horizon_uav_closed: paired closed-loop runs of one model variant and horizon."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.horizon.simulate_uav import run_horizon_closed

with rule_logging(snakemake):
    p, w = snakemake.params, snakemake.wildcards
    closed = run_horizon_closed(p.uav, p.models, p.cfg, w.hmodel, int(w.H), p.seed)
    write_csv(closed, snakemake.output[0])
