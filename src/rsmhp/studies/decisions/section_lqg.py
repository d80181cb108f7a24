"""Decision study on the scalar LQG, report section: the Markdown tables, the short body with
the figure and the findings, and the appendix with the derivations, assembled into a
:class:`rsmhp.report.ledger.Section` from the claims of :mod:`rsmhp.studies.decisions.claims_lqg`
and the statistics of :mod:`rsmhp.models.lqg.regret_summary`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
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
from rsmhp.studies.decisions.claims_lqg import lqg_claims

__all__ = ["FIGURES", "lqg_decision_section", "lqg_tables", "shown_a"]

#: figure stems of the section (the figure rule writes them; see decisions.smk)
FIGURES = ("dec_lqg_regret",)


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
    """Markdown tables keyed by file stem: ``dec_lqg_regret`` (every cell at ``a_show``,
    default :func:`shown_a`), ``dec_lqg_scaling`` (every slope fit). Absent closed forms and
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
        "dec_lqg_regret": markdown_table(cells, digits=3, missing="none", signed=("z",)),
        "dec_lqg_scaling": markdown_table(scal, digits=3, signed=("slope", "CI low", "CI high")),
    }


def _findings(claims: Sequence[Claim], summary: pd.DataFrame, scaling: pd.DataFrame) -> str:
    """One short paragraph of results, every number from the claims and fits."""
    c = {claim.id: claim for claim in claims}
    out = []
    if "DEC-1" in c:
        exact = c["DEC-1"].verdict == "not supported"
        out.append(
            f"NBO's regret is at most {fmt(c['DEC-1'].key.value, 2)} × J(u*)"
            + (", zero up to rounding: NBO chooses the exact optimum" if exact else "")
            + f" (DEC-1 {c['DEC-1'].verdict})."
        )
    zfam = z_families(summary)
    parts = [
        f"{fmt(zfam[cid].max_abs_z, 3)} of {zfam[cid].cells} {what} cells (limit "
        f"{fmt(zfam[cid].limit, 3)}; {cid} {c[cid].verdict})"
        for cid, what in (
            ("DEC-2", "Monte-Carlo"),
            ("DEC-3", "shared-draw tree"),
            ("DEC-5", f"weighted, P ≥ {WEIGHTED_MIN_P},"),
        )
        if cid in c and cid in zfam
    ]
    if parts:
        out.append("Simulated vs closed-form mean regret: max |z| " + ", ".join(parts) + ".")
    fits = [
        f"{range_text(s['slope'], signed=True)} for {what}"
        for method, what in (("mc", "Monte Carlo"), ("sobol", "scrambled Sobol' points"))
        if not (s := slopes(scaling, method)).empty
    ]
    if fits:
        out.append("Log-log slopes of mean regret in P: " + ", ".join(fits) + ".")
    if "DEC-4" in c:
        d4 = c["DEC-4"]
        shape = (
            "rises again after its minimum over M in some cells (a U shape), so no slope "
            "summarises it"
            if d4.contrary
            else "is summarised by its shape in M"
        )
        out.append(
            f"The pruned tree's regret {shape}: {d4.key.name} = {fmt(d4.key.value, 3)} "
            f"(DEC-4 {d4.verdict}; the regret at the smallest, the best and the largest M of "
            "every cell is in its details)."
        )
    return " ".join(out)


def _setting_paragraph(model: Mapping[str, Any], cfg: Mapping[str, Any]) -> str:
    """The problem, the methods and the regret (first paragraph of the body)."""
    a_txt = ", ".join(param_text(a) for a in cfg["a_values"])
    h_txt = ", ".join(str(int(h)) for h in cfg["H_values"])
    return (
        "Does a method's cost estimate choose good controls? On the paper's scalar LQG, "
        "x_{k+1} = (1 − a)x_k + a u_k + w_k, w_k ~ N(0, σ²), cost J(u) = E[r(x_H − T)² + "
        f"Σ u_k²] (r = {param_text(model['r'])}, target T = {param_text(model['target'])}, "
        f"x_0 = {param_text(model['x0'])}, σ = {param_text(model['sigma'])}; "
        f"a ∈ {{{a_txt}}}, horizon H ∈ {{{h_txt}}} steps) each method draws its sample "
        "once, its sample-average cost is minimised exactly over the open-loop controls "
        "u_0..u_{H−1}, and the minimiser û is scored by its **regret** J(û) − J(u*) ≥ 0 "
        "under the exact cost J, u* being the exact optimum; "
        f"{int(cfg['replicates'])} replicates per stochastic cell (the cells of one method and "
        "sample size share their draws across a and H, a cell of horizon H using the first "
        "H steps: common random numbers, the cells' distributions unchanged). P = "
        "trajectories an "
        "estimate averages, N = draws per tree level (tree: P = N^H leaves), M = trajectories "
        f"the pruned tree keeps (N = {int(cfg['pruned_N'])}); likeliness weights weight each "
        "trajectory by the product of its noise densities."
    )


#: why the regret has a closed form (second paragraph of the body)
CLOSED_FORM_PARAGRAPH = (
    "Why the answer has a closed form: J(u) = r[(m_H − T)² + v_H] + |u|², with m_H "
    "and v_H the mean and variance of the final state, and v_H does not depend on u, "
    "so NBO (noise at its mean) has J's minimiser. A sample average shifts the target "
    "by the mean ē of the sampled final-state noises, giving regret κ ē², "
    "κ = r²a²‖β‖²/(1 + r a²‖β‖²), β_k = (1 − a)^{H−1−k}: mean κ v_H / P for "
    "independent trajectories, κ v_H / N (not / N^H) for the shared-draw tree, 0 for "
    "antithetic pairs and symmetric cubature points. z = (simulated − closed-form "
    "mean) / its standard error."
)


def _appendix(summary: pd.DataFrame, tables: Mapping[str, str]) -> str:
    """Derivations, the regret table at :func:`shown_a` and the slope table."""
    return "\n".join(
        [
            "Derivations (`rsmhp.models.lqg.oven`): the regret of a cell with a closed form is "
            "its mean times a χ²₁ variable, so the standard error of a mean of R replicates is "
            "mean × √(2/R), and z = (simulated − closed form) / (closed form × √(2/R)); a "
            "family of m z-scores is checked against the Bonferroni limit "
            "Φ⁻¹(1 − 0.05/(2m)). With likeliness weights the self-normalised mean of the "
            "final-state noise has variance (4/3)^{H/2} v_H / (3P) to first order in 1/P, "
            "so weighting beats uniform mc for H ≤ 7. Sobol' uses the power of 2 nearest P.",
            "",
            f"Every cell at a = {param_text(shown_a(summary))} (R replicates; mean regret "
            "with 95% t-interval; kind: exact, asymptotic (large P) or none). 'none' in the "
            "closed-form column: no closed form for this method and weighting; 'none' in z: "
            "no closed form, or it is 0 (nbo, antithetic, cubature: the simulated regret is "
            f"rounding error, at most {fmt(max_rel_regret(summary, ZERO_REGRET), 2)} × J(u*)).",
            "",
            tables["dec_lqg_regret"],
            "",
            "Log-log slopes of mean regret in the sample size ('in': P, or N for the tree; M "
            "= P for the pruned tree) with 95% t-intervals; (a, H) cells with fewer than 3 "
            "sample sizes have no slope:",
            "",
            tables["dec_lqg_scaling"],
        ]
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
    body = "\n".join(
        [
            _setting_paragraph(model, cfg),
            "",
            CLOSED_FORM_PARAGRAPH,
            "",
            _findings(claims, summary, scaling),
            "",
            "![LQG regret](figures/dec_lqg_regret.png)",
            "",
            "*Mean regret against P (log-log; tree: N^H leaves, pruned: M) per (a, H); "
            "dashed: closed forms, dotted: likeliness weights. NBO, antithetic, cubature "
            "(regret 0 up to rounding) not drawn.*",
        ]
    )
    return Section(
        key="decisions_lqg",
        title="Decision quality: LQG regret",
        order=30,
        body=body,
        claims=claims,
        figures=list(FIGURES),
        appendix=_appendix(summary, tables),
    )
