"""Rule frontier_tune_select: the tuning rule (rsmhp.pipeline.protocol.select) over every model, the
tuned file with its provenance, the selection table and its Markdown."""

import pandas as pd
import yaml

from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.io import write_csv, write_text
from rsmhp.pipeline.protocol import select, stream_seed, tuned_document, tuning_configurations
from rsmhp.pipeline.script import rule_logging
from rsmhp.report.markdown import markdown_table
from rsmhp.report.provenance import provenance
from rsmhp.studies.frontier.simulate import config_runs_contract, config_timing_contract
from rsmhp.studies.frontier.tuning import candidate_table, depth_table

with rule_logging(snakemake) as log:
    p = snakemake.params
    configs = tuning_configurations(p.tuning)
    runs = range(int(p.tuning["runs"]))
    quality, timing = [], []
    for model, r_path, t_path in zip(
        p.models, snakemake.input.runs, snakemake.input.timing, strict=True
    ):
        quality.append(
            read_checked(r_path, config_runs_contract("frontier_tune", configs, runs, model))
        )
        timing.append(
            read_checked(
                t_path,
                config_timing_contract("frontier_tune_timing", configs, p.tuning["timing"], model),
            )
        )
    quality = pd.concat(quality, ignore_index=True)
    timing = pd.concat(timing, ignore_index=True)
    # every configuration is a candidate of its family, the untuned reference NBO one of NBO's
    tuned = configs
    selection = select(quality, timing, tuned, p.tuning["budgets_ms"])
    prov = provenance(p.config)
    doc = tuned_document(
        selection,
        {
            "stream": "tune",
            "stream seed": stream_seed(p.seed, "tune"),
            "runs per candidate": int(p.tuning["runs"]),
            "candidates": len(tuned),
            "rule": "per model, family and budget: the lowest mean closed-loop error over the "
            "tuning runs among the family's candidates whose planning cost per step is within "
            "the budget; cost = the larger of the median interleaved planning time and the "
            "mean planning time per step of the candidate's own closed-loop tuning runs (ties: "
            "less work, then candidate order)",
            **{k: prov[k] for k in prov if k not in ("host",)},
        },
    )
    write_text(
        "# Written by `make tune` (rule frontier_tune_select): the protocol's tuned "
        "configurations.\n# Do not edit: the preregistration records this file's sha256.\n"
        + yaml.safe_dump(doc, sort_keys=False, allow_unicode=True),
        snakemake.output.tuned,
    )
    write_csv(selection, snakemake.output.selection)
    write_text(
        markdown_table(selection, digits=4, missing="default") + "\n", snakemake.output.table
    )
    cands = candidate_table(quality, timing, tuned)
    write_csv(cands, snakemake.output.candidates)
    depth = depth_table(quality, cands)
    write_text(
        "What depth buys, on the tuning stream: every tree search and the pursuit policy alone "
        "(plan depth 0); diff_pursuit = mean error − the pursuit policy's, paired over the "
        "tuning runs (m, 95% t interval).\n\n"
        + markdown_table(depth, digits=3, missing="—")
        + "\n",
        snakemake.output.depth,
    )
    log.info("%d (model, family, budget) selections from %d candidates", len(selection), len(tuned))
