"""Decision study on the scalar LQG, report section: the Markdown tables, the short body with
the figure and the findings, and the appendix with the derivations, assembled into a
:class:`rsmhp.report.ledger.Section` from the claims of :mod:`rsmhp.studies.decisions.claims_lqg`
and the statistics of :mod:`rsmhp.models.lqg.regret_summary`. The prose is in the templates
beside this module (``section_lqg.md``: body, ``section_lqg_appendix.md``); this module
computes and formats the values they insert.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import pandas as pd

from rsmhp.models.lqg.regret_summary import (
    WEIGHTED_MIN_P,
    ZERO_REGRET,
    max_rel_regret,
    slopes,
    z_families,
)
from rsmhp.report.ledger import Claim, Section
from rsmhp.report.markdown import fmt, fmt_ci, markdown_table, param_text, range_text
from rsmhp.report.templates import render
from rsmhp.studies.decisions import FIGURES_LQG as FIGURES
from rsmhp.studies.decisions.claims_lqg import lqg_claims

__all__ = ["FIGURES", "lqg_decision_section", "lqg_tables", "shown_a"]


def _render(template: str, **values: Any) -> str:
    """The template ``template`` beside this module filled with ``values``, without the line
    break that ends the template file."""
    return render("rsmhp.studies.decisions", template, **values).removesuffix("\n")


def _sample_text(row: pd.Series) -> str:
    """The sample size of a cell in words: ``P = 100``, ``N = 4 (P = 16)``, ``N = 10, M = 30``."""
    method, N, M, P = str(row["method"]), int(row["N"]), int(row["M"]), int(row["P"])
    if method == "nbo":
        return "nominal"
    if method == "tree":
        return f"N = {N} (P = {P})"
    if method == "pruned":
        return f"N = {N}, M = {M}"
    return f"P = {P}"


def shown_a(summary: pd.DataFrame) -> float:
    """The value of a whose cells the regret table shows: the middle of the a values run."""
    a_values = sorted(summary["a"].unique())
    return a_values[len(a_values) // 2]


def lqg_tables(
    summary: pd.DataFrame, scaling: pd.DataFrame, a_show: float | None = None
) -> dict[str, str]:
    """Markdown tables keyed by file stem: ``decisions_lqg_regret`` (every cell at ``a_show``,
    default :func:`shown_a`), ``decisions_lqg_scaling`` (every slope fit). Absent closed forms and
    z-scores print as "none" (explained in the section's appendix)."""
    a_show = shown_a(summary) if a_show is None else a_show
    s = summary[summary["a"] == a_show]
    cells = pd.DataFrame(
        {
            "H": s["H"].astype(int),
            "method": s["method"],
            "weighting": s["weighting"],
            "sample": [_sample_text(row) for _, row in s.iterrows()],
            "R": s["n"].astype(int),
            "mean regret": s["mean"],
            "95% CI": [
                fmt_ci(lo, hi) if n > 1 else "single run"
                for lo, hi, n in zip(s["ci_low"], s["ci_high"], s["n"], strict=True)
            ],
            "mean / J(u*)": s["rel_mean"],
            "closed form": s["closed_form"].where(s["closed_kind"] != "none"),
            "kind": s["closed_kind"],
            "z": s["z"],
        }
    )
    scal = scaling.rename(
        columns={"x": "in", "n_points": "points", "low": "CI low", "high": "CI high"}
    ).assign(a=[param_text(a) for a in scaling["a"]])  # configuration values as written
    return {
        "decisions_lqg_regret": markdown_table(cells, digits=3, missing="none", signed=("z",)),
        "decisions_lqg_scaling": markdown_table(
            scal, digits=3, signed=("slope", "CI low", "CI high")
        ),
    }


@dataclass(frozen=True)
class KeyNumberText:
    """A claim's key number for the findings: its name, its value (formatted), the claim's id
    and verdict."""

    id: str
    name: str
    value: str
    verdict: str


@dataclass(frozen=True)
class ZFamily:
    """A family of z-scores (simulated vs closed-form mean regret) for the findings: the
    largest |z| of its cells, their number and their Bonferroni limit (formatted), the cells'
    name and the claim judging them."""

    max_abs_z: str
    cells: str
    limit: str
    what: str
    id: str
    verdict: str


@dataclass(frozen=True)
class SlopeRange:
    """The range of the log-log slopes of mean regret in P of one sample design."""

    slopes: str
    what: str


def _key_text(claim: Claim, digits: int) -> KeyNumberText:
    return KeyNumberText(
        id=claim.id, name=claim.key.name, value=fmt(claim.key.value, digits), verdict=claim.verdict
    )


def _findings(
    claims: Sequence[Claim], summary: pd.DataFrame, scaling: pd.DataFrame
) -> dict[str, Any]:
    """The values of the findings paragraph, every number from the claims and fits: DEC-1
    (NBO's largest relative regret), the z-score families of DEC-2/3/5, the slope ranges, DEC-4
    (the pruned tree's shape in M); each ``None`` or empty when absent."""
    c = {claim.id: claim for claim in claims}
    zfam = z_families(summary)
    d1, d4 = c.get("DEC-1"), c.get("DEC-4")
    return {
        "dec1": _key_text(d1, 2) if d1 is not None else None,
        "dec1_exact": d1 is not None and d1.verdict == "not supported",
        "z_families": [
            ZFamily(
                max_abs_z=fmt(zfam[cid].max_abs_z, 3),
                cells=str(zfam[cid].cells),
                limit=fmt(zfam[cid].limit, 3),
                what=what,
                id=cid,
                verdict=c[cid].verdict,
            )
            for cid, what in (
                ("DEC-2", "Monte-Carlo"),
                ("DEC-3", "shared-draw tree"),
                ("DEC-5", f"weighted, P ≥ {WEIGHTED_MIN_P},"),
            )
            if cid in c and cid in zfam
        ],
        "slope_ranges": [
            SlopeRange(slopes=range_text(s["slope"], signed=True), what=what)
            for method, what in (("mc", "Monte Carlo"), ("sobol", "scrambled Sobol' points"))
            if not (s := slopes(scaling, method)).empty
        ],
        "dec4": _key_text(d4, 3) if d4 is not None else None,
        "dec4_u_shape": bool(d4 is not None and d4.contrary),
    }


def _setting(model: Mapping[str, Any], cfg: Mapping[str, Any]) -> dict[str, str]:
    """The values of the setting paragraph: the LQG model (``lqg.model``) and the design
    (``decisions.lqg``) as configured."""
    return {
        "r": param_text(model["r"]),
        "target": param_text(model["target"]),
        "x0": param_text(model["x0"]),
        "sigma": param_text(model["sigma"]),
        "a_set": "{" + ", ".join(param_text(a) for a in cfg["a_values"]) + "}",
        "h_set": "{" + ", ".join(str(int(h)) for h in cfg["H_values"]) + "}",
        "replicates": str(int(cfg["replicates"])),
        "pruned_N": str(int(cfg["pruned_N"])),
    }


def _appendix(summary: pd.DataFrame, tables: Mapping[str, str]) -> str:
    """Derivations, the regret table at :func:`shown_a` and the slope table."""
    return _render(
        "section_lqg_appendix.md",
        a_shown=param_text(shown_a(summary)),
        zero_regret=fmt(max_rel_regret(summary, ZERO_REGRET), 2),
        regret_table=tables["decisions_lqg_regret"],
        scaling_table=tables["decisions_lqg_scaling"],
    )


def lqg_decision_section(
    summary: pd.DataFrame,
    scaling: pd.DataFrame,
    tables: Mapping[str, str],
    model: Mapping[str, Any],
    cfg: Mapping[str, Any],
) -> Section:
    """The decision study's LQG report section (order 30): short body with the figure,
    tables and the closed-form derivation in the appendix. ``model`` is the ``lqg.model``
    config section, ``cfg`` the ``decisions.lqg`` one."""
    claims = lqg_claims(summary, scaling, model)
    body = _render("section_lqg.md", **_setting(model, cfg), **_findings(claims, summary, scaling))
    return Section(
        key="decisions_lqg",
        title="Decision quality: LQG regret",
        order=30,
        body=body,
        claims=claims,
        figures=list(FIGURES),
        appendix=_appendix(summary, tables),
    )
