"""The replication report: a claims ledger plus one section per experiment family.

Each aggregation rule writes a :class:`Section` as JSON (``results/report/<key>.json``): its
Markdown body (tables inline, figures referenced as ``figures/<name>.png``) and its
:class:`Claim` s. The ``report`` rule renders every section, in ``order``, into
``paper/replication.md`` and copies the referenced figures to ``paper/figures/``. A new
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


def provenance() -> dict[str, str]:
    """Versions of the interpreter and of every package that shaped the numbers."""
    import platform
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version()}
    for pkg in (
        "rsmhp",
        "numpy",
        "scipy",
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
    return out
