# Long horizons (horizon.uav): one job per model variant and horizon H with every method's
# cost estimate against a reference sample, its open-loop regret and its planning time
# (one thread), paired closed-loop runs per (model, H); the oven LQG (horizon.lqg): cost
# estimators and decision regret at long horizons against exact oracles; then aggregation,
# claims and report section, and the figures.
from rsmhp.studies.horizon import FIGURES as HORIZON_FIGURES
from rsmhp.studies.horizon import OPTIMISER_FIGURES, OPTIMISER_TABLES
from rsmhp.studies.horizon import TABLES as HORIZON_TABLES
from rsmhp.pipeline.protocol import stream_seed
from rsmhp.studies.horizon.chunks import layout_runs, unit_files, units

# the seed stream every job of the study draws from (horizon.stream: confirm, the stream of
# the published verdicts; exploratory: the stream of the runs published up to 76a0c01)
HZ_SEED = stream_seed(config["seed"], config["horizon"]["stream"])
HZ = config["horizon"]["uav"]
HZ_FAMILIES = families_of(HZ["methods"], "horizon.uav.methods")
HZL = config["horizon"]["lqg"]
HZL_MODEL = pick(config["lqg"]["model"], "x0", "r", "target", "sigma")
HZ_MODELS = list(HZ["models"])
HZ_REC = HZ.get("recording", {}) or {}
HZ_RECORDING = (
    [f"results/recordings/hz_{HZ_REC['model']}_H{HZ_REC['H']}.rrd"]
    if HZ_MODELS and HZ_REC.get("model")
    else []
)
if HZ_MODELS:
    REPORT_SECTIONS["horizon"] = "results/report/horizon.json"
    REPORT_FIGURES.extend(HORIZON_FIGURES)
# Optimiser error apart from approximation error (horizon.optimiser): one job per model
# variant and H (models: default horizon.uav.models), then the summary with its report
# section (order 34, after the horizon section) and the figure.
HZO = config["horizon"]["optimiser"]
HZO_FAMILIES = families_of(HZO["methods"], "horizon.optimiser.methods")
HZO_MODELS = list(HZ_MODELS if HZO.get("models") is None else HZO["models"])
HZO_JOBS = [f"{m}_H{h}" for m in HZO_MODELS for h in HZO["H"]]
# what one job of the split depends on besides the model, H and the planner
HZO_KEYS = ("runs", "steps", "methods", "budgets", "polish_starts", "polish_maxiter")
# each model variant's uav_models entry (its overrides), for the job of that model
HZ_VARIANTS = {m["name"]: m for m in UAV_MODELS}
HZO_SUMMARY = ["results/horizon/optimiser_summary.csv"] if HZO_MODELS else []
if HZO_MODELS:
    REPORT_SECTIONS["horizon_optimiser"] = "results/report/horizon_optimiser.json"
    REPORT_FIGURES.extend(OPTIMISER_FIGURES)


wildcard_constraints:
    hmodel=r"[a-z][a-z0-9_]*",
    H=r"\d+",


# A (model, H) unit of horizon_uav, horizon_uav_closed and horizon_optimiser runs as jobs of
# contiguous runs (config split: the count at the largest H, fewer at shorter H;
# rsmhp.studies.horizon.chunks); one *_merge job per rule merges every unit's chunks into
# the unit's tables. (model, H, jobs) of every unit, in the order of HZ_JOBS / HZO_JOBS:
HZ_UNITS = {
    "horizon_uav": units(HZ_MODELS, HZ["H"], SPLIT["horizon_uav"], HZ["runs"]),
    "horizon_uav_closed": units(
        HZ_MODELS, HZ["H"], SPLIT["horizon_uav_closed"], HZ["closed_runs"]
    ),
    "horizon_optimiser": units(
        HZO_MODELS, HZO["H"], SPLIT["horizon_optimiser"], HZO["runs"]
    ),
}


rule horizon_uav:
    """UAV horizon study, one model variant, horizon and chunk of runs: cost approximation, regret and planning time of every method at the runs' belief states."""
    output:
        approx="results/horizon/uav/chunks/{hmodel}_H{H}/{chunk}_approx.csv",
        regret="results/horizon/uav/chunks/{hmodel}_H{H}/{chunk}_regret.csv",
    log:
        "results/logs/horizon_uav/{hmodel}_H{H}_{chunk}.log",
    benchmark:
        "results/benchmarks/horizon_uav/{hmodel}_H{H}_{chunk}.tsv"
    priority: PRIORITY["horizon_uav"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=60,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=UAV_MODELS,
        cfg=pick(HZ, "runs", "steps", "plans", "n_ref", "replicates", "methods"),
        scoring=UAV_SCORING,
        # this chunk's runs (the streams are keyed on the run, not on the chunk)
        runs=lambda w: layout_runs(
            HZ_UNITS["horizon_uav"], HZ["runs"], w.hmodel, w.H, int(w.chunk)
        ),
        seed=HZ_SEED,
        families=HZ_FAMILIES,
        code=code_digest("workflow/scripts/horizon_uav.py", HZ_FAMILIES),
    script:
        "../scripts/horizon_uav.py"


rule horizon_uav_merge:
    """UAV horizon study: the chunks of every model variant and horizon checked and merged into their cost-approximation and regret tables."""
    input:
        approx=unit_files(
            "results/horizon/uav/chunks/{hmodel}_H{H}/{chunk}_approx.csv",
            HZ_UNITS["horizon_uav"],
        ),
        regret=unit_files(
            "results/horizon/uav/chunks/{hmodel}_H{H}/{chunk}_regret.csv",
            HZ_UNITS["horizon_uav"],
        ),
    output:
        approx=expand("results/horizon/uav/{job}_approx.csv", job=HZ_JOBS),
        regret=expand("results/horizon/uav/{job}_regret.csv", job=HZ_JOBS),
    log:
        "results/logs/horizon_uav_merge.log",
    benchmark:
        "results/benchmarks/horizon_uav_merge.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        cfg=pick(HZ, "runs", "steps", "plans", "replicates", "methods"),
        units=HZ_UNITS["horizon_uav"],
        code=code_digest("workflow/scripts/horizon_uav_merge.py"),
    script:
        "../scripts/horizon_uav_merge.py"


rule horizon_uav_closed:
    """UAV horizon study, one model variant, horizon and chunk of runs: paired closed-loop runs of every method."""
    output:
        "results/horizon/uav/chunks/{hmodel}_H{H}/{chunk}_closed.csv",
    log:
        "results/logs/horizon_uav_closed/{hmodel}_H{H}_{chunk}.log",
    benchmark:
        "results/benchmarks/horizon_uav_closed/{hmodel}_H{H}_{chunk}.tsv"
    priority: PRIORITY["horizon_uav"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=60,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=UAV_MODELS,
        cfg=pick(HZ, "closed_runs", "methods"),
        # this chunk's closed-loop runs (keyed on the run, not on the chunk)
        runs=lambda w: layout_runs(
            HZ_UNITS["horizon_uav_closed"],
            HZ["closed_runs"],
            w.hmodel,
            w.H,
            int(w.chunk),
        ),
        seed=HZ_SEED,
        families=HZ_FAMILIES,
        code=code_digest("workflow/scripts/horizon_uav_closed.py", HZ_FAMILIES),
    # closed-loop runs go through the run store (config run_store: the script reads it,
    # it is no param, so moving or disabling the store reruns nothing; docs/store.md)
    script:
        "../scripts/horizon_uav_closed.py"


rule horizon_uav_closed_merge:
    """UAV horizon study: the closed-loop chunks of every model variant and horizon checked and merged into one table each."""
    input:
        unit_files(
            "results/horizon/uav/chunks/{hmodel}_H{H}/{chunk}_closed.csv",
            HZ_UNITS["horizon_uav_closed"],
        ),
    output:
        expand("results/horizon/uav/{job}_closed.csv", job=HZ_JOBS),
    log:
        "results/logs/horizon_uav_closed_merge.log",
    benchmark:
        "results/benchmarks/horizon_uav_closed_merge.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        cfg=pick(HZ, "closed_runs", "methods"),
        units=HZ_UNITS["horizon_uav_closed"],
        code=code_digest("workflow/scripts/horizon_uav_closed_merge.py"),
    script:
        "../scripts/horizon_uav_closed_merge.py"


rule horizon_lqg_estimators:
    """Oven LQG at long horizons: pruned trees, Monte Carlo, RQMC, NBO and sigma points against the exact cost."""
    output:
        "results/horizon/lqg_estimators.csv",
    log:
        "results/logs/horizon_lqg_estimators.log",
    benchmark:
        "results/benchmarks/horizon_lqg_estimators.tsv"
    priority: PRIORITY["holds_cores"]
    conda:
        ENV
    threads: 2
    resources:
        mem_mb=3000,
        runtime=30,
    params:
        cfg=pick(HZL, "sim_a", "sim_H", "replicates", "estimators"),
        model=HZL_MODEL,
        seed=HZ_SEED,
        code=code_digest("workflow/scripts/horizon_lqg_estimators.py"),
    script:
        "../scripts/horizon_lqg_estimators.py"


rule horizon_lqg_regret:
    """Oven LQG at long horizons: decision regret of every method's exact sample-average argmin."""
    output:
        "results/horizon/lqg_regret.csv",
    log:
        "results/logs/horizon_lqg_regret.log",
    benchmark:
        "results/benchmarks/horizon_lqg_regret.tsv"
    priority: PRIORITY["horizon_lqg"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=3000,
        runtime=30,
    params:
        cfg=pick(HZL, "sim_a", "sim_H", "replicates", "regret"),
        model=HZL_MODEL,
        seed=HZ_SEED,
        code=code_digest("workflow/scripts/horizon_lqg_regret.py"),
    script:
        "../scripts/horizon_lqg_regret.py"


rule horizon_summary:
    """Long horizons: statistics by horizon (UAV and oven LQG), tables, claims HZ-1..HZ-5, report section."""
    input:
        approx=expand("results/horizon/uav/{job}_approx.csv", job=HZ_JOBS),
        regret=expand("results/horizon/uav/{job}_regret.csv", job=HZ_JOBS),
        closed=expand("results/horizon/uav/{job}_closed.csv", job=HZ_JOBS),
        lqg_estimators="results/horizon/lqg_estimators.csv",
        lqg_regret="results/horizon/lqg_regret.csv",
        optimiser=HZO_SUMMARY,
    output:
        approx="results/horizon/uav_approx_summary.csv",
        regret="results/horizon/uav_regret_summary.csv",
        closed="results/horizon/uav_closed_summary.csv",
        lqg_estimators="results/horizon/lqg_estimators_summary.csv",
        lqg_regret="results/horizon/lqg_regret_summary.csv",
        tables=table_outputs(HORIZON_TABLES, "Long horizons"),
        section="results/report/horizon.json",
    log:
        "results/logs/horizon_summary.log",
    benchmark:
        "results/benchmarks/horizon_summary.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=3000,
        runtime=10,
    params:
        cfg=canonical(HZ),
        lqg=canonical(HZL),
        lqg_model=pick(config["lqg"]["model"], "a", "x0", "r", "target", "sigma"),
        # the optimiser budget every planner of the study runs at (HZ-3, section text)
        planner=pick(config["uav"]["planner"], "maxiter", "maxfun", "restarts"),
        seed=HZ_SEED,
        code=code_digest("workflow/scripts/horizon_summary.py"),
    script:
        "../scripts/horizon_summary.py"


rule horizon_figures:
    """Long-horizon figures: cost-approximation error, planning time, regret and closed loop against H (UAV and oven LQG)."""
    input:
        approx="results/horizon/uav_approx_summary.csv",
        regret="results/horizon/uav_regret_summary.csv",
        closed="results/horizon/uav_closed_summary.csv",
        lqg_estimators="results/horizon/lqg_estimators_summary.csv",
        lqg_regret="results/horizon/lqg_regret_summary.csv",
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


rule horizon_recording:
    """Rerun recording of one closed-loop run at a long horizon (horizon.uav.recording): one member per family, hypotheses and plans."""
    input:
        closed=f"results/horizon/uav/{HZ_REC.get('model')}_H{HZ_REC.get('H')}_closed.csv",
    output:
        HZ_RECORDING,
    log:
        "results/logs/horizon_recording.log",
    benchmark:
        "results/benchmarks/horizon_recording.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=15,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=UAV_MODELS,
        cfg=pick(HZ, "closed_runs", "methods", "claims"),
        recording=canonical(HZ_REC),
        seed=HZ_SEED,
        families=HZ_FAMILIES,
        code=code_digest("workflow/scripts/horizon_recording.py", HZ_FAMILIES),
    script:
        "../scripts/horizon_recording.py"


rule horizon_optimiser:
    """Optimiser split, one model variant, horizon and chunk of runs: every method's plan under each optimiser budget, the near-global minimiser of its own cost, the regret split into approximation and optimisation parts."""
    output:
        "results/horizon/optimiser/chunks/{hmodel}_H{H}/{chunk}.csv",
    log:
        "results/logs/horizon_optimiser/{hmodel}_H{H}_{chunk}.log",
    benchmark:
        "results/benchmarks/horizon_optimiser/{hmodel}_H{H}_{chunk}.tsv"
    priority: PRIORITY["horizon_uav"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=60,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        model=lambda wc: HZ_VARIANTS[wc.hmodel],
        cfg=pick(HZO, *HZO_KEYS),
        scoring=pick(UAV_SCORING, "n_eval", "polish", "random_starts"),
        # this chunk's runs (the streams are keyed on the run, not on the chunk)
        runs=lambda w: layout_runs(
            HZ_UNITS["horizon_optimiser"], HZO["runs"], w.hmodel, w.H, int(w.chunk)
        ),
        seed=HZ_SEED,
        families=HZO_FAMILIES,
        code=code_digest("workflow/scripts/horizon_optimiser.py", HZO_FAMILIES),
    script:
        "../scripts/horizon_optimiser.py"


rule horizon_optimiser_merge:
    """Optimiser split: the chunks of every model variant and horizon checked and merged into one table each."""
    input:
        unit_files(
            "results/horizon/optimiser/chunks/{hmodel}_H{H}/{chunk}.csv",
            HZ_UNITS["horizon_optimiser"],
        ),
    output:
        expand("results/horizon/optimiser/{job}.csv", job=HZO_JOBS),
    log:
        "results/logs/horizon_optimiser_merge.log",
    benchmark:
        "results/benchmarks/horizon_optimiser_merge.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        cfg=pick(HZO, *HZO_KEYS),
        units=HZ_UNITS["horizon_optimiser"],
        code=code_digest("workflow/scripts/horizon_optimiser_merge.py"),
    script:
        "../scripts/horizon_optimiser_merge.py"


rule horizon_optimiser_summary:
    """Optimiser split: mean total, approximation and optimisation regret per model, H, method and budget with cluster-t CIs, the optimiser's counters, table and report section."""
    input:
        expand("results/horizon/optimiser/{job}.csv", job=HZO_JOBS),
    output:
        summary="results/horizon/optimiser_summary.csv",
        tables=table_outputs(OPTIMISER_TABLES, "Long horizons"),
        section="results/report/horizon_optimiser.json",
    log:
        "results/logs/horizon_optimiser_summary.log",
    benchmark:
        "results/benchmarks/horizon_optimiser_summary.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        models=HZO_MODELS,
        cfg=pick(HZO, "H", *HZO_KEYS),
        planner=pick(config["uav"]["planner"], "maxiter", "maxfun", "restarts"),
        code=code_digest("workflow/scripts/horizon_optimiser_summary.py"),
    script:
        "../scripts/horizon_optimiser_summary.py"


rule horizon_optimiser_figures:
    """Optimiser split figure: total regret at the default and the largest budget and the approximation part against H, per model and method."""
    input:
        "results/horizon/optimiser_summary.csv",
    output:
        figure_outputs(OPTIMISER_FIGURES, "Long horizons"),
    log:
        "results/logs/horizon_optimiser_figures.log",
    benchmark:
        "results/benchmarks/horizon_optimiser_figures.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        code=code_digest("workflow/scripts/horizon_optimiser_figures.py"),
    script:
        "../scripts/horizon_optimiser_figures.py"


rule horizon:
    """Target: the long-horizon study and its optimiser split (nothing when no model is configured)."""
    input:
        rules.horizon_summary.output if HZ_MODELS else [],
        rules.horizon_figures.output if HZ_MODELS else [],
        HZ_RECORDING,
        rules.horizon_optimiser_summary.output if HZO_MODELS else [],
        rules.horizon_optimiser_figures.output if HZO_MODELS else [],
