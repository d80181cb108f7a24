# Shared settings and helpers of every rule file.

THREADS = config["threads"]

# Software environment of every rule (used with --use-conda).
ENV = "../envs/rsmhp.yaml"

# Report sections: key -> section JSON written by an aggregation rule. Each rule file
# registers its own section here and its figures in REPORT_FIGURES; the order in the report
# comes from each section's `order` field.
REPORT_SECTIONS = {}

REPORT_FIGURES = []


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
