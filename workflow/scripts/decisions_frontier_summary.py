"""Rule decisions_frontier_summary: per (model, method) compute, closed- and open-loop
quality with bootstrap CIs (results/decisions/frontier_summary.csv)."""

import pandas as pd

from rsmhp.analysis.frontier import summarize_frontier
from rsmhp.contracts import read_checked
from rsmhp.experiments.frontier import frontier_contracts
from rsmhp.io import write_csv
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake) as log:
    p = snakemake.params
    runs, regret = [], []
    for model, r_path, g_path in zip(
        p.cfg["models"], snakemake.input.runs, snakemake.input.regret, strict=True
    ):
        c_runs, c_regret = frontier_contracts(p.cfg, model)
        runs.append(read_checked(r_path, c_runs))
        regret.append(read_checked(g_path, c_regret))
    summary = summarize_frontier(
        pd.concat(runs, ignore_index=True),
        pd.concat(regret, ignore_index=True),
        p.seed,
        p.cfg["bootstrap"],
    )
    write_csv(summary, snakemake.output.summary)
    log.info("%d (model, method) rows", len(summary))
