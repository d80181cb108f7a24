"""Choices made after their data were seen, said next to every verdict they touch.

A verdict whose rule (a margin) or scope (which setups count) was fixed after the result it
judges was known is exploratory, whatever it says, until a preregistered rerun judges it
again. The project's history holds such choices (found by an audit, issue 43); each is a
:class:`Disclosure`: the claims it touches (an id, or an id's prefix: ``DEC-7`` covers
``DEC-7-footprint150``), the commits that show when it was made, and its words (macros of
``disclosures.md`` beside this module: ``<macro>_short`` beside a verdict,
``<macro>_long`` in the main text's list). :func:`verdict_note` is what
:func:`rsmhp.report.findings.verdict_text` appends; :func:`disclosure_lines` is the list.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from rsmhp.report.ledger import Claim
from rsmhp.report.templates import Words

__all__ = ["DISCLOSURES", "Disclosure", "disclosure_lines", "disclosures_of", "verdict_note"]

WORDS = Words("rsmhp.report", "disclosures.md")


@dataclass(frozen=True)
class Disclosure:
    """A choice made after the data it judges were seen: ``claims`` (ids or id prefixes),
    ``macro`` (its words in ``disclosures.md``) and the ``values`` those words name (commits,
    dates)."""

    claims: tuple[str, ...]
    macro: str
    values: Mapping[str, Any] = field(default_factory=dict)

    def touches(self, claim_id: str) -> bool:
        """Whether ``claim_id`` is one of :attr:`claims` or starts with one and a hyphen."""
        return any(claim_id == p or claim_id.startswith(p + "-") for p in self.claims)


#: the choices of the project's history made after their data (git log; issue 43's audit)
DISCLOSURES: tuple[Disclosure, ...] = (
    Disclosure(
        ("UAV-1", "UAV-2", "UAV-3", "DEC-6", "DEC-7"),
        "margin_after_result",
        {
            "published": "d90d881",
            "published_date": "2026-11-23",
            "margin_commit": "cae91a3",
            "result": "UAV-2 inconclusive, −0.001 [−0.153, +0.154] m",
        },
    ),
    Disclosure(
        ("DEC-8b",),
        "moved_after_result",
        {"commit": "a300280", "date": "2026-11-27"},
    ),
)


def disclosures_of(
    claim_id: str, disclosures: Sequence[Disclosure] = DISCLOSURES
) -> list[Disclosure]:
    """The disclosures that touch claim ``claim_id``."""
    return [d for d in disclosures if d.touches(claim_id)]


def verdict_note(c: Claim, disclosures: Sequence[Disclosure] = DISCLOSURES) -> str:
    """What follows the verdict of ``c`` ("exploratory: margin set after the first result"),
    the disclosures' short words joined; empty when none touches it."""
    return "; ".join(WORDS(f"{d.macro}_short") for d in disclosures_of(c.id, disclosures))


def disclosure_lines(
    claims: Sequence[Claim], disclosures: Sequence[Disclosure] = DISCLOSURES
) -> list[str]:
    """One line per disclosure that touches a claim of this run: its long words, naming
    those claims."""
    out = []
    for d in disclosures:
        ids = [c.id for c in claims if d.touches(c.id)]
        if ids:
            out.append(WORDS(f"{d.macro}_long", claims=", ".join(ids), **d.values))
    return out
