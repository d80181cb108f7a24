"""The horizon study.

Its outputs' names live here, apart from the code that draws and writes them, so that the rule
file imports them when Snakemake parses it without matplotlib, seaborn or scipy.stats (about 1 s
a parse, and every job of a cluster run parses the workflow)."""

#: the figures (:mod:`rsmhp.studies.horizon.figures`)
FIGURES = ["horizon_uav_error", "horizon_uav_time", "horizon_uav_closed", "horizon_lqg"]
#: the optimiser split's figures (:mod:`rsmhp.studies.horizon.figures_optimiser`)
OPTIMISER_FIGURES = ["horizon_optimiser"]
#: the tables (:mod:`rsmhp.studies.horizon.section`)
TABLES = (
    "horizon_uav_approx",
    "horizon_uav_regret",
    "horizon_uav_closed",
    "horizon_lqg",
    "horizon_lqg_estimators",
    "horizon_lqg_regret",
)
#: the optimiser split's tables (:mod:`rsmhp.studies.horizon.section_optimiser`)
OPTIMISER_TABLES = ("horizon_optimiser",)
