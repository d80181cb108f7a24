"""benchmarks/critical_path.py: the longest chain of job times through the job graph.

Oracles: hand-made DAGs whose heaviest chains are worked out by hand (a diamond, a heavy
isolated job, zero weights, ties, a cycle); a hand-written dry-run listing in Snakemake's
format with benchmark files written here, read end to end.
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _module():
    spec = importlib.util.spec_from_file_location(
        "critical_path", ROOT / "benchmarks/critical_path.py"
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules["critical_path"] = module  # dataclasses look the module up
    spec.loader.exec_module(module)
    return module


cp = _module()


def test_longest_path_on_hand_made_dags():
    # a -> b -> d and a -> c -> d: the diamond's heavier side, a + b + d = 3 + 5 + 1
    deps = {"b": {"a"}, "c": {"a"}, "d": {"b", "c"}}
    w = {"a": 3.0, "b": 5.0, "c": 2.0, "d": 1.0}
    assert cp.longest_path(w, deps) == (9.0, ["a", "b", "d"])
    # a heavier job on its own is the path
    assert cp.longest_path({**w, "e": 10.0}, deps) == (10.0, ["e"])
    # weights move the path to the other side
    assert cp.longest_path({**w, "c": 6.0}, deps) == (10.0, ["a", "c", "d"])
    # zero-weight jobs (no benchmark) still link the chain; missing weights count 0
    deps2 = {"m": {"x"}, "y": {"m"}}
    assert cp.longest_path({"x": 4.0, "y": 2.0}, deps2) == (6.0, ["x", "m", "y"])
    # a tie goes to the job listed first
    assert cp.longest_path({"p": 1.0, "q": 1.0, "r": 0.0}, {"r": {"q", "p"}})[1] == ["p", "r"]
    assert cp.longest_path({}, {}) == (0.0, [])
    with pytest.raises(ValueError, match="cycle"):
        cp.longest_path({"a": 1.0, "b": 1.0}, {"a": {"b"}, "b": {"a"}})


def test_a_long_chain_needs_no_recursion():
    n = 5000
    deps = {str(i): {str(i - 1)} for i in range(1, n)}
    total, path = cp.longest_path({str(i): 1.0 for i in range(n)}, deps)
    assert total == n and path[0] == "0" and path[-1] == str(n - 1)


LISTING = """\
Building DAG of jobs...
Job stats:
job      count
-----  -------
all          1
merge        1
sim          2
total        4

[Fri Nov 27 18:39:38 2026]
rule sim:
    output: results/chunks/0.csv
    log: results/logs/sim/0.log
    jobid: 2
    benchmark: results/benchmarks/sim/0.tsv
    reason: Forced execution
    wildcards: chunk=0
    resources: tmpdir=/tmp

[Fri Nov 27 18:39:38 2026]
rule sim:
    output: results/chunks/1.csv
    jobid: 3
    benchmark: results/benchmarks/sim/1.tsv
    wildcards: chunk=1

[Fri Nov 27 18:39:38 2026]
rule merge:
    input: results/chunks/0.csv, results/chunks/1.csv, config/config.yaml
    output: results/table.csv
    jobid: 1
    benchmark: results/benchmarks/merge.tsv

[Fri Nov 27 18:39:38 2026]
localrule all:
    input: results/table.csv
    jobid: 0
    reason: Forced execution
Job stats:
This was a dry-run (flag -n). The order of jobs does not reflect the order of execution.
"""


def _bench(path: Path, seconds: float) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f"s\th:m:s\tmax_rss\n{seconds}\t0:00:01\t12.3\n{seconds + 99}\t0:00:01\t1\n")


def test_listing_graph_and_benchmarks(tmp_path):
    jobs = cp.parse_dry_run(LISTING)
    assert [(j.jobid, j.rule, j.wildcards) for j in jobs] == [
        ("2", "sim", "chunk=0"),
        ("3", "sim", "chunk=1"),
        ("1", "merge", ""),
        ("0", "all", ""),
    ]
    assert jobs[2].inputs == ["results/chunks/0.csv", "results/chunks/1.csv", "config/config.yaml"]
    assert cp.dependencies(jobs) == {"2": set(), "3": set(), "1": {"2", "3"}, "0": {"1"}}
    _bench(tmp_path / "b.tsv", 12.5)
    assert cp.read_seconds(tmp_path / "b.tsv") == 12.5  # the first data row
    (tmp_path / "bad.tsv").write_text("x\n1\n")
    with pytest.raises(ValueError, match="no column 's'"):
        cp.read_seconds(tmp_path / "bad.tsv")
    with pytest.raises(ValueError, match="holds no job"):
        cp.parse_dry_run("Nothing to be done.\n")


def test_report_of_a_run(tmp_path, capsys):
    _bench(tmp_path / "results/benchmarks/sim/0.tsv", 30.0)
    _bench(tmp_path / "results/benchmarks/sim/1.tsv", 130.0)
    _bench(tmp_path / "results/benchmarks/merge.tsv", 2.5)
    _bench(tmp_path / "results/benchmarks/old_rule.tsv", 1.0)  # of another job structure
    listing = tmp_path / "dry.txt"
    listing.write_text(LISTING)
    out_json = tmp_path / "cp.json"
    args = ["--results", str(tmp_path / "results"), "--dry-run", str(listing)]
    assert cp.main([*args, "--json", str(out_json)]) == 0
    text = capsys.readouterr().out
    assert text.splitlines()[0] == "critical path: 3 jobs, 132.5 s"
    assert "!    130.0     130.0  sim (chunk=1)" in text
    assert "      2.5     132.5  merge" in text
    assert "sum of job times: 162.5 s over 4 jobs (3 with a benchmark)" in text
    assert "at least 132.5 s" in text  # the path, longer than 162.5 / 2
    assert (
        "jobs over 120 s: 1" in text and "no benchmark (counted 0 s): 1 jobs of rules all" in text
    )
    assert (
        "benchmark files no job of this graph names: 1 (e.g. results/benchmarks/old_rule.tsv)"
        in text
    )
    data = json.loads(out_json.read_text())
    assert data["critical_path_s"] == 132.5 and [r["job"] for r in data["over_limit"]] == [
        "sim (chunk=1)"
    ]
    assert cp.main([*args, "--fail-over-limit"]) == 1
    assert cp.main([*args, "--limit", "200", "--fail-over-limit", "--cores", "1"]) == 0
    assert "at least 162.5 s" in capsys.readouterr().out  # one core: the sum
    assert cp.main(["--results", str(tmp_path / "nowhere")]) == 2
