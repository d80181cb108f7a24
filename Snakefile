# rsmhp: replication pipeline for Ragi & Mittelmann (IEEE L-CSS 2021), RS-MHP vs NBO.
# Thin entry point: load and validate the config, then include the rule files.
from snakemake.utils import min_version, validate

from rsmhp.config import check_config

min_version("9.0")


configfile: os.path.join(workflow.basedir, "config", "config.yaml")


# Friendly, complete error list first (names every field and its allowed range) ...
check_config(
    config, os.path.join(workflow.basedir, "workflow", "schemas", "config.schema.yaml")
)


# ... then snakemake's own validation, which also fills in defaults.
validate(config, "workflow/schemas/config.schema.yaml")


include: "workflow/rules/common.smk"
include: "workflow/rules/lqg.smk"
include: "workflow/rules/report.smk"


rule all:
    default_target: True
    input:
        rules.lqg.input,
        rules.report.output,
