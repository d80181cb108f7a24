"""Rule estimators_summary: per-cell statistics, Markdown tables and the report section."""

from pathlib import Path

from rsmhp.models.lqg.ablation import ablation_contract
from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.io import write_csv, write_text
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.estimators import section as narrative
from rsmhp.studies.estimators import summarise as analysis

with rule_logging(snakemake):
    ks = list(snakemake.params.ks)
    contract = ablation_contract(snakemake.params.estimators, snakemake.params.model)
    df = read_checked(snakemake.input.ablation, contract)
    problems = analysis.problems_from_config(
        {"problems": snakemake.params.problems}, snakemake.params.model
    )
    summary = analysis.summarize_ablation(df, problems, snakemake.params.seed)
    cheb = analysis.chebyshev_table(df, summary, ks, problems)
    tables = narrative.tables(df, summary, cheb)
    write_csv(summary, snakemake.output.summary)
    for path in snakemake.output.tables:
        write_text(tables[Path(path).stem] + "\n", path)
    narrative.estimators_section(df, summary, cheb, tables).save(snakemake.output.section)
