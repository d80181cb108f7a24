# Decision-quality study: the regret of the controls each method chooses.
# Simulation, aggregation and figures are separate rules.

REPORT_SECTIONS["decisions_lqg"] = "results/report/decisions_lqg.json"
REPORT_FIGURES.append("dec_lqg_regret")


rule decisions_lqg:
    output:
        "results/decisions/lqg_regret.csv",
    log:
        "results/logs/decisions_lqg.log",
    benchmark:
        "results/benchmarks/decisions_lqg.tsv"
    conda:
        ENV
    threads: THREADS
    resources:
        mem_mb=2000,
        runtime=30,
    params:
        cfg=canonical(config["decisions"]["lqg"]),
        model=pick(config["lqg"]["model"], "x0", "r", "target", "sigma"),
        seed=config["seed"],
    script:
        "../scripts/decisions_lqg.py"


rule decisions_lqg_summary:
    input:
        "results/decisions/lqg_regret.csv",
    output:
        summary="results/decisions/lqg_summary.csv",
        scaling="results/decisions/lqg_scaling.csv",
        tables=expand(
            "results/tables/{name}.md", name=["dec_lqg_regret", "dec_lqg_scaling"]
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
    script:
        "../scripts/decisions_lqg_summary.py"


rule decisions_figures:
    input:
        lqg="results/decisions/lqg_summary.csv",
    output:
        expand("results/figures/dec_lqg_regret.{ext}", ext=("png", "pdf")),
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
    script:
        "../scripts/decisions_figures.py"


rule decisions:
    input:
        rules.decisions_lqg.output,
        rules.decisions_lqg_summary.output,
        rules.decisions_figures.output,
