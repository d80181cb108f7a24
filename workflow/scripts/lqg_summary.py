"""Rule lqg_summary: per-P summary, NBO-error summary, Markdown tables, report section."""

from pathlib import Path

from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.io import write_csv, write_text
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.lqg import section as narrative
from rsmhp.studies.lqg import summarise as analysis
from rsmhp.studies.lqg.simulate import (
    convergence_contract,
    linear_cost_contract,
    nbo_error_contract,
)

with rule_logging(snakemake):
    eps = list(snakemake.params.eps)
    sim = snakemake.params.lqg
    conv = read_checked(snakemake.input.convergence, convergence_contract(sim))
    nbo = read_checked(snakemake.input.nbo_error, nbo_error_contract(sim))
    linear = read_checked(snakemake.input.linear_cost, linear_cost_contract(sim))
    linear_check = analysis.linear_cost_check(linear, snakemake.params.linear_k)
    summary = analysis.summarize_convergence(conv, eps)
    nbo_summary = analysis.summarize_nbo_error(nbo)
    tables = narrative.lqg_tables(summary, nbo_summary, eps)
    write_csv(summary, snakemake.output.summary)
    write_csv(nbo_summary, snakemake.output.nbo_summary)
    for path in snakemake.output.tables:
        write_text(tables[Path(path).stem] + "\n", path)
    section = narrative.lqg_section(summary, nbo_summary, conv, eps, tables, linear_check)
    section.save(snakemake.output.section)
