# rsmhp: replication pipeline for Ragi & Mittelmann (IEEE L-CSS 2021), RS-MHP vs NBO.
# Thin entry point: load and validate the config, then include the rule files.
import sys

from snakemake.utils import min_version, update_config, validate

from rsmhp.pipeline.config import (
    ConfigError,
    check_config,
    load_config_file,
    typed_overrides,
)
from rsmhp.pipeline.resources import memory_problems

min_version("9.0")

# Jobs import rsmhp from this repository's src/, also under --use-conda where the editable
# install of the project's virtual environment is not visible. This prepends to PYTHONPATH;
# the workflow requires no environment variable from the user.
os.environ.update(
    PYTHONPATH=os.pathsep.join(
        filter(
            None, [os.path.join(workflow.basedir, "src"), os.environ.get("PYTHONPATH")]
        )
    )
)


# A broken config/config.yaml is reported with its line (Snakemake only says "not valid
# YAML"); files given with --configfile are parsed by Snakemake before this file runs:
# `python -m rsmhp.pipeline.config FILE` reports their lines.
# A refusal prints its message alone (it names the file, key or rule; no Python frames).
try:
    load_config_file(os.path.join(workflow.basedir, "config", "config.yaml"))
except ConfigError as exc:
    sys.exit(str(exc))


configfile: os.path.join(workflow.basedir, "config", "config.yaml")


# Nested --config values arrive as strings ("0.3"); give them their YAML types.
update_config(config, typed_overrides(workflow.config_settings.config))

# Friendly, complete error list first (names every field and its allowed range) ...
try:
    check_config(
        config,
        os.path.join(workflow.basedir, "workflow", "schemas", "config.schema.yaml"),
    )
except ConfigError as exc:
    sys.exit(str(exc))


# ... then snakemake's own validation, which also fills in defaults.
validate(config, "workflow/schemas/config.schema.yaml")


# The HTML report (snakemake --report) opens on the findings and the summary figure.
report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/lqg.smk"
include: "workflow/rules/estimators.smk"
include: "workflow/rules/uav.smk"
include: "workflow/rules/decisions.smk"
include: "workflow/rules/frontier.smk"
include: "workflow/rules/horizon.smk"
include: "workflow/rules/scenarios.smk"
include: "workflow/rules/report.smk"


# Memory: every simulation rule's estimate for this config within its mem_mb, before any job.
_memory = memory_problems(
    config,
    {r.name: getattr(r.resources.get("mem_mb"), "raw", None) for r in workflow.rules},
)
if _memory:
    sys.exit("invalid configuration (nothing was run):\n  - " + "\n  - ".join(_memory))


# On a SLURM cluster: every job must fit on a node of its partition (threads after
# set-threads and max-threads, mem_mb after set-resources), checked against `sinfo` before
# anything is submitted; SLURM would otherwise keep it pending forever, silently.
onstart:
    if (
        workflow.executor_plugin is not None
        and workflow.executor_plugin.name == "slurm"
    ):
        from rsmhp.pipeline.cluster import ClusterFitError, JobAsk, check_jobs

        try:
            check_jobs(
                JobAsk(
                    job.rule.name,
                    int(job.threads),
                    job.resources.get("mem_mb"),
                    job.resources.get("slurm_partition") or None,
                )
                for job in workflow.dag.needrun_jobs()
                if not job.is_local
            )
        except ClusterFitError as exc:
            sys.exit(str(exc))


rule all:
    """Default target: the full replication and its report."""
    default_target: True
    input:
        rules.lqg.input,
        rules.estimators.input,
        rules.uav.input,
        rules.decisions.input,
        rules.frontier.input,
        rules.frontier_exploratory.input if config["frontier"]["exploratory"] else [],
        rules.horizon.input,
        rules.report.output,
