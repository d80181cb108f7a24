"""Rules lqg_recording, estimators_recording: one LQG tree, step by step, as a rerun recording."""

from rsmhp.models.lqg.oven import LQGModel
from rsmhp.models.lqg.recording import record_lqg_tree
from rsmhp.pipeline.script import rule_logging

with rule_logging(snakemake) as log:
    rec = snakemake.params.recording
    rows = record_lqg_tree(
        snakemake.output[0],
        LQGModel.from_config(snakemake.params.model),
        rec["u"],
        n_branch=rec["N"],
        max_keep=rec["M"],
        seed=snakemake.params.seed,
        experiment=snakemake.params.experiment,
    )
    log.info("logged %d entities, %d rows", len(rows), sum(rows.values()))
