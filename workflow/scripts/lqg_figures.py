"""Rule lqg_figures: Fig. 3 analogue, error vs P with Chebyshev, NBO error (PNG + PDF)."""

from pathlib import Path

from rsmhp.contracts import read_checked
from rsmhp.experiments.lqg import convergence_contract
from rsmhp.figures import lqg as figs
from rsmhp.figures import save_figure
from rsmhp.io import read_table
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake.log[0], snakemake.rule):
    eps = list(snakemake.params.eps)
    conv = read_checked(snakemake.input.convergence, convergence_contract(snakemake.params.lqg))
    summary = read_table(
        snakemake.input.summary,
        [
            "P",
            "mean",
            "ci_low",
            "ci_high",
            "rmse",
            "rmse_low",
            "rmse_high",
            "sd_theory",
            "J_exact",
            "J_nbo",
            "n_replicates",
            *(f"bound_eps{e:g}" for e in eps),
        ],
    )
    nbo = read_table(
        snakemake.input.nbo_summary, ["a", "H", "nbo_error_sim", "nbo_error_closed", "se"]
    )
    outdir = Path(snakemake.output[0]).parent
    save_figure(figs.convergence_figure(conv, summary), outdir / "lqg_convergence")
    save_figure(figs.error_loglog_figure(summary, eps), outdir / "lqg_error_loglog")
    save_figure(figs.nbo_error_figure(nbo), outdir / "lqg_nbo_error")
