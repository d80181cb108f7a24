"""Stable random streams keyed on job identifiers.

Every random number in the project comes from a :class:`numpy.random.SeedSequence` built from

* the project-wide ``root_seed`` (config key ``seed``) as entropy, and
* a 128-bit ``spawn_key`` derived from a canonical text form of the *job identifier*:
  the experiment name and every parameter value that defines one row of output
  (model parameters, sample size, replicate index, ...).

Because the key depends only on what the row *is*, not on when or where it is computed,
results are identical for any worker count and any scheduling order, and adding a new
parameter value or replicate never changes an existing row.
"""

from __future__ import annotations

import hashlib
import json
import math
import struct
from collections.abc import Iterable, Iterator, Mapping
from typing import Any

import numpy as np

from rsmhp.core import guards

__all__ = ["canonical_job_id", "job_rng", "job_rngs", "job_seed_sequence"]


def _plain(value: Any) -> Any:
    """Convert numpy scalars/arrays and tuples to JSON-serialisable Python values."""
    if isinstance(value, np.ndarray):
        return [_plain(v) for v in value.tolist()]
    if isinstance(value, np.generic):
        item = value.item()  # kept as is (np.float64(1.0) stays 1.0: existing streams)
        if isinstance(item, float) and not math.isfinite(item):
            raise ValueError(f"job identifier values must be finite, got {item!r}")
        return item
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError(f"job identifier values must be finite, got {value!r}")
    if isinstance(value, float) and value.is_integer():
        # 1.0 and 1 identify the same parameter value
        return int(value)
    if isinstance(value, (bool, int, float, str)) or value is None:
        return value
    raise TypeError(f"job identifier values must be numbers, strings or sequences, got {value!r}")


def canonical_job_id(experiment: str, /, **params: Any) -> str:
    """Canonical text of a job identifier: JSON with sorted keys, floats in shortest repr.

    ``canonical_job_id("lqg", a=0.5, P=100)`` == ``'{"P":100,"a":0.5,"experiment":"lqg"}'``.
    Integer-valued floats are written as integers so that ``T=1`` and ``T=1.0`` agree.
    """
    _experiment(experiment)
    if "experiment" in params:
        raise ValueError("'experiment' is reserved in job identifiers")
    return _dump({"experiment": experiment, **_params(params)})


def _experiment(experiment: Any) -> None:
    if not isinstance(experiment, str):
        raise TypeError(
            f"experiment must be a non-empty string, got {type(experiment).__name__} {experiment!r}"
        )
    if not experiment:
        raise ValueError("experiment name must be a non-empty string, got ''")


def _params(params: Mapping[str, Any]) -> dict[str, Any]:
    """:func:`_plain` of every value, naming the parameter whose value is refused."""
    try:
        return {k: _plain(v) for k, v in params.items()}
    except (TypeError, ValueError):
        for k, v in params.items():
            try:
                _plain(v)
            except (TypeError, ValueError) as exc:
                raise type(exc)(f"job identifier parameter {k}: {exc}") from None
        raise


def _dump(payload: Mapping[str, Any]) -> str:
    return json.dumps(payload, sort_keys=True, separators=(",", ":"), allow_nan=False)


def _seed_sequence(root_seed: Any, job_id: str) -> np.random.SeedSequence:
    if type(root_seed) is not int or root_seed < 0:  # fast path: a plain int (every job)
        root_seed = guards.nonneg_int("root_seed", root_seed)
    digest = hashlib.blake2b(job_id.encode("utf-8"), digest_size=16).digest()
    words = _WORDS.unpack(digest)  # four little-endian uint32 words, as Python ints
    return np.random.SeedSequence(entropy=int(root_seed), spawn_key=words)


_WORDS = struct.Struct("<4I")


def job_seed_sequence(root_seed: int, experiment: str, /, **params: Any) -> np.random.SeedSequence:
    """SeedSequence for one job: entropy ``root_seed``, spawn key = BLAKE2b-128 of the job id.

    The spawn key is the digest split into four little-endian uint32 words.
    """
    return _seed_sequence(root_seed, canonical_job_id(experiment, **params))


def job_rng(root_seed: int, experiment: str, /, **params: Any) -> np.random.Generator:
    """A PCG64 :class:`numpy.random.Generator` seeded by :func:`job_seed_sequence`."""
    return np.random.Generator(np.random.PCG64(job_seed_sequence(root_seed, experiment, **params)))


def job_rngs(
    root_seed: int, experiment: str, key: str, values: Iterable[Any], /, **params: Any
) -> Iterator[np.random.Generator]:
    """``job_rng(root_seed, experiment, **params, key=v)`` for every ``v`` in ``values``
    (identical streams), converting the shared ``params`` only once (e.g. the replicates of
    one grid cell)."""
    _experiment(experiment)
    if "experiment" in params or key == "experiment":
        raise ValueError("'experiment' is reserved in job identifiers")
    if key in params:
        raise ValueError(f"{key!r} is both the varying key and a fixed parameter")
    base = {"experiment": experiment, **_params(params)}
    # the job id's text with a marker where the varying value goes: each value's id is then
    # one string replacement (the same text as _dump of the whole mapping, since json writes
    # every value independently of the others)
    marker = "\x00rsmhp-value\x00"
    text = _dump({**base, key: marker})
    quoted = json.dumps(marker)
    if text.count(quoted) != 1:  # pragma: no cover - the marker cannot occur in a parameter
        raise ValueError("job_rngs: the value marker occurs in the fixed parameters")
    head, tail = text.split(quoted)
    for v in values:
        value = _params({key: v})[key]
        seq = _seed_sequence(root_seed, head + _dump(value) + tail)
        yield np.random.Generator(np.random.PCG64(seq))
