"""Rule uav_recording: run k with every method side by side, as a rerun recording."""

from rsmhp.models.uav import methods
from rsmhp.models.uav.recording import record_uav_run
from rsmhp.models.uav.simulation import UAVSetup
from rsmhp.pipeline.script import rule_logging

with rule_logging(snakemake) as log:
    rows, _ = record_uav_run(
        snakemake.output[0],
        UAVSetup.from_config(snakemake.params.uav),
        [methods.from_spec(m) for m in snakemake.params.methods],
        seed=snakemake.params.seed,
        run=int(snakemake.wildcards.k),
        max_hypotheses=snakemake.params.max_hypotheses,
    )
    log.info("logged %d entities, %d rows", len(rows), sum(rows.values()))
