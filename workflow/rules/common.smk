# Shared settings of every rule file.

THREADS = config["threads"]

# Report sections, in report order: key -> section JSON written by an aggregation rule.
# Each experiment family adds its entry here (and its figures to REPORT_FIGURES).
REPORT_SECTIONS = {"lqg": "results/report/lqg.json"}

REPORT_FIGURES = []
