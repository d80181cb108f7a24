"""LQG study (paper Sec. III-A, Fig. 3), report section: the Markdown tables, the short main
text with the four figures and the appendix, assembled into a :class:`rsmhp.report.ledger.Section`
from the claims of :mod:`rsmhp.studies.lqg.claims` and the statistics of
:mod:`rsmhp.studies.lqg.summarise`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from rsmhp.models.lqg import oven as lqg
from rsmhp.report.ledger import Claim, Section
from rsmhp.report.markdown import fmt, fmt_ci, markdown_table
from rsmhp.studies.lqg.claims import ci_digits, fmt_exact, lqg_claims
from rsmhp.studies.lqg.summarise import (
    LinearCostCheck,
    chebyshev_check,
    chebyshev_long,
    eps_label,
    fig3_check,
    model_from_table,
    nbo_z_limit,
)

__all__ = [
    "FIGURES",
    "NBO_Z_CLIP",
    "TABLES",
    "chebyshev_table",
    "convergence_table",
    "lqg_section",
    "lqg_tables",
    "nbo_error_table",
    "nbo_z_table",
]

#: figure stems written by the figure rule and referenced by the report section
FIGURES = ("lqg_fig3_paper", "lqg_convergence", "lqg_error_loglog", "lqg_nbo_error")
#: Markdown table stems written by the summary rule (``results/tables/<stem>.md``)
TABLES = ("lqg_convergence", "lqg_nbo_error", "lqg_nbo_z", "lqg_chebyshev")

#: |z| beyond which the NBO-error residual panel draws a point at its edge (and says so)
NBO_Z_CLIP = 8.0


# -------------------------------------------------------------------------------- tables


def _subset_p(summary: pd.DataFrame, max_rows: int = 12) -> pd.DataFrame:
    """At most ``max_rows`` rows of the per-P summary, P log-spaced (first and last kept)."""
    ps = summary["P"].to_numpy()
    if len(ps) <= max_rows:
        return summary
    targets = np.geomspace(ps.min(), ps.max(), max_rows)
    idx = sorted({int(np.abs(ps - t).argmin()) for t in targets})
    return summary.iloc[idx]


def convergence_table(summary: pd.DataFrame, max_rows: int = 12) -> pd.DataFrame:
    """A readable subset of the per-P summary (log-spaced P values), with readable headers."""
    sub = _subset_p(summary, max_rows)
    return pd.DataFrame(
        {
            "P": sub["P"].astype(int),
            "replicates": sub["n_replicates"].astype(int),
            "mean J_P": sub["mean"],
            "95% CI low": sub["ci_low"],
            "95% CI high": sub["ci_high"],
            "SD of J_P": sub["std"],
            "√(Var(g)/P)": sub["sd_theory"],
            "RMSE": sub["rmse"],
            "weighted mean": sub["weighted_mean"],
        }
    )


def nbo_error_table(nbo: pd.DataFrame) -> pd.DataFrame:
    """Pivot: rows a, columns H, cells 'simulated ± 95% half-width (closed form)'."""
    cells = [
        f"{fmt(s, 4)} ± {fmt(1.96 * e, 2)} ({fmt_exact(c, 4)})"
        for s, e, c in zip(nbo["nbo_error_sim"], nbo["se"], nbo["nbo_error_closed"], strict=True)
    ]
    table = nbo.assign(cell=cells).pivot(index="a", columns="H", values="cell")
    table.columns = [f"H={h}" for h in table.columns]
    table = table.reset_index()
    table["a"] = table["a"].map(eps_label)
    return table


def nbo_z_table(nbo: pd.DataFrame) -> pd.DataFrame:
    """Pivot of z = (simulated - closed form)/SE: rows a, columns H."""
    table = nbo.pivot(index="a", columns="H", values="z")
    table.columns = [f"H={h}" for h in table.columns]
    table = table.reset_index()
    table["a"] = table["a"].map(eps_label)
    return table


def chebyshev_table(summary: pd.DataFrame, eps_values: Sequence[float]) -> pd.DataFrame:
    """The Chebyshev cells of the log-spaced subset of P, sorted by (ε, P): bound, exact
    probability, exceedances and their Clopper-Pearson 95% limits."""
    cheb = chebyshev_long(summary, eps_values)
    sel = cheb[cheb["P"].isin(_subset_p(summary)["P"])].sort_values(["eps", "P"], kind="stable")
    return pd.DataFrame(
        {
            "P": sel["P"].astype(int),
            "ε": sel["eps"].map(eps_label),
            "Var(g)/(Pε²)": sel["bound_raw"],
            "exact probability": sel["exact"],
            "exceedances": sel["k"].astype(int),
            "replicates": sel["n"].astype(int),
            "frequency": sel["freq"],
            "CP 95% low": sel["low"],
            "CP 95% high": sel["high"],
        }
    )


def lqg_tables(
    summary: pd.DataFrame, nbo: pd.DataFrame, eps_values: Sequence[float]
) -> dict[str, str]:
    """Markdown tables keyed by file stem (:data:`TABLES`, ``results/tables/<stem>.md``)."""
    return {
        "lqg_convergence": markdown_table(convergence_table(summary), digits=4),
        "lqg_nbo_error": markdown_table(nbo_error_table(nbo)),
        "lqg_nbo_z": markdown_table(nbo_z_table(nbo), digits=2, signed=()),
        "lqg_chebyshev": markdown_table(chebyshev_table(summary, eps_values), digits=3),
    }


# -------------------------------------------------------------------------------- section


def _p_text(summary: pd.DataFrame) -> str:
    """The P grid in words: ``P = 100, 200, ..., 10000`` (even steps) or ``P ∈ {...}``."""
    p_grid = sorted(summary["P"].astype(int))
    step = p_grid[1] - p_grid[0] if len(p_grid) > 1 else 0
    if len(p_grid) > 3 and np.all(np.diff(p_grid) == step):
        return f"P = {p_grid[0]}, {p_grid[1]}, ..., {p_grid[-1]}"
    return "P ∈ {" + ", ".join(str(p) for p in p_grid) + "}"


def _setting_paragraph(summary: pd.DataFrame, nbo: pd.DataFrame, conv: pd.DataFrame) -> str:
    """The model, the paper's setting and what we ran."""
    u, model = model_from_table(conv)
    reps = int(summary.iloc[-1]["n_replicates"])
    return (
        "Scalar oven problem of Sec. III-A: state x_k, control u_k, noise w_k ~ N(0, σ²), "
        "x_{k+1} = (1-a) x_k + a u_k + w_k; cost J = E[r (x_H - T)² + Σ_{k<H} u_k²] with "
        "weight r, target T, horizon H. NBO (nominal belief-state optimisation) sets every "
        "w_k to 0 (cost J_NBO); MHP (multipath hypothesis propagation) averages the cost g "
        "of P independent simulated trajectories (estimate J_P, variance "
        f"Var(g)/P). Paper's setting: x_0 = {eps_label(model.x0)}, r = {eps_label(model.r)}, "
        f"T = {eps_label(model.target)}, σ = {eps_label(model.sigma)}, H = {len(u)}, u = "
        f"({', '.join(eps_label(v) for v in u)}), {_p_text(summary)}; a = "
        f"{eps_label(model.a)} is our choice (the paper gives none). We ran {reps} independent "
        f"replicates per P, and the NBO error on {nbo['a'].nunique()} values of a × "
        f"{nbo['H'].nunique()} of H ({int(nbo['n_replicates'].iloc[0])} replicates of "
        f"P = {int(nbo['P'].iloc[0])}, u_k = {eps_label(nbo['u_value'].iloc[0])})."
    )


def _chebyshev_sentence(summary: pd.DataFrame, eps_values: Sequence[float], c3: Claim) -> str:
    check = chebyshev_check(summary, eps_values)
    t = check.test
    return (
        f"Over {t.cells} (P, ε) cells the count of |J_P - J| ≥ ε matches its exact "
        f"probability (J_P is a generalised chi-square; {t.departing} cells depart, smallest "
        f"adjusted p = {fmt(t.min_p, 3)})"
        + (
            f", and that probability is at most {fmt(t.max_exact_ratio, 2)} × Prop. 3's "
            "Chebyshev bound Var(g)/(Pε²) where the bound is below 1"
            if np.isfinite(t.max_exact_ratio)
            else "; Prop. 3's Chebyshev bound Var(g)/(Pε²) is not below 1 in any cell"
        )
    )


def _linear_sentence(c: Claim | None) -> str:
    if c is None:
        return ""
    return (
        " On a linear-cost system, Prop. 3's own premise, the simulated variance of J_N "
        f"matches the paper's formula C[Σ_k 𝒜_k Σ 𝒜_kᵀ]Cᵀ/N ({c.key.name} = "
        f"{fmt(c.key.value, 3)}; LIN-1 {c.verdict})."
    )


def _results_paragraph(
    summary: pd.DataFrame,
    nbo: pd.DataFrame,
    conv: pd.DataFrame,
    eps_values: Sequence[float],
    claims: Mapping[str, Claim],
) -> str:
    """Closed forms, the RMSE slope (LQG-2), the NBO-error check (LQG-1), the Chebyshev
    cells (LQG-3) and the weighted estimate (LQG-4)."""
    u, model = model_from_table(conv)
    last = summary.iloc[-1]
    var_g = lqg.cost_variance(u, **model.closed_form_args())
    nbo_err = float(last["J_exact"] - last["J_nbo"])
    fit = fig3_check(summary).fit
    sd = ci_digits(fit.low, fit.high)
    j_text = fmt_exact(last["J_exact"], 4)
    c1, c4 = claims["LQG-1"], claims["LQG-4"]
    kd = c4.key.digits
    weighted = f"{fmt(c4.key.value, kd)} {fmt_ci(c4.key.ci_low, c4.key.ci_high, kd)}"
    return (
        f"Closed forms: J = {j_text}, J_NBO = {fmt_exact(last['J_nbo'], 4)}, "
        f"Var(g) = {fmt_exact(var_g, 4)}. The root-mean-square error (RMSE) of J_P scales like "
        f"P^{fmt(fit.slope, sd)} {fmt_ci(fit.low, fit.high, sd)} (theory "
        f"-1/2) and is {fmt(last['rmse'], 3)} at P = {int(last['P'])}, where NBO's error "
        f"J - J_NBO = r σ² Σ_{{n<H}} (1-a)^{{2n}} = {fmt_exact(nbo_err, 4)} is "
        f"{fmt(abs(nbo_err) / float(last['rmse']), 2)} times the RMSE (LQG-2). Simulated and "
        f"closed-form NBO errors differ by at most {fmt(c1.key.value, 3)} standard errors "
        f"over {len(nbo) + 1} checks (Bonferroni limit {fmt(nbo_z_limit(len(nbo)), 3)}; "
        f"LQG-1). {_chebyshev_sentence(summary, eps_values, claims['LQG-3'])} (LQG-3). "
        f"The likeliness-weighted average is {weighted} at P = {int(last['P'])} (J = "
        f"{j_text}); J(σ²/2) = {fmt_exact(last['weighted_limit'], kd)} is its limit, since "
        "the weights tilt the noise to N(0, σ²/2); Prop. 2's proof needs weights monotone in "
        "the sample index, which likeliness weights are not (LQG-4)."
        + _linear_sentence(claims.get("LIN-1"))
    )


def _figures_text(summary: pd.DataFrame, nbo: pd.DataFrame) -> list[str]:
    """The four figures with their captions (main text)."""
    reps = int(summary.iloc[-1]["n_replicates"])
    n_clip = int((nbo["z"].abs() > NBO_Z_CLIP).sum())
    clipped = f" ({n_clip} beyond ±{fmt(NBO_Z_CLIP, 1)} drawn at the panel edge)" if n_clip else ""
    return [
        "![Fig. 3, paper style](figures/lqg_fig3_paper.png)",
        "",
        f"*Paper-style Fig. 3: one realisation of J_P for each P ({_p_text(summary)}); NBO "
        "and exact J as lines.*",
        "",
        "![J_P vs P, statistics](figures/lqg_convergence.png)",
        "",
        f"*Our view of Fig. 3: mean of J_P over {reps} replicates with its 95% CI and the "
        "central 95% of replicates; right, mean − J.*",
        "",
        "![error vs P](figures/lqg_error_loglog.png)",
        "",
        "*RMSE vs P with √(Var(g)/P); observed P(|J_P − J| ≥ ε) vs the Chebyshev bound "
        "(frequency 0 drawn at the floor).*",
        "",
        "![NBO error](figures/lqg_nbo_error.png)",
        "",
        "*NBO error vs H per a, simulated (95% CI) vs closed form; below, the difference in "
        f"standard errors with the Bonferroni limits of LQG-1{clipped}.*",
    ]


def _appendix(conv: pd.DataFrame, nbo: pd.DataFrame, tables: Mapping[str, str]) -> str:
    """Model constants, the weighted-estimator derivation and the four tables."""
    u, model = model_from_table(conv)
    reps, p_nbo = int(nbo["n_replicates"].iloc[0]), int(nbo["P"].iloc[0])
    return "\n".join(
        [
            f"Model constants of the convergence run: a = {eps_label(model.a)}, x_0 = "
            f"{eps_label(model.x0)}, r = {eps_label(model.r)}, T = {eps_label(model.target)}, "
            f"σ = {eps_label(model.sigma)}, u = ({', '.join(eps_label(v) for v in u)}). Every "
            "(P, replicate) draws its own P × H noise (no nesting across P), so the replicates "
            "and the values of P are independent. Full per-P table: `results/lqg/summary.csv`.",
            "",
            "**Weighted estimator.** It weights trajectory i by q_i ∝ Π_k φ(w_k^i; 0, σ²). "
            "Under sampling from N(0, σ²) the weighted average converges to E[q g]/E[q], the "
            "expectation under the density ∝ φ², i.e. N(0, σ²/2): the limit is J(σ²/2) = "
            "J - r Var(x_H)/2. Prop. 2 borrows a result on weighted averages with weights "
            "monotonically decreasing in the sample index; sorting the samples by likeliness "
            "makes the order depend on the samples, so the result does not apply.",
            "",
            "Convergence of J_P (subset of P, log-spaced):",
            "",
            tables["lqg_convergence"],
            "",
            f"NBO error J - J_NBO per a (rows) and H (columns): simulated mean ± 95% half-width "
            f"(closed form), {reps} replicates of P = {p_nbo}, "
            f"u_k = {eps_label(nbo['u_value'].iloc[0])}:",
            "",
            tables["lqg_nbo_error"],
            "",
            f"z = (simulated - closed form)/SE of the same cells (LQG-1 limit ± "
            f"{fmt(nbo_z_limit(len(nbo)), 3)}):",
            "",
            tables["lqg_nbo_z"],
            "",
            "Chebyshev bound Var(g)/(Pε²) (vacuous where ≥ 1) vs the observed exceedances of "
            "|J_P - J| ≥ ε with Clopper-Pearson (CP) 95% limits (subset of P):",
            "",
            tables["lqg_chebyshev"],
        ]
    )


def lqg_section(
    summary: pd.DataFrame,
    nbo: pd.DataFrame,
    conv: pd.DataFrame,
    eps_values: Sequence[float],
    tables: Mapping[str, str],
    linear: LinearCostCheck,
) -> Section:
    """The LQG report section (order 10): short main text with the four figures; the tables,
    the weighted-estimator derivation and the parameters in the appendix; ``linear`` is the
    check of Prop. 3 on a linear-cost system (claim LIN-1)."""
    claims = lqg_claims(summary, nbo, conv, eps_values, linear)
    by_id = {c.id: c for c in claims}
    body = "\n".join(
        [
            _setting_paragraph(summary, nbo, conv),
            "",
            _results_paragraph(summary, nbo, conv, eps_values, by_id),
            "",
            *_figures_text(summary, nbo),
        ]
    )
    return Section(
        key="lqg",
        title="Case study 1: scalar LQG (paper Sec. III-A, Fig. 3)",
        order=10,
        body=body,
        claims=claims,
        figures=[f"{f}.png" for f in FIGURES],
        appendix=_appendix(conv, nbo, tables),
    )
