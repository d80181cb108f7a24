"""The one-page answer: the claims the main text shows, how a verdict reads, and the values of
"What we found".

:data:`MAIN_CLAIMS` names the at most ten claims of the main text: the paper's statements
tested on several setups and the benchmark's own comparisons, one row each with its setups
side by side. The ids are fixed in code, not chosen per run: a run's verdicts cannot move a
claim into or out of the main text (the list was written after earlier runs had been
published, so it is a fixed choice, not a preregistered one). Every other claim stays in
the appendix ledger; the checks of our own machinery
(``Claim.check``) have an appendix part and a count of their own.

:func:`verdict_text` says what a verdict means (an equivalence whose CI excludes the null:
"difference significant but below Δ"). :func:`found_values` computes the preformatted values
of the "What we found" sentences (``findings.md``, rendered by :mod:`rsmhp.report.render`);
every sentence names the claims it rests on and links them. The words of this module (what each
main claim says, how a verdict and its power read, which method is best where) are macros of
``main_claims.md`` beside it (:data:`WORDS`).
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import pandas as pd

from rsmhp.report.disclosures import verdict_note
from rsmhp.report.ledger import STATEMENT_VERDICTS, Claim
from rsmhp.report.markdown import fmt, fmt_ci, param_text
from rsmhp.report.naming import depth_of
from rsmhp.report.power import runs_needed
from rsmhp.report.statements import Judgement
from rsmhp.report.templates import Words

__all__ = [
    "MAIN_CLAIMS",
    "MAX_MAIN",
    "WORDS",
    "MainClaim",
    "anchor",
    "best_sentence",
    "found_values",
    "key_text",
    "link",
    "main_rows",
    "verdict_text",
]

#: the most claims the main text shows
MAX_MAIN = 10

#: the words of the main text's claims and verdicts (``src/rsmhp/report/main_claims.md``)
WORDS = Words("rsmhp.report", "main_claims.md")


@dataclass(frozen=True)
class MainClaim:
    """A main-text row: ``name`` (short), what it claims in words (``says``), the paper
    statement it tests (``statement``, empty for the benchmark's own), and its setups side by
    side: (label, claim id) pairs."""

    name: str
    says: str
    setups: tuple[tuple[str, str], ...]
    statement: str = ""


#: the main text's claims (what each says: the macro ``says_<name>`` of :data:`WORDS`)
MAIN_CLAIMS: tuple[MainClaim, ...] = (
    MainClaim(
        "NBO's plans",
        WORDS("says_nbo_plans"),
        (("oven LQG", "DEC-1"), ("UAV paper", "DEC-6"), ("UAV footprint150", "DEC-7-footprint150")),
        "S1",
    ),
    MainClaim(
        "RS-MHP vs NBO",
        WORDS("says_rsmhp_vs_nbo"),
        (("UAV paper", "UAV-2"), ("map, no footprint", "DEC-8b"), ("map, footprint", "DEC-8a")),
        "S9",
    ),
    MainClaim(
        "Weighting",
        WORDS("says_weighting"),
        (("oven LQG", "LQG-4"), ("estimator problems", "EST-2")),
        "S3",
    ),
    MainClaim(
        "Pruning",
        WORDS("says_pruning"),
        (("estimator problems", "EST-4"), ("oven LQG decisions", "DEC-4"), ("UAV paper", "UAV-3")),
        "S5",
    ),
    MainClaim(
        "RQMC at 1 ms",
        WORDS("says_rqmc"),
        (("UAV paper", "FR-1-paper"), ("UAV footprint150", "FR-1-footprint150")),
    ),
    MainClaim(
        "Sigma points at 1 ms",
        WORDS("says_sigma_points"),
        (("UAV paper", "FR-2-paper"), ("UAV footprint150", "FR-2-footprint150")),
    ),
    MainClaim(
        "Tree search at 1 ms",
        WORDS("says_tree_search"),
        (("UAV paper", "FR-3-paper"), ("UAV footprint150", "FR-3-footprint150")),
    ),
    MainClaim(
        "NBO's error vs H",
        WORDS("says_nbo_error_h"),
        (("UAV paper", "HZ-1-paper"), ("UAV footprint150", "HZ-1-footprint150")),
    ),
    MainClaim(
        "Pruning vs H",
        WORDS("says_pruning_h"),
        (
            ("oven LQG", "HZ-4"),
            ("UAV paper", "HZ-2-paper"),
            ("UAV footprint150", "HZ-2-footprint150"),
        ),
    ),
    MainClaim(
        "Sampling's gain vs H",
        WORDS("says_sampling_gain_h"),
        (("UAV footprint150", "HZ-3-footprint150"),),
    ),
)


def anchor(claim_id: str) -> str:
    """The appendix anchor of a claim's details (its heading is ``### <id>``)."""
    return re.sub(r"[^a-z0-9 -]", "", claim_id.lower()).replace(" ", "-")


def link(claim_id: str, appendix: str = "appendix.md") -> str:
    """``[id](appendix.md#id)``."""
    return f"[{claim_id}]({appendix}#{anchor(claim_id)})"


def key_text(c: Claim) -> str:
    """The key number with its CI and unit: ``-0.050 [-0.20, +0.11] m``."""
    k = c.key
    signed = k.null == 0.0
    out = fmt(k.value, k.digits, signed)
    if k.has_ci:
        out += " " + fmt_ci(k.ci_low, k.ci_high, k.digits, signed)
    return out + (f" {k.unit}" if k.unit else "")


_HOLM = re.compile(r"p = ([^ ]+) ≥ [^:]+: ([a-z ]+) without it, becomes inconclusive")


def verdict_text(c: Claim) -> str:
    """The verdict as it reads: ``equivalent (difference significant but below Δ = 0.25 m)``
    when the CI of an equivalent key number excludes its null; ``inconclusive (after Holm,
    p = 0.0512; equivalent without it)`` when Holm's correction made it inconclusive; else
    the verdict; followed by the note of a choice made after its data
    (:func:`rsmhp.report.disclosures.verdict_note`), e.g. ``equivalent (exploratory: margin
    set after the first result)``."""
    note = verdict_note(c)
    text = _verdict_words(c)
    return WORDS("with_note", verdict=text, note=note) if note else text


def _verdict_words(c: Claim) -> str:
    """:func:`verdict_text` without the disclosures' note."""
    k = c.key
    m = _HOLM.search(c.rule)
    if c.verdict == "inconclusive" and m:
        return WORDS("after_holm", p=m.group(1), without=m.group(2))
    if c.verdict == "equivalent" and k.has_ci and k.null is not None:
        if not k.ci_low <= k.null <= k.ci_high:
            delta = f"Δ = {fmt(k.margin, 3)}{' ' + k.unit if k.unit else ''}" if k.margin else "Δ"
            return WORDS("significant_below", margin=delta)
    return c.verdict


def _power_text(c: Claim) -> str:
    k = c.key
    if k.n is None:
        return ""
    need = runs_needed(k)
    if need is None:
        return "; " + WORDS("power_undecided", n=k.n)
    return "; " + WORDS("power", n=k.n, need=need, holm=k.p_holm is not None)


def main_rows(claims: Sequence[Claim], appendix: str = "appendix.md") -> list[dict[str, str]]:
    """One dict per :data:`MAIN_CLAIMS` row with at least one claim in this run: ``name``,
    ``says``, ``statement``, ``setups`` (the setups side by side: label, linked id, key
    number, verdict and the runs at 80% power)."""
    by_id = {c.id: c for c in claims}
    rows = []
    for m in MAIN_CLAIMS:
        cells = []
        for label, cid in m.setups:
            c = by_id.get(cid)
            if c is None:
                continue
            depth = depth_of(c.claim)  # a tree search named by its measured plan depth
            named = f"**{label}** ({depth})" if depth else f"**{label}**"
            cells.append(
                f"{named} {link(cid, appendix)}: {key_text(c)} → **{verdict_text(c)}**"
                f"{_power_text(c)}"
            )
        if cells:
            rows.append({"name": m.name, "says": m.says, "statement": m.statement, "setups": cells})
    return rows


def _ids(js: Sequence[Judgement]) -> str:
    return ", ".join(j.statement.id for j in js)


def named_setup(label: str, c: Claim) -> str:
    """A setup's label with the measured plan depth of a tree-search claim beside it
    (:func:`rsmhp.report.naming.depth_of`): ``UAV paper (plan depth 1.20: ...)``."""
    depth = depth_of(c.claim)
    return f"{label} ({depth})" if depth else label


def _claim_phrase(c: Claim, appendix: str) -> str:
    return f"{link(c.id, appendix)} {key_text(c)}, {verdict_text(c)}"


def _span(values: Sequence[str], prefix: str, unit: str) -> str:
    inner = values[0] if len(values) == 1 else WORDS("span", first=values[0], last=values[-1])
    return f"{prefix}{inner}{unit}"


def best_sentence(best: pd.DataFrame | None) -> str:
    """Which method is clearly best where, from the summary table ``best`` (columns
    ``group``, ``model``, ``value``, ``best`` (or its label ``best_label``), ``clear``; rows
    in the figure's order): per group and model the runs of neighbouring cells where the same
    method is clearly best, then the cells without a clear best (a tied best is no
    recommendation). Empty without a table."""
    if best is None or best.empty:
        return ""
    unit = {"budget": " ms"}
    prefix = {"horizon": "H = ", "scenario": "q = "}
    parts = []
    for (group, model), g in best.groupby(["group", "model"], sort=False):
        pre, post = prefix.get(group, ""), unit.get(group, "")
        clear: list[list[Any]] = []  # [label, values, last position]
        unclear: list[list[Any]] = []  # [values, last position]
        for pos, (_, r) in enumerate(g.iterrows()):
            value = r["value"]
            value = param_text(value) if isinstance(value, int | float) else str(value)
            name = r["best_label"] if "best_label" in r.index else r["best"]
            if bool(r["clear"]):
                if clear and clear[-1][0] == name and clear[-1][2] == pos - 1:
                    clear[-1][1].append(value)
                    clear[-1][2] = pos
                else:
                    clear.append([name, [value], pos])
            elif unclear and unclear[-1][1] == pos - 1:
                unclear[-1][0].append(value)
                unclear[-1][1] = pos
            else:
                unclear.append([[value], pos])
        segs = [WORDS("best_at", method=name, cells=_span(v, pre, post)) for name, v, _ in clear]
        if unclear and not clear:
            segs.append(WORDS("no_best_anywhere", n=len(g)))
        elif unclear:
            spans = ", ".join(_span(u, pre, post) for u, _ in unclear)
            segs.append(WORDS("no_best_at", cells=spans))
        parts.append(WORDS("best_by", group=group, model=model, cells=", ".join(segs)))
    return "; ".join(parts)


def other_streams(
    claims: Sequence[Claim], history: pd.DataFrame | None, appendix: str | None = "appendix.md"
) -> list[dict[str, Any]]:
    """Per earlier seed stream of ``history`` (rows of kind ``stream``, e.g. a superseded
    confirmatory run) that judged some of ``claims``: its label and the claims it judged
    otherwise ({label, claims: [linked id (the bare id when ``appendix`` is ``None``), its
    verdict there]}), in the history's order. The main text says so next to the claims, not
    only in the fragility list."""
    if history is None or history.empty:
        return []
    by_id = {c.id: c for c in claims}
    rows = history[(history["kind"] == "stream") & history["claim"].isin(list(by_id))]
    out = []
    for label, g in rows.groupby("label", sort=False):
        other = [
            (link(r.claim, appendix) if appendix is not None else str(r.claim), r.verdict)
            for r in g.itertuples(index=False)
            if r.verdict != by_id[r.claim].verdict
        ]
        if other:
            out.append({"label": str(label), "n": len(g), "claims": other})
    return out


def found_values(
    judgements: Sequence[Judgement],
    claims: Sequence[Claim],
    best: pd.DataFrame | None = None,
    appendix: str = "appendix.md",
    history: pd.DataFrame | None = None,
) -> Mapping[str, Any]:
    """The values the "What we found" template fills in: the statements by verdict on the
    paper's setups and on variants, the claims each sentence names (linked, with key number,
    verdict and contrary evidence where a claim has some), the FR claims whose verdict another
    seed stream of ``history`` gave otherwise (:func:`other_streams`), the best-family
    summary and the checks' count."""
    by_id = {c.id: c for c in claims}

    def phrase(cid: str) -> str:
        return _claim_phrase(by_id[cid], appendix) if cid in by_id else ""

    tally = {v: js for v in STATEMENT_VERDICTS if (js := [j for j in judgements if j.verdict == v])}
    variants = [j for j in judgements if j.on_variants is not None and j.on_variants != j.verdict]
    checks = [c for c in claims if c.check]
    fr = [m for m in MAIN_CLAIMS if m.setups[0][1].startswith("FR-")]
    hz = [m for m in MAIN_CLAIMS if m.setups[0][1].startswith("HZ-")]

    def row_phrase(m: MainClaim) -> str:
        got = [(lab, by_id[cid]) for lab, cid in m.setups if cid in by_id]
        if not got:
            return ""
        inner = "; ".join(
            f"{named_setup(lab, c)}: {_claim_phrase(c, appendix)}"
            + (" " + WORDS("contrary_inline", text=c.contrary) if c.contrary else "")
            for lab, c in got
        )
        return f"'{m.says}' ({inner})"

    return {
        "n_statements": len(judgements),
        "tally": [(v, len(js), _ids(js)) for v, js in tally.items()],
        "variants": [(j.statement.id, j.verdict, j.on_variants) for j in variants],
        "statement": {j.statement.id: j for j in judgements},
        "claim": phrase,
        "fr": [p for m in fr if (p := row_phrase(m))],
        "fr_streams": other_streams(
            [c for m in fr for _, cid in m.setups if (c := by_id.get(cid)) is not None],
            history,
            appendix,
        ),
        "hz": [p for m in hz if (p := row_phrase(m))],
        "best": best_sentence(best),
        "n_checks": len(checks),
        "checks_supported": sum(c.verdict == "supported" for c in checks),
        "has": lambda cid: cid in by_id,
    }
