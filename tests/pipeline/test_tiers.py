"""The test tiers (tests/conftest.py): which commands are real workflow runs, the guard that
fails an unmarked test starting one, and the markers that select the tiers."""

from __future__ import annotations

import re
import sys
import tomllib
from pathlib import Path

import pytest

from tests import conftest

ROOT = Path(__file__).resolve().parents[2]
PY = sys.executable


@pytest.mark.parametrize(
    ("args", "kind"),
    [
        ([PY, "-m", "snakemake", "-s", "Snakefile", "-d", "wd", "-j2"], "workflow"),
        ([PY, "-m", "snakemake", "-j1", "verify"], "workflow"),
        ([PY, "-m", "snakemake", "--unlock"], None),
        ([PY, "-m", "snakemake", "-n", "--profile", "workflow/profiles/slurm"], None),
        ([PY, "-m", "snakemake", "-np", "all"], None),
        ([PY, "-m", "snakemake", "--dry-run"], None),
        ([PY, "-m", "snakemake", "--lint"], None),
        ([PY, "-m", "snakemake", "--list-rules"], None),
        ([PY, "-m", "snakemake", "--rulegraph"], None),
        ([PY, "-m", "snakemake", "--report", "report.html"], None),
        ([".venv/bin/snakemake", "-j2", "report"], "workflow"),
        ("snakemake -j2 --forceall", "workflow"),
        ([PY, ".venv/bin/snakemake", "-j1", "tune"], "workflow"),
        ([PY, "-m", "rsmhp.report.portability", "--native", "x", "--no-native-run"], "workflow"),
        ([PY, "-m", "rsmhp.report.portability", "--help"], None),
        (["bash", "scripts/slurm-local.sh", "up"], "slurm"),
        ([PY, "-m", "rsmhp.pipeline.warm", "--cores", "2"], None),
        ([PY, "-c", "import snakemake"], None),
        (["git", "rev-parse", "HEAD"], None),
        ([Path(PY), "-m", "snakemake", b"-j2"], "workflow"),
    ],
)
def test_real_runs_are_told_from_dry_runs(args, kind):
    assert conftest.real_run(args) == kind


def _fake_snakemake(tmp_path: Path) -> Path:
    """An executable named snakemake that only records that it ran."""
    fake = tmp_path / "snakemake"
    fake.write_text('#!/bin/sh\ntouch "$0.ran"\n')
    fake.chmod(0o755)
    return fake


def test_an_unmarked_test_cannot_start_a_real_run(request, tmp_path):
    """This test carries no tier marker: inside the guard a real run fails it before any
    process starts, naming the marker; a dry run starts."""
    import subprocess

    fake = _fake_snakemake(tmp_path)
    ran = tmp_path / "snakemake.ran"
    before = subprocess.Popen
    with conftest._guarded(request.node):
        with pytest.raises(pytest.fail.Exception, match=r"add @pytest.mark.workflow"):
            subprocess.run([str(fake), "-j1", "all"], check=True)
        assert not ran.exists()
        subprocess.run([str(fake), "-n", "all"], check=True)
        assert ran.exists()
    assert subprocess.Popen is before  # restored


@pytest.mark.workflow
def test_a_workflow_test_may_start_one(request, tmp_path):
    """The marker lets the run through (the fake runs instead of the workflow: no cost)."""
    import subprocess

    fake = _fake_snakemake(tmp_path)
    with conftest._guarded(request.node):
        subprocess.run([str(fake), "-j1", "all"], check=True)
    assert (tmp_path / "snakemake.ran").exists()


def test_the_tiers_name_registered_markers_and_the_fixtures_mark_their_tests(request):
    """make test-fast deselects exactly the three registered tier markers; every collected test
    that uses a workflow fixture is marked workflow, every test of a compile file compile."""
    ini = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]
    registered = {m.split(":", 1)[0] for m in ini["markers"]}
    assert "--strict-markers" in ini["addopts"].split()
    fast = re.search(r"^FAST := (.*)$", (ROOT / "Makefile").read_text(), flags=re.M).group(1)
    assert fast == "not workflow and not slurm and not compile"
    assert set(re.findall(r"not (\w+)", fast)) == {"workflow", "slurm", "compile"} <= registered
    for item in request.session.items:
        marks = {m.name for m in item.iter_markers()}
        if conftest.WORKFLOW_FIXTURES & set(getattr(item, "fixturenames", ())):
            assert "workflow" in marks, item.nodeid
        if item.nodeid.split("::")[0] in conftest.COMPILE_FILES:
            assert "compile" in marks, item.nodeid


def _make_once_in_a_process(root: str, out: str) -> None:
    """One pytest-xdist worker's share of the test below: ask for the run named "run"."""
    import subprocess
    import time

    def make(wd: Path) -> subprocess.CompletedProcess:
        with open(Path(root) / "made.log", "a") as fh:
            fh.write(f"{wd.name}\n")
        time.sleep(0.5)  # the other process asks meanwhile and waits on the lock
        (wd / "result").write_text("42")
        return subprocess.CompletedProcess([], 0, "", "made")

    done = conftest.made_once(Path(root), "run", make)
    Path(out).write_text(
        f"{done['returncode']} {done['stderr']} {(Path(root) / 'run' / 'result').read_text()}"
    )


def test_a_shared_run_is_made_once_for_every_worker(tmp_path):
    """Two processes ask for the same shared run at once: it is made once, and both get its
    outcome and read its directory (conftest.made_once, behind run_j2 and run_j1)."""
    import multiprocessing

    ctx = multiprocessing.get_context("spawn")
    outs = [tmp_path / f"out{i}" for i in range(2)]
    procs = [
        ctx.Process(target=_make_once_in_a_process, args=(str(tmp_path), str(o))) for o in outs
    ]
    for p in procs:
        p.start()
    for p in procs:
        p.join(30)
        assert p.exitcode == 0
    assert (tmp_path / "made.log").read_text() == "run\n"  # made once
    assert [o.read_text() for o in outs] == ["0 made 42"] * 2


def test_a_failed_shared_run_fails_every_asker_without_a_second_attempt(tmp_path):
    import subprocess

    calls = []

    def fail(wd: Path) -> subprocess.CompletedProcess:
        calls.append(wd)
        return subprocess.CompletedProcess([], 1, "", "x" * 5000 + "the reason")

    first = conftest.made_once(tmp_path, "run", fail)
    again = conftest.made_once(tmp_path, "run", fail)
    assert first == again and first["returncode"] == 1 and len(calls) == 1
    assert len(first["stderr"]) == 3000 and first["stderr"].endswith("the reason")
