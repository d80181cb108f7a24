"""Rule decisions_recording: one closed-loop run of a model variant, NBO and the method with
the most hypotheses side by side, the sensor footprint drawn at every step."""

from rsmhp.experiments.decisions_uav import recording_setup
from rsmhp.pipeline import rule_logging
from rsmhp.uav.recording import record_uav_run

with rule_logging(snakemake) as log:
    rec = snakemake.params.recording
    setup, methods = recording_setup(
        snakemake.params.uav, snakemake.params.models, snakemake.params.methods, rec["model"]
    )
    rows, summaries = record_uav_run(
        snakemake.output[0],
        setup,
        methods,
        seed=snakemake.params.seed,
        run=int(rec["run"]),
        max_hypotheses=int(rec["max_hypotheses"]),
    )
    for s in summaries:
        log.info(
            "%s: mean error %.2f m, detections %.0f%%",
            s["method"],
            s["mean_error"],
            100 * s.get("detect_rate", 1.0),
        )
    log.info("logged %d entities, %d rows", len(rows), sum(rows.values()))
