# Study "scenarios": across scenarios (rsmhp.studies.scenarios.summarise), every method's
# probability of beating NBO run by run over the map cells and the long-horizon closed loop;
# and (rsmhp.studies.scenarios.best) the method with the lowest closed-loop error per cell of
# the confirmatory equal-compute run (per model and budget), the long-horizon closed loop (per
# model and H) and the map (per cell), with the confidence of that answer (descriptive, no claim).
from rsmhp.studies.scenarios import FIGURES as SCENARIO_FIGURES
from rsmhp.studies.scenarios import TABLES as SCENARIO_TABLES

SCN_MAP = expand("results/decisions/map/{cell}.csv", cell=MAP_CELLS)
SCN_CLOSED = expand("results/horizon/uav/{job}_closed.csv", job=HZ_JOBS)
# the confirmatory run exists only with a preregistration (frontier.smk: CONFIRM)
SCN_CONFIRM = expand("results/frontier/confirm/{model}.csv", model=CONFIRM_MODELS)
if SCN_MAP or SCN_CLOSED:
    REPORT_SECTIONS["scenarios"] = "results/report/scenarios.json"
    REPORT_FIGURES.extend(SCENARIO_FIGURES)


rule scenarios_best:
    """Across scenarios: per cell (model and budget, model and H, map cell) the method with the lowest closed-loop mean error, every other method's paired difference from it with its 95% t interval, ties."""
    input:
        confirm=SCN_CONFIRM,
        closed=SCN_CLOSED,
        map_runs=SCN_MAP,
    output:
        best="results/scenarios/best.csv",
        paired="results/scenarios/best_paired.csv",
    log:
        "results/logs/scenarios_best.log",
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        # the tuned configurations of the confirmatory models and the preregistered budgets
        tuned=(
            {"chosen": {m: CONFIRM["tuned"]["chosen"][m] for m in CONFIRM_MODELS}}
            if CONFIRM is not None
            else None
        ),
        budgets_ms=(
            CONFIRM["preregistration"]["budgets_ms"] if CONFIRM is not None else []
        ),
        code=code_digest("workflow/scripts/scenarios_best.py"),
    script:
        "../scripts/scenarios_best.py"


rule scenarios_summary:
    """Across scenarios: per scenario and method the probability of beating NBO run by run, averaged per group with stratified bootstrap intervals; with the best method per cell, tables and section."""
    input:
        map_runs=SCN_MAP,
        closed=SCN_CLOSED,
        best="results/scenarios/best.csv",
        paired="results/scenarios/best_paired.csv",
    output:
        per_scenario="results/scenarios/per_scenario.csv",
        summary="results/scenarios/summary.csv",
        tables=table_outputs(SCENARIO_TABLES, "Across scenarios"),
        section="results/report/scenarios.json",
    log:
        "results/logs/scenarios_summary.log",
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        n_boot=config["scenarios"]["bootstrap"],
        seed=config["seed"],
        # the seed streams of the groups' runs, named in the appendix
        streams={
            "equal compute": CONFIRM["stream"] if CONFIRM is not None else None,
            "long horizons": config["horizon"]["stream"],
        },
        code=code_digest("workflow/scripts/scenarios_summary.py"),
    script:
        "../scripts/scenarios_summary.py"


rule scenarios_figures:
    """Across scenarios: the best method per cell, and the probability of beating NBO per method and group of scenarios."""
    input:
        summary="results/scenarios/summary.csv",
        best="results/scenarios/best.csv",
    output:
        figure_outputs(SCENARIO_FIGURES, "Across scenarios"),
    log:
        "results/logs/scenarios_figures.log",
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        code=code_digest("workflow/scripts/scenarios_figures.py"),
    script:
        "../scripts/scenarios_figures.py"
