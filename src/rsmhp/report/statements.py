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
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from rsmhp.report.ledger import VERDICTS, Claim
from rsmhp.report.verdicts import Case, Facts, Rule

__all__ = [
    "GENERAL_RULE",
    "HEDGED_RULE",
    "NOT_TESTED",
    "STATEMENTS",
    "Judgement",
    "Statement",
    "evidence_facts",
    "judge",
    "judge_all",
]

#: the verdict of a kind of setup without evidence
NOT_TESTED = "not tested"


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
    basis="over its pieces of evidence on one kind of setup (the paper's, or the variants)",
    cases=(
        Case(NOT_TESTED, "there is none", lambda f: f["n"] == 0),
        *(
            Case(v, f"every piece is {v}", lambda f, v=v: f[v] == f["n"])
            for v in ("supported", "not supported", "equivalent", "inconclusive")
        ),
    ),
    otherwise="mixed",
)

HEDGED_RULE = Rule(
    basis="the paper says 'may', so one setting where it happens suffices unless another shows "
    "it absent; over its pieces of evidence on one kind of setup",
    cases=(
        Case(NOT_TESTED, "there is none", lambda f: f["n"] == 0),
        Case(
            "supported",
            "some piece is supported and none is not supported or equivalent",
            lambda f: f["supported"] >= 1 and f["not supported"] + f["equivalent"] == 0,
        ),
        Case(
            "mixed",
            "some piece is supported and some is not supported or equivalent (shown and shown "
            "absent)",
            lambda f: f["supported"] >= 1,
        ),
        Case(
            "not supported",
            "every piece is not supported or equivalent (shown absent wherever tested)",
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


_SHOWN = {
    "supported": "shown",
    "not supported": "contradicted",
    "equivalent": "absent (equivalent)",
    "inconclusive": "not shown (inconclusive)",
    "mixed": "mixed",
    NOT_TESTED: "not tested",
}


def _scope(on_paper: str, paper: Sequence[Claim], on_var: str | None, var: Sequence[Claim]) -> str:
    out = f"{_SHOWN[on_paper]} on the paper's setups" + (f" ({_pieces(paper)})" if paper else "")
    if on_var is not None:
        out += f"; {_SHOWN[on_var]} on the variants ({_pieces(var)})"
    return out


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


_PROP1_GAP = (
    "The paper's proof of Prop. 1 orders the leaves left to right and states that "
    "Cov(g_i, g_j) = 0 when |i − j| > N, because leaves under different parents share no "
    "draw. That holds for a tree whose every node draws its own noise, not for the tree the "
    "paper builds (Fig. 1a: one set of N draws per level, shared by every node). There, two "
    "leaves share the draw of level k whenever their level-k indices agree, however far apart "
    "they are: leaf (1, 1, …, 1) and leaf (2, 1, …, 1) lie N^{H−1} positions apart and share "
    "H − 1 of their H draws. With g = c + bᵀw + wᵀKw (the LQG's cost as a quadratic form of "
    "the stacked noise w ~ N(0, S), S = I_H ⊗ Σ, c = J_NBO), two leaves sharing the draws of "
    "the set L of levels have Cov = Var(E[g | w_L]) > 0, and averaging over all pairs gives "
    "Var(J_tree) = bᵀSb/N + 2 tr((KS)²)/N² + 2(N−1)/N² Σ_k tr((K_kk Σ)²) (estimator study, "
    "appendix), which decays like 1/N, not like 1/N^H. The conclusion "
    "(convergence in probability) still holds because this variance tends to 0, but the "
    "covariances do not vanish with |i − j|, so the cited condition is not met; the "
    "estimator study (EST-1) measures the 1/N rate."
)

#: the statements of the paper tested here, in the paper's order
STATEMENTS: tuple[Statement, ...] = (
    Statement(
        "S1",
        "Sec. II",
        "NBO completely ignores the uncertainty of the state evolution and may generate "
        "severely sub-optimal controls",
        ("DEC-1", "DEC-6"),
        hedged=True,
        variants=("DEC-7-*", "DEC-8a", "DEC-8b"),
        note="In the oven LQG with open-loop controls, J(u) − J_NBO(u) = r v_H does not "
        "depend on u, so NBO's minimiser is the exact optimum before any simulation runs "
        "(certainty equivalence): DEC-1 confirms the derivation numerically, it cannot come "
        "out otherwise on this model.",
    ),
    Statement(
        "S2",
        "Sec. II, Prop. 1",
        "the uniform average over the tree's trajectories converges in probability to J as "
        "the number of draws N grows",
        ("EST-1",),
        note=_PROP1_GAP,
    ),
    Statement(
        "S3",
        "Sec. II, Prop. 2; Sec. II-A",
        "the likeliness-weighted average (over the tree, or over independent trajectories) "
        "converges in probability to J",
        ("LQG-4", "EST-2"),
    ),
    Statement(
        "S4",
        "Sec. II-A, Prop. 3",
        "for linear dynamics and a linear cost, P(|J_n − J| ≥ ε) ≤ Var(p)/(n ε²) for the "
        "average J_n of n independent trajectories, with Var(p) = C[Σ_k 𝒜_k Σ 𝒜_kᵀ]Cᵀ "
        "(𝒜_k = Σ_{q<H−k} A^q, C the cost's row vector)",
        ("LIN-1",),
        variants=("LQG-3", "EST-3"),
    ),
    Statement(
        "S5",
        "Sec. II; Sec. III-B after Fig. 4",
        "the N_T trend 'suggests that pruning methods would degrade the performance' of "
        "RS-MHP (keeping the M most likely trajectories) 'but can provide gains' in computation",
        ("EST-4", "DEC-4", "UAV-3"),
        hedged=True,
        note="In the oven LQG with open-loop controls NBO's choice is the exact optimum (S1), "
        "and pruning keeps the most likely, near-zero noises, so a pruned tree drifts toward "
        "NBO's choice: there pruning cannot degrade decisions (DEC-4). The computation half "
        "has no evidence of its own: the UAV timings are printed as contrary evidence of "
        "UAV-3 where the pruned tree was the slower.",
    ),
    Statement(
        "S6",
        "Sec. III-A",
        "in the oven LQG, NBO's cost error is |J_NBO − J| = r σ² Σ_{n=0}^{H−1} (1−a)^{2n} "
        "(derived for H = 2, stated for any H)",
        ("LQG-1",),
    ),
    Statement(
        "S7",
        "Sec. III-A, Fig. 3",
        "in the oven LQG the Monte-Carlo estimate approaches J as the number of trajectories "
        "grows (P = 100 … 10000), while NBO's estimate stays biased",
        ("LQG-2",),
    ),
    Statement(
        "S8",
        "Sec. III-B, Fig. 4",
        "the UAV's average target location error falls gradually as N_T grows from 50 to 100 "
        "to 250 (H = 6)",
        ("UAV-1",),
    ),
    Statement(
        "S9",
        "Sec. III-B, Fig. 5",
        "RS-MHP tracks the target with a lower average location error than NBO",
        ("UAV-2",),
        variants=("DEC-8a", "DEC-8b"),
    ),
)
