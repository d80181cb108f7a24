# Study "scenarios": across scenarios (rsmhp.studies.scenarios.summarise), every method's
# probability of beating NBO run by run over the map cells and the long-horizon closed loop
# (descriptive, no claim).
from rsmhp.studies.scenarios.figures import FIGURES as SCENARIO_FIGURES
from rsmhp.studies.scenarios.section import TABLES as SCENARIO_TABLES

SCN_MAP = expand("results/decisions/map/{cell}.csv", cell=MAP_CELLS)
SCN_CLOSED = expand("results/horizon/uav/{job}_closed.csv", job=HZ_JOBS)
if SCN_MAP or SCN_CLOSED:
    REPORT_SECTIONS["scenarios"] = "results/report/scenarios.json"
    REPORT_FIGURES.extend(SCENARIO_FIGURES)


rule scenarios_summary:
    """Across scenarios: per scenario and method the probability of beating NBO run by run, averaged per group with stratified bootstrap intervals; tables, section."""
    input:
        map_runs=SCN_MAP,
        closed=SCN_CLOSED,
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
        n_boot=2000,
        seed=config["seed"],
        code=code_digest("workflow/scripts/scenarios_summary.py"),
    script:
        "../scripts/scenarios_summary.py"


rule scenarios_figures:
    """Across scenarios: the probability of beating NBO per method and group of scenarios."""
    input:
        "results/scenarios/summary.csv",
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
