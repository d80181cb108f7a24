"""The portability drill (rsmhp.report.portability, `make portability`): the comparison logic on
small constructed tables and claims, the emulated environment, and one drill on the tiny config
(native run: the session's `run_j2`; the emulated run in a temporary directory)."""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from rsmhp.report import portability as pt
from rsmhp.report.ledger import Claim, KeyNumber

ROOT = Path(__file__).resolve().parents[2]
TINY = ROOT / "tests" / "config" / "tiny.yaml"


# --- tables --------------------------------------------------------------------------------


def _frame(**cols) -> pd.DataFrame:
    base = {
        "method": ["nbo", "mc", "tree"],
        "P": [10, 20, 30],
        "estimate": [1.25, -0.1, 3.0e5],
        "plan_seconds": [0.5, 0.25, 0.125],
        "code": ["rule:abc"] * 3,
    }
    return pd.DataFrame(base | cols)


def test_identical_tables():
    out = pt.compare_frames(_frame(), _frame())
    assert out["status"] == "identical" and out["columns"] == {}
    assert out["set aside"] == ["plan_seconds", "code"]
    nan = _frame(estimate=[np.nan, 1.0, 2.0])
    assert pt.compare_frames(nan, nan.copy())["status"] == "identical"  # NaN equals NaN


def test_one_ulp_is_a_difference():
    x = _frame()
    y = _frame(estimate=[np.nextafter(1.25, 2.0), -0.1, 3.0e5])
    out = pt.compare_frames(x, y)
    assert out["status"] == "differs" and list(out["columns"]) == ["estimate"]
    col = out["columns"]["estimate"]
    assert (col["cells"], col["of"], col["max ulps"], col["non-finite"]) == (1, 3, 1, 0)
    assert col["max abs"] == np.spacing(1.25)
    assert col["max rel"] == pytest.approx(np.spacing(1.25) / 1.25)
    assert col["max abs / column max"] == pytest.approx(np.spacing(1.25) / 3.0e5)
    # a sign change or a zero has no meaningful ulp distance; abs and rel still tell
    z = pt.compare_frames(x, _frame(estimate=[1.25, 0.0, 3.0e5]))["columns"]["estimate"]
    assert z["max ulps"] is None and z["max abs"] == pytest.approx(0.1) and z["max rel"] == 1.0
    # -0.0 and 0.0 differ in their bits (and by nothing else)
    s = pt.compare_frames(_frame(estimate=[0.0] * 3), _frame(estimate=[0.0, -0.0, 0.0]))
    assert s["status"] == "differs" and s["columns"]["estimate"]["max abs"] == 0.0
    # integer and text columns
    out = pt.compare_frames(x, _frame(P=[10, 21, 30], method=["nbo", "mc", "pruned"]))
    assert out["columns"]["P"]["cells"] == 1 and out["columns"]["P"]["max abs"] == 1.0
    assert out["columns"]["method"] == {"cells": 1, "of": 3}
    # inf on one side only
    inf = pt.compare_frames(x, _frame(estimate=[np.inf, -0.1, 3.0e5]))["columns"]["estimate"]
    assert inf["non-finite"] == 1 and inf["cells"] == 1


def test_timing_and_code_columns_are_set_aside():
    other = _frame(plan_seconds=[9.0, 8.0, 7.0], code=["rule:def"] * 3)
    out = pt.compare_frames(_frame(), other)
    assert out["status"] == "identical"
    timing = ("cpu_seconds", "plan_seconds", "plan_seconds_per_run", "seconds", "cpu_median")
    for name in (*timing, "plan_ms", "ms"):
        assert pt.is_timing_column(name), name
    for name in ("mean", "estimate", "n_seconds_x", "cpu", "code", "items", "terms", "n_ms_x"):
        assert pt.is_timing_column(name) == (name in ("n_seconds_x", "n_ms_x")), name


def test_shape_differences():
    out = pt.compare_frames(_frame(), _frame().drop(columns="estimate"))
    assert out["status"] == "columns differ" and "estimate" in out["detail"]
    out = pt.compare_frames(_frame(), _frame().iloc[:2])
    assert out["status"] == "rows differ" and out["detail"] == "3 rows native, 2 emulated"


def test_compare_results_reads_exact_floats_and_names_missing_tables(tmp_path):
    nat, emu = tmp_path / "nat", tmp_path / "emu"
    for d in (nat, emu):
        (d / "lqg").mkdir(parents=True)
        (d / "uav").mkdir()
        (d / "portability").mkdir()
    x = _frame(estimate=[0.1 + 0.2, 1 / 3, 2.0 / 7])
    y = _frame(estimate=[0.1 + 0.2, np.nextafter(1 / 3, 1.0), 2.0 / 7])
    x.to_csv(nat / "lqg/summary.csv", index=False)  # how rsmhp.pipeline.io writes: shortest repr
    y.to_csv(emu / "lqg/summary.csv", index=False)
    x.to_csv(nat / "lqg/same.csv", index=False)
    x.assign(plan_seconds=1.0).to_csv(emu / "lqg/same.csv", index=False)
    x.to_parquet(nat / "uav/steps.parquet", index=False)
    y.to_parquet(emu / "uav/steps.parquet", index=False)
    x.to_csv(nat / "lqg/only_native.csv", index=False)
    x.to_csv(emu / "uav/only_emulated.csv", index=False)
    x.to_csv(nat / "portability/ignored.csv", index=False)
    x.assign(code="rule:other").to_csv(emu / "uav/stamp.csv", index=False)
    x.to_csv(nat / "uav/stamp.csv", index=False)
    by = {t["table"]: t for t in pt.compare_results(nat, emu)}
    assert list(by) == sorted(by) and "portability/ignored.csv" not in by
    assert by["lqg/summary.csv"]["status"] == "differs"
    assert by["lqg/summary.csv"]["columns"]["estimate"]["max ulps"] == 1  # CSV parsed exactly
    assert by["uav/steps.parquet"]["columns"]["estimate"]["cells"] == 1
    assert by["lqg/same.csv"]["status"] == "identical"
    assert by["lqg/only_native.csv"]["status"] == "missing (emulated)"
    assert by["uav/only_emulated.csv"]["status"] == "missing (native)"
    assert by["uav/stamp.csv"]["status"] == "identical" and "code stamps" in by["uav/stamp.csv"]
    assert by["lqg/summary.csv"]["expected"] == "bitwise"
    assert by["uav/steps.parquet"]["expected"] == "statistical"
    assert pt.expected_class("decisions/lqg_regret.csv") == "bitwise"
    assert pt.expected_class("decisions/map/r0c0.csv") == "statistical"
    assert pt.expected_class("decisions/uav_regret.csv") == "statistical"


# --- claims --------------------------------------------------------------------------------


def _claim(cid: str, value: float, verdict: str = "supported", stat: bool = False) -> Claim:
    ci = {"ci_low": value - 1.0, "ci_high": value + 1.0} if stat else {}
    key = KeyNumber("slope", value, reproducible="statistical" if stat else "bitwise", **ci)
    return Claim(cid, "a claim", "the paper", key, verdict, "a rule")


def test_compare_claims():
    ref = [_claim("A", 1.0), _claim("B", 2.0), _claim("C", 3.0), _claim("D", 0.5, stat=True)]
    nat = list(ref)
    emu = [
        _claim("A", 1.0),
        _claim("B", float(np.nextafter(2.0, 3.0))),
        _claim("C", 3.0, verdict="inconclusive"),
        _claim("D", 0.75, stat=True),
    ]
    rows = {r["id"]: r for r in pt.compare_claims(ref, nat, emu)}
    assert rows["A"]["bitwise equal"] and rows["A"]["emulated - native"] == 0.0
    assert rows["A"]["same verdict"] and rows["A"]["verify (emulated)"] == "ok"
    assert not rows["B"]["bitwise equal"] and rows["B"]["same verdict"]
    assert rows["B"]["emulated - native"] == np.spacing(2.0)
    assert rows["B"]["verify (emulated)"] == "ok" and rows["B"]["tolerance"] == 2e-9
    assert not rows["C"]["same verdict"] and "verdict flipped" in rows["C"]["verify (emulated)"]
    assert rows["C"]["verify (native)"] == "ok"
    assert rows["D"]["emulated - native"] == 0.25 and rows["D"]["verify (emulated)"] == "ok"
    missing = pt.compare_claims(ref, nat, emu[:3])
    assert missing[-1]["verify (emulated)"] == "missing in this run"
    assert not missing[-1]["same verdict"]


def _write_claims(path: Path, claims: list[Claim], config_hash: str | None = "abc") -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    data: dict = {"claims": [dataclasses.asdict(c) for c in claims]}
    if config_hash is not None:
        data["config sha256"] = config_hash
    path.write_text(json.dumps(data))


def test_a_drill_of_some_sections_compares_their_claims(tmp_path):
    """Targets that make report sections but no report: the claims of those sections (the
    native run's sections, the reference's same ids); refused when there is no section, the
    native run lacks one, or the report changed a claim of one (a Holm family)."""
    from types import SimpleNamespace

    from rsmhp.report.portability import cli

    nat, emu = tmp_path / "nat", tmp_path / "emu"
    a, b, c = _claim("A", 1.0), _claim("B", 2.0, stat=True), _claim("C", 3.0)
    _write_claims(tmp_path / "ref.json", [a, b, c])
    _write_claims(nat / "results/paper/claims.json", [a, b, c])
    _write_claims(nat / "results/report/one.json", [a, b], None)
    _write_claims(nat / "results/report/two.json", [c], None)
    _write_claims(emu / "results/report/one.json", [a, _claim("B", 2.5, stat=True)], None)
    plan = SimpleNamespace(
        reference=tmp_path / "ref.json",
        native_dir=nat,
        workdir=emu,
        args=SimpleNamespace(target=["results/report/one.json"]),
        started=None,
    )
    got = cli._load_claims(plan)
    assert got.sections == ["one"] and got.config_hash == "abc"
    assert [x.id for x in got.reference] == [x.id for x in got.native] == ["A", "B"]
    assert got.emulated[1].key.value == 2.5
    assert got.n_statistical == 1  # the whole reference's, as make verify counts them
    # a section the targets neither name nor made (an earlier drill's) is left out
    _write_claims(emu / "results/report/two.json", [c], None)
    assert cli._load_claims(plan).sections == ["one"]
    # the whole report, when the targets make it
    _write_claims(emu / "results/paper/claims.json", [a, b, c])
    plan.args.target = ["report"]
    full = cli._load_claims(plan)
    assert full.sections is None and [x.id for x in full.emulated] == ["A", "B", "C"]
    plan.args.target = ["results/report/one.json"]
    (emu / "results/paper/claims.json").unlink()
    # refusals
    _write_claims(nat / "results/paper/claims.json", [a, _claim("B", 2.0, "inconclusive", True), c])
    with pytest.raises(cli._Abort, match="the report changes the claims B of these sections"):
        cli._load_claims(plan)
    _write_claims(nat / "results/paper/claims.json", [a, b, c])
    (nat / "results/report/one.json").unlink()
    with pytest.raises(cli._Abort, match="the native run has no report section one"):
        cli._load_claims(plan)
    (emu / "results/report/one.json").unlink()
    with pytest.raises(cli._Abort, match=r"make neither results/paper/claims\.json nor a report"):
        cli._load_claims(plan)
    _write_claims(tmp_path / "ref.json", [a, b, c], "def")
    with pytest.raises(cli._Abort, match="config sha256 differs"):
        cli._load_claims(plan)


# --- the emulation -------------------------------------------------------------------------


def test_emulation_env(tmp_path):
    base = {"PATH": "/bin", "PYTHONPATH": "/x", "NUMBA_CPU_FEATURES": "+avx2"}
    env = pt.emulation_env(base, tmp_path, "Haswell", ["X86_V3", "X86_V4"])
    assert env["NUMBA_CPU_NAME"] == "generic" and "NUMBA_CPU_FEATURES" not in env
    assert env["NUMBA_CACHE_DIR"] == str(tmp_path.resolve() / "numba-cache")
    assert env["OPENBLAS_CORETYPE"] == "Haswell"
    assert env["NPY_DISABLE_CPU_FEATURES"] == "X86_V3 X86_V4"
    assert env["PYTHONPATH"].split(":") == [str(tmp_path.resolve() / "hook"), "/x"]
    assert base == {"PATH": "/bin", "PYTHONPATH": "/x", "NUMBA_CPU_FEATURES": "+avx2"}
    only_blas = pt.emulation_env({"OPENBLAS_CORETYPE": "Zen"}, tmp_path, "Haswell", (), False)
    assert "NUMBA_CPU_NAME" not in only_blas and "NPY_DISABLE_CPU_FEATURES" not in only_blas
    assert "NUMBA_CACHE_DIR" in only_blas  # the host's cache is never used
    assert "OPENBLAS_CORETYPE" not in pt.emulation_env({"OPENBLAS_CORETYPE": "Zen"}, tmp_path, None)


def test_hook_records_from_inside_an_emulated_process(tmp_path):
    """A process in the emulated environment reports another OpenBLAS core type and no numpy
    SIMD; the hook records what it used at exit."""
    native = pt.probe()
    assert native["openblas"] and native["numba_cpu"] != "generic"
    pt.install_hook(tmp_path)
    env = pt.emulation_env(os.environ, tmp_path, "Nehalem", native["numpy_dispatch"])
    emulated = pt.probe(env)
    assert emulated["openblas"] == ["Nehalem"] != native["openblas"]
    assert emulated["numba_cpu"] == "generic" and emulated["numba_features"] == ""
    assert emulated["numpy_simd"] == []
    subprocess.run([sys.executable, "-c", "import numpy"], env=env, check=True, timeout=120)
    records = pt.read_records(tmp_path / "records")
    assert records and all(r["openblas"] == ["Nehalem"] for r in records)
    assert all(r["numpy_simd"] == [] for r in records)


def _record(cpu: str, compiled: int, loaded: int, blas: str = "Nehalem") -> dict:
    kernel = {"targets": [[cpu, ""]], "compiled": compiled, "loaded": loaded, "cache": "c"}
    return {
        "pid": 1,
        "argv0": "tmpab_c.uav_simulate.py",
        "openblas": [blas],
        "numpy_simd": [],
        "numba": {"kernels": {"rsmhp.models.uav.fused.k": kernel}},
    }


def test_summarise_emulation_names_what_did_not_take_effect():
    native = {"openblas": ["SkylakeX"], "numpy_simd": ["X86_V3"]}
    emulated = {"openblas": ["Nehalem"], "numpy_simd": []}
    blas = "openblas 0.3.30 Nehalem"
    good = pt.summarise_emulation(
        native, emulated, [_record("generic", 1, 0), _record("generic", 0, 3)], {}, None, blas
    )
    assert good["effective"] and good["problems"] == []
    inside = good["inside the emulated run"]
    assert inside["rules with compiled kernels"] == ["uav_simulate"]
    assert inside["kernels"]["rsmhp.models.uav.fused.k"] == {
        "targets": ["generic"],
        "compiled": 1,
        "loaded": 3,
    }

    def problems(records, emu=emulated, cache=None, prov=blas, components=pt.COMPONENTS):
        out = pt.summarise_emulation(native, emu, records, cache or {}, None, prov, components)
        assert out["effective"] == (not out["problems"])
        return " | ".join(out["problems"])

    assert "built for ['znver4']" in problems([_record("znver4", 1, 0)])
    assert "all from a cache" in problems([_record("generic", 0, 2)])
    assert "hook not loaded" in problems([])
    assert "host's OpenBLAS" in problems([_record("generic", 1, 0, blas="SkylakeX")])
    assert "is the host's" in problems([_record("generic", 1, 0)], emu=native)
    assert "cache holds kernels for ['znver4']" in problems(
        [_record("generic", 1, 0)], cache={"k.nbi": ["znver4"]}
    )
    # a component that is not emulated is not checked
    assert problems([_record("generic", 1, 0, blas="SkylakeX")], components=("numba",)) == ""


def test_render_shows_every_table_and_differing_column():
    nat = {"openblas": ["SkylakeX"], "numpy_simd": ["X86_V3"], "numba_cpu": "znver4"}
    nat["numba_features"] = "+avx512f,+fma"
    emulation = pt.summarise_emulation(
        nat, {"openblas": ["Nehalem"], "numpy_simd": []}, [_record("generic", 1, 0)], {}, "", ""
    )
    tables = [
        {"table": "lqg/a.csv", "expected": "bitwise", "status": "identical", "columns": {}},
        {
            "table": "lqg/b.csv",
            "expected": "bitwise",
            "status": "missing (emulated)",
            "columns": {},
        },
        {
            "table": "uav/c.csv",
            "expected": "statistical",
            **pt.compare_frames(_frame(), _frame(estimate=[1.25, -0.1, 3.0e5 + 1.0])),
        },
    ]
    drill = {
        "result": "PASS",
        "native": "n",
        "emulated": "e",
        "reference": "r",
        "config sha256": "abc",
        "env": {"NUMBA_CPU_NAME": "generic"},
        "verify native": "PASS",
        "verify emulated": "PASS",
        "emulation": emulation,
        "claims": pt.compare_claims([_claim("A", 1.0)], [_claim("A", 1.0)], [_claim("A", 1.0)]),
        "tables": tables,
    }
    text = pt.render(drill)
    assert text.startswith("# Portability drill: PASS")
    assert "| lqg/a.csv | bitwise | identical | - |" in text
    assert "| lqg/b.csv | bitwise | missing (emulated) |" in text
    assert "| uav/c.csv | estimate | 1/3 | 1 |" in text
    assert "| A | bitwise | 1 | 0 | 0 | yes |" in text


# --- the drill on the tiny config ----------------------------------------------------------


def _files(results: Path) -> dict[str, str]:
    return {
        str(p.relative_to(results)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(results.rglob("*"))
        if p.is_file()
    }


def _content(path: Path, aside: list[str]) -> str:
    df = pt.read_table(path).drop(columns=aside, errors="ignore")
    return df.to_csv(index=False)


#: the drill's targets: two studies' report sections (the LQG and estimator studies: bitwise
#: claims, tables with timing columns). Their jobs call the Sobol' kernels alone, so the drill
#: compiles only those for the generic CPU (the planner kernel's build for another CPU is
#: tests/models/uav/test_cpu_targets.py's); the whole report's drill is `make portability`'s
#: default, its comparison of claims files (statistical ones too) tested above on constructed
#: claims
DRILL_TARGETS = ["results/report/lqg.json", "results/report/estimators.json"]


@pytest.mark.workflow
@pytest.mark.compile  # the kernels the targets need, compiled for the generic CPU
def test_drill_on_the_tiny_config(run_j2, tmp_path):
    """The emulated run of two studies of the tiny config (DRILL_TARGETS): numba compiled the
    kernels their jobs need for the generic CPU (in the warm-up, only those, none in a job),
    OpenBLAS ran on another core
    type (recorded inside the run), every verdict of those studies is the native run's, the
    native results are untouched, and each table is classified as its content says."""
    before = _files(run_j2 / "results")
    emulated = tmp_path / "emulated"
    t0 = time.perf_counter()
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "rsmhp.report.portability",
            "--native",
            str(run_j2),
            "--no-native-run",
            "--workdir",
            str(emulated),
            "--configfile",
            str(TINY),
            "--reference",
            str(run_j2 / "results/paper/claims.json"),
            "--output",
            str(tmp_path / "drill"),
            "--quiet",
            "--target",
            *DRILL_TARGETS,
        ],
        capture_output=True,
        text=True,
        timeout=900,
        cwd=tmp_path,
    )
    seconds = time.perf_counter() - t0
    assert res.returncode == 0, res.stdout[-4000:] + res.stderr[-3000:]
    drill = json.loads((tmp_path / "drill.json").read_text())
    text = (tmp_path / "drill.md").read_text()
    assert text.startswith("# Portability drill: PASS") and text in res.stdout
    assert drill["sections"] == ["estimators", "lqg"] and "only the claims of the report" in text
    emu = drill["emulation"]
    inside = emu["inside the emulated run"]
    assert emu["effective"] and emu["problems"] == [], emu["problems"]
    # numba: every kernel the run used was generated for the generic CPU, without features,
    # compiled in the run into its own cache (the copied source tree holds no cache)
    assert emu["native"]["numba_cpu"] not in ("generic", "")
    assert inside["numba target CPUs"] == ["generic"] and inside["numba features"] == ["(none)"]
    # the warm-up compiled what the targets' rule scripts can import (rsmhp.pipeline.warm
    # --scripts): the Sobol' points, not the planner kernel nor the tree search
    assert {k.rpartition(".")[0] for k in inside["kernels"]} == {"rsmhp.core.designs"}
    assert all(k["compiled"] >= 1 for k in inside["kernels"].values())
    assert "estimators_ablation" in inside["rules with compiled kernels"]
    assert emu["emulated numba cache"] and all(
        v == ["generic"] for v in emu["emulated numba cache"].values()
    )
    assert not list((emulated / ".drill/workflow/src").rglob("*.nb[ic]"))
    # ... by the warm-up, from the copy's src/ that the jobs import (numba's cache is keyed on
    # the source file): no job of the run compiled a kernel, each loaded what it used
    jobs = [r for r in pt.read_records(emulated / ".drill/records") if r.get("rule")]
    assert {"estimators_ablation", "lqg_convergence"} <= {r["rule"] for r in jobs}
    compiled = [
        (r["rule"], name)
        for r in jobs
        for name, k in r.get("numba", {}).get("kernels", {}).items()
        if k["compiled"]
    ]
    assert not compiled, compiled
    # OpenBLAS: the emulated core type inside every process (the run made no provenance.json:
    # the report rule writes it)
    assert inside["openblas core types"] == ["Nehalem"]
    assert "Nehalem" not in emu["native"]["openblas"]
    assert emu["emulated run blas (provenance.json)"] is None
    assert "Nehalem" not in emu["native run blas (provenance.json)"]
    assert inside["numpy SIMD extensions"] == []
    # claims: those of the two sections, every verdict the same, both runs pass verify
    assert drill["verify native"] == drill["verify emulated"] == "PASS"
    ids = [r["id"] for r in drill["claims"]]
    assert ids == [c["id"] for s in ("lqg", "estimators") for c in _section(run_j2, s)["claims"]]
    assert all(r["same verdict"] for r in drill["claims"])
    # (both studies' claims are bitwise; the statistical class is compared above, on
    # constructed claims files)
    assert {r["reproducible"] for r in drill["claims"]} == {"bitwise"}
    # tables: the emulated run's, each classified as its content (timing and code aside) says
    tables = {t["table"]: t for t in drill["tables"]}
    emulated_tables = {
        str(p.relative_to(emulated / "results"))
        for p in (emulated / "results").rglob("*")
        if p.suffix in (".csv", ".parquet")
    }
    assert set(tables) == emulated_tables
    # ... and those are the two studies' alone: the run made what its targets need
    assert {name.split("/")[0] for name in tables} == {"lqg", "estimators"}
    assert {"lqg/convergence.csv", "estimators/ablation.csv"} <= set(tables)
    assert not [n for n, t in tables.items() if t["status"].startswith("missing")]
    for name, t in tables.items():
        same = _content(run_j2 / "results" / name, t["set aside"]) == _content(
            emulated / "results" / name, t["set aside"]
        )
        assert t["status"] == ("identical" if same else "differs"), name
        assert bool(t["columns"]) == (not same), name
    assert tables["estimators/ablation.csv"]["set aside"] == ["cpu_seconds", "code"]
    # the native results were only read
    assert _files(run_j2 / "results") == before
    print(
        f"tiny drill: {seconds:.0f} s; {sum(t['status'] == 'identical' for t in tables.values())}"
        f" of {len(tables)} tables identical"
    )


def _section(run: Path, name: str) -> dict:
    return json.loads((run / "results/report" / f"{name}.json").read_text())


def test_rule_scripts_finds_every_rule_script_and_only_those(tmp_path):
    from rsmhp.pipeline.code_digest import rule_scripts

    found = rule_scripts(ROOT / "workflow")
    text = "".join(p.read_text() for p in (ROOT / "workflow/rules").glob("*.smk"))
    assert len(found) == text.count("\n    script:")
    assert all(p.is_file() for p in found.values())
    assert found["lqg_recording"].name == "tree_recording.py"
    assert found["uav_simulate"].name == "uav_simulate.py"
    # a rule without a script takes none of the next rule's
    (tmp_path / "workflow/rules").mkdir(parents=True)
    (tmp_path / "workflow/rules/a.smk").write_text(
        'rule target:\n    input:\n        "x"\n\n\n'
        'rule job:\n    output:\n        "x"\n    script:\n        "../scripts/job.py"\n'
    )
    assert rule_scripts(tmp_path / "workflow") == {"job": tmp_path / "workflow/scripts/job.py"}


def test_a_reused_workdir_compares_only_the_sections_this_drill_made(tmp_path):
    import time as _time

    from rsmhp.report.portability.cli import _whole_report, target_sections

    report = tmp_path / "results" / "report"
    report.mkdir(parents=True)
    old = report / "uav.json"  # left by an earlier drill in the same working directory
    old.write_text("{}")
    os.utime(old, (1_000_000_000, 1_000_000_000))
    since = _time.time()
    (report / "lqg.json").write_text("{}")  # made by this drill's rule target
    # named targets count even when already up to date; an earlier drill's section does not
    assert target_sections(["lqg"], tmp_path, since) == {"lqg"}
    assert target_sections(["results/report/horizon.json"], tmp_path, since) == {
        "horizon",
        "lqg",
    }
    assert target_sections(["./results/report/uav.json"], tmp_path, since) == {"uav", "lqg"}
    assert target_sections(["lqg"], tmp_path, None) == set()
    assert _whole_report(["report"]) and _whole_report(["all", "x"])
    assert _whole_report(["results/paper/claims.json"]) and _whole_report(["verify"])
    assert _whole_report(["./results/verify.md"]) and _whole_report(["results/provenance.json"])
    assert not _whole_report(["results/report/lqg.json", "uav_collect"])
