"""Rule horizon_optimiser: the optimiser split of one model variant and horizon, at the
belief states of one chunk of the runs."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.horizon.simulate_optimiser import run_optimiser_split

with rule_logging(snakemake):
    p, w = snakemake.params, snakemake.wildcards
    table = run_optimiser_split(p.uav, p.model, int(w.H), p.cfg, p.scoring, p.seed, runs=p.runs)
    write_csv(table, snakemake.output[0])
