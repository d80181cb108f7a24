"""Rule decisions_lqg_summary: per-cell regret summary, slopes, tables, report section."""

from pathlib import Path

from rsmhp.analysis import decisions as analysis
from rsmhp.experiments.decisions_lqg import LQG_REGRET_COLUMNS
from rsmhp.io import read_table, write_csv, write_text
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake.log[0], snakemake.rule):
    model = snakemake.params.model
    df = read_table(snakemake.input[0], LQG_REGRET_COLUMNS)
    summary = analysis.summarize_lqg_regret(df, model)
    scaling = analysis.lqg_scaling(summary)
    tables = analysis.lqg_tables(summary, scaling)
    write_csv(summary, snakemake.output.summary)
    write_csv(scaling, snakemake.output.scaling)
    for path in snakemake.output.tables:
        write_text(tables[Path(path).stem] + "\n", path)
    section = analysis.lqg_decision_section(summary, scaling, tables, model, snakemake.params.cfg)
    section.save(snakemake.output.section)
