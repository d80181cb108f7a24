"""Rule frontier_confirm_summary: the confirmatory run's statistics (per configuration and per
budget rung), claims FR-*, tables and the report section."""

import json
from pathlib import Path

import pandas as pd

from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.io import write_csv, write_text
from rsmhp.pipeline.protocol import Configuration, file_commit, tuned_configurations
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.frontier.claims import confirm_claims
from rsmhp.studies.frontier.section import ConfirmInputs, confirm_section, confirm_tables
from rsmhp.studies.frontier.simulate import config_runs_contract, config_timing_contract
from rsmhp.studies.frontier.summarise import ladder, summarize_configs

with rule_logging(snakemake) as log:
    c = snakemake.params.confirm
    runs, timing = [], []
    for model, r_path, t_path in zip(
        c["models"], snakemake.input.runs, snakemake.input.timing, strict=True
    ):
        configs = [Configuration.from_spec(s) for s in c["plans"][model]]
        n = range(int(c["runs"][model]))
        runs.append(
            read_checked(r_path, config_runs_contract("frontier_confirm", configs, n, model))
        )
        timing.append(
            read_checked(
                t_path,
                config_timing_contract(
                    "frontier_confirm_timing", configs, snakemake.params.timing, model
                ),
            )
        )
    runs = pd.concat(runs, ignore_index=True)
    timing = pd.concat(timing, ignore_index=True)
    pre = c["preregistration"]
    chosen = {m: tuned_configurations(c["tuned"], m) for m in c["models"]}
    summary = summarize_configs(runs, timing)
    lad = ladder(runs, summary, chosen, pre["budgets_ms"])
    claims = confirm_claims(runs, summary, lad, pre, chosen, c["sha256"])
    tables = confirm_tables(summary, lad, c["tuned"])
    exploratory = json.loads(Path(snakemake.input.exploratory).read_text(encoding="utf-8"))
    exploratory = exploratory["claims"]
    superseded = json.loads(Path(snakemake.input.superseded).read_text(encoding="utf-8"))
    commit = file_commit(Path(snakemake.scriptdir).resolve().parents[1] / c["path"])
    meta = {"path": c["path"], "sha256": c["sha256"], "commit": commit}
    section = confirm_section(
        ConfirmInputs(
            summary=summary,
            lad=lad,
            claims=claims,
            tables=tables,
            prereg=pre,
            prereg_meta=meta,
            tuned=c["tuned"],
            exploratory=exploratory,
            superseded=superseded,
        )
    )
    write_csv(summary, snakemake.output.summary)
    write_csv(lad, snakemake.output.ladder)
    for path in snakemake.output.tables:
        write_text(tables[Path(path).stem] + "\n", path)
    section.save(snakemake.output.section)
    log.info("%d configurations, %d ladder rows, %d claims", len(summary), len(lad), len(claims))
