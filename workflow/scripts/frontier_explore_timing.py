"""Rule frontier_explore_timing: interleaved wall-clock timing of every method's plan call
on one model variant of the equal-compute study."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.frontier.simulate import time_planners

with rule_logging(snakemake):
    p = snakemake.params
    timing = time_planners(p.uav, p.models, p.cfg, snakemake.wildcards.model, p.seed)
    write_csv(timing, snakemake.output[0])
