"""Rule decisions_lqg: regret of each method's argmin on the scalar LQG."""

from rsmhp.models.lqg.regret import run_lqg_regret
from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging

with rule_logging(snakemake):
    df = run_lqg_regret(
        snakemake.params.cfg, snakemake.params.model, snakemake.params.seed, snakemake.threads
    )
    write_csv(df, snakemake.output[0])
