"""Rule horizon_uav: one model variant and horizon of the UAV horizon study."""

from rsmhp.experiments.horizon import run_horizon
from rsmhp.io import write_csv
from rsmhp.pipeline import rule_logging

with rule_logging(snakemake):
    p, w = snakemake.params, snakemake.wildcards
    approx, regret = run_horizon(p.uav, p.models, p.cfg, p.scoring, w.hmodel, int(w.H), p.seed)
    write_csv(approx, snakemake.output.approx)
    write_csv(regret, snakemake.output.regret)
