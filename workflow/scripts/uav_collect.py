"""Rule uav_collect: concatenate the chunks into results/uav/runs.csv and steps.parquet."""

import pandas as pd

from rsmhp.experiments.uav import RUN_COLUMNS, STEP_COLUMNS
from rsmhp.io import read_table, write_csv, write_parquet
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake.log[0], snakemake.rule) as log:
    order = {m: i for i, m in enumerate(snakemake.params.methods)}

    def collect(paths, columns, keys):
        df = pd.concat([read_table(p, columns) for p in paths], ignore_index=True)
        df = df.assign(_o=df["method"].map(order)).sort_values(["_o", *keys], kind="stable")
        return df.drop(columns="_o").reset_index(drop=True)[columns]

    runs = collect(snakemake.input.runs, RUN_COLUMNS, ["run"])
    steps = collect(snakemake.input.steps, STEP_COLUMNS, ["run", "step"])
    if runs.duplicated(["method", "run"]).any():
        raise ValueError("duplicate (method, run) rows across chunks")
    write_csv(runs, snakemake.output.runs)
    write_parquet(steps, snakemake.output.steps)
    log.info("%d runs, %d steps", len(runs), len(steps))
