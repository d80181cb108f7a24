# Case study 1: scalar LQG (paper Sec. III-A, Fig. 3).
# Simulation, aggregation, figures, recording are separate rules: changing a figure
# never reruns a simulation.

LQG_TABLES = ["lqg_convergence", "lqg_nbo_error", "lqg_nbo_z", "lqg_chebyshev"]
LQG_FIGURES = ["lqg_fig3_paper", "lqg_convergence", "lqg_error_loglog", "lqg_nbo_error"]
REPORT_SECTIONS["lqg"] = "results/report/lqg.json"
REPORT_FIGURES.extend(LQG_FIGURES)
# what the simulations were asked for: the aggregation rules check their inputs against it
LQG_SIM = {
    "model": pick(config["lqg"]["model"], "a", "x0", "r", "target", "sigma"),
    "convergence": pick(config["lqg"]["convergence"], "u", "P", "replicates"),
    "nbo_error": canonical(config["lqg"]["nbo_error"]),
    "linear_cost": pick(config["lqg"]["linear_cost"], "H", "n", "replicates"),
}


rule lqg_convergence:
    """Fig. 3 simulation: MHP estimates (uniform and weighted) for every P of the grid, next to the NBO and exact costs."""
    output:
        "results/lqg/convergence.csv",
    log:
        "results/logs/lqg_convergence.log",
    benchmark:
        "results/benchmarks/lqg_convergence.tsv"
    priority: PRIORITY["lqg_convergence"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=20,
    params:
        # only what the simulation depends on: changing chebyshev_eps reruns no simulation
        lqg={
            "model": pick(config["lqg"]["model"], "a", "x0", "r", "target", "sigma"),
            "convergence": pick(config["lqg"]["convergence"], "u", "P", "replicates"),
        },
        seed=config["seed"],
        code=code_digest("workflow/scripts/lqg_convergence.py"),
    script:
        "../scripts/lqg_convergence.py"


rule lqg_nbo_error:
    """NBO error over the (a, H) grid: simulated J_P - J_NBO next to the closed form r sigma^2 sum (1-a)^{2n}."""
    output:
        "results/lqg/nbo_error.csv",
    log:
        "results/logs/lqg_nbo_error.log",
    benchmark:
        "results/benchmarks/lqg_nbo_error.tsv"
    priority: PRIORITY["lqg_nbo_error"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=20,
    params:
        lqg=pick(config["lqg"], "model", "nbo_error"),
        seed=config["seed"],
        code=code_digest("workflow/scripts/lqg_nbo_error.py"),
    script:
        "../scripts/lqg_nbo_error.py"


rule lqg_linear_cost:
    """Prop. 3 on its own setting: Monte-Carlo estimates of a linear cost under linear dynamics, next to the paper's variance formula."""
    output:
        "results/lqg/linear_cost.csv",
    log:
        "results/logs/lqg_linear_cost.log",
    benchmark:
        "results/benchmarks/lqg_linear_cost.tsv"
    priority: PRIORITY["lqg_linear_cost"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        lqg={"linear_cost": LQG_SIM["linear_cost"]},
        seed=config["seed"],
        code=code_digest("workflow/scripts/lqg_linear_cost.py"),
    script:
        "../scripts/lqg_linear_cost.py"


rule lqg_summary:
    """LQG aggregation: per-P statistics, NBO-error summary, Markdown tables, report section."""
    input:
        convergence="results/lqg/convergence.csv",
        nbo_error="results/lqg/nbo_error.csv",
        linear_cost="results/lqg/linear_cost.csv",
    output:
        summary="results/lqg/summary.csv",
        nbo_summary="results/lqg/nbo_error_summary.csv",
        tables=table_outputs(LQG_TABLES, "LQG"),
        section="results/report/lqg.json",
    log:
        "results/logs/lqg_summary.log",
    benchmark:
        "results/benchmarks/lqg_summary.tsv"
    priority: PRIORITY["lqg_summary"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        eps=config["lqg"]["convergence"]["chebyshev_eps"],
        linear_k=config["lqg"]["linear_cost"]["k"],
        # the inputs are checked against what the simulations were asked for
        lqg=LQG_SIM,
        code=code_digest("workflow/scripts/lqg_summary.py"),
    script:
        "../scripts/lqg_summary.py"


rule lqg_figures:
    """LQG figures: paper-style Fig. 3, its statistical view, error vs P on log-log axes, NBO error with residuals."""
    input:
        convergence="results/lqg/convergence.csv",
        summary="results/lqg/summary.csv",
        nbo_summary="results/lqg/nbo_error_summary.csv",
    output:
        figure_outputs(LQG_FIGURES, "LQG"),
    log:
        "results/logs/lqg_figures.log",
    benchmark:
        "results/benchmarks/lqg_figures.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        eps=config["lqg"]["convergence"]["chebyshev_eps"],
        lqg=LQG_SIM,
        code=code_digest("workflow/scripts/lqg_figures.py"),
    script:
        "../scripts/lqg_figures.py"


rule lqg_recording:
    """Rerun recording of one sampled and pruned LQG trajectory tree."""
    output:
        "results/recordings/lqg_tree.rrd",
    log:
        "results/logs/lqg_recording.log",
    benchmark:
        "results/benchmarks/lqg_recording.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        model=canonical(config["lqg"]["model"]),
        recording=canonical(config["lqg"]["recording"]),
        seed=config["seed"],
        experiment="lqg_recording",
        code=code_digest("workflow/scripts/tree_recording.py"),
    script:
        "../scripts/tree_recording.py"


rule lqg:
    """Target: every LQG output."""
    input:
        rules.lqg_convergence.output,
        rules.lqg_nbo_error.output,
        rules.lqg_summary.output,
        rules.lqg_figures.output,
        rules.lqg_recording.output,
