"""The estimator study's report section: the body (what was run, symbols, findings, figures),
the appendix (why the findings hold, the samplers beyond the paper, every table) and the
Markdown tables, from the statistics of :mod:`rsmhp.studies.estimators.summarise` and the claims of
:mod:`rsmhp.studies.estimators.claims`."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.report.ledger import Section
from rsmhp.report.markdown import fmt, fmt_ci, markdown_table
from rsmhp.studies.estimators.claims import claims, k_text, range_text
from rsmhp.studies.estimators.summarise import (
    MIN_TREE_SIZES,
    antithetic_ratios,
    best_stochastic_gains,
    equal_cpu_gains,
    exact_rule_error,
    largest_cells,
    largest_leaf_ratios,
    mc_variance_slopes,
    pruning_at_largest_n,
    pruning_pivot,
    select,
    sobol_rmse_ratios,
    tree_slopes,
    tree_vs_independent,
    weighted_at_largest,
    weighted_fractions,
    weighted_fractions_all,
)

__all__ = ["ABSENT", "FIGURES", "estimators_section", "gain_table", "tables"]

#: the figures the section shows, in order (drawn by :mod:`rsmhp.studies.estimators.figures`)
FIGURES = (
    "est_rmse_vs_n",
    "est_bias_vs_n",
    "est_tree_variance",
    "est_weighted_vs_uniform",
    "est_pruning_heatmap",
    "est_frontier",
)
#: text of a table cell without a value, explained under each table that uses it
ABSENT = "—"


def _method(r: Mapping[str, Any]) -> str:
    return str(r["scheme"]) + (", weighted" if r["weighting"] == "weighted" else "")


def _size(r: Mapping[str, Any]) -> str:
    """Human size of a cell: n for samplers, N (and M) for trees."""
    if r["scheme"] in ("tree", "tree_pernode"):
        return f"N = {int(r['N'])}"
    if r["scheme"] == "pruned":
        return f"N = {int(r['N'])}, M = {int(r['M'])}"
    if r["scheme"] == "gauss_hermite":
        return f"q = {int(r['N'])}"
    return ""


def _and(items: Iterable[str]) -> str:
    """``a``, ``a and b``, ``a, b and c``."""
    items = [str(i) for i in items]
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def _ci_column(lows: pd.Series, highs: pd.Series, digits: int = 3) -> list[str]:
    return [fmt_ci(a, b, digits) for a, b in zip(lows, highs, strict=True)]


# --- tables ---------------------------------------------------------------------------------


def _largest_table(s: pd.DataFrame) -> str:
    largest = largest_cells(s)
    out = pd.DataFrame(
        {
            "problem": largest["problem"],
            "estimator": [_method(r) for _, r in largest.iterrows()],
            "size": [_size(r) or ABSENT for _, r in largest.iterrows()],
            "n": largest["n_trajectories"].astype(int),
            "bias": largest["bias"],
            "bias 95% CI": _ci_column(largest["bias_low"], largest["bias_high"]),
            "sd": largest["sd"],
            "derived sd": np.sqrt(largest["var_theory"]),
            "RMSE": largest["rmse"],
            "RMSE 95% CI": _ci_column(largest["rmse_low"], largest["rmse_high"]),
            "CPU ms (this run)": largest["cpu_median"] * 1e3,
        }
    )
    return markdown_table(out, digits=3, missing=ABSENT)


def gain_table(s: pd.DataFrame) -> str:
    """Markdown table of :func:`~rsmhp.studies.estimators.summarise.equal_cpu_gains`; exact rules
    read "exact (error at rounding level)" instead of a gain. CPU columns are this run's
    measurements."""
    g = equal_cpu_gains(s)
    if g.empty:
        return "No plain-MC cells: no equal-CPU comparison."
    out = pd.DataFrame(
        {
            "problem": g["problem"],
            "scheme": g["scheme"],
            "MC time budget ms": g["cpu_seconds"] * 1e3,
            "n reached": g["n_trajectories"],
            "its CPU ms": g["cpu_used"] * 1e3,
            "RMSE": g["rmse"],
            "RMSE gain vs MC": [
                "exact (error at rounding level)" if e else fmt(v, 3)
                for e, v in zip(g["exact"], g["gain_vs_mc"], strict=True)
            ],
            "note": g["note"],
        }
    )
    return markdown_table(out, digits=3)


def _chebyshev_table(cheb: pd.DataFrame) -> str:
    """The Chebyshev exceedances at the largest n, with the exact probability."""
    if not len(cheb):
        return markdown_table(pd.DataFrame({"problem": []}), digits=3)
    cheb = cheb[cheb["n"] == cheb["n"].max()]
    out = pd.DataFrame(
        {
            "problem": cheb["problem"],
            "n": cheb["n"],
            "k": [k_text(k) for k in cheb["k"]],
            "bound 1/k²": cheb["bound"],
            "exact": cheb["exact"],
            "observed": cheb["freq"],
            "95% CI": _ci_column(cheb["low"], cheb["high"]),
        }
    )
    return markdown_table(out, digits=3)


def _weighted_table(s: pd.DataFrame) -> str:
    rows = [
        {
            "problem": r["problem"],
            "estimator": f"{r['scheme']}, weighted",
            "size": _size(r) or f"n = {int(r['n_trajectories'])}",
            "mean": r["mean"],
            "mean 95% CI": fmt_ci(r["ci_low"], r["ci_high"], 4),
            "J": r["J_exact"],
            "J(Σ/2)": r["limit"],
            "f": r["f"],
            "f 95% CI": fmt_ci(r["f_low"], r["f_high"], 4),
        }
        for _, r in weighted_at_largest(s).iterrows()
    ]
    return markdown_table(pd.DataFrame(rows), digits=4)


def tables(df: pd.DataFrame, s: pd.DataFrame, cheb: pd.DataFrame) -> dict[str, str]:
    """Markdown tables keyed by file stem (``results/tables/<stem>.md``)."""
    tvi = tree_vs_independent(s).rename(
        columns={
            "var_tree": "Var tree",
            "var_mc": "Var mc",
            "ratio_measured": "ratio",
            "ratio_derived": "derived ratio",
        }
    )
    return {
        "est_largest": _largest_table(s),
        "est_tree_vs_independent": markdown_table(tvi, digits=3),
        "est_pruning": markdown_table(pruning_pivot(s), digits=3, missing=ABSENT),
        "est_weighted": _weighted_table(s),
        "est_equal_cpu": gain_table(s),
        "est_chebyshev": _chebyshev_table(cheb),
    }


# --- the body -------------------------------------------------------------------------------


def _tree_findings(s: pd.DataFrame) -> list[str]:
    out = []
    sl = tree_slopes(s)
    counted = sl[sl["counted"]]
    if len(counted):
        out.append(
            f"The shared tree's variance falls like 1/N (slopes {range_text(counted['slope'], 3)} "
            f"where >= {MIN_TREE_SIZES} sizes ran), not 1/N^H: its leaves reuse N·H draws."
        )
    head = largest_leaf_ratios(s)
    if len(head):
        r = head.loc[head["leaves"].idxmax()]
        out.append(
            f"At {int(r['leaves'])} leaves its variance is "
            f"{range_text(head[head['leaves'] == r['leaves']]['ratio_measured'], 2)} times that "
            "of as many independent trajectories."
        )
    return out


def _weighting_finding(s: pd.DataFrame) -> list[str]:
    wf = weighted_fractions(s)
    if not len(wf):
        return []
    last = wf.loc[wf.groupby("problem", sort=False)["N"].idxmax()]
    reached = last[(last["f_low"] <= 1) & (last["f_high"] >= 1)]
    short = last[last["f_high"] < 1]
    txt = (
        "Likeliness weighting multiplies N(0, Σ) by its own density, i.e. samples "
        "N(0, Σ/2): f = (mean - J)/(J(Σ/2) - J) of the weighted tree grows from 0 at N = 1 "
        "toward 1 as N grows (a trend; no finite-N closed form)"
    )
    if len(reached):
        txt += f"; at the largest N its CI contains 1 for {_and(reached['problem'])}"
    if len(short):
        txt += ", but the tree is not yet at its limit for " + _and(
            f"{r['problem']} (N = {int(r['N'])}, f = {fmt(r['f'], 2)})" for _, r in short.iterrows()
        )
    return [txt + "."]


def _other_findings(s: pd.DataFrame, cheb: pd.DataFrame) -> list[str]:
    out = []
    top = pruning_at_largest_n(s)
    if len(top):
        out.append(
            "Pruning with M fixed keeps draws ever nearer the mode as N grows, so the estimate "
            f"tends to the NBO cost J_NBO: at N = {int(top['N'].max())} its bias is "
            f"{range_text(top['bias_fraction_of_nbo'] * 100, 2, '%')} of J_NBO - J."
        )
    if len(cheb):
        rate = [f.slope for f in mc_variance_slopes(s).values()]
        out.append(
            "Plain MC's exceedance frequency is below Chebyshev's bound (upper CI limit) in "
            f"{int((cheb['high'] < cheb['bound']).sum())}/{len(cheb)} (problem, n, k) cells, "
            "and the exact probability (a generalised chi-square) lies at "
            f"{range_text(cheb['exact'] / cheb['bound'], 2)} × the bound"
            + (f"; its variance slope vs n is {range_text(rate, 3)}." if rate else ".")
        )
    big = sobol_rmse_ratios(s)
    if len(big):
        out.append(
            f"Sobol' points cut the RMSE {range_text(big['ratio'], 2)} times "
            f"against MC at n = {int(big['n_trajectories'].iloc[0])}; cubature and "
            "Gauss-Hermite are exact for these quadratic costs."
        )
    return out


def _findings(s: pd.DataFrame, cheb: pd.DataFrame) -> list[str]:
    """Sentences of the body's findings paragraph, each built only if its data exist."""
    return [*_tree_findings(s), *_weighting_finding(s), *_other_findings(s, cheb)]


_SYMBOLS = (
    "**Symbols.** H: horizon; n: trajectories averaged (a tree's leaves); mc: n "
    "independent trajectories; tree: N draws per level shared by every node of the level "
    "(N^H leaves); tree_pernode: N fresh draws at every node; pruned: keeps the M most "
    "likely partial trajectories (product of draw densities) per level; weighted: "
    "average with normalised likeliness. The stacked noise w = (w_0..w_{H-1}) ~ N(0, S), "
    "S = I_H ⊗ Σ, Σ the per-step noise covariance; each trajectory cost is "
    "g(w) = c + bᵀw + wᵀKw, so J = c + tr(KS), the NBO (nominal-trajectory) cost J_NBO = c,"
    " and J(Σ/2) = c + tr(KS)/2 is J with Σ halved."
)

#: (alt text, caption) of each figure of :data:`FIGURES`
_CAPTIONS = (
    ("RMSE vs n", "RMSE (95% CI) vs n; pruned at its largest N (n = M)."),
    ("bias vs n", "Bias / (J_NBO - J): 0 unbiased, 0.5 J(Σ/2), 1 the NBO cost."),
    (
        "tree variance",
        "Variance vs leaves: shared tree, per-node tree, independent; dashed: derived.",
    ),
    (
        "weighted vs uniform",
        "Mean (95% CI): uniform on J; weighted (dotted) below J, approaching J(Σ/2) as n grows.",
    ),
    ("pruning", "Pruned tree: bias / (J_NBO - J) over (N, M); colour clipped to [0, 1]."),
    ("frontier", "RMSE vs CPU time per estimate (this run's timings; they vary per run)."),
)


def _run_text(s: pd.DataFrame) -> str:
    reps = int(s["n_replicates"].max())
    hs = s.groupby("problem", sort=False)["H"].first()
    prob_txt = ", ".join(f"{p} (H={int(hs[p])})" for p in dict.fromkeys(s["problem"]))
    mc = select(s, "mc")
    n_max = int(mc["n_trajectories"].max()) if len(mc) else 0
    return (
        "**Run.** Every estimator of the paper, and samplers it does not use (antithetic "
        "pairs w, -w; scrambled Sobol' quasi-random points; cubature and Gauss-Hermite "
        f"quadrature), on problems with an exactly known expected cost J: {prob_txt} "
        "(lqg_*: scalar oven LQG, lqg_paper the paper's setting; ncv*: 2-D point mass). "
        f"{reps} seeded replicates per cell, n <= {n_max}."
    )


def _body(s: pd.DataFrame, cheb: pd.DataFrame) -> str:
    parts = [
        _run_text(s),
        _SYMBOLS,
        "**Found.** " + " ".join(_findings(s, cheb)),
        "Figures: weighted variants dotted, derived values dashed; y ranges follow the point "
        "estimates, CI bars beyond are cut (count in the panel title).",
    ]
    for name, (alt, caption) in zip(FIGURES, _CAPTIONS, strict=True):
        parts += [f"![{alt}](figures/{name}.png)", f"*{caption}*"]
    return "\n\n".join(parts)


def estimators_section(
    df: pd.DataFrame, s: pd.DataFrame, cheb: pd.DataFrame, tabs: Mapping[str, str]
) -> Section:
    """The estimator-study report section (order 15): a short body (what was run, symbols,
    findings, figures), the claims EST-1..EST-4 and an appendix (rules, samplers beyond the
    paper, tables ``tabs`` from :func:`tables`)."""
    return Section(
        key="estimators",
        title="Estimator study: tree vs independent sampling, pruning, weighting, samplers",
        order=15,
        body=_body(s, cheb),
        claims=claims(s, cheb),
        figures=[f"{f}.png" for f in FIGURES],
        appendix=_appendix(s, tabs),
    )


# --- the appendix ---------------------------------------------------------------------------


def _weighted_note(s: pd.DataFrame) -> str:
    """Where the measured f of every weighted cell lies relative to [0, 1] (within its CI)."""
    wf = weighted_fractions_all(s)
    if wf.empty:
        return ""
    inside = wf["in_unit_interval"]
    out = (
        f"The measured f lies between 0 and 1 (within its 95% CI) in {int(inside.sum())} of "
        f"{len(wf)} weighted cells and tends to grow with N or n"
    )
    odd = wf[~inside]
    if len(odd):
        out += "; outside: " + ", ".join(
            f"{r['scheme']} {r['problem']} n = {int(r['n_trajectories'])} (f = {fmt(r['f'], 4)} "
            f"{fmt_ci(r['f_low'], r['f_high'], 4)})"
            for _, r in odd.iterrows()
        )
        out += f", about what {len(wf)} intervals at 95% leave outside by chance"
    return out + "."


def _exact_note(s: pd.DataFrame) -> str:
    err = exact_rule_error(s)
    if err is None:
        return ""
    cells, rel = err
    return (
        f"Cubature (2·H·d sigma points, d = noise dimension) and Gauss-Hermite (q^(H·d) points) "
        f"ran once per problem and size ({cells} cells) and reproduce J to a relative error of "
        f"at most {fmt(rel, 2)}, i.e. floating-point rounding: both are exact for quadratic "
        "costs, so they appear as *exact* and not as an RMSE gain (a ratio with a rounding error "
        "in the denominator carries no information). This says nothing about non-polynomial "
        "costs such as the UAV planner's."
    )


def _why(s: pd.DataFrame) -> list[str]:
    """The appendix's explanations: why the tree converges slowly, why weighting is biased,
    why pruning tends to NBO, and the samplers beyond the paper."""
    anti_txt = ", ".join(f"{p} {fmt(r, 3)}" for p, r in antithetic_ratios(s).items())
    return [
        "Verdict rules in full: docstring of `rsmhp.studies.estimators.claims`. Every number here "
        "except CPU times is bitwise reproducible (seeded draws and bootstrap).",
        "**Why the tree converges slowly.** Every node of a level reuses the same N draws, so "
        "the N^H leaves carry only N·H independent numbers. Averaging g over the product grid "
        "gives the derived variance bᵀSb/N + 2tr((KS)²)/N² + 2(N-1)/N² Σ_k tr((K_kk Σ)²) "
        "(K_kk: the k-th diagonal block of K), which falls like 1/N, not 1/N^H. The per-node "
        "tree's leaves are correlated only through common prefixes; it falls faster.",
        "**Why weighting is biased.** The likeliness of a draw is its density φ_Σ; weighting by "
        "it turns N(0, Σ) into φ_Σ² ∝ N(0, Σ/2), so every weighted estimator tends to "
        "J(Σ/2) = c + tr(KS)/2 as its sample grows. At finite N the self-normalised weights have "
        "no closed-form mean; the two derived end points are N = 1 (one weight, mean J, f = 0) "
        "and N -> infinity (f = 1). " + _weighted_note(s),
        "**Why pruning tends to NBO.** The M most likely of N draws per level are the M nearest "
        "the mode 0; as N grows with M fixed they shrink to 0 and the pruned estimate to g(0) = c, "
        "the NBO cost.",
        "**Samplers beyond the paper.** Antithetic pairs (w, -w) cancel the linear part bᵀw but "
        "double the weight of the quadratic part: their variance relative to MC is "
        f"4tr((KS)²)/Var(g) = {anti_txt} (derived), so they barely help here. Scrambled Sobol' "
        "points (randomised quasi-Monte Carlo) gain most. " + _exact_note(s),
    ]


def _table_texts(s: pd.DataFrame, tabs: Mapping[str, str]) -> list[str]:
    """Each appendix table with the sentence that introduces it."""
    best = best_stochastic_gains(equal_cpu_gains(s))
    best_txt = "; ".join(
        f"{r['problem']} {r['scheme']} {fmt(r['gain_vs_mc'], 2)}x" for _, r in best.iterrows()
    )
    return [
        "Weighted estimators at their largest size; f = (mean - J)/(J(Σ/2) - J):",
        tabs["est_weighted"],
        "Tree vs independent sampling at equal leaf counts (variance ratio tree / mc, measured "
        "and derived):",
        tabs["est_tree_vs_independent"],
        f"Pruned tree (uniform), bias / (J_NBO - J) per kept count M and draws per level N; "
        f"{ABSENT}: M > N, not run:",
        tabs["est_pruning"],
        "Prop. 3 at the largest n: frequency of |J_n - J| >= k·sd_n (sd_n derived) vs the "
        "Chebyshev bound 1/k², with its Clopper-Pearson 95% CI:",
        tabs["est_chebyshev"],
        "Equal CPU time. CPU times are measurements of this run and differ between runs and "
        "machines, so nothing here is a key number. Each scheme's best RMSE within the median "
        "CPU time of plain MC's largest budget (its CPU-RMSE frontier at that time); gain = "
        f"RMSE_mc / RMSE. Best stochastic sampler per problem: {best_txt or 'none'}. Exact rules "
        "have no gain (see above).",
        tabs["est_equal_cpu"],
        "Each stochastic estimator at its largest size (full table: "
        "`results/estimators/summary.csv`). size: N draws per level (trees), M kept (pruned); "
        f"derived sd {ABSENT}: no closed form (weighted, Sobol', pruned). CPU ms vary per run:",
        tabs["est_largest"],
    ]


def _appendix(s: pd.DataFrame, tabs: Mapping[str, str]) -> str:
    """Why the findings hold, the samplers beyond the paper, and every table."""
    return "\n\n".join([*_why(s), *_table_texts(s, tabs)])
