"""Pre-flight check of a SLURM run: every job must fit on a node of its partition.

SLURM accepts a job that asks for more CPUs or memory than any node of its partition has and,
under the default ``EnforcePartLimits=NO``, leaves it pending forever (reason
``PartitionConfig``) while Snakemake waits without a message. The workflow's ``onstart``
handler (``workflow/rules/common.smk``) therefore calls :func:`check_jobs` when the executor
is ``slurm``: it reads the partitions' largest node from ``sinfo`` and refuses the run before
anything is submitted, naming each rule, what it asks (threads after ``set-threads`` and
``max-threads``, ``mem_mb`` after ``set-resources``) and what its partition offers.

Units: CPUs per node (SLURM's ``%c``), memory per node in MB (``%m``, SLURM's MB = MiB).
"""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Iterable
from dataclasses import dataclass

__all__ = [
    "ClusterFitError",
    "JobAsk",
    "Partition",
    "check_jobs",
    "misfits",
    "parse_sinfo",
    "read_partitions",
]

#: ``sinfo`` output format: one line per node and partition, ``partition|cpus|memory``
SINFO_FORMAT = "%P|%c|%m"


class ClusterFitError(RuntimeError):
    """A job asks for more than any node of its partition offers (nothing was submitted)."""


@dataclass(frozen=True)
class Partition:
    """The largest node of a partition: ``cpus`` per node and ``mem_mb`` per node."""

    name: str
    cpus: int
    mem_mb: int
    default: bool = False


@dataclass(frozen=True)
class JobAsk:
    """What one job asks: its rule, threads (CPUs per task), memory (MB) and partition (None:
    the cluster's default partition)."""

    rule: str
    threads: int
    mem_mb: int | None = None
    partition: str | None = None


def _number(text: str, what: str, line: str) -> int:
    t = text.strip().rstrip("+")
    if not t.isdigit():
        raise ValueError(f"sinfo: {what} {text!r} is not a whole number (line {line!r})")
    return int(t)


def parse_sinfo(text: str) -> dict[str, Partition]:
    """Partitions from ``sinfo -h -N -o '%P|%c|%m'`` (one line per node and partition; the
    default partition's name ends in ``*``; a ``+`` suffix means 'at least'): per partition
    the largest CPU count and the largest memory over its nodes."""
    out: dict[str, Partition] = {}
    for line in text.splitlines():
        if not line.strip():
            continue
        parts = line.strip().split("|")
        if len(parts) != 3:
            raise ValueError(f"sinfo: expected 'partition|cpus|memory', got {line!r}")
        name, cpus, mem = parts
        default = name.endswith("*")
        name = name.rstrip("*")
        c, m = _number(cpus, "CPUs", line), _number(mem, "memory", line)
        old = out.get(name)
        if old is not None:
            c, m, default = max(c, old.cpus), max(m, old.mem_mb), default or old.default
        out[name] = Partition(name, c, m, default)
    if not out:
        raise ValueError("sinfo listed no partition (is the controller up? `sinfo` says)")
    return out


def misfits(jobs: Iterable[JobAsk], partitions: dict[str, Partition]) -> list[str]:
    """One message per rule whose job cannot run on any node of its partition (the rule's
    largest ask), or whose partition does not exist."""
    default = [p for p in partitions.values() if p.default]
    worst: dict[tuple[str, str | None], JobAsk] = {}
    for j in jobs:
        key = (j.rule, j.partition)
        old = worst.get(key)
        if old is None:
            worst[key] = j
        else:
            worst[key] = JobAsk(
                j.rule,
                max(j.threads, old.threads),
                max(j.mem_mb or 0, old.mem_mb or 0) or None,
                j.partition,
            )
    out = []
    for (rule, part), j in sorted(worst.items(), key=lambda kv: (kv[0][0], kv[0][1] or "")):
        if part is None:
            if not default:
                out.append(
                    f"rule {rule}: no slurm_partition and the cluster has no default partition "
                    f"(partitions: {', '.join(sorted(partitions))}); set slurm_partition in "
                    "the profile's default-resources"
                )
                continue
            p = default[0]
        elif part not in partitions:
            out.append(
                f"rule {rule}: partition {part!r} does not exist (partitions: "
                f"{', '.join(sorted(partitions))})"
            )
            continue
        else:
            p = partitions[part]
        if j.threads > p.cpus:
            out.append(
                f"rule {rule}: asks for {j.threads} CPUs (threads), partition {p.name!r} offers "
                f"at most {p.cpus} per node; lower it with max-threads: {p.cpus} in the profile"
            )
        if j.mem_mb is not None and j.mem_mb > p.mem_mb:
            out.append(
                f"rule {rule}: asks for mem_mb = {j.mem_mb}, partition {p.name!r} offers at most "
                f"{p.mem_mb} MB per node; lower its set-resources entry in the profile"
            )
    return out


def read_partitions(timeout: float = 30.0) -> dict[str, Partition]:
    """The cluster's partitions from ``sinfo`` (:func:`parse_sinfo`)."""
    exe = shutil.which("sinfo")
    if exe is None:
        raise ClusterFitError("the slurm executor is selected but `sinfo` is not on PATH")
    res = subprocess.run(
        [exe, "-h", "-N", "-o", SINFO_FORMAT],
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )
    if res.returncode != 0:
        raise ClusterFitError(f"`sinfo` failed (exit {res.returncode}): {res.stderr.strip()}")
    return parse_sinfo(res.stdout)


def check_jobs(jobs: Iterable[JobAsk], partitions: dict[str, Partition] | None = None) -> None:
    """Raise :class:`ClusterFitError` listing every rule that cannot fit (:func:`misfits`);
    ``partitions`` default: :func:`read_partitions`."""
    jobs = list(jobs)
    if not jobs:
        return
    problems = misfits(jobs, partitions if partitions is not None else read_partitions())
    if problems:
        raise ClusterFitError(
            "these jobs can never start on this cluster (nothing was submitted):\n  - "
            + "\n  - ".join(problems)
        )
