"""The replication report: a claims ledger plus one section per experiment family.

Each aggregation rule writes a :class:`Section` as JSON (``results/report/<key>.json``): its
Markdown body (tables inline, figures referenced as ``figures/<name>.png``) and its
:class:`Claim` s. The ``report`` rule renders every section, in ``order``, into
``results/paper/replication.md`` and copies the referenced figures to ``results/paper/figures/``
(``make publish`` copies both to the tracked ``paper/``). A new
experiment family adds a section file and one entry to the report rule's inputs; nothing
else changes.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import yaml

__all__ = [
    "REPRODUCIBILITY",
    "VERDICTS",
    "Claim",
    "KeyNumber",
    "Section",
    "claims_records",
    "claims_table",
    "fmt",
    "fmt_ci",
    "glance_table",
    "markdown_table",
    "provenance",
    "render_appendix",
    "render_report",
    "splice",
]

VERDICTS = ("supported", "not supported", "inconclusive")

#: how a claim's key number reproduces: ``bitwise`` (same code, config, package versions, BLAS
#: and CPU flags give identical bits; elsewhere it agrees to rounding) or ``statistical``
#: (passes through an optimiser or a closed loop, so another machine gives a different draw
#: of the same distribution; agreement is judged with the CI)
REPRODUCIBILITY = ("bitwise", "statistical")


def fmt(x: float | int, digits: int = 3, signed: bool = False) -> str:
    """``x`` with ``digits`` significant digits (integers in full, no exponent between 1e-4
    and 1e6); ``signed`` puts a + on positive numbers. NaN and inf raise ``ValueError``: a
    value that is absent must be explained in words, not printed as nan."""
    if isinstance(x, bool):
        raise TypeError(f"fmt expects a number, got bool {x!r}")
    xf = float(x)
    if not math.isfinite(xf):
        raise ValueError(f"cannot format {x!r}: say in words why the value is absent")
    sign = "+" if signed and xf > 0 else ""
    if float(xf).is_integer() and abs(xf) < 1e15 and (isinstance(x, int) or abs(xf) >= 10**digits):
        return f"{sign}{int(xf)}"
    if xf == 0.0:
        return "0"
    mag = math.floor(math.log10(abs(xf)))
    if -4 <= mag < 6:
        decimals = max(digits - 1 - mag, 0)
        return f"{sign}{xf:.{decimals}f}"
    return f"{sign}{xf:.{digits - 1}e}"


def fmt_ci(lo: float, hi: float, digits: int = 3, signed: bool = False) -> str:
    """``[lo, hi]``, both with ``digits`` significant digits of the larger magnitude."""
    ref = max(abs(float(lo)), abs(float(hi)))
    if ref == 0.0 or not math.isfinite(ref):
        return f"[{fmt(lo, digits, signed)}, {fmt(hi, digits, signed)}]"
    mag = math.floor(math.log10(ref))
    if -4 <= mag < 6:
        decimals = max(digits - 1 - mag, 0)
        s = "+" if signed else ""
        return f"[{float(lo):{s}.{decimals}f}, {float(hi):{s}.{decimals}f}]"
    return f"[{fmt(lo, digits, signed)}, {fmt(hi, digits, signed)}]"


@dataclass(frozen=True)
class KeyNumber:
    """The one number a claim's verdict rests on, with its 95% CI where it is an estimate.

    ``null`` is the value that would mean the opposite of the claim (e.g. 0 for a paired
    difference): a claim cannot be ``supported`` while its CI contains ``null``.
    ``reproducible`` is one of :data:`REPRODUCIBILITY`; statistical numbers need a CI (it
    gives ``make verify`` its tolerance)."""

    name: str
    value: float
    ci_low: float | None = None
    ci_high: float | None = None
    unit: str = ""
    reproducible: str = "bitwise"
    digits: int = 3
    null: float | None = None

    def __post_init__(self) -> None:
        if self.reproducible not in REPRODUCIBILITY:
            raise ValueError(
                f"reproducible must be one of {REPRODUCIBILITY}, got {self.reproducible!r}"
            )
        values = [self.value] + [v for v in (self.ci_low, self.ci_high) if v is not None]
        if not all(isinstance(v, int | float) and math.isfinite(v) for v in values):
            raise ValueError(f"key number {self.name!r}: value and CI must be finite, got {values}")
        if (self.ci_low is None) != (self.ci_high is None):
            raise ValueError(f"key number {self.name!r}: give both CI limits or neither")
        if self.ci_low is not None and not self.ci_low <= self.ci_high:
            raise ValueError(f"key number {self.name!r}: CI [{self.ci_low}, {self.ci_high}]")
        if self.reproducible == "statistical" and self.ci_low is None:
            raise ValueError(f"key number {self.name!r}: a statistical number needs its CI")

    @property
    def has_ci(self) -> bool:
        return self.ci_low is not None

    def text(self) -> str:
        """``name = value [lo, hi] unit`` with the number's significant digits."""
        signed = self.null == 0.0
        out = fmt(self.value, self.digits, signed)
        if self.has_ci:
            out += " " + fmt_ci(self.ci_low, self.ci_high, self.digits, signed)
        return f"{self.name} = {out}{' ' + self.unit if self.unit else ''}"


@dataclass(frozen=True)
class Claim:
    """One claim: what is tested (``claim``, our words), what the paper states and where
    (``paper``), the key number with its CI, the verdict, and the rule that gave it.
    ``measured`` holds the supporting numbers (appendix), ``dropped`` names every problem or
    cell left out of the evidence and why."""

    id: str
    claim: str
    paper: str
    key: KeyNumber
    verdict: str
    rule: str
    measured: str = ""
    dropped: str = ""

    def __post_init__(self) -> None:
        if self.verdict not in VERDICTS:
            raise ValueError(f"verdict must be one of {VERDICTS}, got {self.verdict!r}")
        if not self.rule.strip():
            raise ValueError(f"claim {self.id}: the verdict rule is missing")
        k = self.key
        if self.verdict == "supported" and k.null is not None and k.has_ci:
            if k.ci_low <= k.null <= k.ci_high:
                raise ValueError(
                    f"claim {self.id}: 'supported' although the CI [{k.ci_low}, {k.ci_high}] "
                    f"of {k.name} contains {k.null}, the value of the opposite claim"
                )

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Claim:
        data = dict(data)
        data["key"] = KeyNumber(**data["key"])
        return cls(**data)


@dataclass
class Section:
    """A report section: title, short Markdown ``body`` for the main text (figures referenced
    as ``figures/<name>.png``), ``appendix`` Markdown (tables, secondary numbers), claims, and
    figure file names it references."""

    key: str
    title: str
    order: int
    body: str
    claims: list[Claim] = field(default_factory=list)
    figures: list[str] = field(default_factory=list)
    appendix: str = ""

    def save(self, path: str | os.PathLike) -> None:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        Path(path).write_text(json.dumps(asdict(self), indent=2) + "\n", encoding="utf-8")

    @classmethod
    def load(cls, path: str | os.PathLike) -> Section:
        try:
            data = json.loads(Path(path).read_text(encoding="utf-8"))
            data["claims"] = [Claim.from_dict(c) for c in data.get("claims", [])]
            return cls(**data)
        except (OSError, ValueError, TypeError, KeyError) as exc:
            raise ValueError(
                f"{path}: not a valid report section ({exc}); rerun the rule that writes it"
            ) from exc


def _escape(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def markdown_table(
    df: pd.DataFrame, digits: int = 4, missing: str | None = None, signed: Sequence[str] = ()
) -> str:
    """Markdown table without index. Integer columns (and float columns whose values are all
    whole numbers) print as integers, other floats with ``digits`` significant digits (per
    cell). NaN/inf cells raise ``ValueError`` naming the column unless ``missing`` gives the
    text to print instead (explain it next to the table); ``signed`` columns get a + sign.
    A ``|`` inside a text cell is escaped (it would end the cell)."""
    out = pd.DataFrame(index=df.index)
    align = []
    for col in df.columns:
        s = df[col]
        text = pd.api.types.is_bool_dtype(s) or not pd.api.types.is_numeric_dtype(s)
        align.append("left" if text else "right")
        if text:
            bad = s.isna()
            if bad.any() and missing is None:
                raise ValueError(f"table column {col!r} has {int(bad.sum())} missing cell(s)")
            cells = s.astype(object).where(~bad, missing).astype(str)
            out[col] = cells.str.replace("|", "\\|", regex=False)  # a bare | ends the cell
            continue
        x = s.astype(float)
        finite = np.isfinite(x)
        if (~finite).any() and missing is None:
            raise ValueError(
                f"table column {col!r} has {int((~finite).sum())} NaN/inf cell(s); pass "
                "missing= with the reason, or drop them"
            )
        whole = bool(finite.any()) and bool((x[finite] == np.round(x[finite])).all())
        whole = whole and (pd.api.types.is_integer_dtype(s) or bool((x[finite].abs() < 1e15).all()))
        cells = []
        for v, ok in zip(x, finite, strict=True):
            if not ok:
                cells.append(missing)
            elif whole:
                cells.append(("+" if col in signed and v > 0 else "") + str(int(v)))
            else:
                cells.append(fmt(v, digits, col in signed))
        out[col] = cells
    return out.to_markdown(index=False, disable_numparse=True, colalign=align)


def _ledger_number(c: Claim) -> str:
    k = c.key
    signed = k.null == 0.0
    out = fmt(k.value, k.digits, signed)
    if k.has_ci:
        out += " " + fmt_ci(k.ci_low, k.ci_high, k.digits, signed)
    return f"{k.name}: {out}{' ' + k.unit if k.unit else ''}"


def claims_table(claims: Iterable[Claim]) -> str:
    """The claims ledger: claim, the paper's statement, our key number with its 95% CI,
    verdict and the rule that gave it."""
    lines = [
        "| id | claim | paper | our number (95% CI) | verdict | verdict rule |",
        "|---|---|---|---|---|---|",
    ]
    for c in claims:
        lines.append(
            f"| {c.id} | {_escape(c.claim)} | {_escape(c.paper)} | {_escape(_ledger_number(c))} "
            f"| **{c.verdict}** | {_escape(c.rule)} |"
        )
    return "\n".join(lines)


def glance_table(claims: Iterable[Claim]) -> str:
    """The README's "results at a glance": id, claim, key number with CI, verdict."""
    lines = ["| id | claim | our number (95% CI) | verdict |", "|---|---|---|---|"]
    for c in claims:
        lines.append(
            f"| {c.id} | {_escape(c.claim)} | {_escape(_ledger_number(c))} | {c.verdict} |"
        )
    return "\n".join(lines)


def claims_records(sections: Iterable[Section]) -> list[dict[str, Any]]:
    """Every claim as a JSON-ready dict (``results/paper/claims.json``; ``make publish``
    copies it to the committed reference ``paper/claims.json`` that ``make verify`` uses)."""
    return [asdict(c) for s in sorted(sections, key=lambda s: (s.order, s.key)) for c in s.claims]


VERDICT_POLICY = (
    "Every verdict comes from the rule printed next to it. The rules share one principle: a "
    "claim is **supported** only when the 95% confidence interval (CI) of its key number lies "
    "entirely on the claimed side (or a derived value is met within its statistical "
    "tolerance), **not supported** when the evidence lies on the opposite side or contradicts "
    "a closed form, and **inconclusive** otherwise. A claim cannot be marked supported while "
    "its key number's CI contains the value of the opposite claim (checked when the report is "
    "built). Where a problem or cell is left out of the evidence, the claim's details in the "
    "appendix name it and say why."
)


def render_report(
    sections: Iterable[Section], provenance: Mapping[str, str], appendix: str = "appendix.md"
) -> str:
    """The main text: introduction, claims ledger, one section per study (in ``order``), a
    short provenance note; details go to :func:`render_appendix` (file ``appendix``)."""
    sections = sorted(sections, key=lambda s: (s.order, s.key))
    all_claims = [c for s in sections for c in s.claims]
    counts = {v: sum(c.verdict == v for c in all_claims) for v in VERDICTS}
    n_bit = sum(c.key.reproducible == "bitwise" for c in all_claims)
    parts = [
        "# rsmhp replication report",
        "",
        "Replication of Ragi & Mittelmann, *Random-Sampling Monte-Carlo Tree Search Methods for "
        "Cost Approximation in Long-Horizon Optimal Control*, IEEE Control Systems Letters 5(5), "
        "2021. Written by the pipeline (`snakemake report`) from `results/` of one run; tables, "
        f"claim details, parameters and provenance are in [{appendix}]({appendix}).",
        "",
        "## Claims ledger",
        "",
        f"{len(all_claims)} claims: "
        + ", ".join(f"{n} {v}" for v, n in counts.items())
        + f". {n_bit} key numbers are bitwise reproducible (same code, config, versions, BLAS "
        f"and CPU flags), {len(all_claims) - n_bit} statistically (UAV closed loop and "
        "optimiser; `make verify` compares a run with the committed reference, "
        "`paper/claims.json`). " + VERDICT_POLICY,
        "",
        claims_table(all_claims),
        "",
    ]
    for s in sections:
        parts += [f"## {s.title}", "", s.body.strip(), ""]
    parts += [
        "## Provenance",
        "",
        "This run: commit `{}`{}, config sha256 `{}`, Python {}, numpy {}, numba {}, BLAS {}, "
        "CPU {} ({}); full list in the appendix and `results/provenance.json`.".format(
            provenance.get("commit", "?")[:12],
            " (with uncommitted changes)"
            if provenance.get("uncommitted changes (outside paper/)") == "yes"
            else "",
            provenance.get("config sha256", "?"),
            provenance.get("python", "?"),
            provenance.get("numpy", "?"),
            provenance.get("numba", "?"),
            provenance.get("blas", "?"),
            provenance.get("cpu", "?"),
            provenance.get("cpu flags", "?"),
        ),
        "",
    ]
    return "\n".join(parts)


_REPRO_TEXT = {"bitwise": "bitwise reproducible", "statistical": "statistically reproducible"}


def render_appendix(
    sections: Iterable[Section], config: Mapping[str, Any], provenance: Mapping[str, str]
) -> str:
    """The appendix: every claim in detail (rule, all measured numbers, what was left out),
    each study's tables and secondary results, the parameters of the run, provenance."""
    sections = sorted(sections, key=lambda s: (s.order, s.key))
    parts = [
        "# rsmhp replication report: appendix",
        "",
        "Details behind [the main text](replication.md), from the same run.",
        "",
        "## A. Claims in detail",
        "",
    ]
    for s in sections:
        for c in s.claims:
            parts += [
                f"### {c.id} ({c.verdict})",
                "",
                f"- Claim: {c.claim}",
                f"- Paper: {c.paper}",
                f"- Key number: {c.key.text()} ({_REPRO_TEXT[c.key.reproducible]})",
                f"- Verdict rule: {c.rule}",
            ]
            if c.measured:
                parts.append(f"- Measured: {c.measured}")
            if c.dropped:
                parts.append(f"- Left out: {c.dropped}")
            parts.append("")
    for i, s in enumerate(sections, start=1):
        if s.appendix.strip():
            parts += [f"## B{i}. {s.title}", "", s.appendix.strip(), ""]
    parts += [
        "## C. Parameters of this run",
        "",
        "The validated configuration (defaults filled in), exactly as the pipeline used it:",
        "",
        "```yaml",
        yaml.safe_dump(dict(config), sort_keys=False).strip(),
        "```",
        "",
        "## D. Provenance",
        "",
        "Host and date are in `results/provenance.json` (they change every run).",
        "",
        *(f"- {k}: `{v}`" for k, v in provenance.items()),
        "",
    ]
    return "\n".join(parts)


MARK_BEGIN = "<!-- results:begin (generated by `make publish`; do not edit) -->"
MARK_END = "<!-- results:end -->"


def splice(text: str, block: str, begin: str = MARK_BEGIN, end: str = MARK_END) -> str:
    """``text`` with the part between the ``begin`` and ``end`` marker lines replaced by
    ``block``; ``ValueError`` if the markers are missing or out of order."""
    i, j = text.find(begin), text.find(end)
    if i < 0 or j < 0 or j < i:
        raise ValueError(f"markers {begin!r} ... {end!r} not found (in this order)")
    return text[: i + len(begin)] + "\n" + block.strip() + "\n" + text[j:]


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

    root = Path(root) if root is not None else Path(__file__).resolve().parents[2]
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
        # for any worker count), so it is left out and shown on its own
        numbers = {k: v for k, v in config.items() if k != "threads"}
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


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m rsmhp.report splice FILE BLOCK``: replace the generated part of FILE (between
    :data:`MARK_BEGIN` and :data:`MARK_END`) by the contents of BLOCK (``make publish`` puts
    the glance table of ``results/paper/glance.md`` into the README this way)."""
    import argparse
    import sys

    p = argparse.ArgumentParser(prog="python -m rsmhp.report")
    sub = p.add_subparsers(dest="command", required=True)
    sp = sub.add_parser("splice", help="replace the generated block of FILE by BLOCK's text")
    sp.add_argument("file")
    sp.add_argument("block")
    args = p.parse_args(argv)
    try:
        text = Path(args.file).read_text(encoding="utf-8")
        new = splice(text, Path(args.block).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        print(f"splice: {exc}", file=sys.stderr)
        return 1
    if new != text:
        Path(args.file).write_text(new, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
