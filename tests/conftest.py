"""Shared fixtures (the paper's LQG setting, the session's tiny workflow runs) and the test tiers.

Tiers: three markers (registered in pyproject.toml) set apart what is slow; ``make test-fast``
runs every test that carries none of them, ``make test`` (CI) runs everything.

* ``workflow``: the test runs the Snakemake workflow for real, i.e. snakemake executes jobs (a
  whole run, named targets, a rerun on a copy of a run, the portability drill), or it uses a
  session fixture that does (:data:`WORKFLOW_FIXTURES`, marked here, for every test that uses
  one). A dry run (``-n``), ``--lint``, a rule listing or graph, ``--unlock`` or ``--report``
  executes no job: a test that only does those is not ``workflow``.
* ``slurm``: the test runs on a local SLURM cluster (tests/pipeline/test_slurm_cluster.py).
* ``compile``: the test compiles numba kernels cold in a fresh process (an empty cache) or for
  an emulated CPU.

An unmarked test that starts a real workflow run (or the SLURM cluster) fails, naming the
marker it lacks (:func:`real_run`, checked around every test's set-up and call), so the fast
tier never runs one unnoticed.
"""

from __future__ import annotations

import contextlib
import os
import re
import shlex
import subprocess
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from rsmhp.models.lqg.oven import LQGModel

PAPER = {"x0": 0.0, "a": 0.5, "r": 10.0, "target": 1.0, "sigma": 1.0}
PAPER_U = np.array([0.55, 0.17])

ROOT = Path(__file__).resolve().parents[1]

# ----------------------------------------------------------------------------------- tiers

#: session fixtures that run the workflow: every test using one is marked ``workflow``
WORKFLOW_FIXTURES = frozenset({"run_j2", "run_j1"})
#: test files marked ``compile`` here (the files of the tiers' own modules carry pytestmark)
COMPILE_FILES = frozenset({"tests/models/uav/test_compile.py"})
#: snakemake options with which it executes no job
NO_JOBS = frozenset(
    {
        "-n", "--dry-run", "--dryrun", "--lint", "-l", "--list", "--list-rules",
        "--list-target-rules", "--lt", "--rulegraph", "--dag", "--filegraph", "--d3dag",
        "-S", "--summary", "-D", "--detailed-summary", "--unlock", "--report", "--version",
        "-v", "-h", "--help", "--list-changes", "--lc", "--cleanup-metadata", "--cm",
    }
)  # fmt: skip
#: the markers that allow a real run of each kind
ALLOWED = {"workflow": {"workflow", "slurm"}, "slurm": {"slurm"}}


def real_run(args) -> str | None:
    """The kind of real run the command ``args`` (as given to :class:`subprocess.Popen`)
    starts: ``"workflow"`` (snakemake executing jobs, or the portability drill), ``"slurm"``
    (scripts/slurm-local.sh, the local cluster), else None."""
    if isinstance(args, str | bytes):
        words = shlex.split(os.fsdecode(args))
    elif isinstance(args, os.PathLike):
        words = [os.fsdecode(args)]
    else:
        words = [os.fsdecode(a) for a in args]
    names = [Path(w).name for w in words]
    if "slurm-local.sh" in names:
        return "slurm"
    module = words[words.index("-m") + 1] if "-m" in words[:-1] else None
    help_only = {"-h", "--help"} & set(words)
    if module == "rsmhp.report.portability":
        return None if help_only else "workflow"
    if module != "snakemake" and "snakemake" not in names[:2]:
        return None
    if NO_JOBS & set(words) or any(re.fullmatch(r"-[a-zA-Z]*n[a-zA-Z]*", w) for w in words):
        return None  # -n, or short flags bundled with it (-np)
    return "workflow"


@contextlib.contextmanager
def _guarded(item: pytest.Item) -> Iterator[None]:
    """While ``item`` sets up or runs: starting a real run its markers do not allow fails it."""
    marks = {m.name for m in item.iter_markers()}
    original = subprocess.Popen

    class Guarded(original):  # type: ignore[misc, valid-type]
        def __init__(self, args, *a, **kw):
            kind = real_run(args)
            if kind and not ALLOWED[kind] & marks:
                one = isinstance(args, str | bytes | os.PathLike)
                command = os.fsdecode(args) if one else " ".join(map(os.fsdecode, args))
                pytest.fail(
                    f"{item.nodeid} starts a real {kind} run without its marker: add "
                    f"@pytest.mark.{kind} (tests/conftest.py, the test tiers): {command[:300]}",
                    pytrace=False,
                )
            super().__init__(args, *a, **kw)

    subprocess.Popen = Guarded
    try:
        yield
    finally:
        subprocess.Popen = original


def _start_order(item: pytest.Item) -> int:
    """When ``item`` starts (lower first, collection order within). Under pytest-xdist (make
    test: ``--dist loadfile --no-loadscope-reorder``, a test file's tests on one worker, files
    in the order of their first test here): the file of a test that makes the shared tiny run
    (:func:`shared_run`), then the SLURM run's (with a local run of its own) and those
    of slow tests that need no shared run, then the portability drill's (the shared run and
    its own emulated one), then the other files of tests that read the shared run (runs on
    copies of it), then the rest. So the longest work starts first on both workers, no worker
    waits long for the shared run, and quick tests fill the end on both. Without xdist, only
    the order changes."""
    uses = WORKFLOW_FIXTURES & set(getattr(item, "fixturenames", ()))
    marks = {m.name for m in item.iter_markers()}
    if "slurm" in marks:
        return 1
    if uses and item.name == "test_outputs_content":
        return 0
    if ("workflow" in marks or "compile" in marks) and not uses:
        return 2
    if item.name == "test_drill_on_the_tiny_config":
        return 3
    if uses:  # the other tests of the shared run, before the quick ones fill the end
        return 4
    return 5


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        if WORKFLOW_FIXTURES & set(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.workflow)
        if item.path.is_relative_to(ROOT) and (
            item.path.relative_to(ROOT).as_posix() in COMPILE_FILES
        ):
            item.add_marker(pytest.mark.compile)
    items.sort(key=_start_order)  # stable: collection order within each start


@pytest.hookimpl(wrapper=True)
def pytest_runtest_setup(item: pytest.Item):
    with _guarded(item):
        return (yield)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item: pytest.Item):
    with _guarded(item):
        return (yield)


# -------------------------------------------------------------------------------- fixtures


@pytest.fixture
def paper_params() -> LQGModel:
    return LQGModel(**PAPER)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


def shared_run(request: pytest.FixtureRequest, name: str, *args: str) -> Path:
    """A tiny-config workflow run (``snakemake *args``) made once per test session, in a
    directory named ``name``: with pytest-xdist, the first worker to ask runs it (the others
    wait on a file lock, then read it) in the session's shared temporary directory, so every
    worker's tests read the same run. Its tests only read it or run commands that execute no
    job there (a dry run, a refused config, ``--report``)."""
    from tests.pipeline.test_workflow import snakemake

    factory = request.getfixturevalue("tmp_path_factory")
    if not hasattr(request.config, "workerinput"):  # one process: no one to share with
        wd = factory.mktemp(name)
        res = snakemake(wd, *args)
        assert res.returncode == 0, res.stderr[-3000:]
        return wd
    root = factory.getbasetemp().parent  # one per session, shared by its workers
    done = made_once(root, name, lambda wd: snakemake(wd, *args))
    assert done["returncode"] == 0, done["stderr"]
    return root / name


def made_once(root: Path, name: str, make) -> dict:
    """``make(root / name)`` (a :class:`subprocess.CompletedProcess`) run by the first process
    that asks, under an exclusive lock on ``root/<name>.lock``; every process, that one
    included, gets its outcome from ``root/<name>.json``: ``{"returncode", "stderr"}`` (the
    last 3000 characters)."""
    import fcntl
    import json

    status = root / f"{name}.json"
    with open(root / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
        if not status.exists():
            (root / name).mkdir()
            res = make(root / name)
            done = {"returncode": res.returncode, "stderr": res.stderr[-3000:]}
            status.write_text(json.dumps(done))
        return json.loads(status.read_text())


@pytest.fixture(scope="session")
def run_j2(request) -> Path:
    """The whole workflow (LQG, UAV, report) on the tiny config with -j2, run once per session
    (:func:`shared_run`)."""
    return shared_run(request, "wf_j2", "-j2")


#: the targets of the session's -j1 run: the tables the -j1 comparisons read (not the studies'
#: figures and recordings: no worker count reaches those but through these tables)
J1_TARGETS = (
    "results/lqg/summary.csv",
    "results/lqg/nbo_error_summary.csv",
    "results/estimators/summary.csv",
    "results/decisions/lqg_regret.csv",
    "uav_collect",
)


@pytest.fixture(scope="session")
def run_j1(request) -> Path:
    """The tiny config's LQG, estimator, LQG-decision and UAV simulations with -j1 (one worker),
    from an empty directory, once per session: compared with ``run_j2``."""
    return shared_run(request, "wf_j1", "-j1", *J1_TARGETS)


@pytest.fixture(scope="session")
def tiny_dry_run(tmp_path_factory) -> str:
    """``snakemake -n`` of the tiny config's default target from an empty directory (its
    output), through the SLURM profile (workflow/profiles/slurm: the same jobs, with the
    cluster's threads and resources) when its executor plugin is installed, as the dev extra
    does: the job layout and resources the dry-run tests check (no job runs)."""
    import importlib.util

    from tests.pipeline.test_workflow import ROOT, snakemake

    profile = ["--profile", str(ROOT / "workflow/profiles/slurm")]
    if importlib.util.find_spec("snakemake_executor_plugin_slurm") is None:
        profile = []
    res = snakemake(tmp_path_factory.mktemp("dry"), "-n", *profile)
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-3000:]
    return out


@pytest.fixture(scope="session")
def tiny() -> dict:
    """The tiny workflow config (tests/config/tiny.yaml) as a dict."""
    import yaml

    from tests.pipeline.test_workflow import TINY

    return yaml.safe_load(TINY.read_text())
