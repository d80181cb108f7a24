"""The published reference of the confirmatory run: its per-run closed-loop table in compact
form and the fingerprint of the scenarios it ran, so that a new planner can be paired with the
reference planners without rerunning them (:mod:`rsmhp.studies.frontier.compare`).

A closed-loop run's random streams are keyed on the run (model, seed stream, run index),
never on the method (:func:`rsmhp.pipeline.protocol.stream_seed`), so run r of a new method
on the same scenario faces the same target, noise and initial belief as run r of every
reference configuration: the difference e_r(new) − e_r(reference) is paired. That holds only
if the scenario is the same: the same code outside the method families (the registry, its
base, the models, the closed loop; :func:`scenario_fingerprint` ``code``) and the same
configuration (``config``: the UAV model keys, the model variants, runs, stream, root seed
and track-loss threshold). :func:`check_reference` names every part that differs; a
comparison that is not paired is refused, never offered.

Files (``make publish`` copies ``results/frontier/reference/`` to ``paper/reference/``):

* ``frontier_confirm_runs.parquet``: one row per (model, configuration, run),
  :data:`REFERENCE_COLUMNS`;
* ``frontier_confirm.json``: the fingerprint, the budget ladder (which configuration is each
  family's tuned member at each budget), the preregistration's sha256, margin and headline
  budget, the run's commit, and the sha256 of the Parquet file.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

__all__ = [
    "META_FILE",
    "REFERENCE_COLUMNS",
    "RUNS_FILE",
    "check_reference",
    "compare_problems",
    "config_sha256",
    "ladder_rows",
    "load_reference",
    "method_sources",
    "scenario_fingerprint",
    "write_reference",
]

RUNS_FILE = "frontier_confirm_runs.parquet"
META_FILE = "frontier_confirm.json"
#: the columns of the reference runs (a subset of the confirmatory table's)
REFERENCE_COLUMNS = [
    "model", "config", "member", "family", "maxiter", "restarts", "run",
    "mean_error", "final_error", "lost", "plan_ms", "work_per_step",
]  # fmt: skip


def config_sha256(config: Mapping[str, Any]) -> str:
    """sha256 of the canonical JSON of a scenario configuration (keys sorted)."""
    text = json.dumps(config, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def scenario_fingerprint(code: str, config: Mapping[str, Any]) -> dict[str, Any]:
    """What makes two closed-loop runs of the confirmatory design the same scenario: ``code``,
    the digest of the confirmatory rule's code without any method family (the rule
    ``frontier_reference`` computes it), and ``config`` with its sha256."""
    return {"code": str(code), "config": dict(config), "config_sha256": config_sha256(config)}


@functools.cache
def _distributions() -> Mapping[str, list[str]]:
    """importlib.metadata.packages_distributions(), scanned once per process (about 0.5 s:
    it reads every installed distribution's records; the workflow asks twice when parsed)."""
    import importlib.metadata

    return importlib.metadata.packages_distributions()


def method_sources(names: Sequence[str]) -> dict[str, str]:
    """Per method name, the distribution that provides its family and the sha256 of the
    family's module source (``"rsmhp-plugin-example lhs 3f2a..."``): the new methods' own
    code, which may live outside this repository (a plugin package), so that an edit of it
    reruns the comparison."""
    import inspect

    from rsmhp.models.uav import methods

    if not names:  # no new method (the default): no scan of the installed distributions
        return {}
    dists = _distributions()
    out = {}
    for name in names:
        cls = type(methods.from_name(name))
        source = Path(inspect.getsourcefile(cls) or "")
        top = cls.__module__.partition(".")[0]
        dist = ",".join(sorted(set(dists.get(top, [top]))))
        digest = hashlib.sha256(source.read_bytes()).hexdigest()[:16] if source.is_file() else "?"
        out[name] = f"{dist} {cls.family} {digest}"
    return out


def ladder_rows(tuned: Mapping[str, Mapping[str, Any]]) -> list[dict[str, Any]]:
    """The budget ladder: one row (model, budget_ms, family, config) per tuned member, from
    ``tuned`` = model -> budget text -> family -> configuration name."""
    return [
        {"model": m, "budget_ms": float(b), "family": f, "config": c}
        for m, budgets in tuned.items()
        for b, fams in budgets.items()
        for f, c in fams.items()
    ]


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def write_reference(
    runs: pd.DataFrame, meta: Mapping[str, Any], directory: str | os.PathLike
) -> tuple[Path, Path]:
    """Write the reference (Parquet of :data:`REFERENCE_COLUMNS`, JSON ``meta`` plus the
    Parquet's sha256) into ``directory``; refuses a table without those columns."""
    missing = [c for c in REFERENCE_COLUMNS if c not in runs.columns]
    if missing:
        raise ValueError(f"reference runs: missing column(s) {missing}")
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    table = runs[REFERENCE_COLUMNS].sort_values(["model", "config", "run"], kind="stable")
    pq = d / RUNS_FILE
    tmp = d / (RUNS_FILE + ".tmp")
    table.reset_index(drop=True).to_parquet(tmp, index=False, compression="zstd")
    os.replace(tmp, pq)
    full = {**dict(meta), "runs_sha256": _sha256(pq), "rows": len(table)}
    js = d / META_FILE
    js.write_text(json.dumps(full, indent=1, sort_keys=True, default=str) + "\n", encoding="utf-8")
    return pq, js


def load_reference(directory: str | os.PathLike) -> tuple[pd.DataFrame, dict[str, Any]]:
    """The reference runs and their metadata; refuses a missing file, a Parquet file whose
    sha256 is not the one recorded (edited or truncated) or missing columns, naming it."""
    d = Path(directory)
    pq, js = d / RUNS_FILE, d / META_FILE
    for p in (pq, js):
        if not p.is_file():
            raise ValueError(
                f"reference: {p} does not exist (`make publish` writes it from a full run)"
            )
    try:
        meta = json.loads(js.read_text(encoding="utf-8"))
    except ValueError as exc:
        raise ValueError(f"reference: {js} is not valid JSON ({exc})") from None
    got = _sha256(pq)
    if got != meta.get("runs_sha256"):
        raise ValueError(
            f"reference: {pq} has sha256 {got[:12]}, its metadata {js} records "
            f"{str(meta.get('runs_sha256'))[:12]}: the runs file was changed after publishing"
        )
    runs = pd.read_parquet(pq)
    missing = [c for c in REFERENCE_COLUMNS if c not in runs.columns]
    if missing:
        raise ValueError(f"reference: {pq} lacks column(s) {missing}")
    return runs, meta


def _diff_keys(a: Any, b: Any, path: str = "") -> list[str]:
    if isinstance(a, Mapping) and isinstance(b, Mapping):
        out = []
        for k in sorted(set(a) | set(b), key=str):
            p = f"{path}.{k}" if path else str(k)
            if k not in a:
                out.append(f"{p} (only in this workflow: {b[k]!r})")
            elif k not in b:
                out.append(f"{p} (only in the reference: {a[k]!r})")
            else:
                out += _diff_keys(a[k], b[k], p)
        return out
    if json.dumps(a, sort_keys=True, default=str) != json.dumps(b, sort_keys=True, default=str):
        return [f"{path} (reference {_short(a)}, this workflow {_short(b)})"]
    return []


def _short(x: Any) -> str:
    text = json.dumps(x, sort_keys=True, default=str)
    return text if len(text) <= 80 else text[:77] + "..."


def check_reference(
    reference: Mapping[str, Any], current: Mapping[str, Any], models: Sequence[str] = ()
) -> list[str]:
    """Every difference between the reference's scenario fingerprint and this workflow's
    (``current``, :func:`scenario_fingerprint`): the code digest, each config key that
    differs (dotted path, both values), and ``models`` the reference did not run. Empty
    when the runs pair."""
    ref = reference.get("scenario", {})
    problems = []
    if ref.get("code") != current.get("code"):
        problems.append(
            f"scenario code: digest {ref.get('code')} in the reference, {current.get('code')} "
            "here (the registry, its base, the models or the closed loop changed)"
        )
    problems += [f"config {d}" for d in _diff_keys(ref.get("config", {}), current["config"])]
    ran = set(ref.get("config", {}).get("runs", {}))
    problems += [
        f"model {m!r}: not in the reference (it ran {sorted(ran)})" for m in models if m not in ran
    ]
    return problems


def compare_problems(
    directory: str | os.PathLike,
    current: Mapping[str, Any],
    models: Sequence[str],
    methods: Sequence[str],
) -> str:
    """``make compare``'s pre-flight check, run when the workflow is parsed so that a
    comparison that would not pair is refused before any job: the reference in
    ``directory`` exists and is intact (:func:`load_reference`), every name of ``methods``
    belongs to a registered family, and the reference ran this workflow's scenarios
    (:func:`check_reference` against ``current``). The refusal message ('' when none)."""
    from rsmhp.pipeline.protocol import Configuration

    try:
        _, meta = load_reference(directory)
        for name in methods:
            Configuration(name)  # refuses a name no registered family parses
    except ValueError as exc:
        return f"plugin_methods: {exc}"
    problems = check_reference(meta, current, models)
    if not problems:
        return ""
    return (
        f"plugin_methods: the published reference ({directory}) ran other scenarios than this "
        "workflow, so its runs would not pair with the new method's; refused. What differs:\n"
        "  - " + "\n  - ".join(problems)
    )
