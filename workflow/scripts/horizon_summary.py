"""Rule horizon_summary: statistics of the long-horizon study (UAV and oven LQG), tables,
claims, section."""

from pathlib import Path

import pandas as pd

from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.io import read_table, write_csv, write_text
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.horizon.section import HorizonInputs, horizon_section, horizon_tables
from rsmhp.studies.horizon.section_optimiser import SUMMARY_COLUMNS as OPTIMISER_COLUMNS
from rsmhp.studies.horizon.simulate_lqg import estimator_contract, regret_contract
from rsmhp.studies.horizon.simulate_uav import closed_contract, horizon_contracts
from rsmhp.studies.horizon.summarise_lqg import (
    summarize_lqg_estimators,
    summarize_lqg_horizon_regret,
)
from rsmhp.studies.horizon.summarise_uav import (
    lqg_horizon_table,
    summarize_approx,
    summarize_closed,
    summarize_horizon_regret,
)

with rule_logging(snakemake) as log:
    p = snakemake.params
    jobs = [(m, int(h)) for m in p.cfg["models"] for h in p.cfg["H"]]
    approx, regret, closed = [], [], []
    for (model, H), a_path, r_path, c_path in zip(
        jobs, snakemake.input.approx, snakemake.input.regret, snakemake.input.closed, strict=True
    ):
        c_approx, c_regret = horizon_contracts(p.cfg, model, H)
        approx.append(read_checked(a_path, c_approx))
        regret.append(read_checked(r_path, c_regret))
        closed.append(read_checked(c_path, closed_contract(p.cfg, model, H)))
    approx = pd.concat(approx, ignore_index=True)
    regret = pd.concat(regret, ignore_index=True)
    closed = pd.concat(closed, ignore_index=True)
    c_sum = summarize_closed(closed, p.seed, int(p.cfg["bootstrap"]))
    a_sum = summarize_approx(approx, p.seed, int(p.cfg["bootstrap"]))
    r_sum = summarize_horizon_regret(regret)
    lq, model = p.lqg, p.lqg_model
    est = read_checked(snakemake.input.lqg_estimators, estimator_contract(lq, model))
    reg = read_checked(snakemake.input.lqg_regret, regret_contract(lq))
    est_sum = summarize_lqg_estimators(est, lq, model, p.seed)
    reg_sum = summarize_lqg_horizon_regret(reg, model)
    lqg_table = lqg_horizon_table(
        lq["a_values"], lq["H"], r=model["r"], sigma=model["sigma"], eps=lq["eps"]
    )
    tables = horizon_tables(a_sum, r_sum, lqg_table, c_sum, est_sum, reg_sum)
    opt = snakemake.input.optimiser
    optimiser = read_table(opt[0], OPTIMISER_COLUMNS) if opt else None
    section = horizon_section(
        HorizonInputs(
            approx=approx,
            approx_summary=a_sum,
            regret_summary=r_sum,
            tables=tables,
            cfg=p.cfg,
            seed=p.seed,
            lqg_table=lqg_table,
            lqg_cfg=lq,
            a_model=model["a"],
            closed=closed,
            closed_summary=c_sum,
            lqg_est=est,
            lqg_est_summary=est_sum,
            lqg_regret_summary=reg_sum,
            planner=p.planner,
            optimiser=optimiser,
        )
    )
    write_csv(a_sum, snakemake.output.approx)
    write_csv(r_sum, snakemake.output.regret)
    write_csv(c_sum, snakemake.output.closed)
    write_csv(est_sum, snakemake.output.lqg_estimators)
    write_csv(reg_sum, snakemake.output.lqg_regret)
    for path in snakemake.output.tables:
        write_text(tables[Path(path).stem] + "\n", path)
    section.save(snakemake.output.section)
    log.info("%d approximation rows, %d claims", len(a_sum), len(section.claims))
