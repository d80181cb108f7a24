"""Reruns at the right grain, on a copy of the workflow and of the finished tiny run:

* a palette edit (colours and labels are presentation) reruns figures, tables and the report,
  never a simulation: the UAV method modules do not import the palette;
* adding a planning-method module (the worked example of docs/methods.md) and listing it in
  ``uav.methods`` schedules the new method's simulation jobs and no other simulation: each
  simulation rule's code digest counts the method registry, its base and the families the job
  runs (``rsmhp.pipeline.code_digest.method_only``), not every family module.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from tests.pipeline.test_workflow import ROOT, TINY
from tests.pipeline.test_workflow_reruns import COPY_TRIGGERS, copy_workflow_and_run

#: reads (a copy of) the session's tiny run; its own snakemake calls are dry runs
pytestmark = pytest.mark.workflow

# every rule that simulates or times planners (what a presentation edit must never rerun)
SIMULATIONS = {
    "lqg_convergence",
    "lqg_nbo_error",
    "lqg_linear_cost",
    "estimators_ablation",
    "uav_simulate",
    "decisions_lqg",
    "decisions_uav",
    "decisions_map_cell",
    "frontier_explore",
    "frontier_explore_timing",
    "frontier_tune",
    "frontier_tune_timing",
    "frontier_confirm",
    "frontier_confirm_timing",
    "horizon_uav",
    "horizon_uav_closed",
    "horizon_lqg_estimators",
    "horizon_lqg_regret",
    "horizon_optimiser",
}


def _jobs(wf: Path, run: Path, *configfiles: Path) -> list[tuple[str, str]]:
    """(rule, wildcards) of every job ``snakemake -n`` schedules, with the copy's src/ first
    on the path (its registry parses the config)."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(wf / "src"), str(ROOT)])}
    cmd = [sys.executable, "-m", "snakemake", "-s", str(wf / "Snakefile"), "-d", str(run)]
    cmd += ["-n", *COPY_TRIGGERS, "--configfile", str(TINY), *map(str, configfiles)]
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=env)
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-3000:]
    jobs = []
    for rule, block in re.findall(r"^(?:local)?rule (\w+):\n((?:    .*\n)*)", out, flags=re.M):
        wildcards = re.search(r"^    wildcards: (.*)$", block, flags=re.M)
        jobs.append((rule, wildcards.group(1) if wildcards else ""))
    return jobs


def _worked_example() -> str:
    """The code block between the ``example:method`` markers (docs or README)."""
    for path in [*sorted((ROOT / "docs").glob("*.md")), ROOT / "README.md"]:
        if not path.is_file():
            continue
        m = re.search(
            r"<!-- example:method:begin -->\s*```python\n(.*?)```\s*<!-- example:method:end -->",
            path.read_text(encoding="utf-8"),
            re.S,
        )
        if m:
            return m.group(1)
    raise AssertionError("the example:method block is missing from docs/ and README.md")


def test_presentation_and_new_methods_rerun_no_other_simulation(run_j2, tmp_path):
    wf, run = copy_workflow_and_run(run_j2, tmp_path)
    assert _jobs(wf, run) == []  # the copy is the same code: nothing to do

    # (a) a palette edit: figures, tables and the report; no simulation
    palette = wf / "src/rsmhp/report/palette.py"
    text = palette.read_text()
    palette.write_text(text.replace('"nbo": _CB[3],', '"nbo": "#123456",', 1))
    assert palette.read_text() != text
    jobs = _jobs(wf, run)
    rules = {r for r, _ in jobs}
    assert not rules & SIMULATIONS, rules & SIMULATIONS
    assert {"uav_figures", "report"} <= rules, rules
    palette.write_text(text)

    # (b) a new family module, listed in uav.methods: only its own simulation jobs
    module = wf / "src/rsmhp/models/uav/methods/mix.py"
    module.write_text(_worked_example())
    overlay = tmp_path / "mix.yaml"
    overlay.write_text("uav:\n  methods:\n    mix_nt: [4]\n")
    jobs = _jobs(wf, run, overlay)
    simulated = [(r, w) for r, w in jobs if r in SIMULATIONS]
    assert simulated, jobs
    assert {r for r, _ in simulated} == {"uav_simulate"}, simulated
    assert all("method=mix_nt4" in w for _, w in simulated), simulated
    # the module alone, not listed in the config: nothing that simulates reruns
    assert not {r for r, _ in _jobs(wf, run)} & SIMULATIONS
