"""Intermediate-file contracts: a truncated, garbled, shortened or foreign intermediate is
refused before any statistic is computed, naming the file and what is wrong.

Unit tests of the mechanism on small frames, then every kind of intermediate the tiny
workflow writes (``run_j2``), clean (it must pass: this checks each contract's expected keys
against a real run) and corrupted four ways, then end to end through Snakemake.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from snakemake.utils import validate

from rsmhp.models.lqg import ablation as estimators
from rsmhp.models.lqg import regret as decisions_lqg
from rsmhp.models.uav import methods as uav_methods
from rsmhp.models.uav import scoring as decisions_uav
from rsmhp.pipeline.config import CONFIG_PATH, SCHEMA_PATH, merge
from rsmhp.pipeline.contracts import Contract, check_table, read_checked
from rsmhp.pipeline.io import IntermediateFileError
from rsmhp.studies.lqg import simulate as lqg
from rsmhp.studies.uav import simulate as uav
from tests.pipeline.test_workflow import TINY, snakemake

# ----------------------------------------------------------------------------- mechanism


def _contract(**kw) -> Contract:
    base = dict(
        rule="make_t",
        columns=("name", "k", "x", "flag"),
        text=("name",),
        boolean=("flag",),
        integer=("k",),
        keys=("name", "k"),
        expected=pd.DataFrame({"name": ["a", "a", "b"], "k": [0, 1, 0]}),
    )
    return Contract(**{**base, **kw})


def _frame() -> pd.DataFrame:
    return pd.DataFrame(
        {"name": ["a", "a", "b"], "k": [0, 1, 0], "x": [0.5, 1.5, 2.5], "flag": [True, False, True]}
    )


def _write(df: pd.DataFrame, path: Path) -> Path:
    df.to_csv(path, index=False, lineterminator="\n")
    return path


def test_a_valid_table_passes_and_gets_numeric_dtypes(tmp_path):
    df = read_checked(_write(_frame(), tmp_path / "t.csv"), _contract())
    assert df["k"].dtype == np.int64 and df["x"].dtype == float and df["flag"].dtype == bool


@pytest.mark.parametrize(
    ("corrupt", "message"),
    [
        (lambda d: d.drop(columns="x"), r"missing column\(s\) \['x'\]"),
        (
            lambda d: d.assign(x=["0.5", "oops", "2.5"]),
            r"column 'x' has the non-numeric value 'oops' in data row 2",
        ),
        (
            lambda d: d.assign(x=[0.5, np.nan, 2.5]),
            r"column 'x' has the non-finite value nan in data row 2",
        ),
        (lambda d: d.assign(x=[0.5, np.inf, 2.5]), r"non-finite value inf in data row 2"),
        (lambda d: d.assign(k=[0, 1.5, 0]), r"column 'k' has the non-integer value 1.5"),
        (lambda d: d.assign(name=["a", None, "b"]), r"column 'name' is empty in data row 2"),
        (
            lambda d: d.assign(flag=["True", "maybe", "False"]),
            r"column 'flag' is not boolean \(data row 2: 'maybe'\)",
        ),
        (lambda d: d.iloc[[0, 2]], r"1 of 3 expected rows are missing \(e.g. name='a', k=1\)"),
        (
            lambda d: pd.concat([d, d.iloc[[1]]]),
            r"1 duplicate row\(s\), e.g. data row 4 \(name='a', k=1\)",
        ),
        (
            lambda d: pd.concat([d, d.iloc[[1]].assign(k=7)]),
            r"1 row\(s\) the config does not ask for \(e.g. name='a', k=7\)",
        ),
        (lambda d: d.iloc[:0], r"0 rows, expected at least 1"),
    ],
)
def test_each_defect_is_named_with_file_and_rule(tmp_path, corrupt, message):
    path = _write(corrupt(_frame()), tmp_path / "t.csv")
    with pytest.raises(IntermediateFileError, match=message) as err:
        read_checked(path, _contract())
    assert str(path) in str(err.value) and "rerun rule make_t" in str(err.value)


def test_nullable_columns_may_be_empty_but_never_infinite(tmp_path):
    c = _contract(nullable=("x",))
    read_checked(_write(_frame().assign(x=[0.5, np.nan, 2.5]), tmp_path / "a.csv"), c)
    with pytest.raises(IntermediateFileError, match="non-finite value -inf"):
        read_checked(_write(_frame().assign(x=[0.5, -np.inf, 2.5]), tmp_path / "b.csv"), c)


def test_constants_must_match_the_config(tmp_path):
    path = _write(_frame().assign(x=1.5), tmp_path / "t.csv")
    read_checked(path, _contract(values={"x": 1.5}))
    with pytest.raises(
        IntermediateFileError, match=r"column 'x' is 1.5 in data row 1, but the config gives 2.0"
    ):
        read_checked(path, _contract(values={"x": 2.0}))


def test_a_csv_cut_mid_row_is_refused(tmp_path):
    path = _write(_frame(), tmp_path / "t.csv")
    text = path.read_bytes()
    path.write_bytes(text[:-3])  # "...,2.5,True\n" -> "...,2.5,Tr"
    with pytest.raises(IntermediateFileError, match="last row is cut off"):
        read_checked(path, _contract())


def test_contract_definition_errors():
    with pytest.raises(ValueError, match=r"columns \['nope'\] are not among"):
        _contract(integer=("nope",))
    with pytest.raises(ValueError, match="must equal keys"):
        _contract(expected=pd.DataFrame({"k": [0]}))


def test_check_table_on_a_frame_names_the_given_label():
    with pytest.raises(IntermediateFileError, match=r"^all chunks: 1 of 3 expected rows"):
        check_table(_frame().iloc[:2], "all chunks", _contract())


# --------------------------------------------------------------- every real intermediate


@pytest.fixture(scope="module")
def effective() -> dict:
    """The config the tiny workflow ran with: config/config.yaml overlaid by tiny.yaml,
    schema defaults filled in (as the Snakefile does)."""
    cfg = merge(yaml.safe_load(CONFIG_PATH.read_text()), yaml.safe_load(TINY.read_text()))
    validate(cfg, str(SCHEMA_PATH))
    return cfg


def _intermediates(cfg: dict) -> dict[str, tuple[str, Contract]]:
    u, dec = cfg["uav"], cfg["decisions"]
    specs = uav_methods.from_config(u["methods"])
    n_chunks = min(u["chunks"], u["runs"])
    method = next(iter(specs))
    chunk_runs, chunk_steps = uav.chunk_contracts(
        specs[method], uav.chunk_runs(u["runs"], n_chunks, 0), u["scenario"]["steps"], cfg["seed"]
    )
    cell = decisions_uav.map_cells(dec["map"])[0].name
    map_runs, map_regret = decisions_uav.map_contracts(dec["map"], cell)
    return {
        "convergence": ("results/lqg/convergence.csv", lqg.convergence_contract(cfg["lqg"])),
        "nbo_error": ("results/lqg/nbo_error.csv", lqg.nbo_error_contract(cfg["lqg"])),
        "ablation": (
            "results/estimators/ablation.csv",
            estimators.ablation_contract(cfg["estimators"], cfg["lqg"]["model"]),
        ),
        "uav_chunk_runs": (f"results/uav/chunks/{method}/0.csv", chunk_runs),
        "uav_chunk_steps": (f"results/uav/chunks/{method}/0.parquet", chunk_steps),
        "uav_runs": (
            "results/uav/runs.csv",
            uav.runs_contract(list(specs), u["runs"], cfg["seed"]),
        ),
        "lqg_regret": (
            "results/decisions/lqg_regret.csv",
            decisions_lqg.regret_contract(dec["lqg"]),
        ),
        "uav_regret": (
            "results/decisions/uav_regret.csv",
            decisions_uav.regret_contract({**dec["uav"], "models": cfg["uav_models"]}),
        ),
        "map_runs": (f"results/decisions/map/{cell}.csv", map_runs),
        "map_regret": (f"results/decisions/map/{cell}_regret.csv", map_regret),
    }


KINDS = [
    "convergence",
    "nbo_error",
    "ablation",
    "uav_chunk_runs",
    "uav_chunk_steps",
    "uav_runs",
    "lqg_regret",
    "uav_regret",
    "map_runs",
    "map_regret",
]


def _read(path: Path) -> pd.DataFrame:
    return pd.read_parquet(path) if path.suffix == ".parquet" else pd.read_csv(path)


def _save(df: pd.DataFrame, path: Path) -> None:
    if path.suffix == ".parquet":
        df.to_parquet(path, index=False)
    else:
        df.to_csv(path, index=False, lineterminator="\n")


def _numeric_finite_column(contract: Contract) -> str:
    skip = {*contract.text, *contract.boolean, *contract.nullable, *contract.keys}
    return next(c for c in contract.columns if c not in skip)


@pytest.mark.workflow
@pytest.mark.parametrize("kind", KINDS)
def test_every_intermediate_of_a_real_run_meets_its_contract(run_j2, effective, kind):
    rel, contract = _intermediates(effective)[kind]
    df = read_checked(run_j2 / rel, contract)
    assert len(df) == len(contract.expected)


@pytest.mark.workflow
@pytest.mark.parametrize("defect", ["truncated", "row_deleted", "garbled", "row_duplicated"])
@pytest.mark.parametrize("kind", KINDS)
def test_every_corrupted_intermediate_is_refused(run_j2, effective, tmp_path, kind, defect):
    rel, contract = _intermediates(effective)[kind]
    src = run_j2 / rel
    path = tmp_path / src.name
    df = _read(src)
    if defect == "truncated":  # a killed writer: the file ends mid-row
        data = src.read_bytes()
        if path.suffix == ".parquet":
            cut = len(data) * 2 // 3
        else:  # halfway through the row that spans 2/3 of the file (never at a row's end)
            start = data.rindex(b"\n", 0, len(data) * 2 // 3) + 1
            cut = start + max(1, (data.index(b"\n", start) - start) // 2)
        path.write_bytes(data[:cut])
        expect = "last row is cut off|cannot be parsed"
    elif defect == "row_deleted":
        _save(df.drop(index=len(df) // 2), path)
        expect = "1 of .* expected rows are missing"
    elif defect == "garbled":
        col = _numeric_finite_column(contract)
        if path.suffix == ".parquet":  # typed storage: the closest defect is a lost value
            _save(df.assign(**{col: df[col].astype(float).where(df.index != 1)}), path)
            expect = f"column '{col}' has the non-finite value nan in data row 2"
        else:
            _save(
                df.astype({col: object}).assign(**{col: df[col].where(df.index != 1, "1.2.3")}),
                path,
            )
            expect = f"column '{col}' has the non-numeric value '1.2.3' in data row 2"
    else:
        _save(pd.concat([df, df.iloc[[0]]], ignore_index=True), path)
        expect = "1 duplicate row"
    with pytest.raises(IntermediateFileError, match=expect) as err:
        read_checked(path, contract)
    assert str(path) in str(err.value) and f"rerun rule {contract.rule}" in str(err.value)


# -------------------------------------------------------------------------- end to end


@pytest.mark.workflow
@pytest.mark.parametrize(
    ("rel", "cut", "rule", "expect"),
    [
        ("results/lqg/convergence.csv", "mid_row", "lqg_summary", "last row is cut off"),
        ("results/lqg/convergence.csv", "last_row", "lqg_summary", "expected rows are missing"),
        ("results/uav/chunks/nbo/0.csv", "last_row", "uav_collect", "expected rows are missing"),
    ],
)
def test_the_workflow_refuses_a_corrupted_intermediate(run_j2, tmp_path, rel, cut, rule, expect):
    """The user's scenario: an intermediate loses rows; the next run must fail, naming the
    file, instead of summarising fewer replicates or runs (it used to exit 0)."""
    wd = tmp_path / "wd"
    shutil.copytree(run_j2, wd, symlinks=True)
    path = wd / rel
    lines = path.read_text().splitlines(keepends=True)
    if cut == "mid_row":
        path.write_text("".join(lines[:-1]) + lines[-1][: len(lines[-1]) // 2])
    else:
        path.write_text("".join(lines[:-1]))
    res = snakemake(wd, "-j1", rule)
    out = res.stdout + res.stderr
    assert res.returncode != 0, out[-2000:]
    assert f"Error in rule {rule}" in out and f"failed: {rel}: " in out and expect in out
    assert "Traceback" not in out  # the message, not a stack


def test_rule_scripts_report_expected_failures_without_a_traceback(tmp_path):
    from rsmhp.pipeline.script import rule_logging

    log = tmp_path / "rule.log"
    with pytest.raises(SystemExit) as exit_:
        with rule_logging(log, "demo"):
            raise IntermediateFileError("results/x.csv: 3 of 9 expected rows are missing")
    assert exit_.value.code == 1
    text = log.read_text()
    assert "failed: results/x.csv: 3 of 9 expected rows are missing" in text
    assert "Traceback" not in text
    with pytest.raises(ZeroDivisionError):  # a bug keeps its traceback
        with rule_logging(log, "demo"):
            1 / 0  # noqa: B018
    assert "Traceback" in log.read_text()


# ------------------------------------------------------------------------- code versions


def _stamped_csv(path: Path, stamp: str | None) -> str:
    from rsmhp.pipeline.io import stamping, write_csv

    with stamping(stamp):
        write_csv(_frame(), path)
    return str(path)


def test_inputs_of_one_code_version_pass(tmp_path):
    from rsmhp.pipeline.contracts import check_codes

    files = [_stamped_csv(tmp_path / f"{k}.csv", "make_t:aaaaaaaaaaaa") for k in range(3)]
    other = _stamped_csv(tmp_path / "o.csv", "make_u:bbbbbbbbbbbb")
    plain = _stamped_csv(tmp_path / "p.csv", None)  # written outside a rule: not checked
    got = check_codes([*files, other, plain, tmp_path / "fig.png"], {"make_t": "aaaaaaaaaaaa"}.get)
    assert got == {**dict.fromkeys(files, "make_t:aaaaaaaaaaaa"), other: "make_u:bbbbbbbbbbbb"}


def test_inputs_of_two_code_versions_of_one_rule_are_refused(tmp_path):
    from rsmhp.pipeline.contracts import check_codes

    old = _stamped_csv(tmp_path / "old.csv", "make_t:aaaaaaaaaaaa")
    new = [_stamped_csv(tmp_path / f"n{k}.csv", "make_t:bbbbbbbbbbbb") for k in range(4)]
    with pytest.raises(IntermediateFileError) as err:
        check_codes([old, *new], {"make_t": "bbbbbbbbbbbb"}.get)
    msg = str(err.value)
    assert msg.startswith(f"{old} by code aaaaaaaaaaaa; {new[0]}, {new[1]}, {new[2]} and 1 more")
    assert "different versions of the code of rule make_t (the current code gives bbbb" in msg
    assert "nothing was computed" in msg and "`snakemake -j2 --forcerun make_t`" in msg
    with pytest.raises(IntermediateFileError, match="different versions"):
        check_codes([old, new[0]])  # mixed is refused even when the current code is unknown


def test_inputs_of_outdated_code_are_refused(tmp_path):
    from rsmhp.pipeline.contracts import check_codes

    files = [_stamped_csv(tmp_path / f"{k}.csv", "make_t:aaaaaaaaaaaa") for k in range(2)]
    with pytest.raises(IntermediateFileError) as err:
        check_codes(files, {"make_t": "cccccccccccc"}.get)
    assert str(err.value) == (
        f"{files[0]}, {files[1]}: made by code aaaaaaaaaaaa of rule make_t, but its code now "
        "gives cccccccccccc (an rsmhp module it imports changed since); nothing was computed: "
        "rerun rule make_t (e.g. `snakemake -j2 --forcerun make_t`)"
    )


def _job(tmp_path: Path, rule: str, code: str | None, inputs: list[str]):
    """What a rule script gets as ``snakemake`` (the fields rule_logging uses)."""
    from types import SimpleNamespace

    scripts = tmp_path / "workflow" / "scripts"
    scripts.mkdir(parents=True, exist_ok=True)
    (tmp_path / "src" / "rsmhp").mkdir(parents=True, exist_ok=True)
    (tmp_path / "src" / "rsmhp" / "__init__.py").touch()
    params = SimpleNamespace(**({"code": code} if code is not None else {}))
    return SimpleNamespace(
        log=[str(tmp_path / "logs" / f"{rule}.log")],
        rule=rule,
        params=params,
        input=inputs,
        scriptdir=str(scripts),
    )


def test_rule_logging_stamps_outputs_and_refuses_mixed_inputs_before_the_block(tmp_path):
    from rsmhp.pipeline.code_digest import code_digest
    from rsmhp.pipeline.io import recorded_code, write_csv
    from rsmhp.pipeline.script import rule_logging

    job = _job(tmp_path, "make_t", "aaaaaaaaaaaa", [])
    with rule_logging(job):
        write_csv(_frame(), tmp_path / "t.csv")
    assert recorded_code(tmp_path / "t.csv") == "make_t:aaaaaaaaaaaa"
    # the producer's current code comes from workflow/scripts/<rule>.py and the workflow's src
    script = tmp_path / "workflow/scripts/make_t.py"
    script.write_text("import rsmhp\n")
    now = code_digest(script, tmp_path / "src")
    good = _stamped_csv(tmp_path / "good.csv", f"make_t:{now}")
    with rule_logging(_job(tmp_path, "use_t", "dddddddddddd", [good])):
        pass
    log = (tmp_path / "logs/use_t.log").read_text()
    assert f"inputs made by: make_t:{now}" in log and "code dddddddddddd" in log
    ran = []
    with pytest.raises(SystemExit) as exit_:
        with rule_logging(_job(tmp_path, "use_t", "dddddddddddd", [good, str(tmp_path / "t.csv")])):
            ran.append(True)
    assert exit_.value.code == 1 and not ran  # refused before the block ran
    log = (tmp_path / "logs/use_t.log").read_text()
    assert "failed: " in log and "rerun rule make_t" in log and "Traceback" not in log


def test_rule_logging_refuses_a_job_whose_code_changed_after_parsing(tmp_path, monkeypatch):
    """Snakemake runs a script with __file__ set to its path: the job compares the digest of
    its code now with the `code` param computed when the workflow was parsed."""
    import sys
    from types import ModuleType

    from rsmhp.pipeline.code_digest import code_digest
    from rsmhp.pipeline.script import rule_logging

    job = _job(tmp_path, "make_t", None, [])
    script = Path(job.scriptdir) / "make_t.py"
    script.write_text("import rsmhp\n")
    main = ModuleType("__main__")
    main.__file__ = str(script)
    monkeypatch.setitem(sys.modules, "__main__", main)
    job.params.code = code_digest(script, tmp_path / "src")
    with rule_logging(job):
        pass
    (tmp_path / "src/rsmhp/__init__.py").write_text("CHANGED = True\n")
    with pytest.raises(SystemExit):
        with rule_logging(job):
            pass
    log = (tmp_path / "logs/make_t.log").read_text()
    assert "the code of rule make_t changed after the workflow was parsed" in log


@pytest.mark.workflow
def test_the_workflow_refuses_chunks_of_mixed_or_outdated_code(run_j2, tmp_path):
    """Issue 18: chunks made by two versions of the simulation code (a partial rerun after an
    edit), or all by a version that is not the current one, stop uav_collect before it
    computes anything, naming the files, their digests and the rule to rerun; the chunks are
    left as they were."""
    wd = tmp_path / "wd"
    shutil.copytree(run_j2, wd, symlinks=True)
    chunks = sorted((wd / "results/uav/chunks").glob("*/*.*"))
    assert len(chunks) >= 4
    nbo = wd / "results/uav/chunks/nbo/0.csv"
    # a simulation's stamp names its rule and the method families its digest counts
    good = pd.read_csv(nbo)["code"].iloc[0]
    assert good.startswith("uav_simulate+nbo:")

    def restamp(path: Path, digest: str) -> None:
        df = _read(path)
        _save(df.assign(code=df["code"].str.rsplit(":", n=1).str[0] + f":{digest}"), path)

    restamp(nbo, "000000000000")  # one chunk from older code
    before = {p: p.read_bytes() for p in chunks}
    res = snakemake(wd, "-j1", "uav_collect")
    out = res.stdout + res.stderr
    assert res.returncode != 0, out[-2000:]
    assert "Error in rule uav_collect" in out and "Traceback" not in out
    assert "failed: results/uav/chunks/nbo/0.csv by code 000000000000; " in out
    assert f"by code {good.split(':')[1]}: inputs made by different versions of the code" in out
    assert "of rule uav_simulate (method families nbo)" in out
    assert "`snakemake -j2 --forcerun uav_simulate`" in out
    assert {p: p.read_bytes() for p in chunks} == before  # nothing overwritten
    assert not (wd / "results/uav/runs.csv").exists()  # and nothing aggregated
    for path in chunks:  # every chunk from the same, outdated code
        restamp(path, "000000000000")
    res = snakemake(wd, "-j1", "uav_collect")
    out = res.stdout + res.stderr
    assert res.returncode != 0 and "Traceback" not in out
    assert "made by code 000000000000 of rule uav_simulate (method families nbo)" in out
    assert "rerun rule uav_simulate" in out
