"""The replication report: the answer on one page (main text) and everything behind it (appendix).

Each aggregation rule writes a :class:`rsmhp.report.ledger.Section` as JSON
(``results/report/<key>.json``): its Markdown body (figures referenced as
``figures/<name>.png``), appendix and claims. The ``report`` rule renders the main text
(:func:`render_report`: "What we found" with the summary figure, the paper's statements judged
on its setups and on variants, the main claims of :data:`rsmhp.report.findings.MAIN_CLAIMS`,
their fragile verdicts, an index of the studies) and the appendix (:func:`render_appendix`:
the whole ledger, every claim in detail, each study's section, parameters, provenance) into
``results/paper/`` (``make publish`` copies them to the tracked ``paper/``). This module only
renders: statistics, verdict rules and each study's prose live elsewhere
(:mod:`rsmhp.core.stats`, :mod:`rsmhp.report.verdicts`, the studies' templates), the
sentences of "What we found" in ``findings.md`` beside this package.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import pandas as pd
import yaml

from rsmhp.report.findings import MAIN_CLAIMS, found_values, key_text, link, main_rows, verdict_text
from rsmhp.report.history import fragility
from rsmhp.report.ledger import STATEMENT_VERDICTS, VERDICTS, Claim, Section
from rsmhp.report.markdown import escape
from rsmhp.report.power import runs_text
from rsmhp.report.statements import GENERAL_RULE, HEDGED_RULE, Judgement, Statement, judge_all
from rsmhp.report.templates import render as render_template

__all__ = [
    "MAIN_POLICY",
    "SUMMARY_CAPTION",
    "SUMMARY_FIGURE",
    "SYMBOLS",
    "VERDICT_POLICY",
    "claims_table",
    "glance_table",
    "render_appendix",
    "render_report",
    "statements_records",
    "statements_table",
    "what_we_found",
]


def _ledger_number(c: Claim) -> str:
    return f"{c.key.name}: {key_text(c)}"


def claims_table(claims: Iterable[Claim]) -> str:
    """The claims: id, claim (with its scope), the setup it was tested on, our key number
    with its 95% CI, verdict, the rule that gave it, and the contrary evidence (cells or
    settings whose CI lies on the opposite side). What the paper says is in the statements
    table and in each claim's details (appendix)."""
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


def statements_table(judgements: Iterable[Judgement], appendix: str = "appendix.md") -> str:
    """The paper's statements, each once, judged on the paper's own setups and, apart, on
    variants: the verdict of each kind of setup with its pieces of evidence (linked)."""
    lines = [
        "| | the paper says | on the paper's setups | on variants |",
        "|---|---|---|---|",
    ]

    def cell(verdict: str | None, claims: Sequence[Claim]) -> str:
        if verdict is None:
            return "–"
        pieces = ", ".join(f"{link(c.id, appendix)} {c.verdict}" for c in claims)
        return f"**{verdict}**" + (f": {pieces}" if pieces else "")

    for j in judgements:
        st = j.statement
        lines.append(
            f"| {st.id} | {escape(st.says)} ({escape(st.where)}"
            f"{'; hedged' if st.hedged else ''}) | {cell(j.verdict, j.counted)} "
            f"| {cell(j.on_variants, j.alongside)} |"
        )
    return "\n".join(lines)


def statements_records(judgements: Iterable[Judgement]) -> list[dict[str, Any]]:
    """The statements' judgements as JSON-ready dicts (``statements`` of ``claims.json``)."""
    return [
        {
            "id": j.statement.id,
            "where": j.statement.where,
            "says": j.statement.says,
            "hedged": j.statement.hedged,
            "verdict": j.verdict,
            "on_variants": j.on_variants,
            "rule": j.rule,
            "counted": [c.id for c in j.counted],
            "alongside": [c.id for c in j.alongside],
        }
        for j in judgements
    ]


def glance_table(claims: Iterable[Claim], statements: Sequence[Statement] | None = None) -> str:
    """The README's "results at a glance": the paper's statements (default
    :data:`rsmhp.report.statements.STATEMENTS`) with their verdicts on the paper's setups and on
    variants, then the benchmark's own main claims (:data:`rsmhp.report.findings.MAIN_CLAIMS`
    without a statement), their verdicts per setup."""
    claims = list(claims)
    by_id = {c.id: c for c in claims}
    judgements, _ = judge_all(claims, statements)
    lines = [
        "| | the paper says | on the paper's setups | on variants |",
        "|---|---|---|---|",
    ]
    for j in judgements:
        pieces = ", ".join(f"{c.id} {c.verdict}" for c in j.counted)
        var = (
            f"{j.on_variants} ({', '.join(f'{c.id} {c.verdict}' for c in j.alongside)})"
            if j.on_variants
            else "–"
        )
        lines.append(
            f"| {j.statement.id} | {escape(j.statement.says)} ({escape(j.statement.where)}) "
            f"| {j.verdict} ({pieces}) | {escape(var)} |"
        )
    ours = [m for m in MAIN_CLAIMS if not m.statement and any(i in by_id for _, i in m.setups)]
    if ours:
        lines += ["", "| | the benchmark's claim | verdict per setup |", "|---|---|---|"]
        for m in ours:
            per = "; ".join(
                f"{lab}: {verdict_text(by_id[i])} ({escape(key_text(by_id[i]))})"
                for lab, i in m.setups
                if i in by_id
            )
            lines.append(f"| {m.name} | {escape(m.says)} | {per} |")
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

#: the same principle, short, for the main text (the rules themselves are in the appendix)
MAIN_POLICY = (
    "Every verdict comes from a rule fixed before the run that judges it and printed with "
    "the claim in the appendix (linked): **supported** only when the 95% CI of the key number "
    "lies entirely on the claimed side, **not supported** when it lies on the opposite side "
    "(or contradicts a closed form), **equivalent** when it lies inside a margin ±Δ fixed "
    "before the run, **inconclusive** otherwise. Two rules add a condition: the FR and HZ "
    "claims are Holm-corrected together (a decisive verdict whose adjusted p is 0.05 or more "
    "becomes inconclusive, and says so), and DEC-8 needs its CI below 0 in every cell of the "
    "group as well as on average."
)


def _counts(verdicts: Iterable[str], vocabulary: tuple[str, ...]) -> str:
    verdicts = list(verdicts)
    return ", ".join(
        f"{n} {v}" for v in vocabulary if (n := sum(x == v for x in verdicts)) or v in VERDICTS
    )


#: the summary figure the main text opens with (the scenarios study draws it)
SUMMARY_FIGURE = "scenarios_best"


def _statements_part(
    judgements: Sequence[Judgement], untested: Sequence[str], appendix: str
) -> list[str]:
    on_var = [j for j in judgements if j.on_variants is not None]
    return [
        "## The paper's statements, judged where the paper made them",
        "",
        f"{len(judgements)} statements of the paper, each judged on the paper's own setups "
        "(the oven LQG, the estimator problems, the UAV reconstruction with its sensor) and, "
        "apart, on our variants (footprint sensors, costs outside a proposition's premise); "
        "a statement's verdict is the one on the paper's setups. On the paper's setups: "
        + _counts((j.verdict for j in judgements), STATEMENT_VERDICTS)
        + (
            f"; on variants ({len(on_var)} statements tested there): "
            + _counts((j.on_variants for j in on_var), STATEMENT_VERDICTS)
            if on_var
            else ""
        )
        + f". A general statement's verdict, {GENERAL_RULE.text()}. A hedged one ('may'): "
        f"{HEDGED_RULE.text()}."
        + (f" Not tested in this run: {', '.join(untested)}." if untested else "")
        + " Notes (S1, S2: a gap in the proof of Prop. 1, S5): "
        + f"[appendix A1]({appendix}#a1-the-papers-statements).",
        "",
        statements_table(judgements, appendix),
        "",
    ]


def _main_claims_part(
    claims: Sequence[Claim], history: pd.DataFrame | None, appendix: str, run: str | None
) -> list[str]:
    rows = main_rows(claims, appendix)
    shown = {cid for m in MAIN_CLAIMS for _, cid in m.setups}
    fragile = []
    if history is not None:
        for c in claims:
            if c.id in shown and (line := fragility(c, history, run)):
                fragile.append(f"- {link(c.id, appendix)} ({c.verdict}): {line}")
    n_other = sum(1 for c in claims if c.id not in shown and not c.check)
    n_checks = sum(c.check for c in claims)
    table = [
        "| | claim | per setup: key number (95% CI) → verdict; n, n for 80% power |",
        "|---|---|---|",
    ]
    for r in rows:
        tag = f" ({r['statement']})" if r["statement"] else ""
        table.append(f"| {r['name']}{tag} | {escape(r['says'])} | {'<br>'.join(r['setups'])} |")
    return [
        f"## The main claims ({len(rows)})",
        "",
        MAIN_POLICY
        + " n is the number of paired runs (or belief states) behind a CI; 'for 80% power': "
        "the n at which the rule would decide with 80% probability if the true difference were "
        f"the estimate (normal approximation). {n_other} further claims are in the appendix "
        f"ledger, and {n_checks} checks of our machinery in a part of their own.",
        "",
        *table,
        "",
        *(
            [
                "**Fragile verdicts** (changed across published runs, machines or seed streams; "
                "`paper/history.csv`):",
                "",
                *fragile,
                "",
            ]
            if fragile
            else []
        ),
    ]


def _studies_part(sections: Sequence[Section]) -> list[str]:
    lines = ["## The studies", "", "| study | figures | details |", "|---|---|---|"]
    for i, s in enumerate(sections, start=1):
        names = [f.removesuffix(".png") for f in s.figures]
        figs = ", ".join(f"[{f}](figures/{f}.png)" for f in names) or "–"
        lines.append(f"| {s.title} | {figs} | appendix C{i} |")
    return [*lines, ""]


#: the caption of the summary figure (main text and the HTML report's landing page)
SUMMARY_CAPTION = (
    "The method with the lowest mean closed-loop error per cell, in its family's colour "
    "(solid: better than every other method, paired 95% t CI over runs; hatched: tied, with "
    "the number of methods tied)."
)


def what_we_found(
    sections: Iterable[Section],
    statements: Sequence[Statement] | None = None,
    best: pd.DataFrame | None = None,
    appendix: str = "appendix.md",
) -> str:
    """The "What we found" sentences (numbered Markdown) of the main text, from the claims
    of ``sections``, their statements' judgements and the best-family table ``best``."""
    sections = sorted(sections, key=lambda s: (s.order, s.key))
    claims = [c for s in sections for c in s.claims]
    judgements, _ = judge_all(claims, statements)
    values = found_values(judgements, claims, best, appendix)
    return render_template("rsmhp.report", "findings.md", **values).strip()


def render_report(
    sections: Iterable[Section],
    provenance: Mapping[str, str],
    appendix: str = "appendix.md",
    statements: Sequence[Statement] | None = None,
    best: pd.DataFrame | None = None,
    history: pd.DataFrame | None = None,
) -> str:
    """The main text on one page: "What we found" (the answer, each sentence linked to its
    claims) with the summary figure, the paper's statements judged on its setups and on
    variants, the main claims (:data:`rsmhp.report.findings.MAIN_CLAIMS`) with their fragile
    verdicts, an index of the studies and a provenance line; everything else goes to
    :func:`render_appendix` (file ``appendix``). ``best``: the best-family table of the
    summary figure; ``history``: :func:`rsmhp.report.history.load_history`."""
    sections = sorted(sections, key=lambda s: (s.order, s.key))
    claims = [c for s in sections for c in s.claims]
    judgements, untested = judge_all(claims, statements)
    found = what_we_found(sections, statements, best, appendix)
    figure = []
    if any(SUMMARY_FIGURE in s.figures for s in sections):
        figure = [
            f"![Best family per scenario, budget and horizon](figures/{SUMMARY_FIGURE}.png)",
            "",
            f"*{SUMMARY_CAPTION}*",
            "",
        ]
    n_bit = sum(c.key.reproducible == "bitwise" for c in claims)
    parts = [
        "# rsmhp replication report",
        "",
        "Replication of Ragi & Mittelmann, *Random-Sampling Monte-Carlo Tree Search Methods for "
        "Cost Approximation in Long-Horizon Optimal Control*, IEEE Control Systems Letters 5(5), "
        "2021, written by the pipeline from one run. This page gives the answer; every claim "
        "with its rule and numbers, each study's section, tables, parameters and provenance are "
        f"in [{appendix}]({appendix}). Of the {len(claims)} key numbers {n_bit} reproduce "
        f"bitwise, {len(claims) - n_bit} statistically (`make verify`).",
        "",
        "## What we found",
        "",
        found,
        "",
        *figure,
        *_statements_part(judgements, untested, appendix),
        *_main_claims_part(claims, history, appendix, provenance.get("commit")),
        *_studies_part(sections),
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


def _ledger_part(
    claims: Sequence[Claim],
    statements: Sequence[Statement] | None,
    history: pd.DataFrame | None,
    run: str | None,
) -> list[str]:
    judgements, _ = judge_all(claims, statements)
    notes = [f"- {j.statement.id}: {j.statement.note}" for j in judgements if j.statement.note]
    mixed = [f"- {j.statement.id} (mixed): {j.disagreeing}" for j in judgements if j.disagreeing]
    paper = [c for c in claims if c.part == "paper" and not c.check]
    beyond = [c for c in claims if c.part == "beyond" and not c.check]
    checks = [c for c in claims if c.check]
    fragile = []
    if history is not None:
        fragile = [
            f"- {c.id} ({c.verdict}): {line}"
            for c in claims
            if (line := fragility(c, history, run))
        ]
    return [
        "## A. The ledger",
        "",
        SYMBOLS,
        "",
        VERDICT_POLICY,
        "",
        "### A1. The paper's statements",
        "",
        f"A general statement's verdict, {GENERAL_RULE.text()}. A hedged one ('may'): "
        f"{HEDGED_RULE.text()}.",
        "",
        statements_table(judgements, ""),
        "",
        *(["Where the evidence disagrees:", "", *mixed, ""] if mixed else []),
        *(["Notes on the statements:", "", *notes, ""] if notes else []),
        "### A2. Findings",
        "",
        f"{len(paper)} claims test the paper's statements on its setups: "
        + _counts((c.verdict for c in paper), VERDICTS)
        + f". {len(beyond)} claims go beyond the paper (our derivations, comparisons and model "
        "variants; the checks of our machinery are not among them): "
        + _counts((c.verdict for c in beyond), VERDICTS)
        + ".",
        "",
        claims_table(paper + beyond),
        "",
        "### A3. Checks of our machinery",
        "",
        f"{len(checks)} checks of our simulation, estimators and optimiser against closed forms "
        "(they test the implementation, not a finding; counted apart): "
        + _counts((c.verdict for c in checks), VERDICTS)
        + ".",
        "",
        claims_table(checks),
        "",
        "### A4. Fragile verdicts",
        "",
        "Every claim whose verdict changed across the published runs, the portability drill "
        "(an emulated other CPU) or seed streams (exploratory against confirmatory), from "
        "`paper/history.csv`" + (":" if fragile else ": none."),
        "",
        *([*fragile, ""] if fragile else []),
    ]


def render_appendix(
    sections: Iterable[Section],
    config: Mapping[str, Any],
    provenance: Mapping[str, str],
    statements: Sequence[Statement] | None = None,
    history: pd.DataFrame | None = None,
) -> str:
    """The appendix: the whole ledger (statements with notes, every finding per model, the
    checks of our machinery apart, the fragile verdicts), every claim in detail (rule, all
    measured numbers, what was left out), each study's section with its tables, the
    parameters of the run and provenance."""
    sections = sorted(sections, key=lambda s: (s.order, s.key))
    claims = [c for s in sections for c in s.claims]
    run = provenance.get("commit")
    parts = [
        "# rsmhp replication report: appendix",
        "",
        "Details behind [the main text](replication.md), from the same run.",
        "",
        *_ledger_part(claims, statements, history, run),
        "## B. Claims in detail",
        "",
    ]
    for c in claims:
        parts += [
            f"### {c.id}",
            "",
            f"- Verdict: **{verdict_text(c)}**"
            + (" (a check of our machinery)" if c.check else ""),
            f"- Claim: {c.claim}",
            f"- Part: {'the paper' if c.part == 'paper' else 'beyond the paper'}; setup: {c.setup}",
            f"- Paper: {c.paper}",
            f"- Key number: {c.key.text()} ({_REPRO_TEXT[c.key.reproducible]})",
            f"- Verdict rule: {c.rule}",
        ]
        if c.key.n is not None:
            parts.append(f"- Runs: {runs_text(c.key)}")
        if c.measured:
            parts.append(f"- Measured: {c.measured}")
        if c.contrary:
            parts.append(f"- Contrary evidence: {c.contrary}")
        if c.dropped:
            parts.append(f"- Left out: {c.dropped}")
        if history is not None and (line := fragility(c, history, run)):
            parts.append(f"- Fragile: {line}")
        parts.append("")
    for i, s in enumerate(sections, start=1):
        parts += [f"## C{i}. {s.title}", "", s.body.strip(), ""]
        if s.appendix.strip():
            parts += [s.appendix.strip(), ""]
    parts += [
        "## D. Parameters of this run",
        "",
        "The validated configuration (defaults filled in), exactly as the pipeline used it:",
        "",
        "```yaml",
        yaml.safe_dump(dict(config), sort_keys=False).strip(),
        "```",
        "",
        "## E. Provenance",
        "",
        "Host and date are in `results/provenance.json` (they change every run).",
        "",
        *(f"- {k}: `{v}`" for k, v in provenance.items()),
        "",
    ]
    return "\n".join(parts)
