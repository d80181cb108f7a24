"""Rule frontier_compare_run: the new methods (config plugin_methods) in closed loop on one
model of the confirmatory design, on the reference's runs and seed stream."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.protocol import Configuration, stream_seed
from rsmhp.pipeline.runstore import open_store, report_line
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.frontier.simulate import run_configurations

with rule_logging(snakemake) as log:
    p = snakemake.params
    log.info("new methods: %s", "; ".join(f"{k} ({v})" for k, v in p.plugins.items()))
    # a plugin family's runs are not stored (its code is outside the digest): only the
    # registry's families share runs here
    store = open_store(snakemake.config["run_store"])
    table = run_configurations(
        p.uav,
        p.models,
        snakemake.wildcards.model,
        [Configuration(m) for m in p.methods],
        range(int(p.runs)),
        stream_seed(p.seed, p.stream),
        p.track_loss_error,
        store,
    )
    log.info(report_line(store))
    write_csv(table, snakemake.output[0])
