"""Rule horizon_uav_closed: paired closed-loop runs of one model variant and horizon."""

from rsmhp.experiments.horizon import run_horizon_closed
from rsmhp.io import write_csv
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    p, w = snakemake.params, snakemake.wildcards
    closed = run_horizon_closed(p.uav, p.models, p.cfg, w.hmodel, int(w.H), p.seed)
    write_csv(closed, snakemake.output[0])
