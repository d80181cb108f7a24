"""Rule uav_figures: the paper's Figs. 4 and 5 drawn its way (CDFs of the per-run average
error) and, for each, the paired view (per-run differences, mean and CI) (PNG + PDF)."""

from pathlib import Path

from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.io import read_table
from rsmhp.pipeline.script import rule_logging
from rsmhp.report.figures import save_figure
from rsmhp.studies.uav import figures as figs
from rsmhp.studies.uav.section import FIGURES
from rsmhp.studies.uav.simulate import runs_contract

with rule_logging(snakemake):
    p = snakemake.params
    runs = read_checked(snakemake.input.runs, runs_contract(p.methods, p.runs, p.seed))
    summary = read_table(snakemake.input.summary, ["method", "family", "label", "N_T", "n_runs"])
    paired = read_table(
        snakemake.input.paired,
        ["method", "baseline", "comparison", "purpose", "n_runs", "mean_diff", "ci_low", "ci_high"],
    )
    draw = {
        "uav_error_cdf_nt": lambda: figs.error_cdf_nt_figure(runs, summary),
        "uav_paired_diff_nt": lambda: figs.paired_diff_nt_figure(runs, summary, paired),
        "uav_error_cdf_nbo": lambda: figs.error_cdf_nbo_figure(runs, summary),
        "uav_paired_diff": lambda: figs.paired_diff_figure(runs, summary, paired),
    }
    outdir = Path(snakemake.output[0]).parent
    for stem in FIGURES:
        save_figure(draw[stem](), outdir / stem)
