"""The replication report: renders the claims ledger, one section per study and the appendix.

Each aggregation rule writes a :class:`rsmhp.report.ledger.Section` as JSON
(``results/report/<key>.json``): its Markdown body (figures referenced as
``figures/<name>.png``), appendix and claims. The ``report`` rule renders every section, in
``order``, into ``results/paper/replication.md`` and ``appendix.md`` (``make publish`` copies
both to the tracked ``paper/``). This module only renders: statistics, verdict rules and each
study's prose live elsewhere (``rsmhp.analysis``, :mod:`rsmhp.report.verdicts`,
``rsmhp.narrative``),
provenance in :mod:`rsmhp.report.provenance`, the README block in :mod:`rsmhp.report.readme`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import yaml

from rsmhp.report.ledger import STATEMENT_VERDICTS, VERDICTS, Claim, Section
from rsmhp.report.markdown import escape, fmt, fmt_ci
from rsmhp.report.statements import GENERAL_RULE, HEDGED_RULE, Judgement, Statement, judge_all

__all__ = [
    "SYMBOLS",
    "VERDICT_POLICY",
    "claims_table",
    "glance_table",
    "render_appendix",
    "render_report",
    "statements_records",
    "statements_table",
]


def _ledger_number(c: Claim) -> str:
    k = c.key
    signed = k.null == 0.0
    out = fmt(k.value, k.digits, signed)
    if k.has_ci:
        out += " " + fmt_ci(k.ci_low, k.ci_high, k.digits, signed)
    return f"{k.name}: {out}{' ' + k.unit if k.unit else ''}"


def claims_table(claims: Iterable[Claim]) -> str:
    """The claims: id, claim (with its scope), the setup it was tested on, our key number
    with its 95% CI, verdict, the rule that gave it, and the contrary evidence (cells or
    settings whose CI lies on the opposite side). What the paper says is in the statements
    table (part 1) and in each claim's details (appendix)."""
    lines = [
        "| id | claim | setup | our number (95% CI) | verdict | verdict rule | contrary evidence |",
        "|---|---|---|---|---|---|---|",
    ]
    for c in claims:
        lines.append(
            f"| {c.id} | {escape(c.claim)} | {escape(c.setup)} "
            f"| {escape(_ledger_number(c))} | **{c.verdict}** | {escape(c.rule)} "
            f"| {escape(c.contrary) if c.contrary else '–'} |"
        )
    return "\n".join(lines)


def statements_table(judgements: Iterable[Judgement]) -> str:
    """Part one of the ledger: each statement of the paper once, its evidence (counted, and
    on variants alongside) and one verdict (the rules that combine the evidence are printed
    once, above the table: :data:`rsmhp.report.statements.GENERAL_RULE`, ``HEDGED_RULE``)."""
    lines = [
        "| | the paper says | evidence (setup: verdict) | verdict |",
        "|---|---|---|---|",
    ]
    for j in judgements:
        st = j.statement
        evidence = j.scope or "–"
        if j.alongside:
            evidence += "; on variants, not counted: " + "; ".join(
                f"{c.setup} ({c.id}: {c.verdict})" for c in j.alongside
            )
        lines.append(
            f"| {st.id} | {escape(st.says)} ({escape(st.where)}"
            f"{'; hedged' if st.hedged else ''}) | {escape(evidence)} | **{j.verdict}** |"
        )
    return "\n".join(lines)


def statements_records(judgements: Iterable[Judgement]) -> list[dict[str, Any]]:
    """Part one as JSON-ready dicts (``statements`` of ``claims.json``)."""
    return [
        {
            "id": j.statement.id,
            "where": j.statement.where,
            "says": j.statement.says,
            "hedged": j.statement.hedged,
            "verdict": j.verdict,
            "rule": j.rule,
            "counted": [c.id for c in j.counted],
            "alongside": [c.id for c in j.alongside],
        }
        for j in judgements
    ]


def glance_table(claims: Iterable[Claim], statements: Sequence[Statement] | None = None) -> str:
    """The README's "results at a glance": the paper's statements (default
    :data:`rsmhp.report.statements.STATEMENTS`) with their verdicts, then the claims beyond the
    paper (id, claim, key number with CI, verdict)."""
    claims = list(claims)
    judgements, _ = judge_all(claims, statements)
    lines = ["| | claim | our number (95% CI) | verdict |", "|---|---|---|---|"]
    for j in judgements:
        nums = "; ".join(f"{c.id}: {_ledger_number(c)}" for c in j.counted)
        pieces = (
            " (" + ", ".join(f"{c.id} {c.verdict}" for c in j.counted) + ")"
            if len(j.counted) > 1
            else ""
        )
        lines.append(
            f"| {j.statement.id} | paper ({j.statement.where}): {escape(j.statement.says)} "
            f"| {escape(nums)} | {j.verdict}{pieces} |"
        )
    for c in claims:
        if c.part == "beyond":
            lines.append(
                f"| {c.id} | beyond the paper: {escape(c.claim)} "
                f"| {escape(_ledger_number(c))} | {c.verdict} |"
            )
    return "\n".join(lines)


#: the symbols of the ledger, defined before any claim uses them
SYMBOLS = (
    "**Symbols.** u = (u_0, …, u_{H−1}): the controls over the horizon of H steps; J(u): the "
    "exact expected cost of u; J_NBO(u): NBO's cost of u (every noise at its mean, 0); "
    "u* = argmin J: the optimal controls, J(u*) the optimal cost. Oven LQG (Sec. III-A): "
    "x_{k+1} = (1−a) x_k + a u_k + w_k, w_k ~ N(0, σ²), terminal weight r; "
    "v_H = σ² Σ_{n<H} (1−a)^{2n}, the variance of the final state, so J − J_NBO = r v_H; "
    "κ = r²a²‖β‖²/(1 + r a²‖β‖²) with β_k = (1−a)^{H−1−k}, the factor that turns the "
    "squared mean of the sampled final-state noise into regret. Estimators: P (or n) "
    "independent trajectories, N draws per tree level, M trajectories kept by pruning, g "
    "(or p) one trajectory's cost, J_P its average, ε a tolerance. Regret: J(û) − J(u*) of "
    "the controls û a method chooses; relative regret: regret / J(u*), in percent; pp: "
    "percentage points (a difference of two percentages). UAV (Sec. III-B): N_T sampled "
    "target trajectories; e_r the average target location error of run r (m); paired "
    'difference d_r = e_r(A) − e_r(B), mean d̄ ("mean d" in the rules); Δ: an equivalence '
    "margin fixed before the run. CI: 95% confidence interval."
)


VERDICT_POLICY = (
    "Every verdict comes from the rule printed next to it; a rule's cases are read in order "
    "and the first that holds gives the verdict. The rules share one principle: a claim is "
    "**supported** only when the 95% confidence interval (CI) of its key number lies "
    "entirely on the claimed side (or a derived value is met within its statistical "
    "tolerance), **not supported** when the evidence lies on the opposite side or contradicts "
    "a closed form, **equivalent** when the CI lies inside an equivalence margin ±Δ fixed "
    "before the run (whatever the difference is, it is smaller than Δ, so the claimed effect "
    "is absent at that resolution), and **inconclusive** otherwise. A claim cannot be marked "
    "supported while its key number's CI contains the value of the opposite claim (checked "
    "when the report is built). Where a problem or cell is left out of the evidence, the "
    "claim's details in the appendix name it and say why; cells or settings whose CI lies on "
    "the side opposite to a claim are named next to it (contrary evidence)."
)


def _counts(verdicts: Iterable[str], vocabulary: tuple[str, ...]) -> str:
    verdicts = list(verdicts)
    return ", ".join(
        f"{n} {v}" for v in vocabulary if (n := sum(x == v for x in verdicts)) or v in VERDICTS
    )


def _ledger(claims: list[Claim], statements: Sequence[Statement] | None) -> list[str]:
    """The two parts of the claims ledger (main text)."""
    judgements, untested = judge_all(claims, statements)
    paper = [c for c in claims if c.part == "paper"]
    beyond = [c for c in claims if c.part == "beyond"]
    n_bit = sum(c.key.reproducible == "bitwise" for c in claims)
    notes = [f"- {j.statement.id}: {j.statement.note}" for j in judgements if j.statement.note]
    return [
        "## Claims ledger",
        "",
        SYMBOLS,
        "",
        VERDICT_POLICY,
        f" {n_bit} of the {len(claims)} key numbers are bitwise reproducible (same code, "
        f"config, versions, BLAS and CPU flags), {len(claims) - n_bit} statistically (UAV "
        "closed loop and optimiser); `make verify` compares a run with the committed "
        "reference, `paper/claims.json`.",
        "",
        "### Part 1: the paper's claims",
        "",
        f"{len(judgements)} statements of the paper, each tested on the paper's own setups "
        f"({len(paper)} claims of evidence; a hedged statement also on variants): "
        + _counts((j.verdict for j in judgements), STATEMENT_VERDICTS)
        + f". A general statement's verdict, {GENERAL_RULE.text()}. A hedged one ('may'): "
        f"{HEDGED_RULE.text()}; the table names where it was and was not shown."
        + (f" Not tested in this run: {', '.join(untested)}." if untested else ""),
        "",
        statements_table(judgements),
        "",
        *(["Notes on the statements:", "", *notes, ""] if notes else []),
        "Evidence on the paper's setups:",
        "",
        claims_table(paper),
        "",
        "### Part 2: beyond the paper",
        "",
        f"{len(beyond)} claims the report derives itself or tests on model variants: "
        + _counts((c.verdict for c in beyond), VERDICTS)
        + ". They are not the paper's claims; where one bears on a statement of the paper it "
        "is listed there as well.",
        "",
        claims_table(beyond),
        "",
    ]


def render_report(
    sections: Iterable[Section],
    provenance: Mapping[str, str],
    appendix: str = "appendix.md",
    statements: Sequence[Statement] | None = None,
) -> str:
    """The main text: introduction, claims ledger, one section per study (in ``order``), a
    short provenance note; details go to :func:`render_appendix` (file ``appendix``)."""
    sections = sorted(sections, key=lambda s: (s.order, s.key))
    all_claims = [c for s in sections for c in s.claims]
    parts = [
        "# rsmhp replication report",
        "",
        "Replication of Ragi & Mittelmann, *Random-Sampling Monte-Carlo Tree Search Methods for "
        "Cost Approximation in Long-Horizon Optimal Control*, IEEE Control Systems Letters 5(5), "
        "2021. Written by the pipeline (`snakemake report`) from `results/` of one run; tables, "
        f"claim details, parameters and provenance are in [{appendix}]({appendix}).",
        "",
        *_ledger(all_claims, statements),
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
                f"- Part: {'the paper' if c.part == 'paper' else 'beyond the paper'}; "
                f"setup: {c.setup}",
                f"- Paper: {c.paper}",
                f"- Key number: {c.key.text()} ({_REPRO_TEXT[c.key.reproducible]})",
                f"- Verdict rule: {c.rule}",
            ]
            if c.measured:
                parts.append(f"- Measured: {c.measured}")
            if c.contrary:
                parts.append(f"- Contrary evidence: {c.contrary}")
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
