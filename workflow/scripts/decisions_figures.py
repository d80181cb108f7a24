"""Rule decisions_figures: decision-study figures (PNG + PDF)."""

from pathlib import Path

from rsmhp.models.lqg.regret_summary import LQG_SUMMARY_COLUMNS
from rsmhp.models.uav.scoring import regret_contract
from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.io import read_table
from rsmhp.pipeline.script import rule_logging
from rsmhp.report.figures import save_figure
from rsmhp.studies.decisions import figures as figs
from rsmhp.studies.decisions.summarise_uav import MAP_COLUMNS

with rule_logging(snakemake):
    outdir = Path(snakemake.output[0]).parent
    summary = read_table(snakemake.input.lqg, LQG_SUMMARY_COLUMNS)
    save_figure(figs.lqg_regret_figure(summary), outdir / "decisions_lqg_regret")
    regret = read_checked(snakemake.input.regret, regret_contract(snakemake.params.cfg))
    # the strip jitter is drawn from a seeded job stream (identical pixels on a rerun)
    save_figure(figs.uav_regret_figure(regret), outdir / "decisions_uav_regret")
    map_df = read_table(snakemake.input.map, MAP_COLUMNS)
    save_figure(figs.uav_map_figure(map_df), outdir / "decisions_uav_map")
