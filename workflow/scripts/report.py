"""Rule report: render paper/replication.md from the report sections and copy its figures."""

import shutil
from pathlib import Path

from rsmhp.pipeline import rule_logging
from rsmhp.report import Section, provenance, render_report

with rule_logging(snakemake.log[0], snakemake.rule):
    sections = [Section.load(p) for p in snakemake.input.sections]
    for src, dst in zip(snakemake.input.figures, snakemake.output.figures, strict=True):
        Path(dst).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(src, dst)
    text = render_report(sections, snakemake.params.config, provenance())
    Path(snakemake.output.report).write_text(text, encoding="utf-8")
