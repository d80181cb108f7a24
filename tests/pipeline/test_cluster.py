"""The SLURM pre-flight check (rsmhp.pipeline.cluster) on sinfo listings and job asks by hand."""

from __future__ import annotations

import pytest

from rsmhp.pipeline.cluster import (
    ClusterFitError,
    JobAsk,
    Partition,
    check_jobs,
    misfits,
    parse_sinfo,
)

SINFO = "debug*|2|23081\nbig|64|512000\nbig|32+|256000\n"


def test_sinfo_gives_each_partitions_largest_node():
    p = parse_sinfo(SINFO)
    assert p["debug"] == Partition("debug", 2, 23081, default=True)
    assert p["big"] == Partition("big", 64, 512000, default=False)
    with pytest.raises(ValueError, match=r"expected 'partition\|cpus\|memory'"):
        parse_sinfo("debug 2 100")
    with pytest.raises(ValueError, match=r"CPUs 'n/a' is not a whole number"):
        parse_sinfo("debug|n/a|100")
    with pytest.raises(ValueError, match="listed no partition"):
        parse_sinfo("\n")


def test_misfits_name_rule_ask_and_offer():
    parts = parse_sinfo(SINFO)
    jobs = [
        JobAsk("a", 1, 1000),
        JobAsk("sim", 8, 4000),
        JobAsk("sim", 2, 4000),  # the rule's largest ask counts
        JobAsk("fat", 1, 30000),
        JobAsk("wide", 8, 1000, "big"),
        JobAsk("lost", 1, 100, "gpu"),
    ]
    got = misfits(jobs, parts)
    assert got == [
        "rule fat: asks for mem_mb = 30000, partition 'debug' offers at most 23081 MB per node; "
        "lower its set-resources entry in the profile",
        "rule lost: partition 'gpu' does not exist (partitions: big, debug)",
        "rule sim: asks for 8 CPUs (threads), partition 'debug' offers at most 2 per node; "
        "lower it with max-threads: 2 in the profile",
    ]
    assert misfits([JobAsk("a", 2, 23081)], parts) == []  # the boundary fits
    no_default = {"big": parts["big"]}
    (msg,) = misfits([JobAsk("a", 1)], no_default)
    assert "no slurm_partition and the cluster has no default partition" in msg


def test_check_jobs_refuses_with_every_problem_and_accepts_a_fit():
    parts = parse_sinfo(SINFO)
    check_jobs([JobAsk("a", 2, 100)], parts)
    check_jobs([], None)  # nothing to submit: sinfo is not asked
    with pytest.raises(ClusterFitError, match=r"nothing was submitted\):\n  - rule b: asks for 4"):
        check_jobs([JobAsk("b", 4, 100)], parts)
