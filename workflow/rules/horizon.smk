# Long horizons (horizon.uav): one job per model variant and horizon H with every method's
# cost estimate against a reference sample, its open-loop regret and its planning time
# (one thread), then aggregation, claims and report section, and the figures.
from rsmhp.figures.horizon import FIGURES as HORIZON_FIGURES
from rsmhp.narrative.horizon import TABLES as HORIZON_TABLES

HZ = config["horizon"]["uav"]
HZ_MODELS = list(HZ["models"])
HZ_JOBS = [f"{m}_H{h}" for m in HZ_MODELS for h in HZ["H"]]
if HZ_MODELS:
    REPORT_SECTIONS["horizon_uav"] = "results/report/horizon_uav.json"
    REPORT_FIGURES.extend(HORIZON_FIGURES)


wildcard_constraints:
    hmodel=r"[a-z][a-z0-9_]*",
    H=r"\d+",


rule horizon_uav:
    """UAV horizon study, one model variant and horizon: cost approximation, regret and planning time of every method."""
    output:
        approx="results/horizon/uav/{hmodel}_H{H}_approx.csv",
        regret="results/horizon/uav/{hmodel}_H{H}_regret.csv",
    log:
        "results/logs/horizon_uav/{hmodel}_H{H}.log",
    benchmark:
        "results/benchmarks/horizon_uav/{hmodel}_H{H}.tsv"
    priority: PRIORITY["horizon_uav"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=60,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=canonical(config["decisions"]["uav"]["models"]),
        cfg=pick(HZ, "runs", "steps", "plans", "n_ref", "replicates", "methods"),
        scoring=DEC_SCORING,
        seed=config["seed"],
        code=code_digest("workflow/scripts/horizon_uav.py"),
    script:
        "../scripts/horizon_uav.py"


rule horizon_uav_closed:
    """UAV horizon study, one model variant and horizon: paired closed-loop runs of every method."""
    output:
        "results/horizon/uav/{hmodel}_H{H}_closed.csv",
    log:
        "results/logs/horizon_uav_closed/{hmodel}_H{H}.log",
    benchmark:
        "results/benchmarks/horizon_uav_closed/{hmodel}_H{H}.tsv"
    priority: PRIORITY["horizon_uav"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=60,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=canonical(config["decisions"]["uav"]["models"]),
        cfg=pick(HZ, "closed_runs", "methods"),
        seed=config["seed"],
        code=code_digest("workflow/scripts/horizon_uav_closed.py"),
    script:
        "../scripts/horizon_uav_closed.py"


rule horizon_uav_summary:
    """UAV horizon study: statistics by horizon, tables, claims HZ-1/HZ-2, report section."""
    input:
        approx=expand("results/horizon/uav/{job}_approx.csv", job=HZ_JOBS),
        regret=expand("results/horizon/uav/{job}_regret.csv", job=HZ_JOBS),
        closed=expand("results/horizon/uav/{job}_closed.csv", job=HZ_JOBS),
    output:
        approx="results/horizon/uav_approx_summary.csv",
        regret="results/horizon/uav_regret_summary.csv",
        closed="results/horizon/uav_closed_summary.csv",
        tables=table_outputs(HORIZON_TABLES, "Long horizons"),
        section="results/report/horizon_uav.json",
    log:
        "results/logs/horizon_uav_summary.log",
    benchmark:
        "results/benchmarks/horizon_uav_summary.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        cfg=canonical(HZ),
        lqg=canonical(config["horizon"]["lqg"]),
        lqg_model=pick(config["lqg"]["model"], "a", "r", "sigma"),
        seed=config["seed"],
        code=code_digest("workflow/scripts/horizon_uav_summary.py"),
    script:
        "../scripts/horizon_uav_summary.py"


rule horizon_figures:
    """UAV horizon study figures: cost-approximation error, planning time and regret against H."""
    input:
        approx="results/horizon/uav_approx_summary.csv",
        regret="results/horizon/uav_regret_summary.csv",
        closed="results/horizon/uav_closed_summary.csv",
    output:
        figure_outputs(HORIZON_FIGURES, "Long horizons"),
    log:
        "results/logs/horizon_figures.log",
    benchmark:
        "results/benchmarks/horizon_figures.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        code=code_digest("workflow/scripts/horizon_figures.py"),
    script:
        "../scripts/horizon_figures.py"


rule horizon:
    """Target: the long-horizon study (nothing when no model is configured)."""
    input:
        rules.horizon_uav_summary.output if HZ_MODELS else [],
        rules.horizon_figures.output if HZ_MODELS else [],
