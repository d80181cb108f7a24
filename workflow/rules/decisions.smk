# Decision-quality study: the regret of the controls each method chooses.
# Simulation, aggregation and figures are separate rules; the sensitivity map runs one job
# per cell (wildcard {cell} = r<i>c<j>), so a cell reruns alone and cells fan out.
from rsmhp.studies.decisions import FIGURES_LQG as DEC_LQG_FIGURES
from rsmhp.studies.decisions import FIGURES_UAV as DEC_UAV_FIGURES
from rsmhp.studies.decisions.chunks import chunk_jobs, model_runs

DEC = config["decisions"]
DEC_UAV_FAMILIES = families_of(DEC["uav"]["methods"], "decisions.uav.methods")
DEC_MAP_FAMILIES = families_of(DEC["map"]["methods"], "decisions.map.methods")
# the open-loop study runs every UAV model variant (uav_models): its cfg param carries them
# as `models`, which is where its code reads them
DEC_UAV = {**DEC["uav"], "models": UAV_MODELS}
DEC_FIGURES = [*DEC_LQG_FIGURES, *DEC_UAV_FIGURES]
REPORT_SECTIONS["decisions_lqg"] = "results/report/decisions_lqg.json"
REPORT_SECTIONS["decisions_uav"] = "results/report/decisions_uav.json"
REPORT_FIGURES.extend(DEC_FIGURES)


wildcard_constraints:
    cell=r"r\d+c\d+",


rule decisions_lqg:
    """Decision study, LQG: regret of every method's sample-average argmin (exact)."""
    output:
        "results/decisions/lqg_regret.csv",
    log:
        "results/logs/decisions_lqg.log",
    benchmark:
        "results/benchmarks/decisions_lqg.tsv"
    priority: PRIORITY["decisions_lqg"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=30,
    params:
        cfg=canonical(config["decisions"]["lqg"]),
        model=pick(config["lqg"]["model"], "x0", "r", "target", "sigma"),
        seed=config["seed"],
        code=code_digest("workflow/scripts/decisions_lqg.py"),
    script:
        "../scripts/decisions_lqg.py"


rule decisions_lqg_summary:
    """Decision study, LQG: per-cell regret, slopes vs closed forms, claims, tables."""
    input:
        "results/decisions/lqg_regret.csv",
    output:
        summary="results/decisions/lqg_summary.csv",
        scaling="results/decisions/lqg_scaling.csv",
        tables=table_outputs(
            ["decisions_lqg_regret", "decisions_lqg_scaling"], "Decision study"
        ),
        section="results/report/decisions_lqg.json",
    log:
        "results/logs/decisions_lqg_summary.log",
    benchmark:
        "results/benchmarks/decisions_lqg_summary.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        cfg=canonical(config["decisions"]["lqg"]),
        model=pick(config["lqg"]["model"], "x0", "r", "target", "sigma"),
        code=code_digest("workflow/scripts/decisions_lqg_summary.py"),
    script:
        "../scripts/decisions_lqg_summary.py"


# The UAV open-loop study runs as split.decisions_uav jobs of runs per model variant
# (rsmhp.studies.decisions.chunks), merged into results/decisions/uav_regret.csv.
DEC_UAV_JOBS = chunk_jobs(DEC_UAV, SPLIT["decisions_uav"])


rule decisions_uav:
    """Decision study, UAV open loop, one model variant and chunk of runs: every method plans at the runs' NBO belief states; plans scored on independent hypotheses."""
    output:
        "results/decisions/uav_regret/{model}/{chunk}.csv",
    log:
        "results/logs/decisions_uav/{model}_{chunk}.log",
    benchmark:
        "results/benchmarks/decisions_uav/{model}_{chunk}.tsv"
    priority: PRIORITY["decisions_uav"]
    conda:
        ENV
    threads: THREADS
    resources:
        mem_mb=2000,
        runtime=30,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        cfg=canonical(DEC_UAV),
        # this chunk's runs (the streams are keyed on model, run and step, not on the chunk)
        runs=lambda w: model_runs(
            DEC["uav"]["runs"], SPLIT["decisions_uav"], int(w.chunk)
        ),
        seed=DEC_SEED,
        families=DEC_UAV_FAMILIES,
        code=code_digest("workflow/scripts/decisions_uav.py", DEC_UAV_FAMILIES),
    script:
        "../scripts/decisions_uav.py"


rule decisions_uav_merge:
    """Decision study, UAV open loop: the jobs of every model variant checked and merged into one table."""
    input:
        [f"results/decisions/uav_regret/{m}/{k}.csv" for m, k in DEC_UAV_JOBS],
    output:
        "results/decisions/uav_regret.csv",
    log:
        "results/logs/decisions_uav_merge.log",
    benchmark:
        "results/benchmarks/decisions_uav_merge.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        cfg=canonical(DEC_UAV),
        jobs=SPLIT["decisions_uav"],
        code=code_digest("workflow/scripts/decisions_uav_merge.py"),
    script:
        "../scripts/decisions_uav_merge.py"


rule decisions_map_cell:
    """Decision study, UAV map: paired closed-loop runs and open-loop regret in map cell {cell}."""
    output:
        runs="results/decisions/map/{cell}.csv",
        regret="results/decisions/map/{cell}_regret.csv",
    log:
        "results/logs/decisions_map_cell/{cell}.log",
    benchmark:
        "results/benchmarks/decisions_map_cell/{cell}.tsv"
    priority: PRIORITY["decisions_map_cell"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=60,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        cfg=pick(
            DEC["map"],
            "rows",
            "cols",
            "runs",
            "methods",
            "regret_runs",
            "regret_steps",
            "track_loss_error",
        ),
        scoring=UAV_SCORING,
        seed=DEC_SEED,
        families=DEC_MAP_FAMILIES,
        code=code_digest("workflow/scripts/decisions_map_cell.py", DEC_MAP_FAMILIES),
    # closed-loop runs go through the run store (config run_store: the script reads it,
    # it is no param, so moving or disabling the store reruns nothing; docs/store.md)
    script:
        "../scripts/decisions_map_cell.py"


rule decisions_uav_summary:
    """Decision study, UAV: regret summary, sensitivity map, claims, tables, section."""
    input:
        regret="results/decisions/uav_regret.csv",
        map_runs=expand("results/decisions/map/{cell}.csv", cell=MAP_CELLS),
        map_regret=expand("results/decisions/map/{cell}_regret.csv", cell=MAP_CELLS),
    output:
        regret_summary="results/decisions/uav_regret_summary.csv",
        map="results/decisions/uav_map.csv",
        map_groups="results/decisions/uav_map_groups.csv",
        tables=table_outputs(
            ["decisions_uav_regret", "decisions_uav_map"], "Decision study"
        ),
        section="results/report/decisions_uav.json",
    log:
        "results/logs/decisions_uav_summary.log",
    benchmark:
        "results/benchmarks/decisions_uav_summary.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        cfg=canonical({**DEC, "uav": DEC_UAV}),
        base_limited=config["uav"]["sensor"]["footprint_radius"] is not None,
        seed=DEC_SEED,
        code=code_digest("workflow/scripts/decisions_uav_summary.py"),
    script:
        "../scripts/decisions_uav_summary.py"


rule decisions_figures:
    """Decision study figures: LQG regret, UAV regret, the map."""
    input:
        lqg="results/decisions/lqg_summary.csv",
        regret="results/decisions/uav_regret.csv",
        map="results/decisions/uav_map.csv",
    output:
        figure_outputs(DEC_FIGURES, "Decision study"),
    log:
        "results/logs/decisions_figures.log",
    benchmark:
        "results/benchmarks/decisions_figures.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        cfg=canonical(DEC_UAV),
        code=code_digest("workflow/scripts/decisions_figures.py"),
    script:
        "../scripts/decisions_figures.py"


rule decisions:
    """Target: the whole decision-quality study."""
    input:
        rules.decisions_lqg.output,
        rules.decisions_lqg_summary.output,
        rules.decisions_uav_summary.output,
        rules.decisions_figures.output,
