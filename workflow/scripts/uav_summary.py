"""Rule uav_summary: per-method summary, paired differences, Markdown tables, report section."""

from pathlib import Path

from rsmhp.analysis import uav as analysis
from rsmhp.experiments.uav import RUN_COLUMNS
from rsmhp.io import read_table, write_csv, write_text
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake.log[0], snakemake.rule):
    an, seed = snakemake.params.analysis, snakemake.params.seed
    runs = read_table(snakemake.input.runs, RUN_COLUMNS)
    summary = analysis.summarize_methods(runs, seed, an["bootstrap"], an["level"])
    paired = analysis.paired_differences(runs, seed, an["bootstrap"], an["level"])
    tables = analysis.uav_tables(summary, paired)
    write_csv(summary, snakemake.output.summary)
    write_csv(paired, snakemake.output.paired)
    for path in snakemake.output.tables:
        write_text(tables[Path(path).stem] + "\n", path)
    section = analysis.uav_section(
        summary, paired, tables, snakemake.params.setting, an["bootstrap"]
    )
    section.save(snakemake.output.section)
