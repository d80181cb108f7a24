"""Rule lqg_nbo_error: simulated vs closed-form NBO error over (a, H)."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.lqg.simulate import run_nbo_error

with rule_logging(snakemake):
    df = run_nbo_error(snakemake.params.lqg, snakemake.params.seed, n_jobs=snakemake.threads)
    write_csv(df, snakemake.output[0])
