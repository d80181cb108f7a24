"""Rule decisions_lqg: regret of each method's argmin on the scalar LQG."""

from rsmhp.experiments.decisions_lqg import run_lqg_regret
from rsmhp.io import write_csv
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    df = run_lqg_regret(
        snakemake.params.cfg, snakemake.params.model, snakemake.params.seed, snakemake.threads
    )
    write_csv(df, snakemake.output[0])
