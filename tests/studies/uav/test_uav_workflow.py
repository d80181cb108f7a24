"""The UAV part of the workflow end to end (tiny config): content of every output, -j1 == -j2."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import yaml
from rerun.chunk import RrdReader

from rsmhp.report.ledger import Section
from rsmhp.report.markdown import fmt
from rsmhp.studies.uav.section import FIGURES
from rsmhp.studies.uav.simulate import NONDETERMINISTIC_COLUMNS
from tests.pipeline.test_workflow import TINY, snakemake

pytestmark = pytest.mark.workflow


def test_uav_runs_and_steps(run_j2, tiny):
    u = tiny["uav"]
    runs = pd.read_csv(run_j2 / "results/uav/runs.csv")
    methods = ["nbo", *(f"rsmhp_nt{n}" for n in u["methods"]["rsmhp_nt"])]
    methods += [f"tree_n{t['N']}_m{t['M']}" for t in u["methods"]["tree"]]
    assert runs["method"].drop_duplicates().tolist() == methods
    assert len(runs) == len(methods) * u["runs"]
    for _, grp in runs.groupby("method"):
        assert grp["run"].tolist() == list(range(u["runs"]))
    assert (runs["seed"] == tiny["seed"]).all()
    assert runs.loc[runs["method"] == "rsmhp_nt20", "N_T"].eq(20).all()
    assert (runs["plan_seconds"] > 0).all() and (runs["mean_error"] > 0).all()
    steps = pd.read_parquet(run_j2 / "results/uav/steps.parquet")
    K = u["scenario"]["steps"]
    assert len(steps) == len(runs) * K
    per_run = steps.groupby(["method", "run"], sort=False)["error"]
    merged = runs.merge(per_run.mean().rename("m").reset_index(), on=["method", "run"])
    np.testing.assert_allclose(merged["mean_error"], merged["m"], rtol=1e-12)
    # paired design: the true target path is the same for every method in a run
    truth = steps.pivot_table(index=["run", "step"], columns="method", values="target_x")
    assert np.all(truth.max(axis=1) == truth.min(axis=1))
    # controls stay in the box
    assert steps["accel"].abs().max() <= 3.0 + 1e-12
    assert steps["bank"].abs().max() <= np.pi / 4 + 1e-12


def test_uav_summary_tables_figures_report(run_j2, tiny):
    runs = pd.read_csv(run_j2 / "results/uav/runs.csv")
    summary = pd.read_csv(run_j2 / "results/uav/summary.csv")
    for _, row in summary.iterrows():
        err = runs.loc[runs["method"] == row["method"], "mean_error"]
        assert row["mean"] == pytest.approx(err.mean())
        assert row["median"] == pytest.approx(err.median())
        assert row["ci_low"] <= row["mean"] <= row["ci_high"]
    paired = pd.read_csv(run_j2 / "results/uav/paired.csv")
    wide = runs.pivot(index="run", columns="method", values="mean_error")
    for _, row in paired.iterrows():
        d = wide[row["method"]] - wide[row["baseline"]]
        assert row["mean_diff"] == pytest.approx(d.mean())
        assert 0 <= row["wilcoxon_p"] <= 1
    assert {"vs NBO", "N_T trend", "pruning"} <= set(paired["purpose"])
    for name in ("uav_methods", "uav_paired"):
        text = (run_j2 / f"results/tables/{name}.md").read_text()
        assert text.startswith("|") and text.count("\n") >= 4
    for name in FIGURES:
        png = (run_j2 / f"results/figures/{name}.png").read_bytes()
        assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000
        assert (run_j2 / f"results/figures/{name}.pdf").read_bytes()[:5] == b"%PDF-"
        assert (run_j2 / f"results/paper/figures/{name}.png").read_bytes() == png
    report = (run_j2 / "results/paper/replication.md").read_text()
    appendix = (run_j2 / "results/paper/appendix.md").read_text()
    for cid in ("UAV-1", "UAV-2", "UAV-3"):
        assert f"| {cid} |" in appendix and f"### {cid}\n" in appendix
        assert f"[{cid}](appendix.md#{cid.lower()})" in report  # linked from the one page
    assert ". Case study 2: UAV target tracking" in appendix
    for name in FIGURES:
        assert f"](figures/{name}.png)" in appendix and f"[{name}](figures/{name}.png)" in report
    big = summary[summary["family"] == "rsmhp"].sort_values("N_T").iloc[-1]
    assert f"{big['label']} {fmt(big['mean'], 4)} m" in appendix
    section = Section.load(run_j2 / "results/report/uav.json")
    assert len(section.body.encode("utf-8")) <= 2600
    assert [c.key.reproducible for c in section.claims] == ["statistical"] * 3
    for rule in ("uav_collect", "uav_summary", "uav_figures"):
        assert "done in" in (run_j2 / f"results/logs/{rule}.log").read_text()
        assert (run_j2 / f"results/benchmarks/{rule}.tsv").exists()


def test_uav_recording(run_j2, tiny):
    n = tiny["uav"]["recording"]["runs"]
    assert sorted(p.name for p in (run_j2 / "results/recordings").glob("uav_run*.rrd")) == [
        f"uav_run{k}.rrd" for k in range(n)
    ]
    reader = RrdReader(run_j2 / "results/recordings/uav_run0.rrd")
    assert len(reader.blueprints()) == 1
    counts: dict[str, int] = {}
    for chunk in reader.store().stream():
        counts[chunk.entity_path] = counts.get(chunk.entity_path, 0) + chunk.num_rows
    K = tiny["uav"]["scenario"]["steps"]
    for m in ("nbo", "rsmhp_nt5", "rsmhp_nt20", "tree_n3_m20"):
        assert counts[f"/{m}/map/hypotheses"] == K and counts[f"/error/{m}"] == K + 1


def test_uav_j1_equals_j2_except_wall_time(run_j2, run_j1):
    """The session's -j1 run (``run_j1``, target uav_collect among others) against -j2."""
    a = pd.read_csv(run_j2 / "results/uav/runs.csv")
    b = pd.read_csv(run_j1 / "results/uav/runs.csv")
    cols = [c for c in a.columns if c not in NONDETERMINISTIC_COLUMNS]
    assert cols == [c for c in b.columns if c not in NONDETERMINISTIC_COLUMNS]
    pd.testing.assert_frame_equal(a[cols], b[cols], check_exact=True)
    assert not a["plan_seconds"].equals(b["plan_seconds"])  # wall time really is excluded
    sa = pd.read_parquet(run_j2 / "results/uav/steps.parquet")
    sb = pd.read_parquet(run_j1 / "results/uav/steps.parquet")
    pd.testing.assert_frame_equal(sa, sb, check_exact=True)


def test_adding_nt_value_reruns_no_existing_simulation(run_j2, tmp_path, tiny):
    changed = {"uav": {"methods": {"rsmhp_nt": [*tiny["uav"]["methods"]["rsmhp_nt"], 7]}}}
    cfg = tmp_path / "nt.yaml"
    cfg.write_text(yaml.safe_dump(changed))
    res = snakemake(run_j2, "-j1", "-n", "uav", configfiles=(TINY, cfg))
    out = res.stdout + res.stderr
    assert res.returncode == 0, out
    sims = [line for line in out.splitlines() if "uav_simulate/" in line and ".log" in line]
    assert sims and all("rsmhp_nt7_" in line for line in sims), sims


def test_paired_diff_figure_redraws_identically(run_j2, tmp_path):
    """The strip jitter comes from the figure's own seeded generator (not NumPy's legacy global
    one, which stays untouched), so two redraws give the same bytes."""
    import numpy as np
    import pandas as pd

    from rsmhp.report.figures import save_figure
    from rsmhp.studies.uav.figures import paired_diff_figure

    runs = pd.read_csv(run_j2 / "results/uav/runs.csv")
    summary = pd.read_csv(run_j2 / "results/uav/summary.csv")
    paired = pd.read_csv(run_j2 / "results/uav/paired.csv")
    out = []
    for i in range(2):
        np.random.random(i + 1)  # noqa: NPY002  (disturb the global state between draws)
        before = np.random.get_state()  # noqa: NPY002
        save_figure(paired_diff_figure(runs, summary, paired), tmp_path / f"d{i}")
        after = np.random.get_state()  # noqa: NPY002
        # the caller's global generator state is restored
        assert (before[1] == after[1]).all() and before[2] == after[2]
        out.append((tmp_path / f"d{i}.png").read_bytes())
    assert out[0] == out[1]
