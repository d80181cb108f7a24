r"""The paper's statements, each once, with the claims that are its evidence, judged where the
paper made them.

Each statement of the paper (:data:`STATEMENTS`) names the claims that test it on **the
paper's own setups** (:attr:`Statement.evidence`: the oven LQG of Sec. III-A, the estimator
problems, the UAV reconstruction of Sec. III-B with its sensor) and those that test it on
**variants** (:attr:`Statement.variants`: the footprint sensors, costs outside a
proposition's premise). The two are judged apart, by the same rule, and the statement's
verdict is the one on the paper's setups; the verdict on variants is shown beside it, never
folded in ("not shown on the paper's setups; shown on the variants").

* A general statement (:data:`GENERAL_RULE`): the common verdict of its pieces, ``mixed``
  when they disagree (the pieces are named with their verdicts).
* A hedged statement ("may", :data:`HEDGED_RULE`) is an existence claim, so one piece that
  shows it suffices, unless another piece on the same kind of setup shows it absent (``not
  supported`` or ``equivalent``): then the evidence disagrees and the verdict is ``mixed``.

The words (what each statement says, its note, the rules' conditions, how a verdict reads) are
macros of the template ``statements.md`` beside this module (:data:`WORDS`); the statements'
ids, places in the paper and evidence are data here.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from rsmhp.report.ledger import VERDICTS, Claim
from rsmhp.report.templates import Words
from rsmhp.report.verdicts import Case, Facts, Rule

__all__ = [
    "GENERAL_RULE",
    "HEDGED_RULE",
    "NOT_TESTED",
    "STATEMENTS",
    "WORDS",
    "Judgement",
    "Statement",
    "evidence_facts",
    "judge",
    "judge_all",
]

#: the verdict of a kind of setup without evidence
NOT_TESTED = "not tested"

#: the words of the statements and their rules (``src/rsmhp/report/statements.md``)
WORDS = Words("rsmhp.report", "statements.md")


@dataclass(frozen=True)
class Statement:
    """A statement of the paper: ``id``, where the paper makes it (``where``), what it says
    in our words (``says``), whether it is hedged ("may"), the ids of the claims that test it
    on the paper's own setups (``evidence``) and on variants (``variants``) (an id ending in
    ``*`` matches every claim id with that prefix, e.g. one claim per model variant), and a
    ``note`` printed with it (e.g. a gap in the paper's proof)."""

    id: str
    where: str
    says: str
    evidence: tuple[str, ...]
    hedged: bool = False
    note: str = ""
    variants: tuple[str, ...] = ()

    @staticmethod
    def _match(patterns: Iterable[str], claim_id: str) -> bool:
        return any(
            claim_id.startswith(e[:-1]) if e.endswith("*") else claim_id == e for e in patterns
        )

    def matches(self, claim_id: str) -> bool:
        """Whether the claim is evidence of this statement (on any setup)."""
        return self._match(self.evidence, claim_id) or self._match(self.variants, claim_id)

    def on_variant(self, claim_id: str) -> bool:
        """Whether the claim tests this statement on a variant (not the paper's setup)."""
        return self._match(self.variants, claim_id) and not self._match(self.evidence, claim_id)


_ABSENT = ("not supported", "equivalent")

GENERAL_RULE = Rule(
    basis=WORDS("general_basis"),
    cases=(
        Case(NOT_TESTED, WORDS("no_evidence"), lambda f: f["n"] == 0),
        *(
            Case(v, WORDS("every_piece", verdict=v), lambda f, v=v: f[v] == f["n"])
            for v in ("supported", "not supported", "equivalent", "inconclusive")
        ),
    ),
    otherwise="mixed",
)

HEDGED_RULE = Rule(
    basis=WORDS("hedged_basis"),
    cases=(
        Case(NOT_TESTED, WORDS("no_evidence"), lambda f: f["n"] == 0),
        Case(
            "supported",
            WORDS("hedged_supported"),
            lambda f: f["supported"] >= 1 and f["not supported"] + f["equivalent"] == 0,
        ),
        Case("mixed", WORDS("hedged_mixed"), lambda f: f["supported"] >= 1),
        Case(
            "not supported",
            WORDS("hedged_not_supported"),
            lambda f: f["not supported"] + f["equivalent"] == f["n"],
        ),
    ),
    otherwise="inconclusive",
)


def evidence_facts(claims: Iterable[Claim]) -> Facts:
    """``n`` and the number of claims with each verdict (the facts of the rules above)."""
    claims = list(claims)
    return {"n": len(claims), **{v: sum(c.verdict == v for c in claims) for v in VERDICTS}}


def _pieces(claims: Sequence[Claim]) -> str:
    return ", ".join(f"{c.id} {c.verdict}" for c in claims)


@dataclass(frozen=True)
class Judgement:
    """A statement judged where the paper made it: its evidence on the paper's setups
    (``counted``; the statement's ``verdict`` rests on it) and on variants (``alongside``,
    judged apart: ``on_variants``, or ``None`` without any), each kind's verdict by the
    statement's rule (:data:`NOT_TESTED` without evidence), the rule's text, and ``scope``:
    the verdicts in words ("not shown on the paper's setups (…); shown on the variants (…)")."""

    statement: Statement
    counted: tuple[Claim, ...]
    alongside: tuple[Claim, ...]
    verdict: str
    rule: str
    scope: str
    on_variants: str | None = None

    @property
    def disagreeing(self) -> str:
        """For a ``mixed`` verdict, the pieces by verdict ("supported: EST-4; not supported:
        DEC-4; equivalent: UAV-3"); empty otherwise."""
        if self.verdict != "mixed":
            return ""
        by = {v: [c.id for c in self.counted if c.verdict == v] for v in VERDICTS}
        return "; ".join(f"{v}: {', '.join(ids)}" for v, ids in by.items() if ids)


def _scope(on_paper: str, paper: Sequence[Claim], on_var: str | None, var: Sequence[Claim]) -> str:
    return WORDS(
        "scope", on_paper=on_paper, paper=_pieces(paper), on_variants=on_var, variants=_pieces(var)
    )


def judge(statement: Statement, claims: Iterable[Claim]) -> Judgement | None:
    """The statement's verdicts from the claims of this run that are its evidence (``None``
    if none of them was run)."""
    evidence = [c for c in claims if statement.matches(c.id)]
    if not evidence:
        return None
    rule = HEDGED_RULE if statement.hedged else GENERAL_RULE
    paper = [c for c in evidence if not statement.on_variant(c.id)]
    var = [c for c in evidence if statement.on_variant(c.id)]
    wrong = [c.id for c in paper if c.part != "paper"]
    if wrong:
        raise ValueError(
            f"statement {statement.id}: claims {wrong} are listed as evidence on the paper's "
            "setups but are marked part 'beyond' (tests on variants or our own): list them "
            "under variants, or mark them part 'paper'"
        )
    on_paper = rule.verdict(evidence_facts(paper))
    on_var = rule.verdict(evidence_facts(var)) if var else None
    return Judgement(
        statement=statement,
        counted=tuple(paper),
        alongside=tuple(var),
        verdict=on_paper,
        rule=rule.text(),
        scope=_scope(on_paper, paper, on_var, var),
        on_variants=on_var,
    )


def judge_all(
    claims: Iterable[Claim], statements: Sequence[Statement] | None = None
) -> tuple[list[Judgement], list[str]]:
    """Every statement (default :data:`STATEMENTS`) with evidence in this run, in order, and
    the ids of the statements without any (not tested in this run). Refuses a claim of part
    ``paper`` that no statement lists (it would be counted nowhere)."""
    claims = list(claims)
    statements = STATEMENTS if statements is None else tuple(statements)
    orphans = [
        c.id for c in claims if c.part == "paper" and not any(s.matches(c.id) for s in statements)
    ]
    if orphans:
        raise ValueError(
            f"claims {orphans} are marked as tests of the paper but no statement in "
            "rsmhp.report.statements.STATEMENTS lists them as evidence"
        )
    out, untested = [], []
    for s in statements:
        j = judge(s, claims)
        if j is None:
            untested.append(s.id)
        else:
            out.append(j)
    return out, untested


#: the statements of the paper tested here, in the paper's order (what each says and its note:
#: ``s<n>_says`` and ``s<n>_note`` of :data:`WORDS`)
STATEMENTS: tuple[Statement, ...] = (
    Statement(
        "S1",
        "Sec. II",
        WORDS("s1_says"),
        ("DEC-1", "DEC-6"),
        hedged=True,
        variants=("DEC-7-*", "DEC-8a", "DEC-8b"),
        note=WORDS("s1_note"),
    ),
    Statement("S2", "Sec. II, Prop. 1", WORDS("s2_says"), ("EST-1",), note=WORDS("s2_note")),
    Statement("S3", "Sec. II, Prop. 2; Sec. II-A", WORDS("s3_says"), ("LQG-4", "EST-2")),
    Statement(
        "S4", "Sec. II-A, Prop. 3", WORDS("s4_says"), ("LIN-1",), variants=("LQG-3", "EST-3")
    ),
    Statement(
        "S5",
        "Sec. II; Sec. III-B after Fig. 4",
        WORDS("s5_says"),
        ("EST-4", "DEC-4", "UAV-3"),
        hedged=True,
        note=WORDS("s5_note"),
    ),
    Statement("S6", "Sec. III-A", WORDS("s6_says"), ("LQG-1",)),
    Statement("S7", "Sec. III-A, Fig. 3", WORDS("s7_says"), ("LQG-2",)),
    Statement("S8", "Sec. III-B, Fig. 4", WORDS("s8_says"), ("UAV-1",)),
    Statement(
        "S9", "Sec. III-B, Fig. 5", WORDS("s9_says"), ("UAV-2",), variants=("DEC-8a", "DEC-8b")
    ),
)
