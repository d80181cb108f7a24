# Equal-compute study of the planners (frontier): one job per model variant with
# paired closed-loop runs and open-loop regret of every method and its planning time per step
# (one thread: the time is the study's measure of compute), then aggregation and the figure.
import numpy as np

from rsmhp.studies.frontier import CONFIRM_FIGURES, CONFIRM_TABLES
from rsmhp.studies.frontier import FIGURES as FRONTIER_FIGURES
from rsmhp.studies.frontier import TABLES as FRONTIER_TABLES
from rsmhp.pipeline.protocol import tuned_configurations
from rsmhp.studies.frontier.chunks import confirm_chunks, confirm_runs
from rsmhp.studies.frontier.reference import (
    compare_problems,
    ladder_rows,
    method_sources,
    scenario_fingerprint,
)

FRONTIER = config["frontier"]
FRONTIER_FAMILIES = families_of(FRONTIER["methods"], "frontier.methods")
FRONTIER_MODELS = list(FRONTIER["models"])
FRONTIER_REC = config["frontier"]["recording"]
FRONTIER_RECORDING = f"results/recordings/frontier_{FRONTIER_REC['model']}_planners.rrd"
# the exploratory design (published up to 76a0c01): only on request, as a section without claims
if FRONTIER_MODELS and FRONTIER["exploratory"]:
    REPORT_SECTIONS["frontier_exploratory"] = "results/report/frontier_exploratory.json"
    REPORT_FIGURES.extend(FRONTIER_FIGURES)
# the confirmatory run (CONFIRM, CONFIRM_MODELS: common.smk)
if CONFIRM is not None:
    REPORT_SECTIONS["frontier"] = "results/report/frontier.json"
    REPORT_FIGURES.extend(CONFIRM_FIGURES)


wildcard_constraints:
    model=r"[a-z][a-z0-9_]*",


rule frontier_explore:
    """Equal-compute study, one model variant: closed- and open-loop quality and planning time of every method."""
    output:
        runs="results/frontier/explore/{model}.csv",
        regret="results/frontier/explore/{model}_regret.csv",
    log:
        "results/logs/frontier_explore/{model}.log",
    benchmark:
        "results/benchmarks/frontier_explore/{model}.tsv"
    priority: PRIORITY["frontier"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=60,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=UAV_MODELS,
        cfg=pick(
            FRONTIER,
            "runs",
            "methods",
            "regret_runs",
            "regret_steps",
            "track_loss_error",
        ),
        scoring=UAV_SCORING,
        seed=config["seed"],
        families=FRONTIER_FAMILIES,
        code=code_digest("workflow/scripts/frontier_explore.py", FRONTIER_FAMILIES),
    # closed-loop runs go through the run store (config run_store: the script reads it,
    # it is no param, so moving or disabling the store reruns nothing; docs/store.md)
    script:
        "../scripts/frontier_explore.py"


rule frontier_explore_timing:
    """Equal-compute study, one model variant: interleaved wall-clock timing of every method's plan call (holds the cores)."""
    output:
        "results/frontier/explore/timing/{model}.csv",
    log:
        "results/logs/frontier_explore_timing/{model}.log",
    benchmark:
        "results/benchmarks/frontier_explore_timing/{model}.tsv"
    priority: PRIORITY["holds_cores"]
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
        models=UAV_MODELS,
        cfg=pick(FRONTIER, "methods", "timing"),
        seed=config["seed"],
        families=FRONTIER_FAMILIES,
        code=code_digest(
            "workflow/scripts/frontier_explore_timing.py", FRONTIER_FAMILIES
        ),
    script:
        "../scripts/frontier_explore_timing.py"


rule frontier_explore_summary:
    """Equal-compute study: per model and method, compute and quality with bootstrap CIs."""
    input:
        runs=expand("results/frontier/explore/{model}.csv", model=FRONTIER_MODELS),
        regret=expand(
            "results/frontier/explore/{model}_regret.csv", model=FRONTIER_MODELS
        ),
        timing=expand(
            "results/frontier/explore/timing/{model}.csv", model=FRONTIER_MODELS
        ),
    output:
        summary="results/frontier/explore_summary.csv",
        tables=table_outputs(FRONTIER_TABLES, "Equal compute"),
        section="results/report/frontier_exploratory.json",
    log:
        "results/logs/frontier_explore_summary.log",
    benchmark:
        "results/benchmarks/frontier_explore_summary.tsv"
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
        code=code_digest("workflow/scripts/frontier_explore_summary.py"),
    script:
        "../scripts/frontier_explore_summary.py"


rule frontier_explore_figures:
    """Equal-compute study figure: quality against planning time, one curve per family."""
    input:
        summary="results/frontier/explore_summary.csv",
    output:
        figure_outputs(FRONTIER_FIGURES, "Equal compute"),
    log:
        "results/logs/frontier_explore_figures.log",
    benchmark:
        "results/benchmarks/frontier_explore_figures.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        budget=canonical(FRONTIER["budget"]),
        code=code_digest("workflow/scripts/frontier_explore_figures.py"),
    script:
        "../scripts/frontier_explore_figures.py"


rule frontier_recording:
    """Rerun recording of one frontier run (chosen by frontier.recording.select): NBO and every family's budget member."""
    input:
        runs=f"results/frontier/explore/{FRONTIER_REC['model']}.csv",
    output:
        FRONTIER_RECORDING,
    log:
        "results/logs/frontier_recording.log",
    benchmark:
        "results/benchmarks/frontier_recording.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=UAV_MODELS,
        cfg=canonical(FRONTIER),
        recording=canonical(FRONTIER_REC),
        seed=config["seed"],
        families=FRONTIER_FAMILIES,
        code=code_digest("workflow/scripts/frontier_recording.py", FRONTIER_FAMILIES),
    script:
        "../scripts/frontier_recording.py"


rule frontier_exploratory:
    """Target: the exploratory equal-compute design published up to 76a0c01 (tables, section, figure, recording)."""
    input:
        rules.frontier_explore_summary.output if FRONTIER_MODELS else [],
        rules.frontier_explore_figures.output if FRONTIER_MODELS else [],
        rules.frontier_recording.output if FRONTIER_MODELS else [],


# ---------------------------------------------------------------------------- the protocol
# Tuning (target `tune`, `make tune`; not part of the default run): every candidate of
# frontier.tuning in closed loop and in an interleaved timing on the tuning stream,
# then the selection rule (rsmhp.pipeline.protocol.select) writes results/tune/tuned.yaml.
TUNING = FRONTIER["tuning"]
# the families the tuning runs: frontier.methods' and its candidates' (e.g. the pursuit policy)
TUNE_FAMILIES = sorted(
    {
        *FRONTIER_FAMILIES,
        *families_of(
            TUNING["candidates"]["methods"], "frontier.tuning.candidates.methods"
        ),
    }
)


rule frontier_tune:
    """Protocol tuning, one model variant: closed-loop runs of every candidate configuration on the tuning stream."""
    output:
        "results/tune/frontier/{model}.csv",
    log:
        "results/logs/frontier_tune/{model}.log",
    benchmark:
        "results/benchmarks/frontier_tune/{model}.tsv"
    priority: PRIORITY["frontier"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=120,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=UAV_MODELS,
        tuning=canonical(TUNING),
        track_loss_error=FRONTIER["track_loss_error"],
        seed=config["seed"],
        families=TUNE_FAMILIES,
        code=code_digest("workflow/scripts/frontier_tune.py", TUNE_FAMILIES),
    # closed-loop runs go through the run store (config run_store: the script reads it,
    # it is no param, so moving or disabling the store reruns nothing; docs/store.md)
    script:
        "../scripts/frontier_tune.py"


rule frontier_tune_timing:
    """Protocol tuning, one model variant: interleaved wall-clock timing of every candidate (holds the cores)."""
    output:
        "results/tune/frontier/timing/{model}.csv",
    log:
        "results/logs/frontier_tune_timing/{model}.log",
    benchmark:
        "results/benchmarks/frontier_tune_timing/{model}.tsv"
    priority: PRIORITY["holds_cores"]
    conda:
        ENV
    # plans on one thread but holds two: nothing runs beside it on the 2-core machine
    threads: 2
    resources:
        mem_mb=2000,
        runtime=30,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=UAV_MODELS,
        tuning=canonical(TUNING),
        seed=config["seed"],
        families=TUNE_FAMILIES,
        code=code_digest("workflow/scripts/frontier_tune_timing.py", TUNE_FAMILIES),
    script:
        "../scripts/frontier_tune_timing.py"


rule frontier_tune_select:
    """Protocol tuning: the configuration of every family at every budget (results/tune/tuned.yaml; make tune copies it to config/)."""
    input:
        runs=expand("results/tune/frontier/{model}.csv", model=FRONTIER_MODELS),
        timing=expand("results/tune/frontier/timing/{model}.csv", model=FRONTIER_MODELS),
    output:
        tuned="results/tune/tuned.yaml",
        selection="results/tune/selection.csv",
        table="results/tune/tuning.md",
        candidates="results/tune/candidates.csv",
        depth="results/tune/depth.md",
    log:
        "results/logs/frontier_tune_select.log",
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        models=FRONTIER_MODELS,
        tuning=canonical(TUNING),
        seed=config["seed"],
        config=canonical(NUMBERS_CONFIG),
        code=code_digest("workflow/scripts/frontier_tune_select.py"),
    script:
        "../scripts/frontier_tune_select.py"


rule tune:
    """Target: the protocol's tuning (not part of the default run): results/tune/tuned.yaml."""
    input:
        rules.frontier_tune_select.output if FRONTIER_MODELS else [],


# The confirmatory run (part of the default run): the preregistered configurations of every
# model on the confirm stream, their interleaved timing, then claims FR-*, tables, figure.


# The confirmatory runs of a model run as split.frontier_confirm jobs of contiguous runs
# (rsmhp.studies.frontier.chunks), merged into results/frontier/confirm/{model}.csv.
rule frontier_confirm:
    """Protocol, confirmatory run, one model variant and chunk of runs: closed-loop runs of the preregistered configurations on the confirm stream."""
    output:
        "results/frontier/confirm/chunks/{model}/{chunk}.csv",
    log:
        "results/logs/frontier_confirm/{model}_{chunk}.log",
    benchmark:
        "results/benchmarks/frontier_confirm/{model}_{chunk}.tsv"
    priority: PRIORITY["frontier"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=30,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=UAV_MODELS,
        plan=lambda w: CONFIRM["plans"][w.model],
        # this chunk's runs (the streams are keyed on the run, not on the chunk)
        runs=lambda w: confirm_runs(
            CONFIRM["runs"][w.model], SPLIT["frontier_confirm"], int(w.chunk)
        ),
        stream=CONFIRM["stream"] if CONFIRM is not None else None,
        track_loss_error=FRONTIER["track_loss_error"],
        seed=config["seed"],
        families=FRONTIER_FAMILIES,
        code=code_digest("workflow/scripts/frontier_confirm.py", FRONTIER_FAMILIES),
    # closed-loop runs go through the run store (config run_store: the script reads it,
    # it is no param, so moving or disabling the store reruns nothing; docs/store.md)
    script:
        "../scripts/frontier_confirm.py"


rule frontier_confirm_merge:
    """Protocol, confirmatory run, one model variant: its chunks checked and merged into the table of every configuration and run."""
    input:
        lambda w: expand(
            "results/frontier/confirm/chunks/{{model}}/{chunk}.csv",
            chunk=confirm_chunks(CONFIRM["runs"][w.model], SPLIT["frontier_confirm"]),
        ),
    output:
        "results/frontier/confirm/{model}.csv",
    log:
        "results/logs/frontier_confirm_merge/{model}.log",
    benchmark:
        "results/benchmarks/frontier_confirm_merge/{model}.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        plan=lambda w: CONFIRM["plans"][w.model],
        runs=lambda w: CONFIRM["runs"][w.model],
        jobs=SPLIT["frontier_confirm"],
        code=code_digest("workflow/scripts/frontier_confirm_merge.py"),
    script:
        "../scripts/frontier_confirm_merge.py"


rule frontier_confirm_timing:
    """Protocol, confirmatory run, one model variant: interleaved timing of the preregistered configurations (holds the cores)."""
    output:
        "results/frontier/confirm/timing/{model}.csv",
    log:
        "results/logs/frontier_confirm_timing/{model}.log",
    benchmark:
        "results/benchmarks/frontier_confirm_timing/{model}.tsv"
    priority: PRIORITY["holds_cores"]
    conda:
        ENV
    # plans on one thread but holds two: nothing runs beside it on the 2-core machine
    threads: 2
    resources:
        mem_mb=2000,
        runtime=30,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=UAV_MODELS,
        plan=lambda w: CONFIRM["plans"][w.model],
        stream=CONFIRM["stream"] if CONFIRM is not None else None,
        timing=canonical(FRONTIER["confirm"]["timing"]),
        seed=config["seed"],
        families=FRONTIER_FAMILIES,
        code=code_digest(
            "workflow/scripts/frontier_confirm_timing.py", FRONTIER_FAMILIES
        ),
    script:
        "../scripts/frontier_confirm_timing.py"


rule frontier_confirm_summary:
    """Protocol, confirmatory run: per configuration and budget, compute and quality with CIs, claims FR-*, tables and the report section."""
    input:
        runs=expand("results/frontier/confirm/{model}.csv", model=CONFIRM_MODELS),
        timing=expand(
            "results/frontier/confirm/timing/{model}.csv", model=CONFIRM_MODELS
        ),
        # the FR and HZ claims published at 76a0c01 (exploratory; kept, not counted), and
        # the first confirmatory run's FR claims (superseded by the second preregistration)
        # (published files of this checkout, wherever the workflow runs: -d elsewhere)
        exploratory=os.path.join(
            workflow.basedir, "paper/exploratory/claims_76a0c01.json"
        ),
        superseded=os.path.join(
            workflow.basedir, "paper/superseded/claims_confirm1.json"
        ),
    output:
        summary="results/frontier/confirm_summary.csv",
        ladder="results/frontier/confirm_ladder.csv",
        tables=table_outputs(CONFIRM_TABLES, "Equal compute"),
        section="results/report/frontier.json",
    log:
        "results/logs/frontier_confirm_summary.log",
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        confirm=CONFIRM,
        timing=canonical(FRONTIER["confirm"]["timing"]),
        code=code_digest("workflow/scripts/frontier_confirm_summary.py"),
    script:
        "../scripts/frontier_confirm_summary.py"


rule frontier_confirm_figures:
    """Protocol, confirmatory run: the ladder figure (error against both compute units, probability of improvement)."""
    input:
        ladder="results/frontier/confirm_ladder.csv",
    output:
        figure_outputs(CONFIRM_FIGURES, "Equal compute"),
    log:
        "results/logs/frontier_confirm_figures.log",
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=5,
    params:
        code=code_digest("workflow/scripts/frontier_confirm_figures.py"),
    script:
        "../scripts/frontier_confirm_figures.py"


rule frontier:
    """Target: the equal-compute study's confirmatory run (tables, section, figure, the reference of make compare; nothing without a preregistration)."""
    input:
        rules.frontier_confirm_summary.output if CONFIRM_MODELS else [],
        rules.frontier_confirm_figures.output if CONFIRM_MODELS else [],
        (
            [
                "results/frontier/reference/frontier_confirm_runs.parquet",
                "results/frontier/reference/frontier_confirm.json",
            ]
            if CONFIRM_MODELS
            else []
        ),


# ---------------------------------------------------------------------------------------
# The published reference and the comparison of new planners with it (make compare):
# the confirmatory run's per-run table with the fingerprint of its scenarios
# (rsmhp.studies.frontier.reference), and new methods (config plugin_methods) run on the same
# scenarios and paired with it run by run (rsmhp.studies.frontier.compare).
REFERENCE_DIR = "paper/reference"
COMPARE_METHODS = list(config["plugin_methods"])
if CONFIRM is not None:
    # what makes a run the same scenario: the confirmatory rule's code without any method
    # family, and its configuration (not the plan: the methods are what differs)
    SCENARIO = scenario_fingerprint(
        code_digest("workflow/scripts/frontier_confirm.py", []),
        {
            "uav": pick(config["uav"], *UAV_MODEL_KEYS),
            "models": UAV_MODELS,
            "runs": CONFIRM["runs"],
            "stream": CONFIRM["stream"],
            "seed": config["seed"],
            "track_loss_error": FRONTIER["track_loss_error"],
            # numpy does not promise the same random streams across versions (NEP 19)
            "numpy": np.__version__,
        },
    )
    LADDER = ladder_rows(
        {
            m: {
                b: {f: c.name for f, c in fams.items()}
                for b, fams in tuned_configurations(CONFIRM["tuned"], m).items()
                if float(b)
                in [float(x) for x in CONFIRM["preregistration"]["budgets_ms"]]
            }
            for m in CONFIRM_MODELS
        }
    )
    REFERENCE_MARGIN = float(
        CONFIRM["preregistration"]["claims"]["FR-1"].get("margin_m", 0.25)
    )
if COMPARE_METHODS:
    # refuse a comparison that would not be paired, before any job runs
    if CONFIRM is None:
        sys.exit(
            "plugin_methods: the comparison needs the confirmatory design "
            "(frontier.models and the preregistration), and this config has none"
        )
    # the one file a rule file reads when parsed: the published reference, so that a
    # comparison that would not pair is refused before any job (docs/compare.md)
    _refused = compare_problems(
        REFERENCE_DIR, SCENARIO, CONFIRM_MODELS, COMPARE_METHODS
    )
    if _refused:
        sys.exit(_refused)


rule frontier_reference:
    """Protocol, confirmatory run: its per-run table in compact form (Parquet) with the fingerprint of its scenarios, the reference new planners are paired with (make publish copies it to paper/reference/)."""
    input:
        runs=expand("results/frontier/confirm/{model}.csv", model=CONFIRM_MODELS),
    output:
        runs="results/frontier/reference/frontier_confirm_runs.parquet",
        meta="results/frontier/reference/frontier_confirm.json",
    log:
        "results/logs/frontier_reference.log",
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        scenario=SCENARIO if CONFIRM is not None else None,
        ladder=LADDER if CONFIRM is not None else None,
        preregistration=(
            {
                "path": CONFIRM["path"],
                "sha256": CONFIRM["sha256"],
                "margin_m": REFERENCE_MARGIN,
                "headline_budget_ms": CONFIRM["preregistration"]["headline_budget_ms"],
            }
            if CONFIRM is not None
            else None
        ),
        code=code_digest("workflow/scripts/frontier_reference.py"),
    script:
        "../scripts/frontier_reference.py"


rule frontier_compare_run:
    """A new planner (config plugin_methods) on the confirmatory design's scenarios of one model: the same runs, seed stream and configuration as the published reference."""
    output:
        "results/compare/runs/{model}.csv",
    log:
        "results/logs/frontier_compare_run/{model}.log",
    benchmark:
        "results/benchmarks/frontier_compare_run/{model}.tsv"
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=60,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=UAV_MODELS,
        methods=COMPARE_METHODS,
        runs=lambda w: CONFIRM["runs"][w.model],
        stream=CONFIRM["stream"] if CONFIRM is not None else None,
        track_loss_error=FRONTIER["track_loss_error"],
        seed=config["seed"],
        # the new methods' own code (a plugin's modules live outside src/)
        plugins=method_sources(COMPARE_METHODS),
        code=code_digest("workflow/scripts/frontier_compare_run.py"),
    # closed-loop runs go through the run store (config run_store: the script reads it,
    # it is no param, so moving or disabling the store reruns nothing; docs/store.md)
    script:
        "../scripts/frontier_compare_run.py"


rule frontier_compare:
    """The comparison report: every new method paired with NBO and each family's tuned member at each budget of the published reference, with CIs and verdicts by the preregistered margin, and the figure."""
    input:
        runs=expand("results/compare/runs/{model}.csv", model=CONFIRM_MODELS),
        reference=[
            f"{REFERENCE_DIR}/frontier_confirm_runs.parquet",
            f"{REFERENCE_DIR}/frontier_confirm.json",
        ],
    output:
        report="results/compare/report.md",
        table="results/compare/paired.csv",
        figure="results/compare/frontier.png",
    log:
        "results/logs/frontier_compare.log",
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        plugins=method_sources(COMPARE_METHODS),
        code=code_digest("workflow/scripts/frontier_compare.py"),
    script:
        "../scripts/frontier_compare.py"


rule compare:
    """Target: the comparison of config plugin_methods with the published reference (make compare PLUGIN_METHODS=...)."""
    input:
        rules.frontier_compare.output if COMPARE_METHODS else [],
