# rsmhp: replication pipeline for Ragi & Mittelmann (IEEE L-CSS 2021), RS-MHP vs NBO.
# Thin entry point: load and validate the config, then include the rule files.
from snakemake.utils import min_version, validate

from rsmhp.config import check_config

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


configfile: os.path.join(workflow.basedir, "config", "config.yaml")


# Friendly, complete error list first (names every field and its allowed range) ...
check_config(
    config, os.path.join(workflow.basedir, "workflow", "schemas", "config.schema.yaml")
)


# ... then snakemake's own validation, which also fills in defaults.
validate(config, "workflow/schemas/config.schema.yaml")


include: "workflow/rules/common.smk"
include: "workflow/rules/lqg.smk"
include: "workflow/rules/estimators.smk"
include: "workflow/rules/uav.smk"
include: "workflow/rules/decisions.smk"
include: "workflow/rules/report.smk"


rule all:
    default_target: True
    input:
        rules.lqg.input,
        rules.estimators.input,
        rules.uav.input,
        rules.decisions.input,
        rules.report.output,
