"""Rule scenarios_summary: the probability of beating NBO per scenario and method, its
average per group of scenarios; with the best method per cell (rule scenarios_best) the
tables and the report section."""

from pathlib import Path

import pandas as pd

from rsmhp.pipeline.io import read_table, write_csv, write_text
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.scenarios.best import BEST_COLUMNS, PAIRED_COLUMNS
from rsmhp.studies.scenarios.section import scenarios_section, scenarios_tables
from rsmhp.studies.scenarios.summarise import improvement_summary, per_scenario, scenario_runs

MAP_COLUMNS = ["cell", "row_value", "col_value", "method", "run", "mean_error"]
CLOSED_COLUMNS = ["model", "H", "method", "run", "mean_error"]

with rule_logging(snakemake) as log:
    p = snakemake.params
    inp = snakemake.input
    map_runs = (
        pd.concat([read_table(f, MAP_COLUMNS) for f in inp.map_runs], ignore_index=True)
        if inp.map_runs
        else None
    )
    closed = (
        pd.concat([read_table(f, CLOSED_COLUMNS) for f in inp.closed], ignore_index=True)
        if inp.closed
        else None
    )
    runs = scenario_runs(map_runs, closed)
    per = per_scenario(runs)
    summary = improvement_summary(runs, n_boot=int(p.n_boot), seed=int(p.seed))
    best = read_table(inp.best, BEST_COLUMNS, min_rows=0)
    paired = read_table(inp.paired, PAIRED_COLUMNS, min_rows=0)
    tables = scenarios_tables(summary, per, best, paired)
    write_csv(per, snakemake.output.per_scenario)
    write_csv(summary, snakemake.output.summary)
    for path in snakemake.output.tables:
        write_text(tables[Path(path).stem] + "\n", path)
    scenarios_section(summary, tables, best, p.streams).save(snakemake.output.section)
    log.info("%d scenario rows, %d summary rows", len(per), len(summary))
