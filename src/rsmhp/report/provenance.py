"""Provenance of a run: commit, config hash, package versions, BLAS, CPU and its vector flags,
and the digests of the code that made the results (``results/provenance.json``; the report
summarises it)."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

__all__ = ["code_provenance", "provenance"]


def _git(root: Path, *args: str) -> str | None:
    import subprocess

    try:
        out = subprocess.run(
            ["git", "-C", str(root), *args], capture_output=True, text=True, timeout=10
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() if out.returncode == 0 else None


def _cpu() -> tuple[str, str]:
    """(CPU model, the vector-instruction flags that change floating-point paths)."""
    import platform

    model, flags = platform.processor() or platform.machine(), ""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            if key.strip() == "model name" and model in ("", platform.machine()):
                model = value.strip()
            elif key.strip() == "flags" and not flags:
                have = set(value.split())
                wanted = ("sse4_2", "avx", "avx2", "fma", "avx512f", "avx512dq", "avx512vl")
                flags = " ".join(f for f in wanted if f in have)
    except OSError:
        pass
    return model, flags or "unknown"


def _blas() -> str:
    """The BLAS/OpenMP libraries numpy and scipy loaded (threadpoolctl), with versions."""
    try:
        import numpy  # noqa: F401  (loads numpy's BLAS)
        import scipy.linalg  # noqa: F401
        from threadpoolctl import threadpool_info
    except ImportError:
        return "unknown"
    libs = sorted(
        {
            " ".join(
                str(v)
                for v in (i.get("internal_api"), i.get("version"), i.get("architecture"))
                if v
            )
            for i in threadpool_info()
        }
    )
    return "; ".join(libs) or "none found"


def provenance(
    config: Mapping[str, Any] | None = None, root: str | os.PathLike | None = None
) -> dict[str, str]:
    """Where and with what the numbers were made: commit (and whether the working tree had
    uncommitted changes), a hash of the validated config, Python and package versions, BLAS,
    CPU model and vector flags, worker threads, host and UTC date. The config hash covers
    every key except ``threads`` (which cannot change a number).

    Bitwise-reproducible numbers need the same code, config, versions, BLAS and CPU flags;
    the UAV closed loop and anything timed can differ otherwise (see the README)."""
    import datetime
    import hashlib
    import platform
    from importlib.metadata import PackageNotFoundError, version

    root = Path(root) if root is not None else Path(__file__).resolve().parents[3]
    commit = _git(root, "rev-parse", "HEAD")
    # paper/ holds the published copy of the report (`make publish` rewrites it)
    status = _git(root, "status", "--porcelain", "--untracked-files=no", "--", ".", ":!paper")
    out = {
        "commit": commit or "unknown (not a git checkout)",
        "uncommitted changes (outside paper/)": "unknown"
        if status is None
        else ("yes" if status else "no"),
    }
    if config is not None:
        # every parameter that can change a number; `threads` cannot (results are identical
        # for any worker count), so it is left out and shown on its own; a change of the
        # config's layout alone changes no number (rsmhp.pipeline.config_layout.hash_view)
        from rsmhp.pipeline.config_layout import hash_view

        numbers = {k: v for k, v in hash_view(config).items() if k != "threads"}
        canon = json.dumps(numbers, sort_keys=True, default=str).encode()
        out["config sha256"] = hashlib.sha256(canon).hexdigest()[:16]
        out["threads"] = f"{config.get('threads', '?')} (of {os.cpu_count()} CPUs)"
    out["python"] = platform.python_version()
    for pkg in (
        "rsmhp",
        "numpy",
        "scipy",
        "numba",
        "pandas",
        "filterpy",
        "joblib",
        "snakemake",
        "seaborn",
        "matplotlib",
        "rerun-sdk",
    ):
        try:
            out[pkg] = version(pkg)
        except PackageNotFoundError:
            out[pkg] = "not installed"
    out["blas"] = _blas()
    out["cpu"], out["cpu flags"] = _cpu()
    out["platform"] = platform.platform()
    out["host"] = platform.node()
    out["date (UTC)"] = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M")
    return out


def code_provenance(
    results: str | os.PathLike,
    scripts: str | os.PathLike,
    src: str | os.PathLike | None = None,
    extra: Mapping[str, tuple[str, list[str]]] | None = None,
) -> dict[str, Any]:
    """The code that made the results: for every rule whose tables under ``results`` record a
    code stamp (:mod:`rsmhp.pipeline.io`; ``results/paper`` is skipped), the digests recorded with
    the files that record each (``recorded``), the digest its code gives now (``current``,
    from ``scripts/<rule>.py`` and ``src``, by default the workflow's) and the modules
    behind it; ``extra`` adds rules by hand (``{rule: (digest, files)}``, e.g. the report
    itself). ``modules`` maps every module named to its own digest
    (:func:`rsmhp.pipeline.code_digest.describe`)."""
    from rsmhp.pipeline.code_digest import (
        DIGEST_LENGTH,
        describe,
        method_only,
        split_stamp_rule,
        workflow_src,
    )
    from rsmhp.pipeline.io import recorded_code

    results, scripts = Path(results), Path(scripts)
    src = workflow_src(scripts) if src is None else src
    recorded: dict[str, dict[str, list[str]]] = {}
    for path in sorted(results.rglob("*")):
        rel = path.relative_to(results)
        if rel.parts[0] == "paper" or path.suffix not in (".csv", ".parquet", ".json"):
            continue
        stamp = recorded_code(path)
        if stamp is not None:
            rule, _, digest = stamp.rpartition(":")
            recorded.setdefault(rule, {}).setdefault(digest, []).append(str(path))
    for rule, (digest, files) in (extra or {}).items():
        recorded.setdefault(rule, {}).setdefault(digest, []).extend(files)
    rules: dict[str, Any] = {}
    modules: dict[str, str] = {}
    for rule in sorted(recorded):
        entry: dict[str, Any] = {"recorded": recorded[rule]}
        name, families = split_stamp_rule(rule)  # "uav_simulate+nbo": restricted to nbo
        script = scripts / f"{name}.py"
        if script.is_file():
            code = describe(script, src, method_only(families))
            entry["current"] = code.digest
            entry["modules"] = list(code.modules)
            modules.update({m: d[:DIGEST_LENGTH] for m, d in code.modules.items()})
        rules[rule] = entry
    return {"rules": rules, "modules": dict(sorted(modules.items()))}
