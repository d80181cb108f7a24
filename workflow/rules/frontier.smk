# Equal-compute study of the planners (decisions.frontier): one job per model variant with
# paired closed-loop runs and open-loop regret of every method and its planning time per step
# (one thread: the time is the study's measure of compute), then aggregation and the figure.
import json

from rsmhp.studies.frontier.figures import CONFIRM_FIGURES
from rsmhp.studies.frontier.figures import FIGURES as FRONTIER_FIGURES
from rsmhp.studies.frontier.section import CONFIRM_TABLES
from rsmhp.studies.frontier.section import TABLES as FRONTIER_TABLES
from rsmhp.pipeline.protocol import confirm_plan

FRONTIER = config["decisions"]["frontier"]
FRONTIER_FAMILIES = families_of(FRONTIER["methods"], "decisions.frontier.methods")
FRONTIER_MODELS = list(FRONTIER["models"])
FRONTIER_REC = config["decisions"]["recording"]
FRONTIER_RECORDING = f"results/recordings/dec_{FRONTIER_REC['model']}_planners.rrd"
# the exploratory design (published up to 76a0c01): only on request, as a section without claims
if FRONTIER_MODELS and FRONTIER["exploratory"]:
    REPORT_SECTIONS["decisions_frontier_exploratory"] = (
        "results/report/decisions_frontier.json"
    )
    REPORT_FIGURES.extend(FRONTIER_FIGURES)
# the confirmatory run: what the committed preregistration and tuned file name (checked here,
# before any job: a tuned file that is not the preregistered one stops the workflow)
CONFIRM = confirm_plan(workflow.basedir, FRONTIER)
if CONFIRM is not None:
    REPORT_SECTIONS["decisions_frontier"] = "results/report/decisions_confirm.json"
    REPORT_FIGURES.extend(CONFIRM_FIGURES)


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
        families=FRONTIER_FAMILIES,
        code=code_digest("workflow/scripts/decisions_frontier.py", FRONTIER_FAMILIES),
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
        models=canonical(config["decisions"]["uav"]["models"]),
        cfg=pick(FRONTIER, "methods", "timing"),
        seed=config["seed"],
        families=FRONTIER_FAMILIES,
        code=code_digest(
            "workflow/scripts/decisions_frontier_timing.py", FRONTIER_FAMILIES
        ),
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
        families=FRONTIER_FAMILIES,
        code=code_digest(
            "workflow/scripts/decisions_frontier_recording.py", FRONTIER_FAMILIES
        ),
    script:
        "../scripts/decisions_frontier_recording.py"


rule frontier_exploratory:
    """Target: the exploratory equal-compute design published up to 76a0c01 (tables, section, figure, recording)."""
    input:
        rules.decisions_frontier_summary.output if FRONTIER_MODELS else [],
        rules.decisions_frontier_figures.output if FRONTIER_MODELS else [],
        rules.decisions_frontier_recording.output if FRONTIER_MODELS else [],


# ---------------------------------------------------------------------------- the protocol
# Tuning (target `tune`, `make tune`; not part of the default run): every candidate of
# decisions.frontier.tuning in closed loop and in an interleaved timing on the tuning stream,
# then the selection rule (rsmhp.pipeline.protocol.select) writes results/tune/tuned.yaml.
TUNING = FRONTIER["tuning"]


rule frontier_tune:
    """Protocol tuning, one model variant: closed-loop runs of every candidate configuration on the tuning stream."""
    output:
        "results/tune/frontier/{model}.csv",
    log:
        "results/logs/frontier_tune/{model}.log",
    benchmark:
        "results/benchmarks/frontier_tune/{model}.tsv"
    priority: PRIORITY["decisions_frontier"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=120,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=canonical(config["decisions"]["uav"]["models"]),
        tuning=canonical(TUNING),
        track_loss_error=FRONTIER["track_loss_error"],
        seed=config["seed"],
        families=FRONTIER_FAMILIES,
        code=code_digest("workflow/scripts/frontier_tune.py", FRONTIER_FAMILIES),
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
        models=canonical(config["decisions"]["uav"]["models"]),
        tuning=canonical(TUNING),
        seed=config["seed"],
        families=FRONTIER_FAMILIES,
        code=code_digest("workflow/scripts/frontier_tune_timing.py", FRONTIER_FAMILIES),
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
        config=canonical(config),
        code=code_digest("workflow/scripts/frontier_tune_select.py"),
    script:
        "../scripts/frontier_tune_select.py"


rule tune:
    """Target: the protocol's tuning (not part of the default run): results/tune/tuned.yaml."""
    input:
        rules.frontier_tune_select.output if FRONTIER_MODELS else [],


# The confirmatory run (part of the default run): the preregistered configurations of every
# model on the confirm stream, their interleaved timing, then claims FR-*, tables, figure.
CONFIRM_MODELS = list(CONFIRM["models"]) if CONFIRM is not None else []
with open(
    os.path.join(workflow.basedir, "paper/exploratory/claims_76a0c01.json")
) as _f:
    EXPLORATORY_CLAIMS = json.load(_f)["claims"]
# the first confirmatory run's FR claims (superseded by the second preregistration; kept)
with open(
    os.path.join(workflow.basedir, "paper/superseded/claims_confirm1.json")
) as _f:
    SUPERSEDED = json.load(_f)


rule frontier_confirm:
    """Protocol, confirmatory run, one model variant: closed-loop runs of the preregistered configurations on the confirm stream."""
    output:
        "results/decisions/confirm/{model}.csv",
    log:
        "results/logs/frontier_confirm/{model}.log",
    benchmark:
        "results/benchmarks/frontier_confirm/{model}.tsv"
    priority: PRIORITY["decisions_frontier"]
    conda:
        ENV
    threads: 1
    resources:
        mem_mb=2000,
        runtime=120,
    params:
        uav=pick(config["uav"], *UAV_MODEL_KEYS),
        models=canonical(config["decisions"]["uav"]["models"]),
        plan=lambda w: CONFIRM["plans"][w.model],
        runs=lambda w: CONFIRM["runs"][w.model],
        stream=CONFIRM["stream"] if CONFIRM is not None else None,
        track_loss_error=FRONTIER["track_loss_error"],
        seed=config["seed"],
        families=FRONTIER_FAMILIES,
        code=code_digest("workflow/scripts/frontier_confirm.py", FRONTIER_FAMILIES),
    script:
        "../scripts/frontier_confirm.py"


rule frontier_confirm_timing:
    """Protocol, confirmatory run, one model variant: interleaved timing of the preregistered configurations (holds the cores)."""
    output:
        "results/decisions/confirm/timing/{model}.csv",
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
        models=canonical(config["decisions"]["uav"]["models"]),
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
        runs=expand("results/decisions/confirm/{model}.csv", model=CONFIRM_MODELS),
        timing=expand(
            "results/decisions/confirm/timing/{model}.csv", model=CONFIRM_MODELS
        ),
    output:
        summary="results/decisions/confirm_summary.csv",
        ladder="results/decisions/confirm_ladder.csv",
        tables=table_outputs(CONFIRM_TABLES, "Decision study"),
        section="results/report/decisions_confirm.json",
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
        # the FR and HZ claims published at 76a0c01 (exploratory; kept, not counted)
        exploratory=EXPLORATORY_CLAIMS,
        superseded=SUPERSEDED,
        code=code_digest("workflow/scripts/frontier_confirm_summary.py"),
    script:
        "../scripts/frontier_confirm_summary.py"


rule frontier_confirm_figures:
    """Protocol, confirmatory run: the ladder figure (error against both compute units, probability of improvement)."""
    input:
        ladder="results/decisions/confirm_ladder.csv",
    output:
        figure_outputs(CONFIRM_FIGURES, "Decision study"),
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
    """Target: the equal-compute study's confirmatory run (tables, section, figure; nothing without a preregistration)."""
    input:
        rules.frontier_confirm_summary.output if CONFIRM_MODELS else [],
        rules.frontier_confirm_figures.output if CONFIRM_MODELS else [],
