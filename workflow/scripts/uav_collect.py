"""Rule uav_collect: check every chunk, concatenate them into results/uav/runs.csv and
steps.parquet."""

from pathlib import Path

import pandas as pd

from rsmhp.pipeline.contracts import check_table, read_checked
from rsmhp.pipeline.io import write_csv, write_parquet
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.uav.simulate import STEP_COLUMNS, chunk_contracts, chunk_runs, runs_contract

with rule_logging(snakemake) as log:
    p = snakemake.params
    order = {m: i for i, m in enumerate(p.methods)}

    def contracts(path):
        """The chunk's (runs, steps) contracts; the path is results/uav/chunks/<method>/<k>.*"""
        method, chunk = Path(path).parent.name, int(Path(path).stem)
        runs = chunk_runs(p.runs, p.chunks, chunk)
        return chunk_contracts(p.specs[method], runs, p.steps, p.seed)

    def collect(frames, keys):
        df = pd.concat(frames, ignore_index=True)
        df = df.assign(_o=df["method"].map(order)).sort_values(["_o", *keys], kind="stable")
        return df.drop(columns="_o").reset_index(drop=True)

    runs = collect([read_checked(f, contracts(f)[0]) for f in snakemake.input.runs], ["run"])
    steps = collect(
        [read_checked(f, contracts(f)[1]) for f in snakemake.input.steps], ["run", "step"]
    )
    contract = runs_contract(p.methods, p.runs, p.seed)
    runs = check_table(runs, "results/uav/chunks (all chunks together)", contract)
    write_csv(runs[list(contract.columns)], snakemake.output.runs)
    write_parquet(steps[STEP_COLUMNS], snakemake.output.steps)
    log.info("%d runs, %d steps", len(runs), len(steps))
