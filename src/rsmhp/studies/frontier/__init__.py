"""The frontier study.

Its outputs' names live here, apart from the code that draws and writes them, so that the rule
file imports them when Snakemake parses it without matplotlib, seaborn or scipy.stats (about 1 s
a parse, and every job of a cluster run parses the workflow)."""

#: the exploratory figures (:mod:`rsmhp.studies.frontier.figures`)
FIGURES = ["frontier_exploratory"]
#: the confirmatory run's figures
CONFIRM_FIGURES = ["frontier_confirm"]
#: the exploratory tables (:mod:`rsmhp.studies.frontier.section`)
TABLES = ("frontier_exploratory", "frontier_budget")
#: the confirmatory run's tables
CONFIRM_TABLES = ("frontier_confirm", "frontier_confirm_ladder", "frontier_confirm_tuning")
