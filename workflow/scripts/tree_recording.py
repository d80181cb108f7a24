"""Rules lqg_recording, estimators_recording: one LQG tree, step by step, as a rerun recording."""

from rsmhp.lqg import LQGModel
from rsmhp.pipeline import rule_logging
from rsmhp.recording import record_lqg_tree

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
