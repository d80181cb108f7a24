"""The scenarios study.

Its outputs' names live here, apart from the code that draws and writes them, so that the rule
file imports them when Snakemake parses it without matplotlib, seaborn or scipy.stats (about 1 s
a parse, and every job of a cluster run parses the workflow)."""

#: the figures (:mod:`rsmhp.studies.scenarios.figures`)
FIGURES = ["scenarios_best", "scenarios_improvement"]
#: the tables (:mod:`rsmhp.studies.scenarios.section`)
TABLES = ("scenarios_best", "scenarios_improvement", "scenarios_per_scenario")
