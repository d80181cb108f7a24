"""Rule decisions_map_cell: paired closed-loop runs and open-loop regret of one map cell."""

from rsmhp.models.uav.scoring import run_map_cell
from rsmhp.pipeline.io import write_csv
from rsmhp.pipeline.runstore import open_store, report_line
from rsmhp.pipeline.script import rule_logging

with rule_logging(snakemake) as log:
    store = open_store(snakemake.config["run_store"])
    runs, regret = run_map_cell(
        snakemake.params.uav,
        snakemake.params.cfg,
        snakemake.params.scoring,
        snakemake.wildcards.cell,
        snakemake.params.seed,
        snakemake.threads,
        store=store,
    )
    log.info(report_line(store))
    write_csv(runs, snakemake.output.runs)
    write_csv(regret, snakemake.output.regret)
