"""Rule horizon_uav_closed: paired closed-loop runs of one model variant and horizon, one
chunk of the runs."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.runstore import open_store, report_line
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.horizon.simulate_uav import run_horizon_closed

with rule_logging(snakemake) as log:
    p, w = snakemake.params, snakemake.wildcards
    store = open_store(snakemake.config["run_store"])
    closed = run_horizon_closed(
        p.uav, p.models, p.cfg, w.hmodel, int(w.H), p.seed, store, runs=p.runs
    )
    log.info(report_line(store))
    write_csv(closed, snakemake.output[0])
