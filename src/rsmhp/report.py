"""The replication report: renders the claims ledger, one section per study and the appendix.

Each aggregation rule writes a :class:`rsmhp.ledger.Section` as JSON
(``results/report/<key>.json``): its Markdown body (figures referenced as
``figures/<name>.png``), appendix and claims. The ``report`` rule renders every section, in
``order``, into ``results/paper/replication.md`` and ``appendix.md`` (``make publish`` copies
both to the tracked ``paper/``). This module only renders: statistics, verdict rules and each
study's prose live elsewhere (``rsmhp.analysis``, :mod:`rsmhp.verdicts`, ``rsmhp.narrative``),
provenance in :mod:`rsmhp.provenance`, the README block in :mod:`rsmhp.readme`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import yaml

from rsmhp.ledger import VERDICTS, Claim, Section
from rsmhp.markdown import escape, fmt, fmt_ci

__all__ = ["VERDICT_POLICY", "claims_table", "glance_table", "render_appendix", "render_report"]


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
            f"| {c.id} | {escape(c.claim)} | {escape(c.paper)} | {escape(_ledger_number(c))} "
            f"| **{c.verdict}** | {escape(c.rule)} |"
        )
    return "\n".join(lines)


def glance_table(claims: Iterable[Claim]) -> str:
    """The README's "results at a glance": id, claim, key number with CI, verdict."""
    lines = ["| id | claim | our number (95% CI) | verdict |", "|---|---|---|---|"]
    for c in claims:
        lines.append(f"| {c.id} | {escape(c.claim)} | {escape(_ledger_number(c))} | {c.verdict} |")
    return "\n".join(lines)


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
