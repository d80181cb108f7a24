"""Rule frontier_tune: closed-loop runs of every tuning candidate (and NBO) on one model
variant, on the tuning stream."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.protocol import stream_seed, tuning_configurations
from rsmhp.pipeline.runstore import open_store, report_line
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.frontier.simulate import run_configurations

with rule_logging(snakemake) as log:
    p = snakemake.params
    configs = tuning_configurations(p.tuning)
    runs = range(int(p.tuning["runs"]))
    seed = stream_seed(p.seed, "tune")
    store = open_store(snakemake.config["run_store"])
    table = run_configurations(
        p.uav, p.models, snakemake.wildcards.model, configs, runs, seed, p.track_loss_error, store
    )
    log.info(report_line(store))
    write_csv(table, snakemake.output[0])
