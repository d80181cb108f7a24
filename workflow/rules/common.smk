# Shared settings and helpers of every rule file.
from rsmhp.models.uav import methods as _registry
from rsmhp.pipeline.code_digest import code_digest as _code_digest
from rsmhp.pipeline.code_digest import method_only
from rsmhp.pipeline.protocol import confirm_plan as _confirm_plan
from rsmhp.pipeline.protocol import stream_seed as _stream_seed
from rsmhp.models.uav.scoring import map_cells as _map_cells
from rsmhp.models.uav.simulation import MODEL_KEYS as _UAV_MODEL_KEYS

THREADS = config["threads"]

# Keys that change no number of any output: run_store only says where closed-loop runs are
# kept (rsmhp.pipeline.runstore; jobs read it from the config, it is no rule's param), split
# how many jobs the longest simulations run as (rsmhp.pipeline.split: the merged tables are
# the unsplit ones; only the split rules and their merges see it). The rules that record the
# whole config (provenance, its config sha256) get it without them, so moving or disabling
# the store, or splitting otherwise, changes neither the hash `make verify` compares nor any
# other job's params.
NUMBERS_CONFIG = {k: v for k, v in config.items() if k not in ("run_store", "split")}
# jobs per unit of the split rules (config split; defaults from the schema)
SPLIT = config["split"]
# `--config run_store=null` arrives as the string "null" (Snakemake keeps a top-level value
# it cannot read as a number or bool a string): it means no store, as `run_store: null` does
if config.get("run_store") == "null":
    config["run_store"] = None

# Scheduling: Snakemake starts the set of ready jobs that fits in the free cores with the
# largest sum of priorities. The longest jobs (estimator ablation, UAV decision study: threads
# from the config, 1 by default; then the equal-compute study, one job per model) get
# priorities above any two shorter jobs together and start first, one per core; then the
# one-core jobs on the chains to the report, and the many short simulation jobs (map cells,
# UAV runs: 1-9 s) fill both cores to the end. Jobs that gained little from a second worker
# (LQG convergence 1.34x, NBO error 1.03x, decision study LQG 1.16x, estimator figures 1.06x:
# pool start-up and serial parts) declare one thread (measured with the default config, -j1
# and -j2 runs of one machine).
PRIORITY = {
    # jobs that hold both cores (threads: 2) start first, while nothing else runs: at the end
    # they would wait for both cores and leave one idle before and after them
    "holds_cores": 2000,
    "estimators_ablation": 1000,
    "decisions_uav": 990,
    "frontier": 980,
    "horizon_uav": 970,
    "horizon_lqg": 960,
    "estimators_summary": 100,
    "lqg_convergence": 100,
    "lqg_nbo_error": 100,
    "lqg_linear_cost": 100,
    "decisions_lqg": 100,
    "lqg_summary": 90,
    "estimators_figures": 80,
    "decisions_map_cell": 10,
    "uav_simulate": 10,
}

# Software environment of every rule (used with --use-conda).
ENV = "../envs/rsmhp.yaml"

# Report sections: key -> section JSON written by an aggregation rule. Each rule file
# registers its own section here and its figures in REPORT_FIGURES; the order in the report
# comes from each section's `order` field.
REPORT_SECTIONS = {}

REPORT_FIGURES = []


def code_digest(script, families=None):
    """The `code` param for `script` (workflow/scripts/<x>.py): the digest of that script
    and of every rsmhp module under this workflow's src/ it can import
    (rsmhp.pipeline.code_digest, content-based, comments and formatting aside). A change to
    that code changes the param, so Snakemake reruns the job and everything downstream.
    `families` (a job that runs UAV planning methods: `families_of(...)`, also its
    `families` param) counts only those method families' modules of the registry, so adding
    or editing another family reruns none of its jobs."""
    return _code_digest(
        os.path.join(workflow.basedir, script),
        os.path.join(workflow.basedir, "src"),
        method_only(families),
    )


def families_of(methods, key=None):
    """Module names of the method families of `methods`: registry members, or a `methods`
    block of the config (then `key` names it in error messages)."""
    if isinstance(methods, dict):
        methods = _registry.from_config(methods, key).values()
    return sorted({type(m).__module__.rpartition(".")[2] for m in methods})


def canonical(value):
    """Recursively key-sorted copy: rule params must not depend on the config's key order
    (Snakemake reruns a job whose params differ, and it compares dicts in order)."""
    if isinstance(value, dict):
        return {k: canonical(value[k]) for k in sorted(value)}
    if isinstance(value, list):
        return [canonical(v) for v in value]
    return value


def pick(mapping, *keys):
    """The sub-dict of ``mapping`` with just ``keys`` (key-sorted), for a rule's params."""
    return canonical({k: mapping[k] for k in keys})


# Snakemake's report() flag; a line starting with "report" would parse as the report directive
_in_report = report


def figure_outputs(names, category):
    """PNG and PDF of each figure; the PNGs go into the Snakemake report (``snakemake
    --report report.html``), captioned by workflow/report/<name>.rst."""
    pngs = [
        _in_report(
            f"results/figures/{n}.png",
            caption=f"../report/{n}.rst",
            category=category,
            labels={"figure": n},
        )
        for n in names
    ]
    return pngs + expand("results/figures/{name}.pdf", name=names)


def table_outputs(names, category):
    """Markdown tables, in the Snakemake report with workflow/report/table_<name>.rst."""
    return [
        _in_report(
            f"results/tables/{n}.md",
            caption=f"../report/table_{n}.rst",
            category=category,
            labels={"table": n},
        )
        for n in names
    ]


# ---------------------------------------------------------------------------------------
# What several rule files read. A rule file reads the names defined here and its own, never
# another rule file's (tests/pipeline/test_layout.py checks it), so the include order of the
# study files does not matter; this file comes first.
#
# the keys of the uav section every UAV simulation depends on (besides its method and seed)
UAV_MODEL_KEYS = _UAV_MODEL_KEYS
# the UAV model variants (config uav_models): the decision study runs every one, the other
# UAV studies the ones they name
UAV_MODELS = canonical(config["uav_models"])
# the scoring settings of the open-loop regret (decisions.uav), shared by the decision
# study's map cells, the equal-compute and the long-horizon studies
UAV_SCORING = pick(
    config["decisions"]["uav"],
    "n_eval",
    "polish",
    "random_starts",
    "eval_maxiter",
    "n_random",
)
# the confirmatory design: what the committed preregistration and tuned file name (checked
# here, before any job: a tuned file that is not the preregistered one stops the workflow)
# a dry run's stand-in for a stream a preregistration has not named yet (the placeholder
# "<named by the run issue>"): allowed in `snakemake -n` only, so no job draws from it
DRY_RUN = bool(getattr(getattr(workflow, "output_settings", None), "dryrun", False))
DRY_RUN_STREAM = config.get("dry_run_stream")
_dry = [
    k
    for k, v in (
        ("dry_run_stream", DRY_RUN_STREAM),
        ("horizon.stream", config["horizon"]["stream"]),
        ("uav.stream", config["uav"].get("stream")),
        ("decisions.stream", config["decisions"].get("stream")),
    )
    if v == "dry-run"
]
if _dry and not DRY_RUN:
    sys.exit(
        f"{', '.join(_dry)}: 'dry-run' is a dry run's stand-in for a stream not yet named; "
        "it is allowed with snakemake -n only (the run issue names the stream)"
    )
try:
    CONFIRM = _confirm_plan(workflow.basedir, config["frontier"], DRY_RUN_STREAM)
except ValueError as exc:  # e.g. a preregistration whose stream is not named yet
    sys.exit(f"invalid confirmatory design (nothing was run): {exc}")
if CONFIRM is not None and CONFIRM["stream"] == "dry-run" and not DRY_RUN:
    sys.exit(
        "the confirmatory stream is the dry run's stand-in 'dry-run': snakemake -n only"
    )
CONFIRM_MODELS = list(CONFIRM["models"]) if CONFIRM is not None else []
# the seed stream of the UAV study (uav.stream) and of the decision study's UAV parts
# (decisions.stream): absent, exploratory = the config seed itself (the published runs); a
# confirmatory rerun names its stream (rsmhp.pipeline.protocol.stream_seed)
UAV_SEED = _stream_seed(config["seed"], config["uav"].get("stream", "exploratory"))
DEC_SEED = _stream_seed(
    config["seed"], config["decisions"].get("stream", "exploratory")
)
# the sensitivity map's cells (decisions.map): one job each, wildcard {cell} = r<i>c<j>
MAP_CELLS = [c.name for c in _map_cells(config["decisions"]["map"])]
# the long-horizon study's (model, H) jobs (horizon.uav)
HZ_JOBS = [
    f"{m}_H{h}"
    for m in config["horizon"]["uav"]["models"]
    for h in config["horizon"]["uav"]["H"]
]
