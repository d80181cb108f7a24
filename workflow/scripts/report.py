"""Rule report: render results/paper/replication.md from the report sections, copy its
figures, write results/provenance.json."""

import json
import shutil
from pathlib import Path

from rsmhp.io import write_text
from rsmhp.pipeline import rule_logging
from rsmhp.report import Section, provenance, render_report

with rule_logging(snakemake.log[0], snakemake.rule):
    sections = [Section.load(p) for p in snakemake.input.sections]
    for src, dst in zip(snakemake.input.figures, snakemake.output.figures, strict=True):
        Path(dst).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(src, dst)
    prov = provenance(snakemake.params.config)
    write_text(json.dumps(prov, indent=1) + "\n", snakemake.output.provenance)
    # the report summarises it; host and date stay in the JSON (they change every run)
    summary = {k: v for k, v in prov.items() if k not in ("host", "date (UTC)")}
    text = render_report(sections, snakemake.params.config, summary)
    Path(snakemake.output.report).write_text(text, encoding="utf-8")
