"""End-to-end runs of the Snakemake workflow on tests/config/tiny.yaml in temporary directories.

The full tiny run (``run_j2``) and the -j1 run of the simulations it is compared with
(``run_j1``), each made once per session and shared with every test that reads them, are in
conftest.py; the dry runs are in test_dry_runs.py (no job runs there: the fast tier).
"""

from __future__ import annotations

import hashlib
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from rerun.chunk import RrdReader

from rsmhp.models.lqg import oven as lqg

ROOT = Path(__file__).resolve().parents[2]
TINY = ROOT / "tests" / "config" / "tiny.yaml"
pytestmark = pytest.mark.workflow

CSVS = [
    "results/lqg/convergence.csv",
    "results/lqg/nbo_error.csv",
    "results/lqg/summary.csv",
    "results/lqg/nbo_error_summary.csv",
]


def snakemake(
    workdir: Path,
    *args: str,
    configfiles: tuple[Path, ...] = (TINY,),
    snakefile: Path = ROOT / "Snakefile",
) -> subprocess.CompletedProcess:
    cmd = [
        sys.executable,
        "-m",
        "snakemake",
        "-s",
        str(snakefile),
        "-d",
        str(workdir),
        "--configfile",
        *map(str, configfiles),
        *args,
    ]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=600)


def digest(workdir: Path) -> dict[str, str]:
    files = [p for p in sorted((workdir / "results").rglob("*")) if p.is_file()]
    return {str(p.relative_to(workdir)): hashlib.sha256(p.read_bytes()).hexdigest() for p in files}


def test_outputs_content(run_j2, tiny):
    conv = pd.read_csv(run_j2 / "results/lqg/convergence.csv")
    grid = tiny["lqg"]["convergence"]["P"]
    ps = list(range(grid["start"], grid["stop"] + 1, grid["step"]))
    reps = tiny["lqg"]["convergence"]["replicates"]
    assert len(conv) == len(ps) * reps
    for col in (
        "a",
        "H",
        "sigma",
        "r",
        "target",
        "x0",
        "P",
        "replicate",
        "J_mhp",
        "J_nbo",
        "J_exact",
    ):
        assert col in conv.columns
    u = [0.55, 0.17]  # default u (not overridden by the tiny config)
    kw = {"x0": 0.0, "a": 0.5, "r": 10.0, "target": 1.0, "sigma": 1.0}
    assert np.allclose(conv["J_exact"], lqg.exact_cost(u, **kw))
    summary = pd.read_csv(run_j2 / "results/lqg/summary.csv")
    assert summary["P"].tolist() == ps
    assert (summary["n_replicates"] == reps).all()
    for P, grp in conv.groupby("P"):
        row = summary[summary["P"] == P].iloc[0]
        assert row["mean"] == pytest.approx(grp["J_mhp"].mean())
        assert row["rmse"] == pytest.approx(np.sqrt(np.mean((grp["J_mhp"] - grp["J_exact"]) ** 2)))
        for eps in tiny["lqg"]["convergence"]["chebyshev_eps"]:
            freq = np.mean(np.abs(grp["J_mhp"] - grp["J_exact"]) >= eps)
            assert row[f"exceed_eps{eps:g}"] == pytest.approx(freq)
    nbo = pd.read_csv(run_j2 / "results/lqg/nbo_error_summary.csv")
    assert len(nbo) == 4
    for _, row in nbo.iterrows():
        assert row["nbo_error_closed"] == pytest.approx(
            lqg.nbo_error(int(row["H"]), a=row["a"], r=10.0, sigma=1.0)
        )
    for name in ("lqg_convergence", "lqg_nbo_error", "lqg_chebyshev"):
        text = (run_j2 / f"results/tables/{name}.md").read_text()
        assert text.startswith("|") and text.count("\n") >= 3
    for name in ("lqg_convergence", "lqg_error_loglog", "lqg_nbo_error"):
        png = (run_j2 / f"results/figures/{name}.png").read_bytes()
        assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000
        assert (run_j2 / f"results/figures/{name}.pdf").read_bytes()[:5] == b"%PDF-"
        assert (run_j2 / f"results/paper/figures/{name}.png").read_bytes() == png
    for rule in ("lqg_convergence", "lqg_nbo_error", "lqg_summary", "lqg_figures", "report"):
        assert (run_j2 / f"results/benchmarks/{rule}.tsv").exists()
        assert "done in" in (run_j2 / f"results/logs/{rule}.log").read_text()


def test_recording_and_report(run_j2, tiny):
    rec = tiny["lqg"]["recording"]
    counts: dict[str, int] = {}
    for chunk in RrdReader(run_j2 / "results/recordings/lqg_tree.rrd").store().stream():
        counts[chunk.entity_path] = counts.get(chunk.entity_path, 0) + chunk.num_rows
    for k in range(1, len(rec["u"]) + 1):
        assert f"/tree/level_{k}/kept" in counts
    report = (run_j2 / "results/paper/replication.md").read_text()
    appendix = (run_j2 / "results/paper/appendix.md").read_text()
    claims = json.loads((run_j2 / "results/paper/claims.json").read_text())
    by_id = {c["id"]: c for c in claims["claims"]}
    for cid in ("LQG-1", "LQG-2", "LQG-3", "LQG-4"):
        assert f"| {cid} |" in appendix and f"### {cid}\n\n- Verdict: **" in appendix
        assert by_id[cid]["key"]["reproducible"] == "bitwise"
    # the one page: findings, statements, main claims; the checks counted apart
    assert report.index("## What we found") < report.index("## The paper's statements")
    assert len(report.encode()) <= 25_000
    checks = [cid for cid, c in by_id.items() if c.get("check")]
    assert {"LQG-1", "LQG-3", "LIN-1"} <= set(checks)
    assert f"{len(checks)} checks of our simulation" in appendix
    # the glance table: the paper's statements, then the benchmark's own main claims
    glance = (run_j2 / "results/paper/glance.md").read_text()
    statements = [st["id"] for st in claims["statements"]]
    first = glance.split("\n\n")[0]
    assert [line.split(" | ")[0][2:] for line in first.splitlines()[2:]] == statements
    # the HTML report's landing page: the same findings
    summary = (run_j2 / "results/paper/summary.html").read_text()
    assert "<h2>What we found</h2>" in summary and summary.count("<li>") <= 7
    # every claim of the paper is evidence of exactly the statements that list it
    counted = {cid for st in claims["statements"] for cid in st["counted"] + st["alongside"]}
    assert {cid for cid, c in by_id.items() if c["part"] == "paper"} <= counted
    assert all(c["setup"] for c in by_id.values())
    assert "seed: 7" in appendix  # the tiny config's seed, i.e. the parameters actually used
    prov = json.loads((run_j2 / "results/provenance.json").read_text())
    assert {"commit", "config sha256", "blas", "cpu", "host", "date (UTC)"} <= prov.keys()
    assert claims["config sha256"] == prov["config sha256"] and claims["commit"] == prov["commit"]
    assert f"config sha256 `{prov['config sha256']}`" in report
    assert f"- config sha256: `{prov['config sha256']}`" in appendix and "- host:" not in appendix
    for link in ("figures/lqg_convergence.png", "figures/lqg_error_loglog.png"):
        assert f"]({link})" in appendix and (run_j2 / "results/paper" / link).exists()
    for text in (report, appendix):
        assert not re.search(r"\b(nan|inf)\b", text, flags=re.IGNORECASE)


def test_j1_and_j2_give_identical_results(run_j2, run_j1):
    """The LQG and estimator studies' tables with one worker (``run_j1``, conftest.J1_TARGETS)
    are the -j2 run's."""
    for rel in CSVS:
        assert (run_j1 / rel).read_bytes() == (run_j2 / rel).read_bytes(), rel
    # the ablation's CPU times are measurements; every other column is identical
    for rel, timing in (
        ("results/estimators/ablation.csv", "cpu_seconds"),
        ("results/estimators/summary.csv", "cpu_median"),
    ):
        a = pd.read_csv(run_j1 / rel).drop(columns=timing)
        b = pd.read_csv(run_j2 / rel).drop(columns=timing)
        assert a.to_csv(index=False) == b.to_csv(index=False), rel
    assert not (run_j1 / "results/paper").exists()  # named targets do not build the report


def test_estimator_study_outputs(run_j2, tiny):
    est = tiny["estimators"]
    ablation = pd.read_csv(run_j2 / "results/estimators/ablation.csv")
    summary = pd.read_csv(run_j2 / "results/estimators/summary.csv")
    assert set(ablation["problem"]) == {p["name"] for p in est["problems"]}
    mc = ablation[(ablation["scheme"] == "mc") & (ablation["weighting"] == "uniform")]
    assert len(mc) == len(est["problems"]) * len(est["budgets"]) * est["replicates"]
    trees = ablation[ablation["scheme"] == "tree"]
    assert (trees["n_trajectories"] <= est["max_leaves"]).all()
    for _, row in summary.iterrows():
        raw = ablation[
            (ablation["problem"] == row["problem"])
            & (ablation["scheme"] == row["scheme"])
            & (ablation["weighting"] == row["weighting"])
            & (ablation["N"] == row["N"])
            & (ablation["M"] == row["M"])
            & (ablation["n_trajectories"] == row["n_trajectories"])
        ]
        assert len(raw) == row["n_replicates"]
        assert row["mean"] == pytest.approx(raw["estimate"].mean())
    for name in (
        "estimators_rmse_vs_n",
        "estimators_bias_vs_n",
        "estimators_tree_variance",
        "estimators_weighted_vs_uniform",
        "estimators_pruning_heatmap",
        "estimators_frontier",
    ):
        assert (run_j2 / f"results/figures/{name}.png").read_bytes()[:4] == b"\x89PNG"
        assert (run_j2 / f"results/paper/figures/{name}.png").exists()
    report = (run_j2 / "results/paper/appendix.md").read_text()  # sections and ledger
    for cid in ("EST-1", "EST-2", "EST-3", "EST-4"):
        assert f"| {cid} |" in report
    # sections in report order: LQG (10) before the estimator study (15)
    assert report.index(". Case study 1") < report.index(". Estimator study")
    rec = est["recording"]
    counts: dict[str, int] = {}
    for chunk in RrdReader(run_j2 / "results/recordings/estimators_tree.rrd").store().stream():
        counts[chunk.entity_path] = counts.get(chunk.entity_path, 0) + chunk.num_rows
    assert counts["/pruning"] == len(rec["u"])
    assert all(f"/tree/level_{k}/nodes" in counts for k in range(1, len(rec["u"]) + 1))


def test_up_to_date_and_figure_change_reruns_no_simulation(run_j2, tmp_path, tiny):
    res = snakemake(run_j2, "-j1", "-n")
    assert res.returncode == 0 and "Nothing to be done" in res.stdout + res.stderr
    changed = yaml.safe_load(TINY.read_text())
    changed["lqg"]["convergence"]["chebyshev_eps"] = [0.5, 3.0]
    cfg = tmp_path / "eps.yaml"
    cfg.write_text(yaml.safe_dump(changed))
    res = snakemake(run_j2, "-j1", "-n", configfiles=(cfg,))
    out = res.stdout + res.stderr
    assert res.returncode == 0, out
    assert "lqg_summary" in out and "lqg_figures" in out
    assert "rule lqg_convergence" not in out and "rule lqg_nbo_error" not in out


@pytest.mark.parametrize(
    ("override", "field"),
    [
        ({"lqg": {"model": {"sigma": -1.0}}}, "lqg.model.sigma"),
        ({"lqg": {"model": {"a": 1.3}}}, "lqg.model.a"),
        ({"lqg": {"model": {"bogus_key": 1}}}, "lqg.model.bogus_key"),
        ({"lqg": {"recording": {"N": 2, "M": 5}}}, "lqg.recording.M"),
        ({"estimators": {"recording": {"N": 2, "M": 3}}}, "estimators.recording.M"),
        ({"estimators": {"budgets": [16, 48]}}, "estimators.budgets"),
        ({"uav": {"target": {"q": float("nan")}}}, "uav.target.q"),
        ({"seed": 7.0}, "seed"),
    ],
)
def test_invalid_config_fails_before_any_job(run_j2, tmp_path, override, field):
    before = digest(run_j2)
    cfg = tmp_path / "bad.yaml"
    cfg.write_text(yaml.safe_dump(override))
    res = snakemake(run_j2, "-j2", "--forceall", configfiles=(TINY, cfg))
    out = res.stdout + res.stderr
    assert res.returncode != 0
    assert field in out and "invalid configuration" in out
    assert "Select jobs to execute" not in out and "rule lqg_" not in out
    assert "Traceback" not in out and 'File "' not in out  # the message alone
    assert digest(run_j2) == before


def test_nested_command_line_override_is_applied(run_j2):
    """docs/workflow.md's override syntax: a nested YAML value after --config, typed like the
    file."""
    res = snakemake(run_j2, "-n", "--config", "lqg={model: {a: 0.3}}")
    out = res.stdout + res.stderr
    assert res.returncode == 0, out[-2000:]
    assert "rule lqg_convergence" in out and "rule uav_simulate" not in out  # params changed
    res = snakemake(run_j2, "-n", "--config", "lqg={model: {a: 1.3}}")
    out = res.stdout + res.stderr
    assert res.returncode != 0 and "lqg.model.a: 1.3" in out and "rule lqg_" not in out


def test_config_beyond_a_rules_memory_is_refused_before_any_job(run_j2, tmp_path):
    before = digest(run_j2)
    big = tmp_path / "big.yaml"
    big.write_text("lqg:\n  nbo_error: {P: 10000000, H_values: [200]}\n")
    res = snakemake(run_j2, "-j2", configfiles=(TINY, big))
    out = res.stdout + res.stderr
    assert res.returncode != 0
    assert "lqg_nbo_error: needs about" in out and "lqg.nbo_error.P" in out
    assert "Traceback" not in out and 'File "' not in out
    assert "Select jobs to execute" not in out and digest(run_j2) == before
    # a machine with the memory: raise the rule's mem_mb and the plan goes through
    res = snakemake(
        run_j2, "-n", "--set-resources", "lqg_nbo_error:mem_mb=300000", configfiles=(TINY, big)
    )
    assert res.returncode == 0 and "rule lqg_nbo_error" in res.stdout + res.stderr


def test_decision_study_outputs(run_j2, run_j1, tiny):
    cfg = tiny["decisions"]["lqg"]
    df = pd.read_csv(run_j2 / "results/decisions/lqg_regret.csv")
    assert set(df["a"]) == set(cfg["a_values"]) and set(df["H"]) == set(cfg["H_values"])
    mc = df[(df.method == "mc") & (df.weighting == "uniform")]
    assert (
        len(mc) == len(cfg["a_values"]) * len(cfg["H_values"]) * len(cfg["P"]) * cfg["replicates"]
    )
    assert (df["regret"] >= 0).all()
    assert df.loc[df.method == "nbo", "regret"].max() < 1e-12
    report = (run_j2 / "results/paper/appendix.md").read_text()  # sections and ledger
    for cid in ("DEC-1", "DEC-2", "DEC-3"):
        assert f"| {cid} |" in report
    assert "](figures/decisions_lqg_regret.png)" in report
    assert (run_j2 / "results/paper/figures/decisions_lqg_regret.png").exists()
    # one worker gives the same file (seeds keyed on the cell and replicate, not the worker;
    # run_j1 made it with -j1 as a named target)
    assert (run_j1 / "results/decisions/lqg_regret.csv").read_bytes() == (
        run_j2 / "results/decisions/lqg_regret.csv"
    ).read_bytes()


def test_frontier_outputs(run_j2, tiny):
    """The equal-compute study runs in the default target: one job per model, every method's
    paired runs with its planning time, the summary and the figure."""
    cfg = tiny["frontier"]
    names = ["nbo", "rsmhp_nt8", "rqmc_nt8", "sigma", "dpw_s20"]
    for model in cfg["models"]:
        runs = pd.read_csv(run_j2 / f"results/frontier/explore/{model}.csv")
        assert list(dict.fromkeys(runs["method"])) == names
        assert len(runs) == len(names) * cfg["runs"] and (runs["plan_ms"] > 0).all()
        assert (run_j2 / f"results/benchmarks/frontier_explore/{model}.tsv").exists()
    summary = pd.read_csv(run_j2 / "results/frontier/explore_summary.csv")
    assert len(summary) == len(names) * len(cfg["models"])
    assert (summary.loc[summary["method"] == "nbo", "error_diff"] == 0).all()
    png = (run_j2 / "results/figures/frontier_exploratory.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    # in the report: section, claims FR-1..3 per model, figure, both tables
    report = (run_j2 / "results/paper/appendix.md").read_text()  # sections and ledger
    assert report.index(". Decision quality: UAV") < report.index(". Planners at equal compute")
    for model in cfg["models"]:
        for k in (1, 2, 3):
            assert f"| FR-{k}-{model} |" in report
    assert (run_j2 / "results/paper/figures/frontier_exploratory.png").exists()
    appendix = (run_j2 / "results/paper/appendix.md").read_text()
    for table in ("frontier_exploratory", "frontier_budget"):
        text = (run_j2 / f"results/tables/{table}.md").read_text()
        assert text.strip() and text.strip() in appendix
    # the exploratory design (tiny: exploratory: true) has its section, never claims
    assert ". Planners at equal compute: the exploratory design" in report


def test_confirm_outputs(run_j2, tiny):
    """The protocol's confirmatory run in the default target: the preregistered
    configurations' closed-loop runs on the confirm stream and their interleaved timing, the
    summary and ladder, claims FR-1..3 judged under the preregistration (its sha256 in each
    rule and in claims.json), the figure and tables, the 76a0c01 exploratory claims kept."""
    from rsmhp.pipeline.protocol import (
        Preregistration,
        file_sha256,
        stream_seed,
        tuned_configurations,
    )

    cfg = tiny["frontier"]["confirm"]
    pre = Preregistration.load(ROOT / cfg["preregistration"], ROOT / cfg["tuned"])
    tuned = yaml.safe_load((ROOT / cfg["tuned"]).read_text())
    for model in pre.doc["models"]:
        runs = pd.read_csv(run_j2 / f"results/frontier/confirm/{model}.csv")
        want = {c.name for c in pre.configurations(tuned, model)}
        assert set(runs["config"]) == want and len(runs) == len(want) * pre.runs(model)
        timing = pd.read_csv(run_j2 / f"results/frontier/confirm/timing/{model}.csv")
        assert set(timing["config"]) == want and (timing["ms"] > 0).all()
        # the confirm stream: NBO's runs are not the exploratory frontier's (another seed)
        explo = pd.read_csv(run_j2 / f"results/frontier/explore/{model}.csv")
        nbo_c = runs[runs["config"] == "nbo"].set_index("run")["mean_error"]
        nbo_e = explo[explo["method"] == "nbo"].set_index("run")["mean_error"]
        common = nbo_c.index.intersection(nbo_e.index)
        assert len(common) and (nbo_c[common] != nbo_e[common]).all()
        assert stream_seed(tiny["seed"], "confirm") != tiny["seed"]
        per = tuned_configurations(tuned, model)
        lad = pd.read_csv(run_j2 / "results/frontier/confirm_ladder.csv")
        assert len(lad[lad["model"] == model]) == sum(
            len(per.get(f"{float(b):g}", {})) for b in pre.doc["budgets_ms"]
        )
    data = json.loads((run_j2 / "results/paper/claims.json").read_text())
    sha = file_sha256(ROOT / cfg["preregistration"])
    assert data["preregistration"]["sha256"] == sha
    fr = [c for c in data["claims"] if c["id"].startswith("FR-")]
    assert fr and all(f"sha256 {sha[:12]}" in c["rule"] for c in fr)
    assert all(c["key"]["p_value"] is not None and c["key"]["p_holm"] is not None for c in fr)
    report = (run_j2 / "results/paper/appendix.md").read_text()  # sections and ledger
    assert ". Planners at equal compute (confirmatory)" in report
    assert "](figures/frontier_confirm.png)" in report
    appendix = (run_j2 / "results/paper/appendix.md").read_text()
    assert "76a0c01" in appendix
    for table in ("frontier_confirm", "frontier_confirm_ladder", "frontier_confirm_tuning"):
        assert (run_j2 / f"results/tables/{table}.md").read_text().strip() in appendix


def test_horizon_outputs(run_j2, tiny):
    """The UAV horizon study: one job per (model, H) with every method's cost-approximation
    rows (none for the tree search) and regret rows, the summaries, claims HZ-1/HZ-2 per
    model in the report, figures and tables."""
    cfg = tiny["horizon"]["uav"]
    for model in cfg["models"]:
        for H in cfg["H"]:
            a = pd.read_csv(run_j2 / f"results/horizon/uav/{model}_H{H}_approx.csv")
            r = pd.read_csv(run_j2 / f"results/horizon/uav/{model}_H{H}_regret.csv")
            assert set(a["H"]) == set(r["H"]) == {H}
            assert "dpw_s20" in set(r["method"]) and "dpw_s20" not in set(a["method"])
            assert (r["plan_ms"] > 0).all()
    summary = pd.read_csv(run_j2 / "results/horizon/uav_approx_summary.csv")
    assert set(summary["H"]) == set(cfg["H"]) and (summary["rel_rmse"] >= 0).all()
    report = (run_j2 / "results/paper/appendix.md").read_text()  # sections and ledger
    assert report.index(". Planners at equal compute") < report.index(". Long horizons")
    for model in cfg["models"]:
        for cid in (f"HZ-1-{model}", f"HZ-2-{model}", f"HZ-3-{model}"):
            assert f"| {cid} |" in report
    for name in ("horizon_uav_error", "horizon_uav_time", "horizon_uav_closed"):
        assert (run_j2 / f"results/paper/figures/{name}.png").read_bytes()[:4] == b"\x89PNG"
    appendix = (run_j2 / "results/paper/appendix.md").read_text()
    for table in ("horizon_uav_approx", "horizon_uav_regret", "horizon_uav_closed", "horizon_lqg",
                  "horizon_lqg_estimators", "horizon_lqg_regret"):  # fmt: skip
        assert (run_j2 / f"results/tables/{table}.md").read_text().strip() in appendix
    # the N_T ∝ H member has 2 H hypotheses at every H (tiny: rsmhp_nt_per_step [2])
    assert "rsmhp_nt2h" in set(summary["method"])
    appendix = (run_j2 / "results/paper/appendix.md").read_text()
    assert "Runs needed (closed loop; table horizon_uav_closed" in appendix


def test_scenarios_outputs(run_j2, tiny):
    """The summary across scenarios: one row per (map cell or model and H, method) with its
    paired runs, the per-group summary, its section after the long-horizon ones, the figure
    and tables."""
    per = pd.read_csv(run_j2 / "results/scenarios/per_scenario.csv")
    cells = len(tiny["decisions"]["map"]["rows"]["values"]) * len(
        tiny["decisions"]["map"]["cols"]["values"]
    )
    hz = len(tiny["horizon"]["uav"]["models"]) * len(tiny["horizon"]["uav"]["H"])
    assert per["scenario"].nunique() == cells + hz
    assert "nbo" not in set(per["method"]) and per["p_improve"].between(0, 1).all()
    summary = pd.read_csv(run_j2 / "results/scenarios/summary.csv")
    assert (summary["low"] <= summary["p_improve"]).all()
    report = (run_j2 / "results/paper/appendix.md").read_text()  # sections and ledger
    assert report.index(". Optimiser error apart") < report.index(". Across scenarios")
    assert "](figures/scenarios_improvement.png)" in report
    assert (run_j2 / "results/paper/figures/scenarios_improvement.png").read_bytes()[
        :4
    ] == b"\x89PNG"
    appendix = (run_j2 / "results/paper/appendix.md").read_text()
    for table in ("scenarios_improvement", "scenarios_per_scenario"):
        assert (run_j2 / f"results/tables/{table}.md").read_text().strip() in appendix


def test_horizon_lqg_outputs(run_j2, tiny):
    """Oven LQG at long horizons: estimator and regret rows, their summaries, HZ-4/HZ-5 in the
    report with their rules, the figure."""
    cfg = tiny["horizon"]["lqg"]
    est = pd.read_csv(run_j2 / "results/horizon/lqg_estimators.csv")
    assert set(est["H"]) == set(cfg["sim_H"]) and set(est["scheme"]) == {
        "nbo", "cubature", "mc", "sobol", "pruned"}  # fmt: skip
    pruned = est[est["scheme"] == "pruned"]
    assert (pruned["N"] ** pruned["H"] > pruned["M"]).all()
    reg = pd.read_csv(run_j2 / "results/horizon/lqg_regret_summary.csv")
    assert set(reg["H"]) == set(cfg["sim_H"]) and reg["limit"].notna().any()
    report = (run_j2 / "results/paper/appendix.md").read_text()  # sections and ledger
    for cid in ("HZ-4", "HZ-5"):
        assert f"| {cid} |" in report
    assert (run_j2 / "results/paper/figures/horizon_lqg.png").read_bytes()[:4] == b"\x89PNG"


def test_horizon_recording_replays_the_run_its_rule_chooses(run_j2, tiny):
    """horizon.uav.recording: one member per family at the configured H, in the run chosen by
    `select` from the closed-loop runs (claims.monte_carlo − NBO), each with its map and
    hypotheses (the tree search has none); the replay equals the closed-loop rows."""
    from rsmhp.studies.frontier.summarise import select_run

    hz = tiny["horizon"]["uav"]
    rec = hz["recording"]
    log = (run_j2 / "results/logs/horizon_recording.log").read_text()
    closed = pd.read_csv(run_j2 / f"results/horizon/uav/{rec['model']}_H{rec['H']}_closed.csv")
    mc = hz["claims"]["monte_carlo"]
    run, d = select_run(closed, rec["model"], mc, "nbo", rec["select"])
    assert f"run {run} ({rec['select']} of {mc} − nbo: d = {d:+.3f} m)" in log
    families = list(dict.fromkeys(closed["family"]))
    path = run_j2 / f"results/recordings/hz_{rec['model']}_H{rec['H']}.rrd"
    entities = set()
    for chunk in RrdReader(path).store().stream():
        entities.add(str(chunk.entity_path))
    one = closed[closed["run"] == run].groupby("family", sort=False)["method"].last()
    assert list(one.index) == families
    for family, m in one.items():
        assert f"/{m}/map/plan" in entities and f"/{m}/map/uav_path" in entities
        if family != "dpw":
            assert f"/{m}/map/hypotheses" in entities
        row = closed[(closed["run"] == run) & (closed["method"] == m)].iloc[0]
        assert f"{m}: mean error {row['mean_error']:.2f} m" in log


def test_frontier_recording_replays_the_run_its_rule_chooses(run_j2, tiny):
    """frontier.recording: NBO and every budget member, in the run chosen by `select` from
    the frontier's paired differences (the log says which; the replay equals the table)."""
    from rsmhp.studies.frontier.summarise import select_run

    rec, fr = tiny["frontier"]["recording"], tiny["frontier"]
    runs = pd.read_csv(run_j2 / f"results/frontier/explore/{rec['model']}.csv")
    run, d = select_run(runs, rec["model"], "rsmhp_nt8", "nbo", rec["select"])
    log = (run_j2 / "results/logs/frontier_recording.log").read_text()
    assert f"run {run} ({rec['select']} of rsmhp_nt8 − nbo: d = {d:+.3f} m)" in log
    path = run_j2 / f"results/recordings/frontier_{rec['model']}_planners.rrd"
    entities = set()
    for chunk in RrdReader(path).store().stream():
        entities.add(str(chunk.entity_path))
    for m in ["nbo", *fr["budget"]["members"]]:
        assert f"/{m}/map/uav_path" in entities and f"/error/{m}" in entities
    assert "/about" in entities
    assert not list((run_j2 / "results/recordings").glob("frontier_*_run*.rrd"))


def test_uav_decision_outputs(run_j2, tiny):
    cfg = tiny["decisions"]
    regret = pd.read_csv(run_j2 / "results/decisions/uav_regret.csv")
    n_states = cfg["uav"]["runs"] * len(cfg["uav"]["steps"]) * len(tiny["uav_models"])
    n_methods = 1 + len(cfg["uav"]["methods"]["rsmhp_nt"]) + len(cfg["uav"]["methods"]["tree"])
    assert len(regret) == n_states * n_methods
    assert (regret["regret"] >= -1e-9 * regret["best_cost"]).all()
    map_df = pd.read_csv(run_j2 / "results/decisions/uav_map.csv")
    n_cells = len(cfg["map"]["rows"]["values"]) * len(cfg["map"]["cols"]["values"])
    # RS-MHP N_T=8 and 20, RQMC N_T=8, sigma points, tree search 20 sims (every budget member)
    compared = ["rsmhp_nt8", "rsmhp_nt20", "rqmc_nt8", "sigma", "dpw_s20"]
    assert set(tiny["frontier"]["budget"]["members"]) <= set(compared)
    assert list(dict.fromkeys(map_df["comparison"])) == [f"{m} − nbo" for m in compared]
    assert len(map_df) == n_cells * len(compared)
    assert (map_df["n_runs"] == cfg["map"]["runs"]).all()
    for cell in ("r0c0", "r1c1"):
        runs = pd.read_csv(run_j2 / f"results/decisions/map/{cell}.csv")
        assert len(runs) == cfg["map"]["runs"] * (1 + len(compared))
        assert (run_j2 / f"results/benchmarks/decisions_map_cell/{cell}.tsv").exists()
    report = (run_j2 / "results/paper/appendix.md").read_text()  # sections and ledger
    for cid in ("DEC-6", "DEC-8a", "DEC-8b"):
        assert f"| {cid} |" in report
    for name in ("decisions_uav_regret", "decisions_uav_map"):
        assert (run_j2 / f"results/paper/figures/{name}.png").exists()


def test_a_run_writes_only_under_results(run_j2):
    """A replication never rewrites tracked files: everything it writes is under results/
    (the report included, results/paper/); `make publish` alone updates paper/."""
    written = {p.name for p in run_j2.iterdir()} - {".snakemake"}
    assert written == {"results"}, written
    assert (run_j2 / "results/paper/replication.md").exists()
