"""Rule decisions_lqg_summary: per-cell regret summary, slopes, tables, report section."""

from pathlib import Path

from rsmhp.analysis import decisions_lqg as analysis
from rsmhp.contracts import read_checked
from rsmhp.experiments.decisions_lqg import regret_contract
from rsmhp.io import write_csv, write_text
from rsmhp.narrative import decisions_lqg as narrative
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    model = snakemake.params.model
    df = read_checked(snakemake.input[0], regret_contract(snakemake.params.cfg))
    summary = analysis.summarize_lqg_regret(df, model)
    scaling = analysis.lqg_scaling(summary)
    tables = narrative.lqg_tables(summary, scaling)
    write_csv(summary, snakemake.output.summary)
    write_csv(scaling, snakemake.output.scaling)
    for path in snakemake.output.tables:
        write_text(tables[Path(path).stem] + "\n", path)
    section = narrative.lqg_decision_section(summary, scaling, tables, model, snakemake.params.cfg)
    section.save(snakemake.output.section)
