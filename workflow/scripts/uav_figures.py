"""Rule uav_figures: Fig. 4 and Fig. 5 analogues (ECDFs) and paired differences (PNG + PDF)."""

from pathlib import Path

from rsmhp.contracts import read_checked
from rsmhp.experiments.uav import runs_contract
from rsmhp.figures import save_figure
from rsmhp.figures import uav as figs
from rsmhp.io import read_table
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake.log[0], snakemake.rule):
    p = snakemake.params
    runs = read_checked(snakemake.input.runs, runs_contract(p.methods, p.runs, p.seed))
    summary = read_table(snakemake.input.summary, ["method", "family", "label", "N_T", "n_runs"])
    paired = read_table(
        snakemake.input.paired, ["method", "baseline", "mean_diff", "ci_low", "ci_high"]
    )
    outdir = Path(snakemake.output[0]).parent
    save_figure(figs.error_cdf_nt_figure(runs, summary), outdir / "uav_error_cdf_nt")
    save_figure(figs.error_cdf_nbo_figure(runs, summary), outdir / "uav_error_cdf_nbo")
    save_figure(figs.paired_diff_figure(runs, summary, paired), outdir / "uav_paired_diff")
