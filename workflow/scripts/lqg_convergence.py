"""Rule lqg_convergence: MHP estimates vs P (paper Fig. 3) -> results/lqg/convergence.csv."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.lqg.simulate import run_convergence

with rule_logging(snakemake):
    df = run_convergence(snakemake.params.lqg, snakemake.params.seed, n_jobs=snakemake.threads)
    write_csv(df, snakemake.output[0])
