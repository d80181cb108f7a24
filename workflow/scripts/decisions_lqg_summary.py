"""Rule decisions_lqg_summary: per-cell regret summary, slopes, tables, report section."""

from pathlib import Path

from rsmhp.models.lqg import regret_summary as analysis
from rsmhp.models.lqg.regret import regret_contract
from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.io import write_csv, write_text
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.decisions import section_lqg as narrative

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
