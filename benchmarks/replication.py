"""Wall time of the full default replication, from an empty ``results/``, for several core
counts and (optionally) against another checkout, each run in a fresh working directory.

    .venv/bin/python benchmarks/replication.py                      # -j1 and -j2, this checkout
    .venv/bin/python benchmarks/replication.py --cores 2 --baseline /tmp/rsmhp-d90d881
    .venv/bin/python benchmarks/replication.py --repeat 2 -- --config threads=2

Runs ``<checkout>/.venv/bin/snakemake -s <checkout>/Snakefile --directory <tmp> -j<cores>``
(every run writes its own ``results/`` under a temporary directory, so the checkout's own
results are never touched) in alternating order (this checkout, then the baseline, for each
core count and repeat: a machine whose speed drifts affects both sides alike) and prints per
run the wall time, the sum of the jobs' wall times from Snakemake's ``benchmark:`` files and
``fill`` = sum / (cores x wall) (a job on two threads counts once, so with ``-j2`` and
two-thread jobs the cores were busier than ``fill`` says), then the ratios: ``-j1`` over each
other core count (the parallel speed-up) and the baseline over this checkout. Extra arguments
after ``--`` go to every Snakemake call. The baseline must have set up its own ``.venv``
(``make setup`` in that checkout) and compiled its kernels once (a first run does it).
Takes about 7 min per ``-j1`` run and 4 min per ``-j2`` run on a 2-core machine.
"""

from __future__ import annotations

import argparse
import csv
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def job_seconds(workdir: Path) -> tuple[int, float]:
    """(number of jobs, sum of their wall seconds) from the run's ``benchmark:`` files."""
    files = sorted((workdir / "results" / "benchmarks").rglob("*.tsv"))
    total = 0.0
    for f in files:
        with f.open() as fh:
            rows = list(csv.DictReader(fh, delimiter="\t"))
        total += float(rows[-1]["s"])
    return len(files), total


def run(root: Path, cores: int, extra: list[str]) -> dict[str, float]:
    """One full replication of checkout ``root`` on ``cores`` cores in a fresh directory."""
    snakemake = root / ".venv" / "bin" / "snakemake"
    if not snakemake.exists():
        sys.exit(f"{snakemake} not found: run `make setup` in {root} first")
    with tempfile.TemporaryDirectory(prefix="rsmhp-replication-") as tmp:
        cmd = [str(snakemake), "-s", str(root / "Snakefile"), "--directory", tmp]
        cmd += [f"-j{cores}", "--quiet", "all", *extra]
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            sys.exit(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr[-3000:]}")
        n, busy = job_seconds(Path(tmp))
    return {"wall": wall, "jobs": n, "busy": busy, "fill": busy / (cores * wall)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cores", type=int, nargs="+", default=[1, 2], help="core counts (-j)")
    ap.add_argument("--baseline", type=Path, help="another checkout with its own .venv")
    ap.add_argument("--repeat", type=int, default=1, help="runs per (checkout, cores)")
    ap.add_argument("extra", nargs="*", help="arguments for snakemake (after --)")
    args = ap.parse_args()
    if any(c < 1 for c in args.cores) or args.repeat < 1:
        ap.error(f"--cores and --repeat must be >= 1, got {args.cores} and {args.repeat}")
    sides = {"this": ROOT} | ({"baseline": args.baseline.resolve()} if args.baseline else {})
    walls: dict[tuple[str, int], list[float]] = {}
    print(f"{'checkout':9} {'-j':>3} {'wall s':>8} {'jobs':>5} {'sum of jobs s':>14} {'fill':>6}")
    for _ in range(args.repeat):
        for cores in args.cores:
            for side, root in sides.items():
                r = run(root, cores, args.extra)
                walls.setdefault((side, cores), []).append(r["wall"])
                print(
                    f"{side:9} {cores:>3} {r['wall']:8.1f} {r['jobs']:5d} {r['busy']:14.1f} "
                    f"{r['fill']:6.2f}",
                    flush=True,
                )
    med = {k: statistics.median(v) for k, v in walls.items()}
    for side in sides:
        if (side, 1) in med:
            for cores in args.cores:
                if cores > 1:
                    ratio = med[(side, 1)] / med[(side, cores)]
                    print(f"{side}: -j1 / -j{cores} = {ratio:.2f}x")
    if args.baseline:
        for cores in args.cores:
            ratio = med[("baseline", cores)] / med[("this", cores)]
            print(f"-j{cores}: baseline / this = {ratio:.2f}x")


if __name__ == "__main__":
    main()
