"""Rule frontier_explore: the equal-compute study of one model variant (closed and open
loop, planning time per step)."""

from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.runstore import open_store, report_line
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.frontier.simulate import run_frontier_model

with rule_logging(snakemake) as log:
    p = snakemake.params
    store = open_store(snakemake.config["run_store"])
    runs, regret = run_frontier_model(
        p.uav, p.models, p.cfg, p.scoring, snakemake.wildcards.model, p.seed, store
    )
    log.info(report_line(store))
    write_csv(runs, snakemake.output.runs)
    write_csv(regret, snakemake.output.regret)
