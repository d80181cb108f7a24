"""Rule uav_summary: per-method summary, paired differences, Markdown tables, report section."""

from pathlib import Path

from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.io import write_csv, write_text
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.uav import section as narrative
from rsmhp.studies.uav import summarise as analysis
from rsmhp.studies.uav.simulate import runs_contract

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
