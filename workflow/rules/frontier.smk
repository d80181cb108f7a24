# Equal-compute study of the planners (decisions.frontier): one job per model variant with
# paired closed-loop runs and open-loop regret of every method and its planning time per step
# (one thread: the time is the study's measure of compute), then aggregation and the figure.
from rsmhp.figures.frontier import FIGURES as FRONTIER_FIGURES
from rsmhp.narrative.frontier import TABLES as FRONTIER_TABLES

FRONTIER = config["decisions"]["frontier"]
FRONTIER_MODELS = list(FRONTIER["models"])
FRONTIER_REC = config["decisions"]["recording"]
FRONTIER_RECORDING = f"results/recordings/dec_{FRONTIER_REC['model']}_planners.rrd"
if FRONTIER_MODELS:
    REPORT_SECTIONS["decisions_frontier"] = "results/report/decisions_frontier.json"
    REPORT_FIGURES.extend(FRONTIER_FIGURES)


wildcard_constraints:
    model=r"[a-z][a-z0-9_]*",


rule decisions_frontier:
    """Equal-compute study, one model variant: closed- and open-loop quality and planning time of every method."""
    output:
        runs="results/decisions/frontier/{model}.csv",
        regret="results/decisions/frontier/{model}_regret.csv",
    log:
        "results/logs/decisions_frontier/{model}.log",
    benchmark:
        "results/benchmarks/decisions_frontier/{model}.tsv"
    priority: PRIORITY["decisions_frontier"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=60,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=canonical(config["decisions"]["uav"]["models"]),
        cfg=pick(
            FRONTIER,
            "runs",
            "methods",
            "regret_runs",
            "regret_steps",
            "track_loss_error",
        ),
        scoring=DEC_SCORING,
        seed=config["seed"],
        code=code_digest("workflow/scripts/decisions_frontier.py"),
    script:
        "../scripts/decisions_frontier.py"


rule decisions_frontier_timing:
    """Equal-compute study, one model variant: interleaved wall-clock timing of every method's plan call (holds the cores)."""
    output:
        "results/decisions/frontier/timing/{model}.csv",
    log:
        "results/logs/decisions_frontier_timing/{model}.log",
    benchmark:
        "results/benchmarks/decisions_frontier_timing/{model}.tsv"
    priority: PRIORITY["decisions_frontier"]
    conda:
        ENV
    # the job plans on one thread but holds two: on the 2-core reference machine nothing runs
    # beside it while it times (snakemake caps threads at --cores)
    threads: 2
    resources:
        mem_mb=2000,
        runtime=30,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=canonical(config["decisions"]["uav"]["models"]),
        cfg=pick(FRONTIER, "methods", "timing"),
        seed=config["seed"],
        code=code_digest("workflow/scripts/decisions_frontier_timing.py"),
    script:
        "../scripts/decisions_frontier_timing.py"


rule decisions_frontier_summary:
    """Equal-compute study: per model and method, compute and quality with bootstrap CIs."""
    input:
        runs=expand("results/decisions/frontier/{model}.csv", model=FRONTIER_MODELS),
        regret=expand(
            "results/decisions/frontier/{model}_regret.csv", model=FRONTIER_MODELS
        ),
        timing=expand(
            "results/decisions/frontier/timing/{model}.csv", model=FRONTIER_MODELS
        ),
    output:
        summary="results/decisions/frontier_summary.csv",
        tables=table_outputs(FRONTIER_TABLES, "Decision study"),
        section="results/report/decisions_frontier.json",
    log:
        "results/logs/decisions_frontier_summary.log",
    benchmark:
        "results/benchmarks/decisions_frontier_summary.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        cfg=canonical(FRONTIER),
        horizon=config["uav"]["planner"]["horizon"],
        seed=config["seed"],
        code=code_digest("workflow/scripts/decisions_frontier_summary.py"),
    script:
        "../scripts/decisions_frontier_summary.py"


rule decisions_frontier_figures:
    """Equal-compute study figure: quality against planning time, one curve per family."""
    input:
        summary="results/decisions/frontier_summary.csv",
    output:
        figure_outputs(FRONTIER_FIGURES, "Decision study"),
    log:
        "results/logs/decisions_frontier_figures.log",
    benchmark:
        "results/benchmarks/decisions_frontier_figures.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        budget=canonical(FRONTIER["budget"]),
        code=code_digest("workflow/scripts/decisions_frontier_figures.py"),
    script:
        "../scripts/decisions_frontier_figures.py"


rule decisions_frontier_recording:
    """Rerun recording of one frontier run (chosen by decisions.recording.select): NBO and every family's budget member."""
    input:
        runs=f"results/decisions/frontier/{FRONTIER_REC['model']}.csv",
    output:
        FRONTIER_RECORDING,
    log:
        "results/logs/decisions_frontier_recording.log",
    benchmark:
        "results/benchmarks/decisions_frontier_recording.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=canonical(config["decisions"]["uav"]["models"]),
        cfg=canonical(FRONTIER),
        recording=canonical(FRONTIER_REC),
        seed=config["seed"],
        code=code_digest("workflow/scripts/decisions_frontier_recording.py"),
    script:
        "../scripts/decisions_frontier_recording.py"


rule frontier:
    """Target: the equal-compute study (tables, section, figure, recording; nothing when no model is configured)."""
    input:
        rules.decisions_frontier_summary.output if FRONTIER_MODELS else [],
        rules.decisions_frontier_figures.output if FRONTIER_MODELS else [],
        rules.decisions_frontier_recording.output if FRONTIER_MODELS else [],
