"""Rule lqg_convergence: MHP estimates vs P (paper Fig. 3) -> results/lqg/convergence.csv."""

from rsmhp.experiments.lqg import run_convergence
from rsmhp.io import write_csv
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    df = run_convergence(snakemake.params.lqg, snakemake.params.seed, n_jobs=snakemake.threads)
    write_csv(df, snakemake.output[0])
