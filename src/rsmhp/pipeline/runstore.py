r"""A content-addressed store of computed runs, so that a run several rules need is computed
once and read by the others.

What an entry is
----------------
An entry holds the value of one deterministic computation: a *summary* (a mapping of
strings to scalars, nested mappings and lists) and, optionally, *rows* (a list of mappings
with the same keys, each column all ``float``, all ``int`` or all ``bool``: the per-step
rows of a closed-loop run). It is addressed by its *key*, a mapping that names everything
the value is a function of (for a UAV closed-loop run:
:func:`rsmhp.models.uav.runs.closed_loop_key`). The key's *digest* is the SHA-256 (64 hex
digits) of its canonical JSON text (:func:`canonical_json`: sorted keys, no spaces; a float
in its shortest repr, which reads back to the same bits, so an ``int`` and a ``float`` of
equal value differ; non-finite floats, numpy arrays (dtype, shape, values) and dataclasses
(class and every field) as tagged objects). Two keys have the same digest exactly when their
canonical texts are equal (up to SHA-256 collisions; the entry also holds the whole key text,
checked on every read).

Where it lives
--------------
``<root>/<namespace>/<d[:2]>/<d>.run`` for digest ``d``; ``<d>.lock`` beside it while a process
computes it. Removing the whole store (``rm -rf <root>``) is always safe: missing entries are
computed again.

File format (version 1)
-----------------------
::

    rsmhp-runstore 1\n
    <SHA-256 hex of the body>\n
    body = <header JSON>\n<column data>

The header holds the key's canonical text (checked against the key asked for), the summary in
a typed JSON form (a float as the 16 hex digits of its IEEE-754 bits, so every float, NaN
payloads and the sign of zero included, reads back bit for bit; ``int``, ``bool``, ``str``,
``None``, mappings in their order, lists), and the rows' count and columns (name and dtype
``<f8``, ``<i8`` or ``|b1``). The column data is each column's values, little-endian, one
column after the other. numpy scalars are stored as the Python scalars they equal and read
back as those (``np.float64`` is a ``float``; ``np.int64`` comes back as ``int``). A file whose
magic line, checksum, header, key or data length is wrong (truncated by a crash, corrupt,
written by another format) is never returned: :meth:`RunStore.get_many` logs a warning naming
the file, computes the entry again and replaces the file.

Writing and concurrency
-----------------------
An entry is written to a temporary file in its own directory and moved into place with
:func:`os.replace`, so a reader sees either no file or a whole one. Several processes may use
one store at once (``snakemake -j2`` runs two jobs; a rule's worker processes): each entry is
computed under an exclusive ``fcntl.flock`` of its lock file. :meth:`RunStore.get_many` first
reads what is there; of the missing keys it takes the lock of each it can *without waiting*
and computes those (in batches, with the caller's function, which may run them in parallel);
a key whose lock another process holds is deferred. Only after its own work, holding no lock,
does it wait for each deferred key's lock and read the entry, or compute it if the other
process ended without writing it (it failed or was killed; ``flock`` locks end with their
process). A process never waits while holding a lock, so two processes cannot deadlock; and
an entry is computed once however many processes ask for it, as long as ``flock`` works on the
store's filesystem (local filesystems; on NFS, Linux emulates it with POSIX locks). Where it
does not, two processes may both compute an entry: harmless, both values are valid and one
replaces the other. Lock files are removed by their holder after use (a holder checks after
locking that its lock file is still the one at the path, and retries if not).

Counts: :attr:`RunStore.stats` tells how many entries this process computed, read
(``reused``) and read after waiting for another process (``waited``);
:meth:`RunStore.report` is the line the rules log.
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import errno
import fcntl
import hashlib
import json
import logging
import math
import os
import re
import struct
import tempfile
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "FORMAT",
    "EntryError",
    "RunStore",
    "StoreStats",
    "Value",
    "canonical_json",
    "key_digest",
    "open_store",
    "report_line",
]

log = logging.getLogger(__name__)

#: version of the file format (the magic line); another version's file is never read
FORMAT = 1
_MAGIC = f"rsmhp-runstore {FORMAT}\n".encode()
_SUFFIX = ".run"
_NAMESPACE = re.compile(r"[a-z][a-z0-9_]{0,63}")
#: column dtypes of the rows (little-endian float64, int64, bool)
_DTYPES = {float: "<f8", int: "<i8", bool: "|b1"}

#: an entry's value: (summary, rows or None)
Value = tuple[dict[str, Any], list[dict[str, Any]] | None]


class EntryError(ValueError):
    """An entry file that cannot be trusted (truncated, corrupt, another key or format)."""


# ------------------------------------------------------------------------ canonical keys


def _canonical(value: Any, path: str) -> Any:
    """The JSON-ready canonical form of one key value (see :func:`canonical_json`)."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        if isinstance(value, np.floating) and not isinstance(value, np.float64):
            return {"__float__": float.hex(float(value)), "dtype": value.dtype.str}
        x = float(value)
        return x if math.isfinite(x) else {"__float__": float.hex(x)}
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in "biuf":
            raise TypeError(f"key field {path}: array of dtype {value.dtype} (allowed: b, i, u, f)")
        return {
            "__ndarray__": value.dtype.str,
            "shape": list(value.shape),
            "data": [_canonical(v, path) for v in value.ravel().tolist()],
        }
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        cls = type(value)
        return {
            "__dataclass__": f"{cls.__module__}.{cls.__qualname__}",
            "fields": {
                f.name: _canonical(getattr(value, f.name), f"{path}.{f.name}")
                for f in dataclasses.fields(value)
            },
        }
    if isinstance(value, Mapping):
        out = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise TypeError(f"key field {path}: mapping key {k!r} is not a string")
            out[k] = _canonical(v, f"{path}.{k}")
        return out
    if isinstance(value, (list, tuple)):
        return [_canonical(v, f"{path}[{i}]") for i, v in enumerate(value)]
    raise TypeError(
        f"key field {path}: {type(value).__name__} {value!r} has no canonical form (allowed: "
        "None, bool, int, float, str, numpy scalars and arrays, dataclasses, mappings, lists)"
    )


def canonical_json(key: Mapping[str, Any]) -> str:
    """The canonical JSON text of ``key``: sorted keys, no spaces; finite floats in their
    shortest repr (the same bits read back; ``1`` and ``1.0`` stay apart), non-finite ones as
    ``{"__float__": "inf"}``; numpy arrays as ``{"__ndarray__": dtype, "shape", "data"}``;
    dataclasses as ``{"__dataclass__": "<module>.<class>", "fields": {...}}`` with every field;
    tuples as lists. (:func:`rsmhp.core.seeding.canonical_job_id` is not used: it writes
    ``1.0`` as ``1``, which identifies a parameter value but not a value's type.)"""
    if not isinstance(key, Mapping):
        raise TypeError(f"a store key must be a mapping, got {type(key).__name__}")
    return json.dumps(_canonical(key, "key"), sort_keys=True, separators=(",", ":"))


def key_digest(key: Mapping[str, Any]) -> str:
    """SHA-256 (64 hex digits) of :func:`canonical_json` of ``key``."""
    return hashlib.sha256(canonical_json(key).encode("utf-8")).hexdigest()


# ------------------------------------------------------------------------ values


def _float_bits(x: float) -> str:
    return struct.pack("<d", x).hex()


def _bits_float(h: str) -> float:
    return struct.unpack("<d", bytes.fromhex(h))[0]


def _encode(value: Any, path: str) -> Any:
    """Typed JSON of a summary value: ``{"f": bits}`` for a float, ``{"d": [[k, v], ...]}``
    for a mapping (order kept), ``{"l": [...]}`` for a list; None, bool, int, str as they are."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, float):  # np.float64 included
        return {"f": _float_bits(float(value))}
    if isinstance(value, Mapping):
        items = []
        for k, v in value.items():
            if not isinstance(k, str):
                raise TypeError(f"summary field {path}: mapping key {k!r} is not a string")
            items.append([k, _encode(v, f"{path}.{k}")])
        return {"d": items}
    if isinstance(value, list):
        return {"l": [_encode(v, f"{path}[{i}]") for i, v in enumerate(value)]}
    raise TypeError(
        f"summary field {path}: {type(value).__name__} {value!r} cannot be stored exactly "
        "(allowed: None, bool, int, float, str, mappings with string keys, lists)"
    )


def _decode(value: Any) -> Any:
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, dict) and len(value) == 1:
        ((tag, inner),) = value.items()
        if tag == "f":
            return _bits_float(inner)
        if tag == "d":
            return {k: _decode(v) for k, v in inner}
        if tag == "l":
            return [_decode(v) for v in inner]
    raise EntryError(f"unknown summary value {value!r}")


def _columns(rows: Sequence[Mapping[str, Any]]) -> tuple[list[list[str]], bytes]:
    """(``[[name, dtype], ...]``, column data) of ``rows`` (see the module docstring)."""
    if not rows:
        return [], b""
    names = list(rows[0])
    for i, row in enumerate(rows):
        if not isinstance(row, Mapping):
            raise TypeError(f"rows[{i}] is a {type(row).__name__}, not a mapping")
        if list(row) != names:
            raise ValueError(f"rows[{i}] has the keys {list(row)}, rows[0] has {names}")
    spec, parts = [], []
    for name in names:
        if not isinstance(name, str):
            raise TypeError(f"rows: column name {name!r} is not a string")
        values = [row[name] for row in rows]
        kinds = set()
        for v in values:
            if isinstance(v, (bool, np.bool_)):
                kinds.add(bool)
            elif isinstance(v, (int, np.integer)):
                kinds.add(int)
            elif isinstance(v, float):
                kinds.add(float)
            else:
                raise TypeError(
                    f"rows: column {name!r} holds {type(v).__name__} {v!r} "
                    "(allowed: float, int, bool)"
                )
        if len(kinds) != 1:
            raise TypeError(
                f"rows: column {name!r} mixes {sorted(k.__name__ for k in kinds)} "
                "(a column must be all float, all int or all bool to read back exactly)"
            )
        dtype = _DTYPES[kinds.pop()]
        try:
            arr = np.array(values, dtype=dtype)
        except OverflowError as exc:
            raise ValueError(f"rows: column {name!r} has an int outside int64: {exc}") from None
        spec.append([name, dtype])
        parts.append(arr.tobytes())
    return spec, b"".join(parts)


def _rows(n: int, spec: list[list[str]], data: bytes) -> list[dict[str, Any]]:
    if n < 0:
        raise EntryError(f"a negative row count {n}")
    sizes = [np.dtype(dtype).itemsize * n for _, dtype in spec]
    if sum(sizes) != len(data):
        raise EntryError(f"{len(data)} bytes of rows, expected {sum(sizes)}")
    cols, at = [], 0
    for (_, dtype), size in zip(spec, sizes, strict=True):
        cols.append(np.frombuffer(data, dtype=dtype, count=n, offset=at).tolist())
        at += size
    names = [name for name, _ in spec]
    if not names:
        return [{} for _ in range(n)]
    return [dict(zip(names, vals, strict=True)) for vals in zip(*cols, strict=True)]


def _serialise(
    canonical_key: str, summary: Mapping[str, Any], rows: Sequence[Mapping[str, Any]] | None
) -> bytes:
    if not isinstance(summary, Mapping):
        raise TypeError(f"the summary must be a mapping, got {type(summary).__name__}")
    if rows is not None and not isinstance(rows, Sequence):
        raise TypeError(f"rows must be a list of mappings or None, got {type(rows).__name__}")
    spec, data = _columns(rows) if rows is not None else ([], b"")
    header = {
        "key": canonical_key,
        "summary": _encode(summary, "summary"),
        "rows": None if rows is None else len(rows),
        "columns": spec,
    }
    body = json.dumps(header, separators=(",", ":")).encode("utf-8") + b"\n" + data
    return _MAGIC + hashlib.sha256(body).hexdigest().encode() + b"\n" + body


def _deserialise(blob: bytes, canonical_key: str) -> Value:
    if not blob.startswith(_MAGIC):
        raise EntryError(f"not a format-{FORMAT} entry (first line {blob[:40]!r})")
    rest = blob[len(_MAGIC) :]
    checksum, sep, body = rest.partition(b"\n")
    if not sep or hashlib.sha256(body).hexdigest().encode() != checksum:
        raise EntryError("checksum mismatch (truncated or corrupt)")
    head, sep, data = body.partition(b"\n")
    if not sep:
        raise EntryError("no header line")
    try:
        header = json.loads(head)
        if header["key"] != canonical_key:
            raise EntryError("the entry holds another key")
        summary = _decode(header["summary"])
        n = header["rows"]
        rows = None if n is None else _rows(int(n), header["columns"], data)
    except (KeyError, TypeError, ValueError, struct.error) as exc:
        if isinstance(exc, EntryError):
            raise
        raise EntryError(f"unreadable header: {exc}") from None
    if not isinstance(summary, dict):
        raise EntryError("the summary is not a mapping")
    return summary, rows


# ------------------------------------------------------------------------ the store


@dataclasses.dataclass
class StoreStats:
    """What this process did: entries ``computed`` (and written), ``reused`` (read), and
    ``waited`` (read after another process that was computing them finished)."""

    computed: int = 0
    reused: int = 0
    waited: int = 0


class RunStore:
    """A content-addressed store under the directory ``root`` (created if missing; see the
    module docstring). Refuses a root that is not a path or that cannot be written."""

    def __init__(self, root: str | os.PathLike[str], *, batch: int = 32) -> None:
        if isinstance(root, bytes) or not isinstance(root, (str, os.PathLike)):
            raise TypeError(
                f"RunStore root must be a path (str or os.PathLike), got {type(root).__name__} "
                f"{root!r}"
            )
        if not str(root):
            raise ValueError("RunStore root must be a non-empty path, got ''")
        if isinstance(batch, bool) or not isinstance(batch, int) or batch < 1:
            raise ValueError(f"RunStore batch must be an int >= 1, got {batch!r}")
        self.root = Path(root)
        self.batch = batch
        try:
            self.root.mkdir(parents=True, exist_ok=True)
        except FileExistsError:
            raise NotADirectoryError(
                f"RunStore root {str(root)!r} exists and is not a directory"
            ) from None
        except OSError as exc:
            raise type(exc)(
                f"RunStore root {str(root)!r} cannot be created ({exc.strerror}); set run_store "
                "to a writable directory, or to null to run without a store"
            ) from None
        if not os.access(self.root, os.W_OK | os.X_OK):
            raise PermissionError(
                f"RunStore root {str(root)!r} is not writable; set run_store to a writable "
                "directory, or to null to run without a store"
            )
        self.stats = StoreStats()

    def __repr__(self) -> str:
        return f"RunStore({str(self.root)!r})"

    def report(self) -> str:
        """``run store: N computed, M reused, W waited (<root>)``: the line a rule logs."""
        s = self.stats
        return (
            f"run store: {s.computed} computed, {s.reused} reused, {s.waited} waited ({self.root})"
        )

    # -------------------------------------------------------------------- paths

    def path(self, namespace: str, key: Mapping[str, Any]) -> Path:
        """The entry file of ``key`` in ``namespace`` (whether or not it exists)."""
        return self._path(_check_namespace(namespace), key_digest(key))

    def _path(self, namespace: str, digest: str) -> Path:
        return self.root / namespace / digest[:2] / f"{digest}{_SUFFIX}"

    # -------------------------------------------------------------------- single entries

    def get(self, namespace: str, key: Mapping[str, Any]) -> Value | None:
        """The stored value of ``key``, or None if there is none or it cannot be trusted (a
        warning names the file). Counts nothing."""
        canon = canonical_json(key)
        path = self._path(_check_namespace(namespace), _sha(canon))
        return self._read(path, canon)

    def put(
        self,
        namespace: str,
        key: Mapping[str, Any],
        summary: Mapping[str, Any],
        rows: Sequence[Mapping[str, Any]] | None = None,
    ) -> Path:
        """Write the entry of ``key`` (atomically, replacing any) and return its path."""
        canon = canonical_json(key)
        path = self._path(_check_namespace(namespace), _sha(canon))
        self._write(path, _serialise(canon, summary, rows))
        return path

    def _read(self, path: Path, canon: str) -> Value | None:
        try:
            blob = path.read_bytes()
        except FileNotFoundError:
            return None
        except OSError as exc:
            log.warning("run store: cannot read %s (%s): computing it again", path, exc)
            return None
        try:
            return _deserialise(blob, canon)
        except EntryError as exc:
            log.warning("run store: %s is not a valid entry (%s): computing it again", path, exc)
            return None

    def _write(self, path: Path, blob: bytes) -> None:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem[:16]}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as fh:
                fh.write(blob)
            os.chmod(tmp, 0o644)
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise

    # -------------------------------------------------------------------- many entries

    def get_many(
        self,
        namespace: str,
        keys: Sequence[Mapping[str, Any]],
        compute: Callable[[list[int]], Sequence[Value]],
    ) -> list[Value]:
        """The values of ``keys``, in order: read where stored, otherwise computed by
        ``compute(indices)`` (positions in ``keys``; it returns their values in that order,
        as ``(summary, rows or None)``) and stored. Locking as in the module docstring:
        missing keys another process is computing are deferred and read once it is done.
        Equal keys are computed once. Counts go to :attr:`stats`."""
        ns = _check_namespace(namespace)
        if not callable(compute):
            raise TypeError(f"compute must be callable, got {type(compute).__name__}")
        canons = [canonical_json(k) for k in keys]
        digests = [_sha(c) for c in canons]
        first: dict[str, int] = {}
        for i, d in enumerate(digests):
            first.setdefault(d, i)
        out: dict[int, Value] = {}
        missing = []
        for i in first.values():
            got = self._read(self._path(ns, digests[i]), canons[i])
            if got is None:
                missing.append(i)
            else:
                out[i] = got
                self.stats.reused += 1
        deferred: list[int] = []
        for start in range(0, len(missing), self.batch):
            batch = missing[start : start + self.batch]
            deferred += self._own_batch(ns, batch, canons, digests, compute, out)
        for i in deferred:
            self._wait_for(ns, i, canons, digests, compute, out)
        # a repeated key gets its own copy: callers may change the rows they get
        return [
            out[i] if first[d] == i else copy.deepcopy(out[first[d]]) for i, d in enumerate(digests)
        ]

    def _own_batch(
        self,
        ns: str,
        batch: list[int],
        canons: list[str],
        digests: list[str],
        compute: Callable[[list[int]], Sequence[Value]],
        out: dict[int, Value],
    ) -> list[int]:
        """Lock what can be locked at once of ``batch``, compute and write it; return the
        indices another process holds."""
        deferred, owned = [], []
        try:
            for i in batch:
                path = self._path(ns, digests[i])
                fd = _lock(path.with_suffix(".lock"), blocking=False)
                if fd is None:
                    deferred.append(i)
                    continue
                got = self._read(path, canons[i])  # written between our read and our lock
                if got is not None:
                    out[i] = got
                    self.stats.reused += 1
                    _unlock(path.with_suffix(".lock"), fd)
                    continue
                owned.append((i, fd))
            if owned:
                values = _checked(compute([i for i, _ in owned]), len(owned))
                for (i, _), value in zip(owned, values, strict=True):
                    self._store(ns, i, canons, digests, value)
                    out[i] = value
                    self.stats.computed += 1
        finally:
            for i, fd in owned:
                _unlock(self._path(ns, digests[i]).with_suffix(".lock"), fd)
        return deferred

    def _wait_for(
        self,
        ns: str,
        i: int,
        canons: list[str],
        digests: list[str],
        compute: Callable[[list[int]], Sequence[Value]],
        out: dict[int, Value],
    ) -> None:
        """Wait for the lock of deferred key ``i``, then read it, or compute it if its holder
        ended without writing it."""
        path = self._path(ns, digests[i])
        lock = path.with_suffix(".lock")
        fd = _lock(lock, blocking=True)
        try:
            got = self._read(path, canons[i])
            if got is not None:
                out[i] = got
                self.stats.waited += 1
                return
            log.info("run store: %s was not written by the process that held it; computing it",
                     path.name)  # fmt: skip
            (value,) = _checked(compute([i]), 1)
            self._store(ns, i, canons, digests, value)
            out[i] = value
            self.stats.computed += 1
        finally:
            _unlock(lock, fd)

    def _store(self, ns: str, i: int, canons: list[str], digests: list[str], value: Value) -> None:
        summary, rows = value
        blob = _serialise(canons[i], summary, rows)  # a value that cannot be stored: a bug
        path = self._path(ns, digests[i])
        try:
            self._write(path, blob)
        except OSError as exc:  # a full disk must not lose the computed value
            log.warning("run store: cannot write %s (%s); the value is used, not stored", path, exc)


def _sha(canon: str) -> str:
    return hashlib.sha256(canon.encode("utf-8")).hexdigest()


def _check_namespace(namespace: Any) -> str:
    if not isinstance(namespace, str) or not _NAMESPACE.fullmatch(namespace):
        raise ValueError(
            f"run store namespace {namespace!r}: must match {_NAMESPACE.pattern} "
            "(a lower-case identifier, at most 64 characters)"
        )
    return namespace


def _checked(values: Any, n: int) -> list[Value]:
    values = list(values)
    if len(values) != n:
        raise ValueError(f"compute returned {len(values)} values for {n} keys")
    for v in values:
        if not (isinstance(v, tuple) and len(v) == 2):
            raise TypeError(f"compute must return (summary, rows or None) pairs, got {v!r:.80}")
    return values


def _lock(path: Path, *, blocking: bool) -> int | None:
    """An exclusive ``flock`` of the lock file ``path`` (created if missing): its descriptor,
    or None if another process holds it and ``blocking`` is False. After locking, the
    descriptor must still be the file at ``path`` (its previous holder removes it); if not,
    lock the current one."""
    path.parent.mkdir(parents=True, exist_ok=True)
    flags = fcntl.LOCK_EX | (0 if blocking else fcntl.LOCK_NB)
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, flags)
        except OSError as exc:
            os.close(fd)
            if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                return None
            raise
        try:
            now = os.stat(path)
            held = os.fstat(fd)
            if (now.st_dev, now.st_ino) == (held.st_dev, held.st_ino):
                return fd
        except FileNotFoundError:
            pass
        os.close(fd)


def _unlock(path: Path, fd: int) -> None:
    """Remove the lock file ``path`` (still held, so nobody else holds it) and release it."""
    try:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(path)
    finally:
        os.close(fd)


def open_store(root: str | os.PathLike[str] | None) -> RunStore | None:
    """The store at ``root`` (config key ``run_store``), or None (no store) for None."""
    return None if root is None else RunStore(root)


def report_line(store: RunStore | None) -> str:
    """The line a rule logs: :meth:`RunStore.report`, or that there is no store."""
    return "run store: off (run_store is null)" if store is None else store.report()
