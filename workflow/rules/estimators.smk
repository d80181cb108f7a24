# Estimator study (beyond the paper): tree vs independent sampling, pruning, weighting,
# variance-reduction samplers, on problems with an exact J. Simulation, aggregation,
# figures and recording are separate rules.

from rsmhp.studies.estimators.chunks import ablation_chunks

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


# The ablation runs as split.estimators_ablation jobs of cells (largest first, dealt round
# robin; rsmhp.studies.estimators.chunks), merged into results/estimators/ablation.csv.
EST_CHUNKS = ablation_chunks(
    EST_SIM, config["lqg"]["model"], SPLIT["estimators_ablation"]
)


rule estimators_ablation:
    """Estimator study simulation, one job of cells: every (problem, scheme, size) cell of the job, replicated."""
    output:
        "results/estimators/ablation/{chunk}.csv",
    log:
        "results/logs/estimators_ablation/{chunk}.log",
    benchmark:
        "results/benchmarks/estimators_ablation/{chunk}.tsv"
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
        # the cells follow from the grid and the job count (streams keyed on the cell)
        jobs=SPLIT["estimators_ablation"],
        seed=config["seed"],
        code=code_digest("workflow/scripts/estimators_ablation.py"),
    script:
        "../scripts/estimators_ablation.py"


rule estimators_ablation_merge:
    """Estimator study: the ablation's jobs checked and merged into one table, in table order."""
    input:
        expand("results/estimators/ablation/{chunk}.csv", chunk=EST_CHUNKS),
    output:
        "results/estimators/ablation.csv",
    log:
        "results/logs/estimators_ablation_merge.log",
    benchmark:
        "results/benchmarks/estimators_ablation_merge.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        estimators=EST_SIM,
        model=canonical(config["lqg"]["model"]),
        jobs=SPLIT["estimators_ablation"],
        code=code_digest("workflow/scripts/estimators_ablation_merge.py"),
    script:
        "../scripts/estimators_ablation_merge.py"


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
        rules.estimators_ablation_merge.output,
        rules.estimators_summary.output,
        rules.estimators_figures.output,
        rules.estimators_recording.output,
