"""Rule frontier_reference: the confirmatory run's per-run table as the published reference
(Parquet) with the fingerprint of its scenarios (rsmhp.studies.frontier.reference)."""

import pandas as pd

from rsmhp.pipeline.script import rule_logging
from rsmhp.report.provenance import provenance
from rsmhp.studies.frontier.reference import write_reference

with rule_logging(snakemake) as log:
    p = snakemake.params
    runs = pd.concat([pd.read_csv(f) for f in snakemake.input.runs], ignore_index=True)
    meta = {
        "what": "the confirmatory run's closed-loop runs of every preregistered configuration "
        "(rsmhp.studies.frontier.reference); make compare pairs new methods with them",
        "scenario": p.scenario,
        "ladder": p.ladder,
        "preregistration": p.preregistration,
        "commit": provenance({}).get("commit", "unknown"),
    }
    pq, js = write_reference(runs, meta, str(snakemake.output.runs).rpartition("/")[0])
    log.info("reference: %d runs, %d bytes of Parquet", len(runs), pq.stat().st_size)
