"""Rule report: render results/paper/replication.md (main text) and appendix.md from the
report sections, copy their figures, write the claims (claims.json, the README's glance
table) and results/provenance.json (with the digests of the code that made the results)."""

import json
import shutil
from pathlib import Path

import pandas as pd

from rsmhp.pipeline.io import write_text
from rsmhp.pipeline.protocol import file_commit
from rsmhp.pipeline.script import rule_logging
from rsmhp.report.history import load_history
from rsmhp.report.html import summary_fragment
from rsmhp.report.ledger import Section, claims_records
from rsmhp.report.provenance import code_provenance, provenance
from rsmhp.report.render import (
    SUMMARY_CAPTION,
    SUMMARY_FIGURE,
    glance_table,
    render_appendix,
    render_report,
    statements_records,
    what_we_found,
)
from rsmhp.report.statements import judge_all
from rsmhp.report.verdicts import holm_sections

with rule_logging(snakemake) as log:
    # Holm's correction over the benchmark's own comparisons (FR and HZ claims) before any
    # verdict is rendered or counted
    sections = holm_sections([Section.load(p) for p in snakemake.input.sections])
    for src, dst in zip(snakemake.input.figures, snakemake.output.figures, strict=True):
        Path(dst).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(src, dst)
    prov = provenance(snakemake.params.config)
    prov["code"] = code_provenance(
        Path(snakemake.output.provenance).parent,
        snakemake.scriptdir,
        extra={snakemake.rule: (snakemake.params.code, [snakemake.output.provenance])},
    )
    write_text(json.dumps(prov, indent=1) + "\n", snakemake.output.provenance)
    # the report summarises it; host and date stay in the JSON (they change every run), the
    # code as one digest per rule
    summary = {k: v for k, v in prov.items() if k not in ("host", "date (UTC)", "code")}
    pre = dict(snakemake.params.preregistration)
    if pre:
        pre["commit"] = file_commit(Path(snakemake.scriptdir).resolve().parents[1] / pre["path"])
        summary["preregistration"] = (
            f"{pre['path']} sha256 {pre['sha256']} (commit {pre['commit']})"
        )
    summary["code (rule digest)"] = ", ".join(
        f"{rule} {' / '.join(e['recorded'])}" for rule, e in prov["code"]["rules"].items()
    )
    # every verdict each claim had before (published runs, the portability drill, other
    # seed streams): the fragility lines; the best family per cell: the summary figure's table
    history = load_history(snakemake.input.history[0]) if snakemake.input.history else None
    best = pd.read_csv(snakemake.input.best[0]) if snakemake.input.best else None
    main = render_report(sections, summary, best=best, history=history)
    write_text(main, snakemake.output.report)
    # the HTML report's landing page (workflow/report/workflow.rst): the same findings and figure
    figure = next((f for f in snakemake.output.figures if Path(f).stem == SUMMARY_FIGURE), None)
    write_text(
        summary_fragment(
            what_we_found(sections, best=best),
            figure,
            SUMMARY_CAPTION if figure else "",
        ),
        snakemake.output.summary,
    )
    write_text(
        render_appendix(sections, snakemake.params.config, summary, history=history),
        snakemake.output.appendix,
    )
    records = claims_records(sections)
    claims = [c for s in sorted(sections, key=lambda s: (s.order, s.key)) for c in s.claims]
    claims_file = {
        "config sha256": prov.get("config sha256"),
        "commit": prov.get("commit"),
        "preregistration": pre,
        "statements": statements_records(judge_all(claims)[0]),
        "claims": records,
    }
    write_text(
        json.dumps(claims_file, indent=1, ensure_ascii=False) + "\n", snakemake.output.claims
    )
    write_text(glance_table(claims, history=history) + "\n", snakemake.output.glance)
    log.info("main text %d bytes, %d claims", len(main.encode()), len(records))
