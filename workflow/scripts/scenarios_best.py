"""Rule scenarios_best: per cell of the three groups (equal compute per budget, long horizons
per H, map scenarios) the method with the lowest closed-loop mean error, every other method's
paired difference from it with its 95% t interval, the tied methods and whether the best is
clear."""

import pandas as pd

from rsmhp.pipeline.io import read_table, write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.scenarios.best import best_family, best_runs

CONFIRM_COLUMNS = ["model", "config", "member", "run", "mean_error"]
CLOSED_COLUMNS = ["model", "H", "method", "run", "mean_error"]
MAP_COLUMNS = ["row_value", "col_value", "method", "run", "mean_error"]


def read_all(paths, columns):
    """The files' rows in one table, ``None`` without files (a study that is not configured)."""
    if not paths:
        return None
    return pd.concat([read_table(f, columns) for f in paths], ignore_index=True)


with rule_logging(snakemake) as log:
    inp, p = snakemake.input, snakemake.params
    runs = best_runs(
        confirm=read_all(inp.confirm, CONFIRM_COLUMNS),
        tuned=p.tuned,
        budgets_ms=p.budgets_ms,
        closed=read_all(inp.closed, CLOSED_COLUMNS),
        map_runs=read_all(inp.map_runs, MAP_COLUMNS),
    )
    best = best_family(runs)
    write_csv(best.cells, snakemake.output.best)
    write_csv(best.paired, snakemake.output.paired)
    log.info("%d cells (%d clear), %d paired comparisons", len(best.cells),
             int(best.cells["clear"].sum()), len(best.paired))  # fmt: skip
