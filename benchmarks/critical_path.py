"""The critical path of a finished run: the longest chain of job times through the workflow's
job graph, from Snakemake's ``benchmark:`` files.

    .venv/bin/python benchmarks/critical_path.py [--results results] [--limit 120]
        [--cores 2] [--snakefile Snakefile] [--dry-run FILE] [--json OUT] [-- SNAKEMAKE ARGS]

The job graph is the one Snakemake builds for the run: ``snakemake -n -F`` (a dry run that
lists every job of the target, done or not) in the directory that holds ``results/``, with
the arguments after ``--`` (``--configfile``, ``--config``, targets; default target ``all``).
Each job's listing gives its rule, wildcards, input and output files and its benchmark file
(``results/benchmarks/<rule>/<wildcards>.tsv``); job B depends on job A when one of B's
inputs is one of A's outputs (exactly Snakemake's notion of a dependency). A job's time is
the ``s`` column (wall seconds) of its benchmark file's first data row; a job without a
benchmark directive or file counts 0 s and is reported. Nothing is run and nothing is
written (``--dry-run FILE`` reads a saved listing instead of calling Snakemake).

It prints the critical path job by job with each time and the running total, the path's
total, the sum of job times over the number of jobs, the bound on the wall time with
``--cores`` cores (the larger of the path and the sum over the cores), and every job over
``--limit`` seconds (flagged ``!``). It works on any job structure: a run made by another
version of the workflow (before the split of issue 41, say) is read with that version's
graph (``--snakefile`` of its checkout, whose ``src/`` is then first on the path); benchmark
files no job of the graph names are counted and reported, a sign of a mismatch.

Exit status: 0, or 1 when a job is over the limit (``--fail-over-limit``), 2 on bad input.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import re
import subprocess
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LIMIT_S = 120.0

_HEADER = re.compile(r"^(?:local)?rule (\w+):\s*$")
_FIELD = re.compile(r"^    (\w+): ?(.*)$")


@dataclass
class Job:
    """One job of the dry run's listing."""

    jobid: str
    rule: str
    wildcards: str = ""
    inputs: list[str] = field(default_factory=list)
    outputs: list[str] = field(default_factory=list)
    benchmark: str | None = None
    seconds: float | None = None

    @property
    def label(self) -> str:
        return f"{self.rule} ({self.wildcards})" if self.wildcards else self.rule


def _files(value: str) -> list[str]:
    return [f.strip() for f in value.split(", ") if f.strip()]


def parse_dry_run(text: str) -> list[Job]:
    """Every job of a ``snakemake -n`` listing (``rule <name>:`` or ``localrule <name>:``
    followed by indented ``key: value`` lines). Refuses a listing without jobs or a job
    without a ``jobid``."""
    jobs: list[Job] = []
    current: dict[str, str] | None = None
    rule = ""

    def close() -> None:
        if current is None:
            return
        if "jobid" not in current:
            raise ValueError(f"job of rule {rule} has no jobid line in the listing")
        jobs.append(
            Job(
                jobid=current["jobid"].strip(),
                rule=rule,
                wildcards=current.get("wildcards", "").strip(),
                inputs=_files(current.get("input", "")),
                outputs=_files(current.get("output", "")),
                benchmark=current.get("benchmark", "").strip() or None,
            )
        )

    for line in text.splitlines():
        m = _HEADER.match(line)
        if m:
            close()
            current, rule = {}, m.group(1)
            continue
        f = _FIELD.match(line) if current is not None else None
        if f:
            current[f.group(1)] = f.group(2)
        elif current is not None and not line.startswith("    "):
            close()
            current = None
    close()
    if not jobs:
        raise ValueError("the dry-run listing holds no job (was it made with -n -F?)")
    ids = [j.jobid for j in jobs]
    if len(set(ids)) != len(ids):
        raise ValueError("the dry-run listing names a jobid twice")
    return jobs


def dependencies(jobs: Sequence[Job]) -> dict[str, set[str]]:
    """jobid -> the jobids whose outputs it reads."""
    producer: dict[str, str] = {}
    for j in jobs:
        for out in j.outputs:
            producer[os.path.normpath(out)] = j.jobid
    return {
        j.jobid: {
            producer[os.path.normpath(i)]
            for i in j.inputs
            if os.path.normpath(i) in producer and producer[os.path.normpath(i)] != j.jobid
        }
        for j in jobs
    }


def read_seconds(path: str | os.PathLike[str]) -> float:
    """The ``s`` column of the first data row of a Snakemake benchmark file (TSV)."""
    with open(path, newline="", encoding="utf-8") as fh:
        rows = csv.DictReader(fh, delimiter="\t")
        if rows.fieldnames is None or "s" not in rows.fieldnames:
            raise ValueError(f"{path}: no column 's' (not a Snakemake benchmark file)")
        for row in rows:
            return float(row["s"])
    raise ValueError(f"{path}: no data row")


def longest_path(
    weights: Mapping[str, float], deps: Mapping[str, set[str]]
) -> tuple[float, list[str]]:
    """The heaviest chain of the DAG: ``(total weight, nodes from first to last)``, where
    ``deps[n]`` are the nodes ``n`` depends on and a chain's weight is the sum of its nodes'
    ``weights`` (missing: 0). The chain ends at a node nothing depends on; ties go to the node
    first in ``weights``' order. Refuses a cycle, naming a node on it."""
    nodes = list(dict.fromkeys([*weights, *deps, *(d for ds in deps.values() for d in ds)]))
    order = {n: i for i, n in enumerate(nodes)}

    def before(n: str) -> list[str]:
        return sorted(deps.get(n, ()), key=order.__getitem__)

    best: dict[str, float] = {}
    prev: dict[str, str | None] = {}
    on_stack: set[str] = set()
    for start in nodes:
        if start in best:
            continue
        stack = [(start, iter(before(start)))]
        on_stack.add(start)
        while stack:  # depth first, without recursion (graphs of thousands of jobs)
            node, pending = stack[-1]
            child = next(pending, None)
            if child is not None:
                if child in on_stack:
                    raise ValueError(f"the job graph has a cycle through {child}")
                if child not in best:
                    on_stack.add(child)
                    stack.append((child, iter(before(child))))
                continue
            stack.pop()
            on_stack.discard(node)
            top = max(before(node), key=best.__getitem__, default=None)
            best[node] = float(weights.get(node, 0.0)) + (best[top] if top is not None else 0.0)
            prev[node] = top
    if not nodes:
        return 0.0, []
    # the path ends at a job nothing depends on (one with the largest total always does:
    # what depends on a job weighs at least as much), so zero-second targets close it
    used = {d for ds in deps.values() for d in ds}
    end = max((n for n in nodes if n not in used), key=best.__getitem__)
    path: list[str] = []
    node: str | None = end
    while node is not None:
        path.append(node)
        node = prev[node]
    return best[end], path[::-1]


@dataclass
class Report:
    """What :func:`analyse` finds."""

    path: list[Job]
    total: float
    jobs: list[Job]
    over: list[Job]
    missing: list[Job]
    unmatched: list[str]
    limit: float
    cores: int

    @property
    def job_seconds(self) -> float:
        return sum(j.seconds or 0.0 for j in self.jobs)

    def text(self) -> str:
        flag = lambda j: "!" if (j.seconds or 0.0) > self.limit else " "  # noqa: E731
        lines = [f"critical path: {len(self.path)} jobs, {self.total:.1f} s"]
        lines.append(f"  {'s':>8} {'total s':>9}  job")
        cum = 0.0
        for j in self.path:
            cum += j.seconds or 0.0
            s = "-" if j.seconds is None else f"{j.seconds:.1f}"
            lines.append(f"{flag(j)} {s:>8} {cum:>9.1f}  {j.label}")
        timed = len(self.jobs) - len(self.missing)
        bound = max(self.total, self.job_seconds / self.cores)
        lines.append(
            f"sum of job times: {self.job_seconds:.1f} s over {len(self.jobs)} jobs "
            f"({timed} with a benchmark); on {self.cores} cores the wall time is at least "
            f"{bound:.1f} s (the larger of the path and the sum / {self.cores})"
        )
        if self.over:
            lines.append(f"jobs over {self.limit:g} s: {len(self.over)}")
            for j in sorted(self.over, key=lambda j: -(j.seconds or 0.0)):
                lines.append(f"! {j.seconds:>8.1f}  {j.label}")
        else:
            lines.append(f"jobs over {self.limit:g} s: none")
        if self.missing:
            rules = sorted({j.rule for j in self.missing})
            lines.append(
                f"no benchmark (counted 0 s): {len(self.missing)} jobs of rules {', '.join(rules)}"
            )
        if self.unmatched:
            lines.append(
                f"benchmark files no job of this graph names: {len(self.unmatched)} (e.g. "
                f"{self.unmatched[0]}): a run of another job structure? Pass the "
                "--snakefile of the workflow version that made it"
            )
        return "\n".join(lines)

    def as_dict(self) -> dict:
        row = lambda j: {"job": j.label, "rule": j.rule, "wildcards": j.wildcards,  # noqa: E731
                         "seconds": j.seconds}  # fmt: skip
        return {
            "critical_path_s": self.total,
            "critical_path": [row(j) for j in self.path],
            "job_seconds": self.job_seconds,
            "jobs": len(self.jobs),
            "jobs_without_benchmark": len(self.missing),
            "limit_s": self.limit,
            "over_limit": [row(j) for j in self.over],
            "unmatched_benchmarks": self.unmatched,
        }


def analyse(jobs: list[Job], workdir: Path, limit: float = LIMIT_S, cores: int = 2) -> Report:
    """Read every job's benchmark (relative to ``workdir``, the directory that holds
    ``results/``) and find the critical path."""
    named = set()
    for j in jobs:
        if j.benchmark is None:
            continue
        path = workdir / j.benchmark
        named.add(os.path.normpath(path))
        if path.is_file():
            j.seconds = read_seconds(path)
    total, ids = longest_path({j.jobid: j.seconds or 0.0 for j in jobs}, dependencies(jobs))
    by_id = {j.jobid: j for j in jobs}
    bench_dir = workdir / "results" / "benchmarks"
    found = sorted(bench_dir.rglob("*.tsv")) if bench_dir.is_dir() else []
    unmatched = [str(p.relative_to(workdir)) for p in found if os.path.normpath(p) not in named]
    return Report(
        path=[by_id[i] for i in ids],
        total=total,
        jobs=jobs,
        over=[j for j in jobs if (j.seconds or 0.0) > limit],
        missing=[j for j in jobs if j.seconds is None],
        unmatched=unmatched,
        limit=limit,
        cores=cores,
    )


def dry_run(workdir: Path, snakefile: Path, extra: Sequence[str]) -> str:
    """``snakemake -n -F`` of ``snakefile`` in ``workdir``: its listing (stdout and stderr)."""
    env = dict(os.environ)
    src = snakefile.resolve().parent / "src"
    if src.is_dir():  # the workflow version's own package first
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(src), env.get("PYTHONPATH")]))
    cmd = [sys.executable, "-m", "snakemake", "-s", str(snakefile), "-d", str(workdir)]
    cmd += ["-n", "-F", *extra]
    res = subprocess.run(cmd, capture_output=True, text=True, env=env, check=False)
    if res.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{(res.stdout + res.stderr)[-3000:]}")
    return res.stdout + res.stderr


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    extra: list[str] = []
    if "--" in argv:
        at = argv.index("--")
        argv, extra = argv[:at], argv[at + 1 :]
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--results", type=Path, default=Path("results"), help="the run's results/")
    ap.add_argument("--limit", type=float, default=LIMIT_S, help="flag jobs over this (s)")
    ap.add_argument("--cores", type=int, default=2, help="cores of the wall-time bound")
    ap.add_argument("--snakefile", type=Path, default=ROOT / "Snakefile")
    ap.add_argument("--dry-run", type=Path, help="a saved `snakemake -n -F` listing")
    ap.add_argument("--json", type=Path, help="also write the report as JSON here")
    ap.add_argument("--fail-over-limit", action="store_true", help="exit 1 if a job is over")
    args = ap.parse_args(argv)
    results = args.results.resolve()
    if not (results / "benchmarks").is_dir():
        print(f"{results}/benchmarks: no such directory (a finished run?)", file=sys.stderr)
        return 2
    if args.cores < 1 or args.limit <= 0:
        print("--cores must be >= 1 and --limit > 0", file=sys.stderr)
        return 2
    workdir = results.parent
    try:
        text = (
            args.dry_run.read_text(encoding="utf-8")
            if args.dry_run
            else dry_run(workdir, args.snakefile, extra)
        )
        report = analyse(parse_dry_run(text), workdir, args.limit, args.cores)
    except (OSError, RuntimeError, ValueError) as exc:
        print(f"critical_path: {exc}", file=sys.stderr)
        return 2
    print(report.text())
    if args.json:
        args.json.write_text(json.dumps(report.as_dict(), indent=1) + "\n", encoding="utf-8")
    return 1 if args.fail_over_limit and report.over else 0


if __name__ == "__main__":
    sys.exit(main())
