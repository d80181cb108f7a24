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
(:mod:`rsmhp.core.stats`, :mod:`rsmhp.report.verdicts`, the studies' templates). Its words are
templates beside it: the two pages (``report.md``, the main text; ``report_appendix.md``, the
appendix), filled with counts, tables and texts preformatted here; the fixed texts used
outside them (symbols, verdict policy, caption, table headers) as macros of
``report_words.md`` (:data:`WORDS`); the sentences of "What we found" in ``findings.md``.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

import pandas as pd
import yaml

from rsmhp.report.disclosures import disclosure_lines, verdict_note
from rsmhp.report.findings import (
    MAIN_CLAIMS,
    found_values,
    key_text,
    link,
    main_rows,
    named_setup,
    other_streams,
    verdict_text,
)
from rsmhp.report.history import fragility
from rsmhp.report.ledger import CLAIM_OUTCOMES, STATEMENT_VERDICTS, VERDICTS, Claim, Section
from rsmhp.report.markdown import escape
from rsmhp.report.power import runs_text
from rsmhp.report.statements import GENERAL_RULE, HEDGED_RULE, Judgement, Statement, judge_all
from rsmhp.report.templates import Words
from rsmhp.report.templates import render as render_template

__all__ = [
    "APPENDIX_TEMPLATE",
    "MAIN_POLICY",
    "MAIN_TEMPLATE",
    "SUMMARY_CAPTION",
    "SUMMARY_FIGURE",
    "SYMBOLS",
    "VERDICT_POLICY",
    "WORDS",
    "claims_table",
    "glance_table",
    "render_appendix",
    "render_report",
    "statements_records",
    "statements_table",
    "what_we_found",
]


#: the fixed words of the report outside its pages (``src/rsmhp/report/report_words.md``)
WORDS = Words("rsmhp.report", "report_words.md")
#: the main text's page and the appendix's (templates beside this module)
MAIN_TEMPLATE = "report.md"
APPENDIX_TEMPLATE = "report_appendix.md"

#: the symbols of the ledger, defined before any claim uses them
SYMBOLS = WORDS("symbols")
#: how every verdict is given (the ledger)
VERDICT_POLICY = WORDS("verdict_policy")
#: the same principle, short, for the main text (the rules themselves are in the appendix)
MAIN_POLICY = WORDS("main_policy")
#: the summary figure the main text opens with (the scenarios study draws it)
SUMMARY_FIGURE = "scenarios_best"
#: the caption of the summary figure (main text and the HTML report's landing page)
SUMMARY_CAPTION = WORDS("summary_caption")


def _ledger_number(c: Claim) -> str:
    return f"{c.key.name}: {key_text(c)}"


def claims_table(claims: Iterable[Claim]) -> str:
    """The claims: id, claim (with its scope), the setup it was tested on, our key number
    with its 95% CI, verdict, the rule that gave it, and the contrary evidence (cells or
    settings whose CI lies on the opposite side). What the paper says is in the statements
    table and in each claim's details (appendix)."""
    lines = [WORDS("claims_header"), "|---|---|---|---|---|---|---|"]
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
    lines = [WORDS("statements_header"), "|---|---|---|---|"]

    def cell(verdict: str | None, claims: Sequence[Claim]) -> str:
        if verdict is None:
            return "–"
        pieces = ", ".join(f"{link(c.id, appendix)} {c.verdict}" for c in claims)
        return f"**{verdict}**" + (f": {pieces}" if pieces else "")

    for j in judgements:
        st = j.statement
        where = WORDS("statement_where", where=escape(st.where), hedged=st.hedged)
        lines.append(
            f"| {st.id} | {escape(st.says)} ({where}) | {cell(j.verdict, j.counted)} "
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


def glance_table(
    claims: Iterable[Claim],
    statements: Sequence[Statement] | None = None,
    history: pd.DataFrame | None = None,
) -> str:
    """The README's "results at a glance": the paper's statements (default
    :data:`rsmhp.report.statements.STATEMENTS`) with their verdicts on the paper's setups and on
    variants (each piece with the note of a choice made after its data,
    :func:`rsmhp.report.disclosures.verdict_note`), then the benchmark's own main claims
    (:data:`rsmhp.report.findings.MAIN_CLAIMS` without a statement), their verdicts per
    setup with their contrary evidence, and the verdicts an earlier seed stream of
    ``history`` gave them otherwise (:func:`rsmhp.report.findings.other_streams`)."""
    claims = list(claims)
    by_id = {c.id: c for c in claims}
    judgements, _ = judge_all(claims, statements)

    def piece(c: Claim) -> str:
        note = verdict_note(c)
        return f"{c.id} {c.verdict}" + (f" ({note})" if note else "")

    lines = [WORDS("statements_header"), "|---|---|---|---|"]
    for j in judgements:
        pieces = ", ".join(piece(c) for c in j.counted)
        var = (
            f"{j.on_variants} ({', '.join(piece(c) for c in j.alongside)})"
            if j.on_variants
            else "–"
        )
        lines.append(
            f"| {j.statement.id} | {escape(j.statement.says)} ({escape(j.statement.where)}) "
            f"| {j.verdict} ({pieces}) | {escape(var)} |"
        )
    ours = [m for m in MAIN_CLAIMS if not m.statement and any(i in by_id for _, i in m.setups)]
    if ours:
        lines += ["", WORDS("ours_header"), "|---|---|---|"]
        for m in ours:
            per = "; ".join(
                f"{named_setup(lab, by_id[i])}: {verdict_text(by_id[i])} "
                f"({escape(key_text(by_id[i]))})"
                + (f"; contrary: {escape(by_id[i].contrary)}" if by_id[i].contrary else "")
                for lab, i in m.setups
                if i in by_id
            )
            lines.append(f"| {m.name} | {escape(m.says)} | {per} |")
        mine = [by_id[i] for m in ours for _, i in m.setups if i in by_id]
        for st in other_streams(mine, history, appendix=None):
            others = ", ".join(f"{cid} {v}" for cid, v in st["claims"])
            lines += ["", WORDS("glance_streams", label=st["label"], n=st["n"], others=others)]
    return "\n".join(lines)


def _counts(verdicts: Iterable[str], vocabulary: tuple[str, ...]) -> str:
    verdicts = list(verdicts)
    return ", ".join(
        f"{n} {v}" for v in vocabulary if (n := sum(x == v for x in verdicts)) or v in VERDICTS
    )


def _statement_rules() -> str:
    """How a general and a hedged statement are judged (main text and ledger)."""
    return WORDS("statement_rules", general=GENERAL_RULE.text(), hedged=HEDGED_RULE.text())


def what_we_found(
    sections: Iterable[Section],
    statements: Sequence[Statement] | None = None,
    best: pd.DataFrame | None = None,
    appendix: str = "appendix.md",
    history: pd.DataFrame | None = None,
) -> str:
    """The "What we found" sentences (numbered Markdown) of the main text, from the claims
    of ``sections``, their statements' judgements, the best-family table ``best`` and the
    earlier judgements ``history`` (:func:`rsmhp.report.history.load_history`)."""
    sections = sorted(sections, key=lambda s: (s.order, s.key))
    claims = [c for s in sections for c in s.claims]
    judgements, _ = judge_all(claims, statements)
    values = found_values(judgements, claims, best, appendix, history)
    return render_template("rsmhp.report", "findings.md", **values).strip()


def _statements_values(
    judgements: Sequence[Judgement], untested: Sequence[str], appendix: str
) -> dict[str, Any]:
    """The main text's values of the paper's statements: counts by verdict on the paper's
    setups and on variants, the statements not tested, the table."""
    on_var = [j for j in judgements if j.on_variants is not None]
    return {
        "n_statements": len(judgements),
        "on_paper": _counts((j.verdict for j in judgements), STATEMENT_VERDICTS),
        "n_variants": len(on_var),
        "on_variants": _counts((j.on_variants for j in on_var), STATEMENT_VERDICTS),
        "rules": _statement_rules(),
        "untested": ", ".join(untested),
        "statements_table": statements_table(judgements, appendix),
    }


def _main_claims_values(
    claims: Sequence[Claim], history: pd.DataFrame | None, appendix: str, run: str | None
) -> dict[str, Any]:
    """The main text's values of the main claims: their rows (setups side by side), the
    claims left to the appendix and the checks, the fragile verdicts among the rows'
    claims (linked id, verdict, fragility line)."""
    shown = {cid for m in MAIN_CLAIMS for _, cid in m.setups}
    fragile = []
    if history is not None:
        for c in claims:
            if c.id in shown and (line := fragility(c, history, run)):
                fragile.append(f"- {link(c.id, appendix)} ({c.verdict}): {line}")
    return {
        "main_policy": MAIN_POLICY,
        "main": [{**r, "says": escape(r["says"])} for r in main_rows(claims, appendix)],
        "n_other": sum(1 for c in claims if c.id not in shown and not c.check),
        "n_checks": sum(c.check for c in claims),
        "fragile": fragile,
        "after_data": disclosure_lines(claims),
    }


def _run_values(provenance: Mapping[str, str]) -> dict[str, Any]:
    """The provenance line's values (``?`` where the provenance lacks one)."""
    get = provenance.get
    return {
        "commit": get("commit", "?")[:12],
        "uncommitted": get("uncommitted changes (outside paper/)") == "yes",
        "config": get("config sha256", "?"),
        **{k: get(k, "?") for k in ("python", "numpy", "numba", "blas", "cpu")},
        "flags": get("cpu flags", "?"),
    }


def render_report(
    sections: Iterable[Section],
    provenance: Mapping[str, str],
    appendix: str = "appendix.md",
    statements: Sequence[Statement] | None = None,
    best: pd.DataFrame | None = None,
    history: pd.DataFrame | None = None,
) -> str:
    """The main text on one page (template :data:`MAIN_TEMPLATE`): "What we found" (the
    answer, each sentence linked to its claims) with the summary figure, the paper's
    statements judged on its setups and on variants, the main claims
    (:data:`rsmhp.report.findings.MAIN_CLAIMS`) with their fragile verdicts, an index of the
    studies and a provenance line; everything else goes to :func:`render_appendix` (file
    ``appendix``). ``best``: the best-family table of the summary figure; ``history``:
    :func:`rsmhp.report.history.load_history`."""
    sections = sorted(sections, key=lambda s: (s.order, s.key))
    claims = [c for s in sections for c in s.claims]
    judgements, untested = judge_all(claims, statements)
    n_bit = sum(c.key.reproducible == "bitwise" for c in claims)
    studies = []
    for s in sections:
        names = [f.removesuffix(".png") for f in s.figures]
        studies.append((s.title, ", ".join(f"[{f}](figures/{f}.png)" for f in names) or "–"))
    return render_template(
        "rsmhp.report",
        MAIN_TEMPLATE,
        appendix=appendix,
        n_claims=len(claims),
        n_bitwise=n_bit,
        n_statistical=len(claims) - n_bit,
        found=what_we_found(sections, statements, best, appendix, history),
        figure=SUMMARY_FIGURE if any(SUMMARY_FIGURE in s.figures for s in sections) else "",
        caption=SUMMARY_CAPTION,
        **_statements_values(judgements, untested, appendix),
        **_main_claims_values(claims, history, appendix, provenance.get("commit")),
        studies=studies,
        run=_run_values(provenance),
    )


def _details(c: Claim, history: pd.DataFrame | None, run: str | None) -> dict[str, Any]:
    """A claim's details in the appendix: its fields, the verdict as it reads, the key number
    with its CI, the runs behind it (empty without ``n``), its fragility line (or empty)."""
    return {
        "id": c.id,
        "verdict": verdict_text(c),
        "check": c.check,
        "claim": c.claim,
        "part": c.part,
        "setup": c.setup,
        "paper": c.paper,
        "key": c.key.text(),
        "reproducible": c.key.reproducible,
        "rule": c.rule,
        "runs": runs_text(c.key) if c.key.n is not None else "",
        "measured": c.measured,
        "contrary": c.contrary,
        "dropped": c.dropped,
        "fragile": fragility(c, history, run) if history is not None else "",
    }


def render_appendix(
    sections: Iterable[Section],
    config: Mapping[str, Any],
    provenance: Mapping[str, str],
    statements: Sequence[Statement] | None = None,
    history: pd.DataFrame | None = None,
) -> str:
    """The appendix (template :data:`APPENDIX_TEMPLATE`): the whole ledger (statements with
    notes, every finding per model, the checks of our machinery apart, the fragile
    verdicts), every claim in detail (rule, all measured numbers, what was left out), each
    study's section with its tables, the parameters of the run and provenance."""
    sections = sorted(sections, key=lambda s: (s.order, s.key))
    claims = [c for s in sections for c in s.claims]
    run = provenance.get("commit")
    judgements, _ = judge_all(claims, statements)
    paper = [c for c in claims if c.part == "paper" and not c.check]
    beyond = [c for c in claims if c.part == "beyond" and not c.check]
    checks = [c for c in claims if c.check]
    details = [_details(c, history, run) for c in claims]
    return render_template(
        "rsmhp.report",
        APPENDIX_TEMPLATE,
        symbols=SYMBOLS,
        verdict_policy=VERDICT_POLICY,
        rules=_statement_rules(),
        statements_table=statements_table(judgements, ""),
        mixed=[j for j in judgements if j.disagreeing],
        notes=[j.statement for j in judgements if j.statement.note],
        paper=paper,
        paper_counts=_counts((c.verdict for c in paper), CLAIM_OUTCOMES),
        beyond=beyond,
        beyond_counts=_counts((c.verdict for c in beyond), CLAIM_OUTCOMES),
        findings_table=claims_table(paper + beyond),
        checks=checks,
        checks_counts=_counts((c.verdict for c in checks), CLAIM_OUTCOMES),
        checks_table=claims_table(checks),
        fragile=[(c, d["fragile"]) for c, d in zip(claims, details, strict=True) if d["fragile"]],
        details=details,
        sections=[
            {"title": s.title, "body": s.body.strip(), "appendix": s.appendix.strip()}
            for s in sections
        ],
        config=yaml.safe_dump(dict(config), sort_keys=False).strip(),
        provenance=provenance,
    )
