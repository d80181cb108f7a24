"""Rule horizon_optimiser_summary: statistics of the optimiser split, its table and report
section."""

from pathlib import Path

import pandas as pd

from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.io import write_csv, write_text
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.horizon.section_optimiser import (
    optimiser_section,
    optimiser_summary,
    optimiser_tables,
)
from rsmhp.studies.horizon.simulate_optimiser import split_contract

with rule_logging(snakemake) as log:
    p = snakemake.params
    jobs = [(m, int(h)) for m in p.models for h in p.cfg["H"]]
    table = pd.concat(
        [
            read_checked(path, split_contract(p.cfg, model, H))
            for (model, H), path in zip(jobs, snakemake.input, strict=True)
        ],
        ignore_index=True,
    )
    summary = optimiser_summary(table)
    tables = optimiser_tables(summary)
    section = optimiser_section(summary, tables, p.cfg, p.planner)
    write_csv(summary, snakemake.output.summary)
    for path in snakemake.output.tables:
        write_text(tables[Path(path).stem] + "\n", path)
    section.save(snakemake.output.section)
    log.info("%d split rows, %d summary rows", len(table), len(summary))
