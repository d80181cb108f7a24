"""Rule frontier_compare: the new methods paired with the published reference (report,
table, figure; rsmhp.studies.frontier.compare)."""

from pathlib import Path

import pandas as pd

from rsmhp.pipeline.io import write_csv, write_text
from rsmhp.pipeline.script import rule_logging
from rsmhp.report.figures import save_figure
from rsmhp.studies.frontier.compare import compare_figure, compare_markdown, paired_comparison
from rsmhp.studies.frontier.reference import load_reference

with rule_logging(snakemake) as log:
    reference, meta = load_reference(Path(snakemake.input.reference[0]).parent)
    new = pd.concat([pd.read_csv(f) for f in snakemake.input.runs], ignore_index=True)
    margin = float(meta["preregistration"]["margin_m"])
    table = paired_comparison(new, reference, meta["ladder"], margin)
    write_csv(table, snakemake.output.table)
    write_text(
        compare_markdown(table, meta, margin, dict(snakemake.params.plugins)),
        snakemake.output.report,
    )
    fig = compare_figure(table, reference, meta["ladder"])
    save_figure(fig, str(snakemake.output.figure).removesuffix(".png"))
    log.info("%d paired comparisons: %s", len(table), table["verdict"].value_counts().to_dict())
