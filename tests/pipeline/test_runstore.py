"""rsmhp.pipeline.runstore: exact round trip of entries, reads instead of computes, corrupt
entries recomputed (never returned), one computation per key across processes, and bad
input named.

Oracles: the values are made by the tests (the stored value must equal the computed one, bit
for bit); calls are counted by the compute functions themselves (in memory, or in files when
they run in other processes)."""

from __future__ import annotations

import logging
import math
import multiprocessing as mp
import os
import struct
import time
import uuid
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rsmhp.pipeline import runstore
from rsmhp.pipeline.runstore import RunStore, canonical_json, key_digest, open_store, report_line

NS = "demo"


def _bits(x: float) -> bytes:
    return struct.pack("<d", x)


def _same(a, b) -> bool:
    """Equal values with equal types, floats compared bit for bit (NaN payloads, -0.0)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, float):
        return _bits(a) == _bits(b)
    if isinstance(a, dict):
        return list(a) == list(b) and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return a == b


def _value(k: int) -> runstore.Value:
    """A value made from ``k`` alone (so any process can check it)."""
    summary = {"k": k, "x": k / 7, "name": f"v{k}", "nested": {"nan": math.nan, "neg": -0.0}}
    rows = [{"step": s, "e": s * k / 3, "ok": s % 2 == 0} for s in range(3)]
    return summary, rows


class Counter:
    """A compute function of ``_value`` that counts its calls per key."""

    def __init__(self, keys):
        self.keys = keys
        self.calls: list[int] = []

    def __call__(self, positions):
        self.calls += [self.keys[p]["k"] for p in positions]
        return [_value(self.keys[p]["k"]) for p in positions]


# ---------------------------------------------------------------------- exact round trip

floats = st.floats(allow_nan=True, allow_infinity=True, width=64)
nan_payloads = st.tuples(st.booleans(), st.integers(1, 2**52 - 1)).map(
    lambda sm: struct.unpack("<d", struct.pack("<Q", (sm[0] << 63) | 0x7FF0000000000000 | sm[1]))[0]
)
scalars = st.one_of(
    st.none(), st.booleans(), st.integers(-(2**70), 2**70), floats, nan_payloads, st.text()
)
summaries = st.recursive(
    scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=5), inner, max_size=4)
    ),
    max_leaves=12,
)


@st.composite
def row_tables(draw):
    n = draw(st.integers(0, 6))
    names = draw(st.lists(st.text(min_size=1, max_size=6), unique=True, max_size=4))
    kinds = [draw(st.sampled_from(["f", "i", "b"])) for _ in names]
    values = {
        "f": st.one_of(floats, nan_payloads),
        "i": st.integers(-(2**63), 2**63 - 1),
        "b": st.booleans(),
    }
    cols = {c: [draw(values[k]) for _ in range(n)] for c, k in zip(names, kinds, strict=True)}
    return [{c: cols[c][i] for c in names} for i in range(n)] if names else []


@settings(max_examples=150, deadline=None)
@given(summary=st.dictionaries(st.text(max_size=8), summaries, max_size=6), rows=row_tables())
def test_summary_and_rows_round_trip_bit_for_bit(tmp_path_factory, summary, rows):
    store = RunStore(tmp_path_factory.mktemp("s"))
    key = {"case": 1}
    store.put(NS, key, summary, rows)
    got_summary, got_rows = store.get(NS, key)
    assert _same(got_summary, summary)
    assert _same(got_rows, rows)
    store.put(NS, key, summary, None)
    assert store.get(NS, key)[1] is None  # "no rows" stays apart from "zero rows"


def test_numpy_scalars_come_back_as_the_python_scalars_they_equal(tmp_path):
    store = RunStore(tmp_path)
    store.put(NS, {"a": 1}, {"i": np.int64(3), "f": np.float64(0.1), "b": np.bool_(True)},
              [{"i": np.int64(-2), "f": np.float64(1e-300), "b": np.bool_(False)}])  # fmt: skip
    summary, rows = store.get(NS, {"a": 1})
    assert _same(summary, {"i": 3, "f": 0.1, "b": True})
    assert _same(rows, [{"i": -2, "f": 1e-300, "b": False}])


@pytest.mark.parametrize(
    ("summary", "rows", "message"),
    [
        ({"t": (1, 2)}, None, "summary field summary.t: tuple"),
        ({"x": np.float32(1.5)}, None, "summary field summary.x: float32"),
        ({1: 2}, None, "mapping key 1 is not a string"),
        ({}, [{"a": 1}, {"a": 1.5}], "column 'a' mixes ['float', 'int']"),
        ({}, [{"a": "s"}], "column 'a' holds str"),
        ({}, [{"a": 1}, {"b": 1}], "rows[1] has the keys ['b']"),
        ({}, [{"a": 2**63}], "column 'a' has an int outside int64"),
    ],
)
def test_values_that_cannot_be_stored_exactly_are_refused_by_field(
    tmp_path, summary, rows, message
):
    with pytest.raises((TypeError, ValueError)) as err:
        RunStore(tmp_path).put(NS, {"k": 0}, summary, rows)
    assert message in str(err.value)


# ---------------------------------------------------------------------- keys


def test_the_canonical_key_keeps_types_bits_and_structure_apart():
    """1 and 1.0, 0.0 and -0.0, arrays of other dtype or shape, tuples and lists (the same),
    key order (irrelevant), nested dataclasses (their class and every field)."""
    from dataclasses import dataclass

    @dataclass(frozen=True)
    class P:
        a: float
        m: np.ndarray

    base = {"x": 1, "p": P(0.5, np.eye(2))}
    variants = [
        {"x": 1.0, "p": P(0.5, np.eye(2))},
        {"x": 1, "p": P(0.5 + 2**-52, np.eye(2))},
        {"x": 1, "p": P(0.5, np.eye(2, dtype=np.float32))},
        {"x": 1, "p": P(0.5, np.eye(2).reshape(1, 4))},
        {"x": 1, "p": P(0.5, np.array([[1.0, -0.0], [0.0, 1.0]]))},  # -0.0 is not 0.0
        {"x": 1, "p": P(0.5, np.eye(2)), "y": None},
    ]
    digests = {key_digest(v) for v in [base, *variants]}
    assert len(digests) == 1 + len(variants)
    assert key_digest({"p": P(0.5, np.eye(2)), "x": 1}) == key_digest(base)  # order
    assert canonical_json({"t": (1, 2.5)}) == canonical_json({"t": [1, 2.5]})
    assert '{"__float__":"inf"}' in canonical_json({"r": math.inf})
    with pytest.raises(TypeError, match=r"key field key\.f: builtin_function_or_method"):
        canonical_json({"f": len})
    with pytest.raises(TypeError, match="a store key must be a mapping"):
        canonical_json([1])


# ---------------------------------------------------------------------- reads, not computes


def test_a_second_request_reads_and_computes_nothing(tmp_path):
    keys = [{"k": k} for k in range(5)]
    first = RunStore(tmp_path)
    compute = Counter(keys)
    a = first.get_many(NS, keys, compute)
    assert sorted(compute.calls) == list(range(5))
    assert (first.stats.computed, first.stats.reused, first.stats.waited) == (5, 0, 0)
    more = [*keys, {"k": 9}]
    again, compute2 = RunStore(tmp_path), Counter(more)
    b = again.get_many(NS, more, compute2)
    assert compute2.calls == [9]
    assert (again.stats.computed, again.stats.reused) == (1, 5)
    assert all(_same(x, y) for x, y in zip(a, b, strict=False))
    assert all(_same(v, _value(k["k"])) for v, k in zip(a, keys, strict=True))
    assert again.report() == f"run store: 1 computed, 5 reused, 0 waited ({tmp_path})"
    assert report_line(None).startswith("run store: off")
    files = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file())
    d = key_digest({"k": 0})
    assert Path(NS, d[:2], f"{d}.run") in files and len(files) == 6  # no lock file is left


def test_a_key_asked_twice_in_one_request_is_computed_once_and_copied(tmp_path):
    keys = [{"k": 1}, {"k": 1}]
    compute = Counter(keys)
    a, b = RunStore(tmp_path).get_many(NS, keys, compute)
    assert compute.calls == [1] and _same(a, b) and a[1] is not b[1]


def test_without_a_store_nothing_is_written(tmp_path):
    assert open_store(None) is None
    assert isinstance(open_store(tmp_path / "s"), RunStore) and (tmp_path / "s").is_dir()


# ---------------------------------------------------------------------- corrupt entries


def _truncate(p: Path) -> None:
    p.write_bytes(p.read_bytes()[:-7])


def _flip(p: Path) -> None:
    b = bytearray(p.read_bytes())
    b[-3] ^= 0x01  # a bit of the last row's data
    p.write_bytes(bytes(b))


def _empty(p: Path) -> None:
    p.write_bytes(b"")


def _other_format(p: Path) -> None:
    p.write_bytes(p.read_bytes().replace(b"rsmhp-runstore 1", b"rsmhp-runstore 9", 1))


@pytest.mark.parametrize("damage", [_truncate, _flip, _empty, _other_format])
def test_a_damaged_entry_is_recomputed_with_a_warning_never_returned(tmp_path, caplog, damage):
    keys = [{"k": 3}]
    store = RunStore(tmp_path)
    store.get_many(NS, keys, Counter(keys))
    path = store.path(NS, keys[0])
    damage(path)
    compute = Counter(keys)
    with caplog.at_level(logging.WARNING, logger="rsmhp.pipeline.runstore"):
        (got,) = store.get_many(NS, keys, compute)
    assert compute.calls == [3] and _same(got, _value(3))
    assert str(path) in caplog.text and "computing it again" in caplog.text
    assert _same(store.get(NS, keys[0]), _value(3))  # the file was replaced


def test_an_entry_of_another_key_at_the_path_is_not_returned(tmp_path, caplog):
    store = RunStore(tmp_path)
    store.put(NS, {"k": 1}, *_value(1))
    store.path(NS, {"k": 2}).parent.mkdir(parents=True, exist_ok=True)
    store.path(NS, {"k": 1}).rename(store.path(NS, {"k": 2}))
    with caplog.at_level(logging.WARNING):
        assert store.get(NS, {"k": 2}) is None
    assert "holds another key" in caplog.text


# ---------------------------------------------------------------------- processes


def _compute_in_files(calls: str, keys, positions, delay: float):
    out = []
    for p in positions:
        k = keys[p]["k"]
        Path(calls, f"{k}-{os.getpid()}-{uuid.uuid4().hex}").touch()
        time.sleep(delay)
        out.append(_value(k))
    return out


def _worker(root, calls, ks, start, results):
    keys = [{"k": k} for k in ks]
    store = RunStore(root, batch=3)
    start.wait()
    got = store.get_many(NS, keys, lambda pos: _compute_in_files(calls, keys, pos, 0.02))
    ok = all(_same(v, _value(k)) for v, k in zip(got, ks, strict=True))
    results.put((os.getpid(), ok, store.stats.computed, store.stats.reused, store.stats.waited))


def test_two_processes_with_overlapping_keys_compute_each_key_once(tmp_path):
    ctx = mp.get_context("spawn")
    calls = tmp_path / "calls"
    calls.mkdir()
    start, results = ctx.Event(), ctx.Queue()
    ranges = [list(range(0, 14)), list(range(6, 20))[::-1]]  # overlap 6..13, met from both ends
    procs = [
        ctx.Process(target=_worker, args=(str(tmp_path / "s"), str(calls), r, start, results))
        for r in ranges
    ]
    for p in procs:
        p.start()
    start.set()
    out = [results.get(timeout=120) for _ in procs]
    for p in procs:
        p.join(60)
        assert p.exitcode == 0
    assert all(ok for _, ok, *_ in out)
    per_key: dict[int, int] = {}
    for f in calls.iterdir():
        k = int(f.name.split("-")[0])
        per_key[k] = per_key.get(k, 0) + 1
    assert per_key == {k: 1 for k in range(20)}
    assert sum(c for _, _, c, _, _ in out) == 20
    assert all(c + r + w == 14 for _, _, c, r, w in out)  # every key of each, once
    assert sum(r + w for _, _, _, r, w in out) == 8  # the overlap, read once by one of them


def _holder(root, calls, started, die: bool):
    """Take key 0 and compute it slowly, telling the test when it has started; or die
    while computing (without writing)."""
    keys = [{"k": 0}]

    def compute(pos):
        Path(calls, f"0-{os.getpid()}-holder").touch()
        started.set()
        time.sleep(1.0)
        if die:
            os._exit(3)
        return [_value(0)]

    RunStore(root).get_many(NS, keys, compute)


@pytest.mark.parametrize("die", [False, True])
def test_a_key_another_process_holds_is_deferred_then_read_or_taken_over(tmp_path, die):
    ctx = mp.get_context("spawn")
    calls = tmp_path / "calls"
    calls.mkdir()
    started = ctx.Event()
    holder = ctx.Process(target=_holder, args=(str(tmp_path / "s"), str(calls), started, die))
    holder.start()
    assert started.wait(120)
    keys = [{"k": 0}, {"k": 1}]
    order: list[int] = []

    def compute(pos):
        order.extend(keys[p]["k"] for p in pos)
        return [_value(keys[p]["k"]) for p in pos]

    store = RunStore(tmp_path / "s")
    got = store.get_many(NS, keys, compute)
    holder.join(60)
    assert all(_same(v, _value(k["k"])) for v, k in zip(got, keys, strict=True))
    if die:  # the holder ended without writing: this process computed key 0 after waiting
        assert holder.exitcode == 3
        assert order == [1, 0] and (store.stats.computed, store.stats.waited) == (2, 0)
    else:  # key 1 first (key 0 was held), then key 0 read once the holder wrote it
        assert holder.exitcode == 0
        assert order == [1] and (store.stats.computed, store.stats.waited) == (1, 1)
    assert len(list(calls.iterdir())) == 1  # the holder's one call


# ---------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    ("root", "error", "message"),
    [
        (123, TypeError, "RunStore root must be a path (str or os.PathLike), got int 123"),
        (b"results", TypeError, "got bytes"),
        (None, TypeError, "got NoneType"),
        ("", ValueError, "non-empty path"),
    ],
)
def test_a_root_that_is_no_path_is_refused(root, error, message):
    with pytest.raises(error) as err:
        RunStore(root)
    assert message in str(err.value)


def test_a_root_that_cannot_be_a_directory_is_named(tmp_path):
    file = tmp_path / "file"
    file.write_text("x")
    with pytest.raises(NotADirectoryError, match=r"RunStore root '.*file' exists and is not a"):
        RunStore(file)
    with pytest.raises(NotADirectoryError, match=r"RunStore root '.*file/sub' cannot be created"):
        RunStore(file / "sub")


def test_an_unwritable_root_is_refused(tmp_path, monkeypatch):
    root = tmp_path / "ro"
    root.mkdir()
    root.chmod(0o500)
    try:
        if not os.access(root, os.W_OK):  # not root: the permission itself refuses it
            with pytest.raises(PermissionError, match="is not writable"):
                RunStore(root)
        real = os.access
        monkeypatch.setattr(os, "access", lambda p, m: False if Path(p) == root else real(p, m))
        with pytest.raises(
            PermissionError, match=r"RunStore root '.*ro' is not writable; set run_"
        ):
            RunStore(root)
    finally:
        root.chmod(0o700)


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (lambda s: s.get("Bad NS", {"k": 1}), ValueError, "run store namespace 'Bad NS'"),
        (lambda s: s.get_many(NS, [{"k": 1}], 5), TypeError, "compute must be callable"),
        (lambda s: s.get_many(NS, [{"k": 1}], lambda p: []), ValueError, "returned 0 values"),
        (lambda s: s.get_many(NS, [{"k": 1}], lambda p: [1]), TypeError, "(summary, rows"),
        (lambda s: RunStore(s.root, batch=0), ValueError, "batch must be an int >= 1"),
    ],
)
def test_bad_arguments_are_named(tmp_path, call, error, message):
    with pytest.raises(error) as err:
        call(RunStore(tmp_path))
    assert message in str(err.value)
