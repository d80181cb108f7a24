"""Rules lqg_recording, estimators_recording: one LQG tree, step by step, as a rerun recording."""

from rsmhp.experiments.lqg import LQGParams
from rsmhp.pipeline import rule_logging
from rsmhp.recording import record_lqg_tree

with rule_logging(snakemake.log[0], snakemake.rule) as log:
    rec = snakemake.params.recording
    rows = record_lqg_tree(
        snakemake.output[0],
        LQGParams.from_config(snakemake.params.model),
        rec["u"],
        n_branch=rec["N"],
        max_keep=rec["M"],
        seed=snakemake.params.seed,
        experiment=snakemake.params.experiment,
    )
    log.info("logged %d entities, %d rows", len(rows), sum(rows.values()))
