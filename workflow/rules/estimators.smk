# Estimator study (beyond the paper): tree vs independent sampling, pruning, weighting,
# variance-reduction samplers, on problems with an exact J. Simulation, aggregation,
# figures and recording are separate rules.

EST_TABLES = [
    "estimators_largest",
    "estimators_tree_vs_independent",
    "estimators_pruning",
    "estimators_equal_cpu",
    "estimators_chebyshev",
    "estimators_weighted",
]
EST_FIGURES = [
    "estimators_rmse_vs_n",
    "estimators_bias_vs_n",
    "estimators_tree_variance",
    "estimators_weighted_vs_uniform",
    "estimators_pruning_heatmap",
    "estimators_frontier",
]
REPORT_SECTIONS["estimators"] = "results/report/estimators.json"
REPORT_FIGURES.extend(EST_FIGURES)

# what the simulation depends on (analysis-only keys such as chebyshev_k are left out)
EST_SIM = pick(
    config["estimators"],
    "replicates",
    "problems",
    "schemes",
    "budgets",
    "tree_N",
    "max_leaves",
    "pruning",
)


rule estimators_ablation:
    """Estimator study simulation: every (problem, scheme, size) cell, replicated."""
    output:
        "results/estimators/ablation.csv",
    log:
        "results/logs/estimators_ablation.log",
    benchmark:
        "results/benchmarks/estimators_ablation.tsv"
    priority: PRIORITY["estimators_ablation"]
    conda:
        ENV
    threads: THREADS
    resources:
        mem_mb=3000,
        runtime=30,
    params:
        estimators=EST_SIM,
        model=canonical(config["lqg"]["model"]),
        seed=config["seed"],
        code=code_digest("workflow/scripts/estimators_ablation.py"),
    script:
        "../scripts/estimators_ablation.py"


rule estimators_summary:
    """Estimator study aggregation: bias, variance, RMSE, slopes, claims, tables, section."""
    input:
        ablation="results/estimators/ablation.csv",
    output:
        summary="results/estimators/summary.csv",
        tables=table_outputs(EST_TABLES, "Estimator study"),
        section="results/report/estimators.json",
    log:
        "results/logs/estimators_summary.log",
    benchmark:
        "results/benchmarks/estimators_summary.tsv"
    priority: PRIORITY["estimators_summary"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=3000,
        runtime=10,
    params:
        problems=canonical(config["estimators"]["problems"]),
        model=canonical(config["lqg"]["model"]),
        ks=config["estimators"]["chebyshev_k"],
        seed=config["seed"],
        estimators=EST_SIM,
        code=code_digest("workflow/scripts/estimators_summary.py"),
    script:
        "../scripts/estimators_summary.py"


rule estimators_figures:
    """Estimator study figures."""
    input:
        summary="results/estimators/summary.csv",
    output:
        figure_outputs(EST_FIGURES, "Estimator study"),
    log:
        "results/logs/estimators_figures.log",
    benchmark:
        "results/benchmarks/estimators_figures.tsv"
    priority: PRIORITY["estimators_figures"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        problems=canonical(config["estimators"]["problems"]),
        model=canonical(config["lqg"]["model"]),
        code=code_digest("workflow/scripts/estimators_figures.py"),
    script:
        "../scripts/estimators_figures.py"


rule estimators_recording:
    """Rerun recording of a tree of the estimator study."""
    output:
        "results/recordings/estimators_tree.rrd",
    log:
        "results/logs/estimators_recording.log",
    benchmark:
        "results/benchmarks/estimators_recording.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        model=canonical(config["lqg"]["model"]),
        recording=canonical(config["estimators"]["recording"]),
        seed=config["seed"],
        experiment="estimators_recording",
        code=code_digest("workflow/scripts/tree_recording.py"),
    script:
        "../scripts/tree_recording.py"


rule estimators:
    """Target: the whole estimator study."""
    input:
        rules.estimators_ablation.output,
        rules.estimators_summary.output,
        rules.estimators_figures.output,
        rules.estimators_recording.output,
