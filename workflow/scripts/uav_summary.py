"""Rule uav_summary: per-method summary, paired differences, Markdown tables, report section."""

from pathlib import Path

from rsmhp.analysis import uav as analysis
from rsmhp.contracts import read_checked
from rsmhp.experiments.uav import runs_contract
from rsmhp.io import write_csv, write_text
from rsmhp.narrative import uav as narrative
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    an, seed = snakemake.params.analysis, snakemake.params.seed
    contract = runs_contract(snakemake.params.methods, snakemake.params.runs, seed)
    runs = read_checked(snakemake.input.runs, contract)
    summary = analysis.summarize_methods(runs, seed, an["bootstrap"], an["level"])
    paired = analysis.paired_differences(runs, seed, an["bootstrap"], an["level"])
    tables = narrative.uav_tables(summary, paired)
    write_csv(summary, snakemake.output.summary)
    write_csv(paired, snakemake.output.paired)
    for path in snakemake.output.tables:
        write_text(tables[Path(path).stem] + "\n", path)
    section = narrative.uav_section(
        summary,
        paired,
        tables,
        snakemake.params.setting,
        an["bootstrap"],
        runs,
        an["equivalence_margin"],
    )
    section.save(snakemake.output.section)
