"""The claims ledger's data model: a claim (:class:`Claim`) with the key number its verdict rests
on (:class:`KeyNumber`), and a study's report section (:class:`Section`) as the aggregation
rules write it (``results/report/<key>.json``). Statistics live in :mod:`rsmhp.core.stats` and
``rsmhp.analysis``, verdict rules in :mod:`rsmhp.report.verdicts`, rendering in
:mod:`rsmhp.report.render`.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from rsmhp.report.markdown import fmt, fmt_ci

__all__ = [
    "CLAIM_OUTCOMES",
    "OVER_BUDGET",
    "PARTS",
    "REPRODUCIBILITY",
    "STATEMENT_VERDICTS",
    "VERDICTS",
    "Claim",
    "KeyNumber",
    "Section",
    "claims_records",
]

#: verdicts of a claim: its key number's CI lies on the claimed side (``supported``), on the
#: opposite side (``not supported``), inside the claim's equivalence margin ±m so that any
#: difference is smaller than m (``equivalent``), or none of these (``inconclusive``)
VERDICTS = ("supported", "not supported", "equivalent", "inconclusive")

#: what a preregistered claim gets instead of a verdict when a compared member spent more than
#: the budget allows on the confirmatory run (its rule says by how much): no verdict at all
OVER_BUDGET = "over budget"
#: every outcome a claim can have: a verdict, or :data:`OVER_BUDGET`
CLAIM_OUTCOMES = (*VERDICTS, OVER_BUDGET)

#: verdicts of a paper statement with several pieces of evidence: a claim verdict, ``mixed``
#: when its pieces of evidence disagree, ``not tested`` on a kind of setup without evidence
#: (:mod:`rsmhp.report.statements`)
STATEMENT_VERDICTS = (*VERDICTS, "mixed", "not tested")

#: the two parts of the ledger: ``paper`` (a statement of the paper tested on the paper's own
#: setup) and ``beyond`` (claims the report derives itself, and tests on model variants)
PARTS = ("paper", "beyond")

#: how a claim's key number reproduces: ``bitwise`` (same code, config, package versions, BLAS
#: and CPU flags give identical bits; elsewhere it agrees to rounding) or ``statistical``
#: (passes through an optimiser or a closed loop, so another machine gives a different draw
#: of the same distribution; agreement is judged with the CI)
REPRODUCIBILITY = ("bitwise", "statistical")


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
    #: p-value of the test behind the verdict (:func:`rsmhp.report.verdicts.decisive_p`), where the
    #: claim belongs to a family corrected for multiplicity; ``p_holm``: its Holm-adjusted
    #: value over that family (:func:`rsmhp.report.verdicts.holm_correct`)
    p_value: float | None = None
    p_holm: float | None = None
    #: ``n``: the number of independent units the CI rests on (runs, belief states), where
    #: the key number is a mean over them; ``margin``: the rule's margin Δ (equivalence or
    #: non-inferiority), fixed before the run. Both feed the runs needed at 80% power
    #: (:func:`rsmhp.report.power.runs_needed`); ``None`` where they do not apply.
    n: int | None = None
    margin: float | None = None

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
        if self.n is not None and not (isinstance(self.n, int) and self.n >= 2):
            raise ValueError(f"key number {self.name!r}: n must be an integer >= 2, got {self.n!r}")
        if self.margin is not None and not (
            isinstance(self.margin, int | float) and math.isfinite(self.margin) and self.margin > 0
        ):
            raise ValueError(
                f"key number {self.name!r}: margin must be a finite number > 0, got {self.margin!r}"
            )

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
    """One claim: what is tested (``claim``, our words, with its scope), what the paper
    states and where (``paper``), the key number with its CI, the verdict, and the rule that
    gave it. ``measured`` holds the supporting numbers (appendix), ``dropped`` names every
    problem or cell left out of the evidence and why.

    ``part`` is one of :data:`PARTS`; ``setup`` names the model and setting the claim was
    tested on (the paper's, or a named variant); which statement of the paper a claim is
    evidence for is said once, in :data:`rsmhp.report.statements.STATEMENTS`. ``contrary`` names
    every cell or setting whose CI lies on the side opposite to the claim (printed next to
    the claim in the main text). ``check`` marks a check of our own machinery against a
    closed form (counted apart from the findings)."""

    id: str
    claim: str
    paper: str
    key: KeyNumber
    verdict: str
    rule: str
    measured: str = ""
    dropped: str = ""
    part: str = "paper"
    setup: str = "paper"
    contrary: str = ""
    #: a check of our own machinery (simulation, estimator or optimiser against a closed
    #: form), not a finding: counted apart from the findings, in an appendix part of its own
    check: bool = False

    def __post_init__(self) -> None:
        if self.verdict not in CLAIM_OUTCOMES:
            raise ValueError(f"verdict must be one of {CLAIM_OUTCOMES}, got {self.verdict!r}")
        if not self.rule.strip():
            raise ValueError(f"claim {self.id}: the verdict rule is missing")
        if self.part not in PARTS:
            raise ValueError(f"claim {self.id}: part must be one of {PARTS}, got {self.part!r}")
        if not self.setup.strip():
            raise ValueError(f"claim {self.id}: the setup it was tested on is missing")
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
        """Write the section atomically as JSON; in a rule, with the code stamp ``code``."""
        from rsmhp.pipeline.io import write_json

        Path(path).parent.mkdir(parents=True, exist_ok=True)
        write_json(asdict(self), path)

    @classmethod
    def load(cls, path: str | os.PathLike) -> Section:
        try:
            data = json.loads(Path(path).read_text(encoding="utf-8"))
            data.pop("code", None)  # the code stamp (rsmhp.pipeline.io), checked by the report rule
            data["claims"] = [Claim.from_dict(c) for c in data.get("claims", [])]
            return cls(**data)
        except (OSError, ValueError, TypeError, KeyError) as exc:
            raise ValueError(
                f"{path}: not a valid report section ({exc}); rerun the rule that writes it"
            ) from exc


def claims_records(sections: Iterable[Section]) -> list[dict[str, Any]]:
    """Every claim as a JSON-ready dict (``results/paper/claims.json``; ``make publish``
    copies it to the committed reference ``paper/claims.json`` that ``make verify`` uses)."""
    return [asdict(c) for s in sorted(sections, key=lambda s: (s.order, s.key)) for c in s.claims]
