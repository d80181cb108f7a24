"""Rule frontier_confirm: closed-loop runs of the preregistered configurations on one model
variant and one chunk of its runs, on the confirmatory stream."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.protocol import Configuration, stream_seed
from rsmhp.pipeline.runstore import open_store, report_line
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.frontier.simulate import run_configurations

with rule_logging(snakemake) as log:
    p = snakemake.params
    configs = [Configuration.from_spec(c) for c in p.plan]
    store = open_store(snakemake.config["run_store"])
    table = run_configurations(
        p.uav,
        p.models,
        snakemake.wildcards.model,
        configs,
        p.runs,
        stream_seed(p.seed, p.stream),
        p.track_loss_error,
        store,
    )
    log.info(report_line(store))
    write_csv(table, snakemake.output[0])
