# The replication report: results/paper/replication.md (main text), appendix.md, the figures
# they show, the claims with their key numbers (claims.json) and the README's glance table.
# `make publish` copies them to paper/ and README.md (tracked); a replication never touches
# tracked files. `make verify` (rule verify) compares claims.json with paper/claims.json.

# Across scenarios (rsmhp.studies.scenarios.summarise): every method's probability of beating NBO run
# by run over the map cells and the long-horizon closed loop (descriptive, no claim).
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


rule report:
    """The replication report (main text, appendix, figures, claims) from every section."""
    input:
        sections=list(REPORT_SECTIONS.values()),
        figures=expand("results/figures/{name}.png", name=REPORT_FIGURES),
    output:
        report="results/paper/replication.md",
        appendix="results/paper/appendix.md",
        claims="results/paper/claims.json",
        glance="results/paper/glance.md",
        figures=expand("results/paper/figures/{name}.png", name=REPORT_FIGURES),
        provenance="results/provenance.json",
    log:
        "results/logs/report.log",
    benchmark:
        "results/benchmarks/report.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        config=canonical(config),
        # the preregistration the confirmatory claims were judged under (claims.json,
        # make verify): path and sha256 (the script adds the commit that added it)
        preregistration=(
            {k: CONFIRM[k] for k in ("path", "sha256")} if CONFIRM is not None else {}
        ),
        code=code_digest("workflow/scripts/report.py"),
    script:
        "../scripts/report.py"


rule verify:
    """Compare this run's claims with the committed paper/claims.json, claim by claim (make verify)."""
    input:
        run="results/paper/claims.json",
        reference="paper/claims.json",
    output:
        "results/verify.md",
    log:
        "results/logs/verify.log",
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        code=code_digest("workflow/scripts/verify.py"),
    script:
        "../scripts/verify.py"
