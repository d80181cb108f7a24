"""Rule frontier_tune_timing: interleaved wall-clock timing of every tuning candidate (and
NBO) on one model variant, at belief states of the tuning stream."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.protocol import stream_seed, tuning_configurations
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.frontier.simulate import time_configurations

with rule_logging(snakemake):
    p = snakemake.params
    configs = tuning_configurations(p.tuning)
    seed = stream_seed(p.seed, "tune")
    table = time_configurations(
        p.uav, p.models, snakemake.wildcards.model, configs, p.tuning["timing"], seed
    )
    write_csv(table, snakemake.output[0])
