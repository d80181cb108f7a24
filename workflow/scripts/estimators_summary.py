"""Rule estimators_summary: per-cell statistics, Markdown tables and the report section."""

from pathlib import Path

from rsmhp.analysis import estimators as analysis
from rsmhp.experiments.estimators import ABLATION_COLUMNS
from rsmhp.io import read_table, write_csv, write_text
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake.log[0], snakemake.rule):
    ks = list(snakemake.params.ks)
    df = read_table(snakemake.input.ablation, ABLATION_COLUMNS)
    problems = analysis.problems_from_config(
        {"problems": snakemake.params.problems}, snakemake.params.model
    )
    summary = analysis.summarize_ablation(df, problems, snakemake.params.seed)
    tables = analysis.tables(df, summary, ks)
    write_csv(summary, snakemake.output.summary)
    for path in snakemake.output.tables:
        write_text(tables[Path(path).stem] + "\n", path)
    analysis.estimators_section(df, summary, ks, tables).save(snakemake.output.section)
