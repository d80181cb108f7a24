"""Benchmark (not a test): closed-loop UAV runs per family, this code against a baseline
checkout, side by side in one run, on this CPU and on an emulated AVX2 CPU without AVX-512.

For every CPU path (``native``; ``avx2``: :func:`rsmhp.report.portability.emulation.cpu_target_env`,
the environment of ``make ... EMULATE=avx2``) and every round, two fresh worker processes run
the same closed-loop runs, one with this checkout's ``src/`` and one with the baseline's (a
``git archive`` of ``--baseline``, default 92ed2cf, the code before the compiled closed loop,
unpacked in a temporary directory with its own numba cache); which side goes first alternates
by round, so machine load falls on both alike. Each worker first runs one untimed run per
member (compiling the kernels for its CPU target into its cache the first time, loading them
after), then times ``--runs`` runs of each member (runs 0..runs-1 of ``config/config.yaml``'s
UAV model, seed 1) with BLAS pinned to one thread, and reports seconds per run. The table gives
the median over rounds of ms per run for each side and their ratio (baseline / this code: >1
is faster). Each worker also reports which closed loop each member took
(:func:`rsmhp.models.uav.loop.path`; the baseline has only the Python loop) and a digest of
every step row of its timed runs (float hex of every column): the last column says whether
this code's rows are the baseline's, bit for bit, on that CPU path.

    .venv/bin/python benchmarks/closed_loop.py [--baseline 92ed2cf] [--rounds 5] [--runs 10]
        [--paths native,avx2] [--members nbo,rsmhp_nt16,...] [--json out.json]

About 10 minutes with the defaults on a 2-core machine, of which a few minutes compile the
baseline's and this code's kernels for each CPU path (once per cache; the caches are kept in
``--cache`` between invocations, default a directory under the system's temporary directory).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "config.yaml"
PATHS = ("native", "avx2")
#: the issue's families: NBO, RS-MHP N_T = 16..256, RQMC, antithetic, pruned tree, sigma points,
#: tree search
MEMBERS = (
    "nbo",
    "rsmhp_nt16",
    "rsmhp_nt64",
    "rsmhp_nt256",
    "rqmc_nt64",
    "antithetic_nt64",
    "tree_n8_m100",
    "sigma",
    "dpw_s30",
)

WORKER = r"""
import hashlib, json, sys, time
import yaml
from threadpoolctl import threadpool_limits
from rsmhp.models.uav.simulation import UAVSetup, simulate_run
from rsmhp.models.uav.methods import from_name
members, runs, config = sys.argv[1].split(","), int(sys.argv[2]), sys.argv[3]
setup = UAVSetup.from_config(yaml.safe_load(open(config))["uav"])
try:
    from rsmhp.models.uav import loop
except ImportError:
    loop = None
out = {"seconds": {}, "path": {}, "rows": {}}
def text(v):
    return v.hex() if isinstance(v, float) else repr(v)
with threadpool_limits(limits=1):
    for name in members:
        m = from_name(name)
        simulate_run(setup, m, 1, 0)  # compile or load the kernels, fill caches
        digest = hashlib.blake2b(digest_size=12)
        t0 = time.perf_counter()
        for r in range(runs):
            _, rows = simulate_run(setup, m, 1, r)
            digest.update(repr([[text(v) for v in row.values()] for row in rows]).encode())
        out["seconds"][name] = (time.perf_counter() - t0) / runs
        out["rows"][name] = digest.hexdigest()
        out["path"][name] = loop.path(m, setup)[0] if loop is not None else "python"
print("RESULT " + json.dumps(out))
"""


def _env(path: str, src: Path, cache: Path) -> dict[str, str]:
    env = dict(os.environ)
    if path == "avx2":
        sys.path.insert(0, str(ROOT / "src"))
        from rsmhp.report.portability.emulation import cpu_target_env, numpy_avx512_targets

        env = cpu_target_env(env, numpy_disable=numpy_avx512_targets())
    env["PYTHONPATH"] = str(src)
    env["NUMBA_CACHE_DIR"] = str(cache)
    env["OMP_NUM_THREADS"] = env["OPENBLAS_NUM_THREADS"] = "1"
    return env


def _worker(path: str, src: Path, cache: Path, members: list[str], runs: int) -> dict:
    proc = subprocess.run(
        [sys.executable, "-c", WORKER, ",".join(members), str(runs), str(CONFIG)],
        env=_env(path, src, cache),
        cwd=str(ROOT),
        capture_output=True,
        text=True,
        check=False,
    )
    line = next((x for x in proc.stdout.splitlines() if x.startswith("RESULT ")), None)
    if proc.returncode != 0 or line is None:
        raise SystemExit(f"worker ({path}, {src}) failed:\n{proc.stderr[-3000:]}")
    return json.loads(line[len("RESULT ") :])


def _baseline(rev: str, where: Path) -> Path:
    """``src/`` of ``rev`` unpacked under ``where`` (reused when already there)."""
    dest = where / f"baseline-{rev}"
    if not (dest / "src" / "rsmhp").is_dir():
        dest.mkdir(parents=True, exist_ok=True)
        archive = subprocess.run(
            ["git", "-C", str(ROOT), "archive", rev, "src"], capture_output=True, check=True
        ).stdout
        tar = dest / "src.tar"
        tar.write_bytes(archive)
        with tarfile.open(tar) as t:
            t.extractall(dest, filter="data")
        tar.unlink()
    return dest / "src"


def _machine() -> str:
    model = "unknown CPU"
    flags = ""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name") and model == "unknown CPU":
                model = line.split(":", 1)[1].strip()
            if line.startswith("flags") and not flags:
                flags = line
    except OSError:
        pass
    avx512 = "AVX-512" if " avx512f" in flags else "no AVX-512"
    return f"{model}, {os.cpu_count()} cores, {avx512}, {platform.python_version()}"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(
        prog="benchmarks/closed_loop.py", description=__doc__.split("\n")[0]
    )
    ap.add_argument("--baseline", default="92ed2cf", help="git revision to compare with")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--runs", type=int, default=10, help="timed runs per member per worker")
    ap.add_argument("--paths", default=",".join(PATHS), help="native, avx2 or both")
    ap.add_argument("--members", default=",".join(MEMBERS))
    ap.add_argument("--cache", type=Path, default=Path(tempfile.gettempdir()) / "rsmhp-bench")
    ap.add_argument("--json", type=Path, default=None)
    a = ap.parse_args(argv)
    paths = [p for p in a.paths.split(",") if p]
    for p in paths:
        if p not in PATHS:
            ap.error(f"--paths: {p!r} is not one of {list(PATHS)}")
    if a.rounds < 1 or a.runs < 1:
        ap.error(f"--rounds and --runs must be >= 1, got {a.rounds} and {a.runs}")
    members = [m for m in a.members.split(",") if m]
    sides = {"baseline": _baseline(a.baseline, a.cache), "this": ROOT / "src"}
    head = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
    ).stdout.strip()
    print(f"machine: {_machine()}")
    print(f"baseline {a.baseline} against this code ({head}, working tree), {a.rounds} rounds x "
          f"{a.runs} runs per member, ms per closed-loop run (median over rounds)")  # fmt: skip
    results: dict = {}
    for p in paths:
        times: dict[str, dict[str, list[float]]] = {s: {m: [] for m in members} for s in sides}
        loops: dict[str, str] = {}
        digests: dict[str, dict[str, set[str]]] = {s: {m: set() for m in members} for s in sides}
        for r in range(a.rounds):
            order = list(sides) if r % 2 == 0 else list(reversed(sides))
            for side in order:
                cache = a.cache / f"numba-{side}-{p}"
                out = _worker(p, sides[side], cache, members, a.runs)
                for m in members:
                    times[side][m].append(out["seconds"][m])
                    digests[side][m].add(out["rows"][m])
                if side == "this":
                    loops = out["path"]
            print(f"  {p}: round {r + 1}/{a.rounds} done", file=sys.stderr)
        print(f"\n{p}:")
        print("| member | loop | baseline (ms) | this (ms) | ratio | rows as baseline's |")
        print("|---|---|---|---|---|---|")
        results[p] = {}
        for m in members:
            b = statistics.median(times["baseline"][m]) * 1e3
            t = statistics.median(times["this"][m]) * 1e3
            same = len(digests["this"][m] | digests["baseline"][m]) == 1
            results[p][m] = {
                "baseline_ms": b, "this_ms": t, "ratio": b / t, "loop": loops[m], "same_rows": same,
            }  # fmt: skip
            flag = "yes" if same else "NO"
            print(f"| {m} | {loops[m]} | {b:.2f} | {t:.2f} | {b / t:.2f}x | {flag} |")
    if a.json is not None:
        a.json.write_text(json.dumps({"machine": _machine(), "results": results}, indent=1))


if __name__ == "__main__":
    main()
