"""Rule horizon_uav: one model variant, horizon and chunk of runs of the UAV horizon study."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.horizon.simulate_uav import run_horizon

with rule_logging(snakemake):
    p, w = snakemake.params, snakemake.wildcards
    approx, regret = run_horizon(
        p.uav, p.models, p.cfg, p.scoring, w.hmodel, int(w.H), p.seed, runs=p.runs
    )
    write_csv(approx, snakemake.output.approx)
    write_csv(regret, snakemake.output.regret)
