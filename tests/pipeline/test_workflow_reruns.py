"""End-to-end runs that start from the shared tiny run (``run_j2``, conftest.py) in a copy of
their own: ``make verify``, a killed run resumed, ``snakemake --report``, reruns after code edits
and ``make compare`` (apart from test_workflow.py, so that pytest-xdist can run them on
another worker than the tests that read the run)."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from tests.pipeline.test_workflow import CSVS, ROOT, TINY, snakemake

pytestmark = pytest.mark.workflow


def test_verify_compares_a_run_with_the_reference(run_j2, tmp_path):
    """`snakemake verify`: the run against itself passes; a flipped verdict or a reference of
    another configuration fails with a message and no traceback, and writes no result."""
    wd = tmp_path / "wd"
    shutil.copytree(run_j2, wd, symlinks=True)
    (wd / "paper").mkdir()
    ref = wd / "paper/claims.json"
    shutil.copyfile(wd / "results/paper/claims.json", ref)
    res = snakemake(wd, "-j1", "verify")
    assert res.returncode == 0, res.stderr[-3000:]
    out = (wd / "results/verify.md").read_text()
    assert out.startswith("# verify: PASS")
    n = len(json.loads(ref.read_text())["claims"])
    assert f"{n} of {n} claims agree" in out
    assert "rule report" not in res.stdout + res.stderr  # nothing but the comparison ran
    data = json.loads(ref.read_text())
    data["claims"][0]["verdict"] = next(  # a verdict any key number can carry
        v for v in ("not supported", "inconclusive") if v != data["claims"][0]["verdict"]
    )
    ref.write_text(json.dumps(data))
    res = snakemake(wd, "-j1", "verify")
    err = res.stdout + res.stderr
    assert res.returncode != 0 and "verdict flipped" in err and "disagrees" in err
    assert "Traceback" not in err and not (wd / "results/verify.md").exists()
    data["config sha256"] = "another"
    ref.write_text(json.dumps(data))
    res = snakemake(wd, "-j1", "verify")
    err = res.stdout + res.stderr
    assert res.returncode != 0 and "same configuration" in err and "Traceback" not in err


def test_killed_run_resumes_to_identical_results(run_j2, tmp_path):
    """docs/workflow.md's recovery recipe: SIGKILL mid-run (jobs in flight), --unlock, then
    --rerun-incomplete gives the same data as the uninterrupted run."""
    import os
    import signal
    import time

    from rsmhp.studies.uav.simulate import NONDETERMINISTIC_COLUMNS

    targets = ("lqg_summary", "uav_collect")
    cmd = [sys.executable, "-m", "snakemake", "-s", str(ROOT / "Snakefile"), "-d", str(tmp_path)]
    cmd += ["--configfile", str(TINY), "-j2", *targets]
    proc = subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True
    )
    deadline = time.monotonic() + 300
    while not list((tmp_path / "results").rglob("*.csv")) and time.monotonic() < deadline:
        time.sleep(0.2)  # kill as soon as the first job has finished and others run
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    assert not (tmp_path / "results/uav/runs.csv").exists()  # it really was interrupted
    assert snakemake(tmp_path, "--unlock").returncode == 0
    res = snakemake(tmp_path, "-j2", "--rerun-incomplete", *targets)
    assert res.returncode == 0, res.stderr[-3000:]
    for rel in CSVS:
        assert (tmp_path / rel).read_bytes() == (run_j2 / rel).read_bytes(), rel
    a = pd.read_csv(tmp_path / "results/uav/runs.csv").drop(columns=list(NONDETERMINISTIC_COLUMNS))
    b = pd.read_csv(run_j2 / "results/uav/runs.csv").drop(columns=list(NONDETERMINISTIC_COLUMNS))
    pd.testing.assert_frame_equal(a, b, check_exact=True)
    pd.testing.assert_frame_equal(
        pd.read_parquet(tmp_path / "results/uav/steps.parquet"),
        pd.read_parquet(run_j2 / "results/uav/steps.parquet"),
        check_exact=True,
    )


def test_snakemake_report_holds_every_figure_and_table_with_its_caption(run_j2, tmp_path):
    """`snakemake --report report.html` on the tiny run: every figure (PNG) and table of the
    pipeline is in it, each with the caption text of workflow/report/."""
    html_path = tmp_path / "report.html"
    res = snakemake(run_j2, "--report", str(html_path))
    assert res.returncode == 0, (res.stdout + res.stderr)[-3000:]
    assert "ERROR/" not in res.stdout + res.stderr  # every caption is valid reStructuredText
    html = html_path.read_text(errors="replace")
    captions = sorted((ROOT / "workflow/report").glob("*.rst"))
    figures = [p.stem for p in (run_j2 / "results/figures").glob("*.png")]
    tables = [p.stem for p in (run_j2 / "results/tables").glob("*.md")]
    assert len(figures) == 26 and len(tables) == 31
    pages = {"workflow", "summary"}  # the landing page and the summary's caption
    assert {c.stem for c in captions} - pages == set(figures) | {f"table_{t}" for t in tables}
    assert "What we found" in html  # the landing page includes results/paper/summary.html
    for name in figures:
        assert f"{name}.png" in html, name
    for name in tables:
        assert f"{name}.md" in html, name
    for cap in (c for c in captions if c.stem not in pages):  # first 4 plain words of each
        words = cap.read_text().split()  # caption (the HTML escapes others)
        plain = next(
            words[i : i + 4]
            for i in range(len(words) - 3)
            if all(re.fullmatch(r"[A-Za-z(),:;.=]+", w) for w in words[i : i + 4])
        )
        assert " ".join(plain) in html, cap.name


# ------------------------------------------------------------------ reruns after code edits

TARGET_RULES = {"all", "lqg", "estimators", "uav", "decisions"}
SIMULATIONS = {
    "lqg_convergence",
    "lqg_nbo_error",
    "estimators_ablation",
    "uav_simulate",
    "decisions_lqg",
    "decisions_uav",
    "decisions_map_cell",
}


def copy_workflow_and_run(run_j2: Path, tmp_path: Path) -> tuple[Path, Path]:
    """(wf, run): a copy of the workflow (its src/ included: the rules' `code` params are
    digests of the copy's src/, and the data files it reads at parse time) and of the
    finished tiny run, under ``tmp_path``."""
    wf, run = tmp_path / "wf", tmp_path / "run"
    wf.mkdir()
    shutil.copy2(ROOT / "Snakefile", wf / "Snakefile")
    for d in ("workflow", "config", "src", "paper/exploratory", "paper/superseded", "tests/config"):
        shutil.copytree(ROOT / d, wf / d, ignore=shutil.ignore_patterns("*.pyc", "*.egg-info"))
    shutil.copytree(run_j2, run, symlinks=True)
    return wf, run


#: what reruns a job in a copy made by copy_workflow_and_run: every trigger but the set of
#: input files, which differs for the rules that read this checkout's published files by
#: absolute path (paper/exploratory, paper/superseded under the workflow's directory: the
#: copy's, not the run's) though no content changed
COPY_TRIGGERS = ("--rerun-triggers", "mtime", "params", "software-env", "code")


def _dry_run(wf: Path, run: Path) -> tuple[set[str], set[str]]:
    """(every rule `snakemake -n` schedules, the rules among them whose reason is a params
    change), target rules aside."""
    res = snakemake(run, "-n", *COPY_TRIGGERS, snakefile=wf / "Snakefile")
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-3000:]
    if "Nothing to be done" in out:
        return set(), set()
    stats = out.split("Job stats:", 1)[1].split("\ntotal", 1)[0]
    scheduled = set(re.findall(r"^(\w+)\s+\d+$", stats, flags=re.M)) - {"job"}
    params = {
        rule
        for rule, block in re.findall(r"^(?:local)?rule (\w+):\n((?:    .*\n)*)", out, flags=re.M)
        if "reason: Params have changed" in block
    }
    return scheduled - TARGET_RULES, params


def _rule_graph(wf: Path, run: Path) -> tuple[dict[str, str], dict[str, set[str]]]:
    """(rule -> its script, rule -> the rules that use its outputs) of the workflow copy."""
    scripts = {}
    for smk in (wf / "workflow/rules").glob("*.smk"):
        for block in re.split(r"\n(?=rule )", smk.read_text()):
            m = re.match(r'rule (\w+):.*?script:\s*\n\s*"\.\./scripts/(\w+\.py)"', block, re.S)
            if m:
                scripts[m.group(1)] = m.group(2)
    res = snakemake(run, "--rulegraph", snakefile=wf / "Snakefile")
    assert res.returncode == 0, res.stderr[-3000:]
    labels = dict(re.findall(r'^\s*(\d+)\[label = "(\w+)"', res.stdout, flags=re.M))
    users: dict[str, set[str]] = {name: set() for name in labels.values()}
    for a, b in re.findall(r"^\s*(\d+) -> (\d+)", res.stdout, flags=re.M):
        users[labels[a]].add(labels[b])
    return scripts, users


def _downstream(rules: set[str], users: dict[str, set[str]]) -> set[str]:
    out, todo = set(rules), list(rules)
    while todo:
        for nxt in users.get(todo.pop(), ()):
            if nxt not in out:
                out.add(nxt)
                todo.append(nxt)
    return out


def test_code_edits_rerun_exactly_the_rules_that_import_the_code(run_j2, tmp_path):
    """Issue 18: a rule reruns when a module its script imports (transitively) changes, and
    so does everything downstream; nothing else does, and comments, formatting or a touch
    rerun nothing. On a copy of the workflow (its src/ included: the rules' `code` params are
    digests of the copy's src/) and of the finished tiny run."""
    from rsmhp.pipeline.code_digest import describe

    wf, run = copy_workflow_and_run(run_j2, tmp_path)
    assert _dry_run(wf, run) == (set(), set())  # the copy is the same code: nothing to do
    scripts, users = _rule_graph(wf, run)

    def edit(rel: str) -> tuple[set[str], set[str], set[str]]:
        """Add a harmless function to src/rsmhp/<rel>; (scheduled, params changed, the rules
        whose scripts import the module); the module restored."""
        path = wf / "src/rsmhp" / rel
        text = path.read_text()
        path.write_text(text + "\n\ndef _probe_of_a_code_edit():\n    return None\n")
        try:
            scheduled, params = _dry_run(wf, run)
        finally:
            path.write_text(text)
        module = "rsmhp." + rel.removesuffix(".py").replace("/", ".")
        importers = {
            rule
            for rule, script in scripts.items()
            if rule in users
            and module in describe(wf / "workflow/scripts" / script, wf / "src").modules
        }
        # Snakemake's reason is the changed `code` param for every importer, except those
        # it schedules already because an input is remade (downstream of another importer)
        roots = {r for r in importers if r not in _downstream(importers - {r}, users)}
        assert roots <= params <= importers, module
        assert scheduled == _downstream(importers, users) - TARGET_RULES, module
        return scheduled, params, importers

    # (a) a model module: the simulations that import it and what is made from them
    scheduled, params, _ = edit("models/uav/kinematics.py")
    assert {"uav_simulate", "decisions_uav", "decisions_map_cell"} <= params
    assert {"uav_collect", "uav_summary", "report"} <= scheduled
    lqg_side = {r for r in users if r.startswith(("lqg_", "estimators_", "decisions_lqg"))}
    assert {"lqg_convergence", "lqg_figures", "estimators_figures"} <= lqg_side
    assert not lqg_side & scheduled, lqg_side & scheduled  # the UAV code is not theirs
    # (b) an analysis module: aggregation (and what uses it) only, no simulation
    scheduled, params, _ = edit("studies/lqg/summarise.py")
    assert "lqg_summary" in params and "report" in scheduled
    assert not scheduled & SIMULATIONS and not any(r.endswith("recording") for r in scheduled)
    # (c) a figure module: figure rules only, and the report that copies the figures
    scheduled, params, _ = edit("studies/uav/figures.py")
    assert "uav_figures" in params
    assert scheduled <= {r for r in users if r.endswith("_figures")} | {"report"}
    # comments, formatting and modification times alone rerun nothing
    kinematics = wf / "src/rsmhp/models/uav/kinematics.py"
    kinematics.write_text("# a comment\n" + kinematics.read_text().replace("\n\n\n", "\n\n\n\n"))
    (wf / "src/rsmhp/models/uav/fused.py").touch()
    assert _dry_run(wf, run) == (set(), set())


def test_provenance_records_the_code_of_every_rule(run_j2):
    """results/provenance.json: per rule the digest its outputs record, which the code now
    gives, and the modules behind it; every table a rule wrote records that rule."""
    from rsmhp.pipeline.code_digest import describe, method_only, split_stamp_rule
    from rsmhp.pipeline.io import recorded_code

    code = json.loads((run_j2 / "results/provenance.json").read_text())["code"]
    rules = code["rules"]
    # a rule that runs UAV planning methods is recorded per set of families it runs
    # ("uav_simulate+nbo"): its digest counts only those families' modules
    names = {split_stamp_rule(r)[0] for r in rules}
    assert SIMULATIONS | {"lqg_summary", "estimators_summary", "uav_collect", "report"} <= names
    assert "uav_simulate+nbo" in rules and "uav_simulate" not in rules
    for rule, entry in rules.items():
        ((digest, files),) = entry["recorded"].items()  # one code version per rule
        assert entry["current"] == digest, rule
        name, families = split_stamp_rule(rule)
        now = describe(ROOT / f"workflow/scripts/{name}.py", ROOT / "src", method_only(families))
        assert digest == now.digest and entry["modules"] == list(now.modules), rule
        assert all(code["modules"][m] == d[:12] for m, d in now.modules.items())
        for f in files:
            if not f.endswith("provenance.json"):
                assert recorded_code(run_j2 / f) == f"{rule}:{digest}", f
    runs = (run_j2 / "results/uav/runs.csv").read_text().splitlines()
    assert runs[0].endswith(",plan_seconds,code")
    assert runs[1].endswith(f",uav_collect:{rules['uav_collect']['current']}")
    appendix = (run_j2 / "results/paper/appendix.md").read_text()
    assert f"lqg_convergence {rules['lqg_convergence']['current']}" in appendix


def test_compare_pairs_a_new_method_with_the_reference_and_refuses_other_scenarios(
    run_j2, tmp_path
):
    """`snakemake compare`: a method the confirmatory run did not run is run on its scenarios
    and paired with every reference configuration read from paper/reference/ (not rerun:
    no confirmatory job runs); a workflow whose scenarios differ from the reference's is
    refused before any job, naming what differs, and writes nothing."""
    wd = tmp_path / "wd"
    shutil.copytree(run_j2, wd, symlinks=True)
    shutil.copytree(wd / "results/frontier/reference", wd / "paper/reference")
    meta = json.loads((wd / "paper/reference/frontier_confirm.json").read_text())
    assert meta["scenario"]["config"]["seed"] == 7 and meta["rows"] > 0
    # the template plugin's member when it is installed (make test installs it), else a
    # built-in member the confirmatory run did not run
    from rsmhp.models.uav import methods

    new = "lhs_nt4" if "lhs" in {c.family for c in methods.families()} else "rsmhp_nt4"
    # NBO, run again through compare, is its own reference: every paired difference is 0
    res = snakemake(wd, "-j1", "compare", "--config", f"plugin_methods=[{new}, nbo]")
    assert res.returncode == 0, res.stderr[-3000:]
    stats = (res.stdout + res.stderr).split("Job stats:", 1)[1].split("\ntotal", 1)[0]
    ran = set(re.findall(r"^(\w+)\s+\d+$", stats, flags=re.M)) - {"job"}
    assert ran == {"frontier_compare_run", "frontier_compare", "compare"}, ran
    table = pd.read_csv(wd / "results/compare/paired.csv")
    reference = pd.read_parquet(wd / "paper/reference/frontier_confirm_runs.parquet")
    assert set(table["config"]) == set(reference["config"])  # NBO and every tuned member
    assert set(table["verdict"]) <= {"better", "worse", "equivalent", "inconclusive"}
    itself = table[(table["method"] == "nbo") & (table["config"] == "nbo")].iloc[0]
    assert (itself["mean_diff"], itself["low"], itself["high"]) == (0.0, 0.0, 0.0)
    assert itself["verdict"] == "equivalent"
    runs = pd.read_csv(wd / "results/compare/runs/fp150.csv")
    for method in (new, "nbo"):  # each new method on exactly the reference's runs
        mine = runs.loc[runs["config"] == method, "run"]
        assert sorted(mine) == sorted(reference.loc[reference.config == "nbo", "run"])
    report = (wd / "results/compare/report.md").read_text()
    assert f"## {new} on 'fp150'" in report and "not rerun" in report
    assert (wd / "results/compare/frontier.png").stat().st_size > 10_000
    # another seed: other scenarios, so nothing would pair: refused before any job
    before = (wd / "results/compare/paired.csv").read_bytes()
    res = snakemake(wd, "-j1", "compare", "--config", f"plugin_methods=[{new}, nbo]", "seed=8")
    assert res.returncode != 0
    assert "config seed (reference 7, this workflow 8)" in res.stderr
    assert "Traceback" not in res.stderr and "Job stats" not in res.stdout + res.stderr
    assert (wd / "results/compare/paired.csv").read_bytes() == before
    res = snakemake(wd, "-j1", "compare", "--config", "plugin_methods=[nosuch_nt4]")
    assert res.returncode != 0 and "belongs to no registered family" in res.stderr
