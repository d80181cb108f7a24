# Case study 2: UAV target tracking (paper Sec. III-B, Figs. 4-5).
# One simulation job per (method, chunk of runs), runs one after another inside (a closed-loop
# run takes about 0.1 s, less than starting a worker pool: parallelism comes from running the
# method jobs side by side); then collection, aggregation (tables, report section), figures
# and recordings as separate rules.
import re

from rsmhp.studies.uav.simulate import chunk_runs
from rsmhp.models.uav import methods as uav_methods

UAV = config["uav"]
UAV_SPECS = uav_methods.from_config(UAV["methods"], "uav.methods")
UAV_FAMILIES = families_of(UAV_SPECS.values())
UAV_METHODS = list(UAV_SPECS)
UAV_CHUNKS = list(range(min(UAV["chunks"], UAV["runs"])))
UAV_RECORDED = list(range(min(UAV["recording"]["runs"], UAV["runs"])))
UAV_TABLES = ["uav_methods", "uav_paired"]
# each paper-style CDF (Figs. 4 and 5) with our paired view next to it
UAV_FIGURES = [
    "uav_error_cdf_nt",
    "uav_paired_diff_nt",
    "uav_error_cdf_nbo",
    "uav_paired_diff",
]
REPORT_SECTIONS["uav"] = "results/report/uav.json"
REPORT_FIGURES.extend(UAV_FIGURES)


wildcard_constraints:
    method="|".join(re.escape(m) for m in UAV_METHODS),
    chunk=r"\d+",
    k=r"\d+",


rule uav_simulate:
    """UAV closed loop: one method, one chunk of Monte-Carlo runs (runs CSV + steps Parquet)."""
    output:
        runs="results/uav/chunks/{method}/{chunk}.csv",
        steps="results/uav/chunks/{method}/{chunk}.parquet",
    log:
        "results/logs/uav_simulate/{method}_{chunk}.log",
    benchmark:
        "results/benchmarks/uav_simulate/{method}_{chunk}.tsv"
    priority: PRIORITY["uav_simulate"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=30,
    params:
        # the model, this method's own spec and this chunk's runs: adding an N_T value or a
        # figure option reruns no existing simulation
        uav=pick(UAV, *UAV_MODEL_KEYS),
        method=lambda wc: UAV_SPECS[wc.method].spec(),
        runs=lambda wc: chunk_runs(UAV["runs"], len(UAV_CHUNKS), int(wc.chunk)),
        seed=UAV_SEED,
        families=lambda wc: families_of([UAV_SPECS[wc.method]]),
        code=lambda wc: code_digest(
            "workflow/scripts/uav_simulate.py", families_of([UAV_SPECS[wc.method]])
        ),
    # closed-loop runs go through the run store (config run_store: the script reads it,
    # it is no param, so moving or disabling the store reruns nothing; docs/store.md)
    script:
        "../scripts/uav_simulate.py"


rule uav_collect:
    """Check every UAV chunk against the config and concatenate them (runs.csv, steps.parquet)."""
    input:
        runs=expand(
            "results/uav/chunks/{method}/{chunk}.csv",
            method=UAV_METHODS,
            chunk=UAV_CHUNKS,
        ),
        steps=expand(
            "results/uav/chunks/{method}/{chunk}.parquet",
            method=UAV_METHODS,
            chunk=UAV_CHUNKS,
        ),
    output:
        runs="results/uav/runs.csv",
        steps="results/uav/steps.parquet",
    log:
        "results/logs/uav_collect.log",
    benchmark:
        "results/benchmarks/uav_collect.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        methods=UAV_METHODS,
        # each chunk is checked against what its simulation was asked for
        specs={m: s.spec() for m, s in UAV_SPECS.items()},
        runs=UAV["runs"],
        chunks=len(UAV_CHUNKS),
        steps=UAV["scenario"]["steps"],
        seed=UAV_SEED,
        code=code_digest("workflow/scripts/uav_collect.py"),
    script:
        "../scripts/uav_collect.py"


rule uav_summary:
    """UAV aggregation: per-method errors, paired differences, claims, tables, section."""
    input:
        runs="results/uav/runs.csv",
    output:
        summary="results/uav/summary.csv",
        paired="results/uav/paired.csv",
        tables=table_outputs(UAV_TABLES, "UAV"),
        section="results/report/uav.json",
    log:
        "results/logs/uav_summary.log",
    benchmark:
        "results/benchmarks/uav_summary.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        analysis=canonical(UAV["analysis"]),
        setting=pick(UAV, *UAV_MODEL_KEYS),
        seed=UAV_SEED,
        methods=UAV_METHODS,
        runs=UAV["runs"],
        code=code_digest("workflow/scripts/uav_summary.py"),
    script:
        "../scripts/uav_summary.py"


rule uav_figures:
    """UAV figures: error CDFs drawn the paper's way (Figs. 4 and 5), each with its paired view."""
    input:
        runs="results/uav/runs.csv",
        summary="results/uav/summary.csv",
        paired="results/uav/paired.csv",
    output:
        figure_outputs(UAV_FIGURES, "UAV"),
    log:
        "results/logs/uav_figures.log",
    benchmark:
        "results/benchmarks/uav_figures.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        methods=UAV_METHODS,
        runs=UAV["runs"],
        seed=UAV_SEED,
        code=code_digest("workflow/scripts/uav_figures.py"),
    script:
        "../scripts/uav_figures.py"


rule uav_recording:
    """Rerun recording of UAV run {k}, every method side by side."""
    output:
        "results/recordings/uav_run{k}.rrd",
    log:
        "results/logs/uav_recording/run{k}.log",
    benchmark:
        "results/benchmarks/uav_recording/run{k}.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        uav=pick(UAV, *UAV_MODEL_KEYS),
        methods=[s.spec() for s in UAV_SPECS.values()],
        max_hypotheses=UAV["recording"]["max_hypotheses"],
        seed=UAV_SEED,
        families=UAV_FAMILIES,
        code=code_digest("workflow/scripts/uav_recording.py", UAV_FAMILIES),
    script:
        "../scripts/uav_recording.py"


rule uav:
    """Target: every UAV output."""
    input:
        rules.uav_collect.output,
        rules.uav_summary.output,
        rules.uav_figures.output,
        expand("results/recordings/uav_run{k}.rrd", k=UAV_RECORDED),
