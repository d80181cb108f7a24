"""Rule frontier_confirm_timing: interleaved wall-clock timing of the preregistered
configurations on one model variant, at belief states of the confirmatory stream."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.protocol import Configuration, stream_seed
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.frontier.simulate import time_configurations

with rule_logging(snakemake):
    p = snakemake.params
    configs = [Configuration.from_spec(c) for c in p.plan]
    table = time_configurations(
        p.uav,
        p.models,
        snakemake.wildcards.model,
        configs,
        p.timing,
        stream_seed(p.seed, p.stream),
    )
    write_csv(table, snakemake.output[0])
