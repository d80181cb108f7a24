r"""A claim as data: what it is (:class:`ClaimSpec`: id, setup, verdict rule, evidence function,
the template of its words) apart from the numbers one run gives it (:class:`Evidence`).

A study declares each claim once, as a :class:`ClaimSpec` in its ``claims`` module::

    LQG_2 = ClaimSpec(
        id="LQG-2",
        setup=SETUP,
        rule=FIG3_RULE,
        evidence=fig3_evidence,          # (summary) -> Evidence
        words=WORDS,                     # Words("rsmhp.studies.lqg", "claims.md")
    )
    claim = LQG_2.build(summary)

:meth:`ClaimSpec.build` calls the evidence function, evaluates the rule on the evidence's facts
and fills the claim's texts from the template's macros named after the claim: for the id
``LQG-2`` (or ``texts="lqg_2"``) the macros ``lqg_2_claim``, ``lqg_2_paper`` and, where the
template has them, ``lqg_2_measured``, ``lqg_2_dropped`` and ``lqg_2_contrary``, each called
with the evidence's ``values`` that it names. So the statistics stay in pure functions, the
rule in a small tested object (:mod:`rsmhp.report.verdicts`) and every sentence in the
template (:class:`rsmhp.report.templates.Words`).

An id or setup may hold ``{name}`` fields, filled from the evidence's ``values``
(``"HZ-1-{model}"``), so one spec serves a claim repeated per model or setting; the macro
names then come from ``texts`` (required for such an id).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from rsmhp.report.ledger import Claim, KeyNumber
from rsmhp.report.templates import Words
from rsmhp.report.verdicts import Facts, Rule

__all__ = ["TEXT_FIELDS", "ClaimSpec", "Evidence"]

#: the claim's texts a template may give, in :class:`rsmhp.report.ledger.Claim`'s field order;
#: ``claim`` and ``paper`` are required
TEXT_FIELDS = ("claim", "paper", "measured", "dropped", "contrary")


@dataclass(frozen=True)
class Evidence:
    """What one run gives a claim: its key number, the ``facts`` its rule is evaluated on,
    the preformatted ``values`` its template fills in (strings, numbers already formatted
    with :mod:`rsmhp.report.markdown`), and a ``rule`` where the rule depends on the data
    (e.g. a Bonferroni limit over the cells run), else the spec's."""

    key: KeyNumber
    facts: Facts
    values: Mapping[str, Any] = field(default_factory=dict)
    rule: Rule | None = None
    #: overrides of the spec's ``part`` and ``check`` where one spec serves both parts
    part: str | None = None


@dataclass(frozen=True)
class ClaimSpec:
    """One claim of a study: ``id`` (``{name}`` fields filled from the evidence's values),
    the ``setup`` it is tested on, its verdict ``rule`` (or ``None`` when every evidence
    brings its own), the ``evidence`` function of the study's tables, the study's ``words``
    and the prefix ``texts`` of its macros (default: the id in lower case with ``-`` as
    ``_``)."""

    id: str
    setup: str
    evidence: Callable[..., Evidence]
    words: Words
    rule: Rule | None = None
    texts: str = ""
    part: str = "paper"
    check: bool = False

    def __post_init__(self) -> None:
        if "{" in self.id and not self.texts:
            raise ValueError(f"claim spec {self.id!r}: an id with fields needs texts=")

    @property
    def prefix(self) -> str:
        """The prefix of the claim's macros in its template."""
        return self.texts or self.id.lower().replace("-", "_")

    def build(self, *tables: Any, **options: Any) -> Claim:
        """The claim from ``evidence(*tables, **options)``: rule evaluated, texts rendered."""
        return self.claim(self.evidence(*tables, **options))

    def claim(self, ev: Evidence) -> Claim:
        """The claim of the evidence ``ev`` (:meth:`build` once the evidence is computed)."""
        rule = ev.rule if ev.rule is not None else self.rule
        if rule is None:
            raise ValueError(f"claim {self.id}: neither the spec nor its evidence gives a rule")
        values = dict(ev.values)
        texts: dict[str, str] = {}
        for name in TEXT_FIELDS:
            macro = f"{self.prefix}_{name}"
            if name in ("claim", "paper") or macro in self.words:
                texts[name] = self.words(macro, **_arguments(self.words, macro, values))
        return Claim(
            id=self.id.format(**values),
            key=ev.key,
            verdict=rule.verdict(ev.facts),
            rule=rule.text(),
            setup=self.setup.format(**values),
            part=ev.part or self.part,
            check=self.check,
            **texts,
        )


def _arguments(words: Words, macro: str, values: Mapping[str, Any]) -> dict[str, Any]:
    """The values a macro names (a macro is called with its own arguments only; one it uses
    but the evidence lacks is an error naming it, :class:`rsmhp.report.templates.Words`)."""
    names = getattr(words._module, macro).arguments
    return {n: values[n] for n in names if n in values}
