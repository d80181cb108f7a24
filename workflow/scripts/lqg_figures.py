"""Rule lqg_figures: paper-style Fig. 3, its statistical view, error vs P with Chebyshev, NBO
error with residuals (PNG + PDF)."""

from pathlib import Path

from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.io import read_table
from rsmhp.pipeline.script import rule_logging
from rsmhp.report.figures import save_figure
from rsmhp.studies.lqg import figures as figs
from rsmhp.studies.lqg.simulate import convergence_contract
from rsmhp.studies.lqg.summarise import eps_label

with rule_logging(snakemake):
    eps = list(snakemake.params.eps)
    conv = read_checked(snakemake.input.convergence, convergence_contract(snakemake.params.lqg))
    per_eps = [
        f"{col}_eps{eps_label(e)}"
        for e in eps
        for col in ("bound", "exceed", "exceed_low", "exceed_high")
    ]
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
            *per_eps,
        ],
    )
    nbo = read_table(
        snakemake.input.nbo_summary, ["a", "H", "nbo_error_sim", "nbo_error_closed", "se", "z"]
    )
    outdir = Path(snakemake.output[0]).parent
    save_figure(figs.fig3_paper_figure(conv, summary), outdir / "lqg_fig3_paper")
    save_figure(figs.convergence_figure(conv, summary), outdir / "lqg_convergence")
    save_figure(figs.error_loglog_figure(summary, eps), outdir / "lqg_error_loglog")
    save_figure(figs.nbo_error_figure(nbo), outdir / "lqg_nbo_error")
