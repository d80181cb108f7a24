"""Rule decisions_uav_summary: open-loop regret summary, the sensitivity map, tables, section."""

from pathlib import Path

import pandas as pd

from rsmhp.analysis import decisions as analysis
from rsmhp.experiments.decisions_uav import MAP_RUN_COLUMNS, REGRET_COLUMNS
from rsmhp.io import read_table, write_csv, write_text
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake.log[0], snakemake.rule):
    cfg, seed = snakemake.params.cfg, snakemake.params.seed
    n_boot = int(cfg["map"]["bootstrap"])
    regret = read_table(snakemake.input.regret, REGRET_COLUMNS)
    map_runs = pd.concat([read_table(p, MAP_RUN_COLUMNS) for p in snakemake.input.map_runs])
    map_regret = pd.concat(
        [read_table(p, REGRET_COLUMNS, min_rows=0) for p in snakemake.input.map_regret]
    )
    summary = analysis.summarize_uav_regret(regret, seed, n_boot)
    map_df = analysis.summarize_map(map_runs, map_regret, cfg["map"], seed, n_boot)
    tables = analysis.uav_tables(summary, map_df)
    write_csv(summary, snakemake.output.regret_summary)
    write_csv(map_df, snakemake.output.map)
    for path in snakemake.output.tables:
        write_text(tables[Path(path).stem] + "\n", path)
    section = analysis.uav_decision_section(
        regret, summary, map_df, tables, cfg, seed, snakemake.params.base_limited
    )
    section.save(snakemake.output.section)
