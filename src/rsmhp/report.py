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
import os
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd
import yaml

__all__ = [
    "VERDICTS",
    "Claim",
    "Section",
    "claims_list",
    "claims_table",
    "markdown_table",
    "provenance",
    "render_report",
]

VERDICTS = ("supported", "not supported", "inconclusive")


@dataclass(frozen=True)
class Claim:
    """One claim of the paper, the experiment that tests it, the measurement and a verdict."""

    id: str
    claim: str
    source: str
    experiment: str
    measured: str
    verdict: str

    def __post_init__(self) -> None:
        if self.verdict not in VERDICTS:
            raise ValueError(f"verdict must be one of {VERDICTS}, got {self.verdict!r}")


@dataclass
class Section:
    """A report section: title, Markdown body, claims, and figure file names it references."""

    key: str
    title: str
    order: int
    body: str
    claims: list[Claim] = field(default_factory=list)
    figures: list[str] = field(default_factory=list)

    def save(self, path: str | os.PathLike) -> None:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        Path(path).write_text(json.dumps(asdict(self), indent=2) + "\n", encoding="utf-8")

    @classmethod
    def load(cls, path: str | os.PathLike) -> Section:
        try:
            data = json.loads(Path(path).read_text(encoding="utf-8"))
            data["claims"] = [Claim(**c) for c in data.get("claims", [])]
            return cls(**data)
        except (OSError, ValueError, TypeError, KeyError) as exc:
            raise ValueError(
                f"{path}: not a valid report section ({exc}); rerun the rule that writes it"
            ) from exc


def _escape(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def markdown_table(df: pd.DataFrame, floatfmt: str = ".4g") -> str:
    """Markdown table without index; integer columns in full, floats with ``floatfmt``."""
    fmts = ["d" if pd.api.types.is_integer_dtype(t) else floatfmt for t in df.dtypes]
    return df.to_markdown(index=False, floatfmt=fmts)


def claims_list(claims: Iterable[Claim]) -> list[str]:
    """One Markdown bullet per claim, ``- **ID** (verdict): claim. Measured: ...``, for a
    section's "Claims" list."""
    return [f"- **{c.id}** ({c.verdict}): {c.claim}. Measured: {c.measured}." for c in claims]


def claims_table(claims: Iterable[Claim]) -> str:
    """Markdown table of claims (the ledger)."""
    lines = [
        "| id | claim (paper) | source | measured | verdict |",
        "|---|---|---|---|---|",
    ]
    for c in claims:
        lines.append(
            f"| {c.id} | {_escape(c.claim)} | {_escape(c.source)} | {_escape(c.measured)} "
            f"| **{c.verdict}** |"
        )
    return "\n".join(lines)


def render_report(
    sections: Iterable[Section], config: Mapping[str, Any], provenance: Mapping[str, str]
) -> str:
    """Render the full report: header, claims ledger, sections in order, parameters appendix."""
    sections = sorted(sections, key=lambda s: (s.order, s.key))
    all_claims = [c for s in sections for c in s.claims]
    counts = {v: sum(c.verdict == v for c in all_claims) for v in VERDICTS}
    parts = [
        "# rsmhp replication report",
        "",
        "Replication of Ragi & Mittelmann, *Random-Sampling Monte-Carlo Tree Search Methods for "
        "Cost Approximation in Long-Horizon Optimal Control*, IEEE Control Systems Letters 5(5), "
        "2021. This file is written by the pipeline (`snakemake report`); do not edit it by "
        "hand. Every number below comes from `results/` of the same run.",
        "",
        "## Provenance",
        "",
        "Code, config and software of this run (host and date: `results/provenance.json`). "
        "LQG, estimator and LQG-decision numbers are bitwise reproducible with the same "
        "versions, BLAS and CPU flags; UAV closed-loop numbers pass through an optimiser and "
        "60 feedback steps and can move with any of them (see the README).",
        "",
        *(f"- {k}: `{v}`" for k, v in provenance.items()),
        "",
        "## Claims ledger",
        "",
        f"{len(all_claims)} claims: "
        + ", ".join(f"{n} {v}" for v, n in counts.items())
        + ". Verdict rules are stated with each claim's section.",
        "",
        claims_table(all_claims),
        "",
    ]
    for s in sections:
        parts += [f"## {s.title}", "", s.body.strip(), ""]
    parts += [
        "## Appendix: parameters of this run",
        "",
        "The validated configuration (defaults filled in), exactly as the pipeline used it:",
        "",
        "```yaml",
        yaml.safe_dump(dict(config), sort_keys=False).strip(),
        "```",
        "",
    ]
    return "\n".join(parts)


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
    CPU model and vector flags, worker threads, host and UTC date.

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
        canon = json.dumps(config, sort_keys=True, default=str).encode()
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
