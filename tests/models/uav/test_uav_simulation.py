"""Closed-loop UAV runs: determinism, paired design, chunking, recordings, analysis rules."""

from __future__ import annotations

import copy
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from rerun.chunk import RrdReader

from rsmhp.models.uav import methods as uav_methods
from rsmhp.models.uav import simulation
from rsmhp.models.uav.recording import record_uav_run
from rsmhp.models.uav.simulation import UAVSetup, draw_scenario, simulate_run
from rsmhp.report.ledger import Section
from rsmhp.report.markdown import fmt
from rsmhp.report.palette import method_colour, method_label, method_rgb
from rsmhp.report.render import render_appendix, render_report
from rsmhp.studies.uav import claims as uav_claims
from rsmhp.studies.uav import section as narrative
from rsmhp.studies.uav import summarise as analysis
from rsmhp.studies.uav.simulate import NONDETERMINISTIC_COLUMNS, RUN_COLUMNS, run_chunk

ROOT = Path(__file__).resolve().parents[3]
DEFAULT_UAV = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["uav"]


@pytest.fixture(scope="module")
def short_cfg() -> dict:
    cfg = copy.deepcopy(DEFAULT_UAV)
    cfg["scenario"]["steps"] = 8
    cfg["planner"].update(horizon=4, maxiter=5, maxfun=10)
    cfg["methods"] = {"nbo": True, "rsmhp_nt": [10], "tree": [{"N": 3, "M": 10}]}
    return cfg


def _det(summary: dict) -> dict:
    return {k: v for k, v in summary.items() if k not in NONDETERMINISTIC_COLUMNS}


def test_same_seed_same_run(short_cfg):
    setup = UAVSetup.from_config(short_cfg)
    for m in uav_methods.from_config(short_cfg["methods"]).values():
        a, sa = simulate_run(setup, m, 11, 2)
        b, sb = simulate_run(setup, m, 11, 2)
        assert _det(a) == _det(b) and sa == sb
    c, _ = simulate_run(setup, uav_methods.from_config(short_cfg["methods"])["nbo"], 12, 2)
    assert c["mean_error"] != a["mean_error"]


def test_methods_share_scenario_truth_and_measurement_noise(short_cfg, monkeypatch):
    setup = UAVSetup.from_config(short_cfg)
    seen: dict[str, list[np.ndarray]] = {}
    real = simulation.Stepper.advance
    current = {}

    def spy(self, uav, x_true, x_est, P, control, w, zeta, det_u):
        # the standard normals of the measurement noise and the truth's process noise
        seen.setdefault(current["m"], []).append(np.concatenate([zeta, w]))
        return real(self, uav, x_true, x_est, P, control, w, zeta, det_u)

    monkeypatch.setattr(simulation.Stepper, "advance", spy)
    steps = {}
    for name, m in uav_methods.from_config(short_cfg["methods"]).items():
        current["m"] = name
        # the spy sits in the Python loop's step; the compiled loop gives its rows bit for bit
        # (test_uav_loop.py), from the same noise arrays
        _, steps[name] = simulate_run(setup, m, 5, 0, path="python")
        assert simulate_run(setup, m, 5, 0)[1] == steps[name]
    names = list(steps)
    truth = {n: [(r["target_x"], r["target_y"]) for r in steps[n]] for n in names}
    for n in names[1:]:
        assert truth[n] == truth[names[0]]
        np.testing.assert_array_equal(np.array(seen[n]), np.array(seen[names[0]]))
    # ... while the methods do fly differently (else the comparison would be vacuous)
    uav = {n: [r["uav_x"] for r in steps[n]] for n in names}
    assert uav["nbo"] != uav["rsmhp_nt10"]


def test_scenario_ranges(short_cfg):
    setup = UAVSetup.from_config(short_cfg)
    sc = short_cfg["scenario"]
    for run in range(50):
        s = draw_scenario(setup, 3, run)
        speed = np.hypot(*s.target[2:])
        dist = np.hypot(*(s.uav[:2] - s.target[:2]))
        assert sc["target_speed_min"] <= speed <= sc["target_speed_max"]
        assert sc["uav_distance_min"] <= dist <= sc["uav_distance_max"]
        assert s.uav[2] == sc["uav_speed"]
        assert np.all(np.abs(s.target[:2]) <= sc["target_box"])


def test_chunking_and_workers_do_not_change_numbers(short_cfg):
    spec = uav_methods.from_config(short_cfg["methods"])["rsmhp_nt10"]
    whole, whole_steps = run_chunk(short_cfg, spec, [0, 1, 2], seed=4, n_jobs=1)
    parts = [run_chunk(short_cfg, spec, r, seed=4, n_jobs=2) for r in ([0], [1, 2])]
    split = pd.concat([p[0] for p in parts], ignore_index=True)
    split_steps = pd.concat([p[1] for p in parts], ignore_index=True)
    cols = [c for c in RUN_COLUMNS if c not in NONDETERMINISTIC_COLUMNS]
    pd.testing.assert_frame_equal(whole[cols], split[cols])
    pd.testing.assert_frame_equal(whole_steps, split_steps)
    # the per-run metric is the mean of the per-step errors
    means = whole_steps.groupby("run")["error"].mean().to_numpy()
    np.testing.assert_allclose(whole["mean_error"].to_numpy(), means, rtol=1e-12)


def test_recording_contents_and_consistency(short_cfg, tmp_path):
    setup = UAVSetup.from_config(short_cfg)
    specs = list(uav_methods.from_config(short_cfg["methods"]).values())
    path = tmp_path / "run.rrd"
    rows, summaries = record_uav_run(path, setup, specs, seed=5, run=1, max_hypotheses=4)
    reader = RrdReader(path)
    assert len(reader.recordings()) == 1 and len(reader.blueprints()) == 1
    counts: dict[str, int] = {}
    for chunk in reader.store().stream():
        counts[chunk.entity_path] = counts.get(chunk.entity_path, 0) + chunk.num_rows
    K = short_cfg["scenario"]["steps"]
    for m in specs:
        for ent in ("uav_path", "uav", "plan", "hypotheses", "target", "estimate", "ellipse"):
            assert counts[f"/{m.name}/map/{ent}"] == K
        assert counts[f"/error/{m.name}"] == K + 1  # + static series style
        assert counts[f"/trace/{m.name}"] == K + 1
    for entity, n in rows.items():
        assert counts["/" + entity] == n
    # the recorded runs are the study's runs
    for m, s in zip(specs, summaries, strict=True):
        ref, _ = simulate_run(setup, m, 5, 1)
        assert _det(s) == _det(ref)


def _runs(
    diff: np.ndarray,
    tree: bool = False,
    base: np.ndarray | None = None,
    mid: np.ndarray | None = None,
    tree_seconds: float = 0.1,
) -> pd.DataFrame:
    """Synthetic runs: NBO error ``base`` (default 10..20 m), RS-MHP N_T=50 ``base + diff``,
    N_T=250 ``base + 2 diff``, (``mid``) N_T=100 ``base + mid`` and (``tree``) a pruned tree
    keeping 250, ``base + 3 diff``, planning ``tree_seconds`` per run (the others 0.1 s)."""
    n = diff.size
    base = np.linspace(10, 20, n) if base is None else base
    methods = [
        ("nbo", "nbo", 1, 0, 0, base, 0.1),
        ("rsmhp_nt50", "rsmhp", 50, 0, 0, base + diff, 0.1),
        ("rsmhp_nt250", "rsmhp", 250, 0, 0, base + 2 * diff, 0.1),
    ]
    if mid is not None:
        methods.append(("rsmhp_nt100", "rsmhp", 100, 0, 0, base + mid, 0.1))
    if tree:
        methods.append(("tree_n8_m250", "tree", 250, 8, 250, base + 3 * diff, tree_seconds))
    rows = []
    for name, fam, nt, N, M, err, secs in methods:
        rows += [
            {"method": name, "family": fam, "N_T": nt, "N": N, "M": M, "run": r, "seed": 0,
             "mean_error": e, "rmse": e, "final_error": e, "mean_trace": 250.0, "mean_nit": 4.5,
             "plan_seconds": secs}
            for r, e in enumerate(err)
        ]  # fmt: skip
    return pd.DataFrame(rows, columns=RUN_COLUMNS)


def _centred_noise(n: int, sd: float, seed: int = 0) -> np.ndarray:
    noise = np.random.default_rng(seed).standard_normal(n)
    return sd * (noise - noise.mean()) / noise.std()


def _analyse(runs: pd.DataFrame, n_boot: int = 2000):
    summary = analysis.summarize_methods(runs, seed=1, n_boot=n_boot)
    paired = analysis.paired_differences(runs, seed=1, n_boot=n_boot)
    return summary, paired


#: the equivalence margin m of UAV-1..3 (config: uav.analysis.equivalence_margin)
MARGIN = DEFAULT_UAV["analysis"]["equivalence_margin"]

#: text budgets of a claim (ledger v2: claims state their scope)
CLAIM_MAX, PAPER_MAX, RULE_MAX = 200, 160, 650


def test_margin_is_configured():
    assert MARGIN == 0.25


@pytest.mark.parametrize(
    ("shift", "sd", "verdict"),
    [
        (-0.5, 0.3, "supported"),
        (0.5, 0.3, "not supported"),
        (0.0, 0.3, "equivalent"),  # CI half-width about 0.04 m, well inside ±0.25 m
        (0.0, 3.0, "inconclusive"),  # CI half-width about 0.4 m: contains 0, exceeds ±m
    ],
)
def test_verdict_rules(shift, sd, verdict):
    # differences shift + N(0, sd^2)-like spread (exactly centred), 200 runs: the bootstrap
    # CI half-width is about 1.96 * sd / sqrt(200)
    runs = _runs(shift + _centred_noise(200, sd), tree=True)
    summary, paired = _analyse(runs)
    claims = {c.id: c for c in uav_claims.uav_claims(summary, paired, MARGIN)}
    # UAV-3: d = e(N_T=250) - e(tree) = -shift per run: the opposite verdict
    opposite = {"supported": "not supported", "not supported": "supported"}.get(verdict, verdict)
    assert {k: c.verdict for k, c in claims.items()} == {
        "UAV-1": verdict,
        "UAV-2": verdict,
        "UAV-3": opposite,
    }
    row = paired[(paired["method"] == "rsmhp_nt250") & (paired["baseline"] == "nbo")].iloc[0]
    assert row["ci_low"] <= row["mean_diff"] <= row["ci_high"]
    assert row["mean_diff"] == pytest.approx(2 * shift, abs=1e-12)
    key = claims["UAV-2"].key
    assert (key.value, key.ci_low, key.ci_high) == (row["mean_diff"], row["ci_low"], row["ci_high"])
    for c in claims.values():
        assert c.key.reproducible == "statistical" and c.key.null == 0.0 and c.key.unit == "m"
        assert isinstance(c.key.value, float) and c.key.has_ci
        assert len(c.claim) <= CLAIM_MAX and len(c.paper) <= PAPER_MAX, c.id
        assert len(c.rule) <= RULE_MAX, c.id
        assert c.part == "paper" and c.setup == uav_claims.SETUP
        assert "inside ±0.25 m" in c.rule
    pairs = {"UAV-1": ("N_T=250", "N_T=50"), "UAV-2": ("N_T=250", "NBO")}
    pairs["UAV-3"] = ("N_T=250", "tree N=8 M=250")
    for cid, (a, b) in pairs.items():
        assert claims[cid].rule == uav_claims.paired_rule(a, b, MARGIN).text()
        assert claims[cid].key.name == f"mean d, e({a}) − e({b})"
    pd.testing.assert_frame_equal(paired, analysis.paired_differences(runs, seed=1, n_boot=2000))


@pytest.mark.parametrize(
    ("lo", "hi", "expected"),
    [
        (-0.3, -1e-12, "supported"),
        (-0.3, 0.0, "inconclusive"),  # the CI touches 0
        (-0.3, 0.2, "inconclusive"),  # the CI contains 0
        (0.0, 0.3, "inconclusive"),
        (1e-12, 0.3, "not supported"),
        (-0.5, 0.5, "inconclusive"),
        # the equivalence margin m = 0.25: strictly inside ±m is equivalent, touching is not
        (-0.2499, 0.2499, "equivalent"),
        (-0.25, 0.1, "inconclusive"),
        (-0.1, 0.25, "inconclusive"),
        (-0.25, -0.01, "supported"),  # below 0, touches -m
        (-0.2499, -0.01, "equivalent"),  # below 0, yet any difference is smaller than m
        (0.01, 0.25, "not supported"),
        (0.01, 0.2499, "equivalent"),
        (0.0, 0.0, "equivalent"),
    ],
)
def test_verdict_rule_edges(lo, hi, expected):
    facts = {f"{uav_claims.KEY}_low": lo, f"{uav_claims.KEY}_high": hi}
    assert uav_claims.paired_rule("A", "B", MARGIN).verdict(facts) == expected
    # the same through uav_claims, from a synthetic paired table with exactly this CI
    summary, paired = _analyse(_runs(_centred_noise(20, 0.3)), n_boot=200)
    key = (paired["method"] == "rsmhp_nt250") & (paired["baseline"] == "nbo")
    paired.loc[key, ["ci_low", "ci_high", "mean_diff"]] = [lo, hi, (lo + hi) / 2]
    uav2 = next(c for c in uav_claims.uav_claims(summary, paired, MARGIN) if c.id == "UAV-2")
    assert uav2.verdict == expected
    assert (uav2.key.ci_low, uav2.key.ci_high) == (lo, hi)


def test_paired_rule_text_and_margin():
    rule = uav_claims.paired_rule("N_T=250", "NBO", 0.25)
    assert rule.verdicts == ("equivalent", "supported", "not supported", "inconclusive")
    text = rule.text()
    assert text.startswith("d_r = e_r(N_T=250) − e_r(NBO)")
    assert "equivalent if the 95% CI of mean d lies inside ±0.25 m" in text
    assert text.endswith("inconclusive otherwise")
    # another margin changes the verdict of the same CI
    facts = {f"{uav_claims.KEY}_low": -0.2, f"{uav_claims.KEY}_high": -0.1}
    assert uav_claims.paired_rule("A", "B", 0.25).verdict(facts) == "equivalent"
    assert uav_claims.paired_rule("A", "B", 0.15).verdict(facts) == "supported"
    for bad in (0.0, -0.25):
        with pytest.raises(ValueError, match="margin"):
            uav_claims.paired_rule("A", "B", bad)


def test_contrary_evidence_is_named():
    # N_T = 100 is worse than N_T = 50 (a trend comparison on the opposite side), while the
    # key comparison N_T = 250 - N_T = 50 lies below 0
    diff = -0.5 + _centred_noise(200, 0.3)
    mid = 1.0 + _centred_noise(200, 0.3, seed=1)
    runs = _runs(diff, tree=True, mid=mid)
    summary, paired = _analyse(runs)
    claims = {c.id: c for c in uav_claims.uav_claims(summary, paired, MARGIN)}
    assert claims["UAV-1"].verdict == "supported"
    # e(N_T=100) - e(N_T=50) = 1.0 - (-0.5) = +1.5 per run
    assert claims["UAV-1"].contrary.startswith("RS-MHP N_T=100 − RS-MHP N_T=50: +1.5")
    assert "N_T=250 − RS-MHP N_T=100" not in claims["UAV-1"].contrary  # its CI is below 0
    # UAV-2: every other method vs NBO whose CI lies above 0 (only N_T=100: +1 m)
    assert claims["UAV-2"].verdict == "supported"
    assert claims["UAV-2"].contrary.startswith("RS-MHP N_T=100 − NBO: +1.0")
    assert "pruned tree N=8 M=250 − NBO" not in claims["UAV-2"].contrary  # -1.5 m, below 0
    assert "RS-MHP N_T=50 − NBO" not in claims["UAV-2"].contrary  # below 0
    assert "RS-MHP N_T=250 − NBO" not in claims["UAV-2"].contrary  # the key comparison
    # no contrary evidence when every comparison agrees
    runs = _runs(-0.5 + _centred_noise(200, 0.3))
    summary, paired = _analyse(runs)
    assert all(not c.contrary for c in uav_claims.uav_claims(summary, paired, MARGIN))


def test_uav3_names_the_planning_time_when_pruning_was_slower():
    diff = 0.5 + _centred_noise(200, 0.3)  # the pruned tree has the larger error: supported
    fast = _runs(diff, tree=True, tree_seconds=0.05)
    summary, paired = _analyse(fast)
    c = next(c for c in uav_claims.uav_claims(summary, paired, MARGIN) if c.id == "UAV-3")
    assert c.verdict == "supported" and not c.contrary
    assert "compute: pruned tree N=8 M=250 planned in 0.0500 s per closed-loop run" in c.measured
    assert "(0.500×; timings of this machine)" in c.measured
    slow = _runs(diff, tree=True, tree_seconds=0.3)
    summary, paired = _analyse(slow)
    c = next(c for c in uav_claims.uav_claims(summary, paired, MARGIN) if c.id == "UAV-3")
    assert c.verdict == "supported" and "compute:" not in c.measured
    assert c.contrary == (
        "compute: pruned tree N=8 M=250 planned in 0.300 s per closed-loop run, RS-MHP "
        "N_T=250 in 0.100 s (3.00×; timings of this machine): the pruned tree did not save "
        "computation here"
    )


def _section(runs: pd.DataFrame, n_boot: int = 500, margin: float = MARGIN):
    summary, paired = _analyse(runs, n_boot)
    tables = narrative.uav_tables(summary, paired)
    section = narrative.uav_section(summary, paired, tables, DEFAULT_UAV, n_boot, runs, margin)
    return section, tables


def _no_bad_numbers(text: str) -> None:
    assert not re.search(r"\b(nan|inf|NaN|Inf|None)\b", text), text
    # integers are printed as integers (no 100.0 runs, 60.0 steps, Δt = 1.0 s); a percentage
    # is a measured ratio printed with its significant digits (2.04% prints as 2.0%)
    bad = re.findall(r"\S*(?<![\d.])\d+\.0\b(?![\d%])\S*", text)
    assert not bad, bad


@pytest.mark.parametrize("zero_diff", [False, True])
def test_section_budget_and_formatting(tmp_path, zero_diff):
    # 200 runs; with zero_diff every method has the same errors: Wilcoxon p is undefined
    diff = np.zeros(200) if zero_diff else _centred_noise(200, 0.05) + 0.01
    base = np.linspace(8, 16, 200)
    base[-1] = 61.7  # one far outlier run: clipped in the CDFs, counted in the captions
    runs = _runs(diff, tree=True, base=base)
    section, tables = _section(runs)
    assert len(section.body.encode("utf-8")) <= 2600
    for stem in narrative.FIGURES:
        assert f"](figures/{stem}.png)" in section.body
    assert section.figures == [f"{f}.png" for f in narrative.FIGURES]
    assert "| UAV-" not in section.body and "### Claims" not in section.body
    clipped = re.findall(
        r"1 run per curve beyond [\d.]+ m not shown \(up to 61.[78] m\)", section.body
    )
    assert len(clipped) == 2  # both CDF captions
    for name in ("uav_methods", "uav_paired"):
        assert tables[name] in section.appendix
    # symbols are defined in the body
    for symbol in ("N_T", "H = 6", "e_r = (1/K)", "d_r = e_r(A) − e_r(B)", "CI:", "p:"):
        assert symbol in section.body, symbol
    report = render_report([section], {"commit": "x"})
    appendix = render_appendix([section], {}, {})
    for text in (section.body, section.appendix, report, appendix):
        _no_bad_numbers(text)
    # every CI lies inside ±m (d = 0 exactly, or 0.01 m with a 0.05 m spread): equivalent
    assert [c.verdict for c in section.claims] == ["equivalent"] * 3
    margin = "Δ = 0.25 m (in the config; set after a first published result, so these verdicts"
    assert f"{margin} are exploratory" in section.body
    assert "3 of 3 CIs lie inside ±Δ and 0 contain 0" in section.body
    assert "the difference of Fig. 4 (UAV-1) and Fig. 5 (UAV-2) does not appear" in section.body
    if zero_diff:
        assert "n/a" in tables["uav_paired"] and "test is undefined" in tables["uav_paired"]
    # the runs column and the counts are integers
    assert re.search(r"\|\s+200 \|", tables["uav_methods"])
    section.save(tmp_path / "uav.json")
    assert Section.load(tmp_path / "uav.json") == section


def test_section_names_the_claims_decided_on_one_side():
    section, _ = _section(_runs(-0.5 + _centred_noise(200, 0.3), tree=True))
    assert [c.verdict for c in section.claims] == ["supported", "supported", "not supported"]
    assert (
        "CIs on one side of 0: UAV-1 (supported), UAV-2 (supported), UAV-3 (not supported)"
        in section.body
    )
    assert "0 of 3 CIs lie inside ±Δ" in section.body
    # a larger margin turns the same data into equivalences
    section, _ = _section(_runs(-0.5 + _centred_noise(200, 0.3), tree=True), margin=2.0)
    assert [c.verdict for c in section.claims] == ["equivalent"] * 3
    assert "Δ = 2 m" in section.body and "±2 m" in section.claims[0].rule


def test_robust_range_and_clip_note():
    x = np.r_[np.linspace(10, 14, 99), 40.0]
    lo, hi = analysis.robust_range(x)
    assert lo == 10.0 and 14.0 <= hi < 40.0
    groups = {"a": x, "b": x + 0.01}
    assert analysis.clip_note(groups, lo, hi) == (
        f"1 run per curve beyond {fmt(hi)} m not shown (up to {fmt(40.01)} m)"
    )
    tight = np.linspace(10, 14, 7)
    assert analysis.robust_range(tight) == (10.0, 14.0)  # nothing out: the data range
    assert analysis.clip_note({"a": tight}, 10.0, 14.0) == ""
    note = analysis.clip_note({"a": np.r_[tight, -9.0, 30.0]}, 10.0, 14.0, "differences")
    assert note.startswith("2 of 9 differences outside [10.0, 14.0] m not shown")


def test_figure_colours_match_palette():
    from matplotlib.colors import to_hex

    from rsmhp.studies.uav import figures as figs

    runs = _runs(_centred_noise(40, 0.3), tree=True)
    summary, paired = _analyse(runs, n_boot=200)
    fig = figs.error_cdf_nt_figure(runs, summary)
    ax = fig.axes[0]
    got = {ln.get_label().split(" (")[0]: to_hex(ln.get_color()) for ln in ax.get_lines()}
    assert got == {method_label(m): method_colour(m) for m in ("rsmhp_nt50", "rsmhp_nt250")}
    assert ax.get_title() and "(m)" in ax.get_xlabel()
    fig = figs.error_cdf_nbo_figure(runs, summary)
    got = {ln.get_label().split(" (")[0]: to_hex(ln.get_color()) for ln in fig.axes[0].get_lines()}
    assert got == {method_label(m): method_colour(m) for m in ("nbo", "rsmhp_nt250")}
    for draw, view in (
        (figs.paired_diff_figure, "nbo"),
        (figs.paired_diff_nt_figure, "nt"),
    ):
        fig = draw(runs, summary, paired)
        left = fig.axes[0]
        colours = [to_hex(c.get_facecolor()[0][:3]) for c in left.collections]
        rows = analysis.paired_view(paired, view)
        assert colours == [method_colour(m) for m in rows["method"]]
        assert fig._suptitle is not None and "(m" in left.get_xlabel()
    import matplotlib.pyplot as plt

    plt.close("all")


def test_recording_colours_are_the_palette(short_cfg, tmp_path):
    from rsmhp.models.uav.recording import EST_C, TRUE_C

    palette = [method_colour(m) for m in ("nbo", "mc", "tree", "tree_pernode", "pruned",
               "antithetic", "sobol", "cubature", "gauss_hermite", "exact")]  # fmt: skip
    palette += [method_colour(f"rsmhp_nt{n}") for n in (10, 50, 100, 250, 1000)]
    rgb = [tuple(int(h[i : i + 2], 16) for i in (1, 3, 5)) for h in palette]
    for c in (TRUE_C, EST_C):
        assert min(np.linalg.norm(np.subtract(c, p)) for p in rgb) > 100
    setup = UAVSetup.from_config(short_cfg)
    specs = list(uav_methods.from_config(short_cfg["methods"]).values())
    path = tmp_path / "run.rrd"
    record_uav_run(path, setup, specs, seed=5, run=1, max_hypotheses=2)

    def packed(c, alpha=255):
        return (c[0] << 24) | (c[1] << 16) | (c[2] << 8) | alpha

    seen: dict[str, set[int]] = {}
    for chunk in RrdReader(path).store().stream():
        batch = chunk.to_record_batch()
        for col in batch.schema.names:
            if col.endswith(":colors"):
                for cell in batch.column(col).to_pylist():
                    seen.setdefault(chunk.entity_path, set()).update(cell or [])
    for m in specs:
        c = method_rgb(m.name)
        for ent in ("uav_path", "uav"):
            assert seen[f"/{m.name}/map/{ent}"] == {packed(c)}
        assert {v >> 8 for v in seen[f"/{m.name}/map/plan"]} == {packed(c) >> 8}
        assert seen[f"/{m.name}/map/target"] == {packed(TRUE_C)}
        assert seen[f"/{m.name}/map/estimate"] == {packed(EST_C)}
        assert seen[f"/error/{m.name}"] == {packed(c)}


def test_figure_lists_agree():
    """The workflow's figure list (rule outputs, report inputs) is the section's FIGURES."""
    smk = (ROOT / "workflow" / "rules" / "uav.smk").read_text()
    listed = re.search(r"UAV_FIGURES = \[(.*?)\]", smk, re.S).group(1)
    assert re.findall(r'"(\w+)"', listed) == list(narrative.FIGURES)
    for stem in narrative.FIGURES:
        assert (ROOT / "workflow" / "report" / f"{stem}.rst").read_text().strip()
