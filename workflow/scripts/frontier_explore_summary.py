"""Rule frontier_explore_summary: per (model, method) compute, closed- and open-loop
quality with bootstrap CIs (results/frontier/explore_summary.csv), the tables, claims
FR-1..3 and the report section."""

from pathlib import Path

import pandas as pd

from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.io import write_csv, write_text
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.frontier.section import FrontierInputs, frontier_section, frontier_tables
from rsmhp.studies.frontier.simulate import frontier_contracts, timing_contract
from rsmhp.studies.frontier.summarise import summarize_frontier

with rule_logging(snakemake) as log:
    p = snakemake.params
    runs, regret, timing = [], [], []
    for model, r_path, g_path, t_path in zip(
        p.cfg["models"],
        snakemake.input.runs,
        snakemake.input.regret,
        snakemake.input.timing,
        strict=True,
    ):
        c_runs, c_regret = frontier_contracts(p.cfg, model)
        runs.append(read_checked(r_path, c_runs))
        regret.append(read_checked(g_path, c_regret))
        timing.append(read_checked(t_path, timing_contract(p.cfg, model)))
    runs = pd.concat(runs, ignore_index=True)
    regret = pd.concat(regret, ignore_index=True)
    timing = pd.concat(timing, ignore_index=True)
    summary = summarize_frontier(runs, regret, timing)
    tables = frontier_tables(summary, p.cfg)
    section = frontier_section(
        FrontierInputs(runs, regret, summary, tables, p.cfg, p.seed, p.horizon)
    )
    write_csv(summary, snakemake.output.summary)
    for path in snakemake.output.tables:
        write_text(tables[Path(path).stem] + "\n", path)
    section.save(snakemake.output.section)
    log.info("%d (model, method) rows, %d claims", len(summary), len(section.claims))
