"""The decisions study.

Its outputs' names live here, apart from the code that draws and writes them, so that the rule
file imports them when Snakemake parses it without matplotlib, seaborn or scipy.stats (about 1 s
a parse, and every job of a cluster run parses the workflow)."""

#: the LQG figures (:mod:`rsmhp.studies.decisions.section_lqg`)
FIGURES_LQG = ("decisions_lqg_regret",)
#: the UAV figures (:mod:`rsmhp.studies.decisions.section_uav`)
FIGURES_UAV = ("decisions_uav_regret", "decisions_uav_map")
