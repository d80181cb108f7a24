"""Rule decisions_uav_summary: open-loop regret summary, the sensitivity map, tables, section."""

from pathlib import Path

import pandas as pd

from rsmhp.models.uav.scoring import map_contracts, regret_contract
from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.io import write_csv, write_text
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.decisions import section_uav as narrative
from rsmhp.studies.decisions import summarise_uav as analysis

with rule_logging(snakemake):
    cfg, seed = snakemake.params.cfg, snakemake.params.seed
    n_boot = int(cfg["map"]["bootstrap"])
    regret = read_checked(snakemake.input.regret, regret_contract(cfg["uav"]))
    # results/decisions/map/<cell>.csv and <cell>_regret.csv, checked against the cell's config
    map_runs = pd.concat(
        [
            read_checked(p, map_contracts(cfg["map"], Path(p).stem)[0])
            for p in snakemake.input.map_runs
        ]
    )
    map_regret = pd.concat(
        [
            read_checked(p, map_contracts(cfg["map"], Path(p).stem.removesuffix("_regret"))[1])
            for p in snakemake.input.map_regret
        ]
    )
    summary = analysis.summarize_uav_regret(regret, seed, n_boot)
    map_df = analysis.summarize_map(map_runs, map_regret, cfg["map"], seed, n_boot)
    groups = analysis.summarize_map_groups(
        map_runs, map_df, seed, n_boot, snakemake.params.base_limited
    )
    tables = narrative.uav_tables(summary, map_df)
    write_csv(summary, snakemake.output.regret_summary)
    write_csv(map_df, snakemake.output.map)
    write_csv(groups, snakemake.output.map_groups)
    for path in snakemake.output.tables:
        write_text(tables[Path(path).stem] + "\n", path)
    section = narrative.uav_decision_section(
        regret, summary, map_df, groups, tables, cfg, seed, snakemake.params.base_limited
    )
    section.save(snakemake.output.section)
