"""Rule frontier_confirm: closed-loop runs of the preregistered configurations on one model
variant, on the confirmatory stream."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.protocol import Configuration, stream_seed
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.frontier.simulate import run_configurations

with rule_logging(snakemake):
    p = snakemake.params
    configs = [Configuration.from_spec(c) for c in p.plan]
    table = run_configurations(
        p.uav,
        p.models,
        snakemake.wildcards.model,
        configs,
        range(int(p.runs)),
        stream_seed(p.seed, p.stream),
        p.track_loss_error,
    )
    write_csv(table, snakemake.output[0])
