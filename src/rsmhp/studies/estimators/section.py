"""The estimator study's report section: the body (what was run, symbols, findings, figures),
the appendix (why the findings hold, the samplers beyond the paper, every table) and the
Markdown tables, from the statistics of :mod:`rsmhp.studies.estimators.summarise` and the claims of
:mod:`rsmhp.studies.estimators.claims`. The prose lives in the templates ``section.md`` (body) and
``appendix.md`` beside this module (:func:`rsmhp.report.templates.render`); this module computes
and formats the values they print."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.report.ledger import Section
from rsmhp.report.markdown import fmt, fmt_ci, markdown_table
from rsmhp.report.templates import render
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

__all__ = [
    "ABSENT",
    "FIGURES",
    "ChebyshevText",
    "ExactRulesText",
    "Findings",
    "LeafRatioText",
    "PruningText",
    "RunText",
    "SobolText",
    "WeightedCellsText",
    "WeightingText",
    "estimators_section",
    "gain_table",
    "tables",
]

#: the figures the section shows, in order (drawn by :mod:`rsmhp.studies.estimators.figures`)
FIGURES = (
    "estimators_rmse_vs_n",
    "estimators_bias_vs_n",
    "estimators_tree_variance",
    "estimators_weighted_vs_uniform",
    "estimators_pruning_heatmap",
    "estimators_frontier",
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
        "estimators_largest": _largest_table(s),
        "estimators_tree_vs_independent": markdown_table(tvi, digits=3),
        "estimators_pruning": markdown_table(pruning_pivot(s), digits=3, missing=ABSENT),
        "estimators_weighted": _weighted_table(s),
        "estimators_equal_cpu": gain_table(s),
        "estimators_chebyshev": _chebyshev_table(cheb),
    }


# --- the body -------------------------------------------------------------------------------

#: the package whose ``section.md`` and ``appendix.md`` hold the prose
_TEMPLATES = "rsmhp.studies.estimators"


def _render(template: str, **values: Any) -> str:
    """``template`` filled with ``values``; the file's final newline is not part of the
    section text."""
    return render(_TEMPLATES, template, **values).removesuffix("\n")


@dataclass(frozen=True)
class RunText:
    """What was run, printed: the problems with their horizons (``lqg_paper (H=2), ...``),
    the replicates per cell and plain MC's largest n (0 without MC cells)."""

    problems: str
    replicates: int
    n_max: int

    @classmethod
    def of(cls, s: pd.DataFrame) -> RunText:
        """The run summarised in ``s``."""
        hs = s.groupby("problem", sort=False)["H"].first()
        mc = select(s, "mc")
        return cls(
            problems=", ".join(f"{p} (H={int(hs[p])})" for p in dict.fromkeys(s["problem"])),
            replicates=int(s["n_replicates"].max()),
            n_max=int(mc["n_trajectories"].max()) if len(mc) else 0,
        )


@dataclass(frozen=True)
class LeafRatioText:
    """Var(shared tree) / Var(independent) at the largest leaf count ``leaves`` (range over the
    problems run at it)."""

    leaves: int
    ratio: str


@dataclass(frozen=True)
class WeightingText:
    """The weighted tree's f = (mean - J)/(J(Σ/2) - J) at each problem's largest N: the
    problems whose CI of f contains 1 (``reached``) and those whose CI lies below 1
    (``short``, with N and f); "" where there are none."""

    reached: str
    short: str


@dataclass(frozen=True)
class PruningText:
    """The pruned tree's bias as a share of J_NBO - J (range, in %) at the largest N = ``n``."""

    n: int
    bias: str


@dataclass(frozen=True)
class ChebyshevText:
    """Plain MC's Chebyshev cells: ``below`` of ``cells`` (problem, n, k) cells have the upper
    CI limit of the exceedance frequency below the bound 1/k²; the exact probability over the
    bound (range); the slopes of log Var vs log n (range; None without a fit)."""

    below: int
    cells: int
    ratio: str
    slopes: str | None


@dataclass(frozen=True)
class SobolText:
    """RMSE of plain MC / RMSE of Sobol' (range over the problems) at n = ``n``."""

    ratio: str
    n: int


@dataclass(frozen=True)
class Findings:
    """The numbers of the body's findings, printed; a finding whose data do not exist is None
    and its sentence is left out. ``tree_slopes``: range of the shared tree's counted slopes of
    log Var vs log N (run at >= ``min_tree_sizes`` sizes)."""

    tree_slopes: str | None
    min_tree_sizes: int
    leaf_ratio: LeafRatioText | None
    weighting: WeightingText | None
    pruning: PruningText | None
    chebyshev: ChebyshevText | None
    sobol: SobolText | None


def _tree_findings(s: pd.DataFrame) -> tuple[str | None, LeafRatioText | None]:
    """The range of the shared tree's counted variance slopes and its variance ratio to
    independent sampling at the largest leaf count (None where absent)."""
    counted = tree_slopes(s)
    counted = counted[counted["counted"]]
    head = largest_leaf_ratios(s)
    leaf_ratio = None
    if len(head):
        leaves = head.loc[head["leaves"].idxmax(), "leaves"]
        leaf_ratio = LeafRatioText(
            leaves=int(leaves),
            ratio=range_text(head[head["leaves"] == leaves]["ratio_measured"], 2),
        )
    return (range_text(counted["slope"], 3) if len(counted) else None), leaf_ratio


def _weighting_finding(s: pd.DataFrame) -> WeightingText | None:
    """Where the weighted tree's f stands at each problem's largest N (None without one)."""
    wf = weighted_fractions(s)
    if not len(wf):
        return None
    last = wf.loc[wf.groupby("problem", sort=False)["N"].idxmax()]
    reached = last[(last["f_low"] <= 1) & (last["f_high"] >= 1)]
    short = last[last["f_high"] < 1]
    return WeightingText(
        reached=_and(reached["problem"]) if len(reached) else "",
        short=(
            _and(
                f"{r['problem']} (N = {int(r['N'])}, f = {fmt(r['f'], 2)})"
                for _, r in short.iterrows()
            )
            if len(short)
            else ""
        ),
    )


def _chebyshev_finding(s: pd.DataFrame, cheb: pd.DataFrame) -> ChebyshevText | None:
    """Plain MC's exceedances against Chebyshev's bound (None without Chebyshev cells)."""
    if not len(cheb):
        return None
    rate = [f.slope for f in mc_variance_slopes(s).values()]
    return ChebyshevText(
        below=int((cheb["high"] < cheb["bound"]).sum()),
        cells=len(cheb),
        ratio=range_text(cheb["exact"] / cheb["bound"], 2),
        slopes=range_text(rate, 3) if rate else None,
    )


def _findings(s: pd.DataFrame, cheb: pd.DataFrame) -> Findings:
    """The numbers of the body's findings paragraph, each only if its data exist."""
    tree_slopes_text, leaf_ratio = _tree_findings(s)
    top = pruning_at_largest_n(s)
    big = sobol_rmse_ratios(s)
    return Findings(
        tree_slopes=tree_slopes_text,
        min_tree_sizes=MIN_TREE_SIZES,
        leaf_ratio=leaf_ratio,
        weighting=_weighting_finding(s),
        pruning=(
            PruningText(
                n=int(top["N"].max()),
                bias=range_text(top["bias_fraction_of_nbo"] * 100, 2, "%"),
            )
            if len(top)
            else None
        ),
        chebyshev=_chebyshev_finding(s, cheb),
        sobol=(
            SobolText(ratio=range_text(big["ratio"], 2), n=int(big["n_trajectories"].iloc[0]))
            if len(big)
            else None
        ),
    )


def _body(s: pd.DataFrame, cheb: pd.DataFrame) -> str:
    """What was run, the symbols, the findings and the figures with their captions
    (``section.md``)."""
    return _render("section.md", run=RunText.of(s), found=_findings(s, cheb))


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


@dataclass(frozen=True)
class WeightedCellsText:
    """Where the measured f of every weighted cell lies relative to [0, 1] (within its 95%
    CI): ``inside`` of ``cells`` cells meet it; ``outside`` names the others with f and its
    CI."""

    inside: int
    cells: int
    outside: tuple[str, ...]


@dataclass(frozen=True)
class ExactRulesText:
    """The quadrature rules (cubature, Gauss-Hermite): ``cells`` cells run, their largest
    relative error |bias| / max(|J|, 1)."""

    cells: int
    error: str


def _weighted_cells(s: pd.DataFrame) -> WeightedCellsText | None:
    """Where f of every weighted cell lies relative to [0, 1] (None without weighted cells)."""
    wf = weighted_fractions_all(s)
    if wf.empty:
        return None
    inside = wf["in_unit_interval"]
    return WeightedCellsText(
        inside=int(inside.sum()),
        cells=len(wf),
        outside=tuple(
            f"{r['scheme']} {r['problem']} n = {int(r['n_trajectories'])} (f = {fmt(r['f'], 4)} "
            f"{fmt_ci(r['f_low'], r['f_high'], 4)})"
            for _, r in wf[~inside].iterrows()
        ),
    )


def _exact_rules(s: pd.DataFrame) -> ExactRulesText | None:
    """The quadrature rules' cells and largest relative error (None if none ran)."""
    err = exact_rule_error(s)
    if err is None:
        return None
    cells, rel = err
    return ExactRulesText(cells=cells, error=fmt(rel, 2))


def _appendix(s: pd.DataFrame, tabs: Mapping[str, str]) -> str:
    """Why the findings hold, the samplers beyond the paper, and every table, each with the
    sentence that introduces it (``appendix.md``)."""
    best = best_stochastic_gains(equal_cpu_gains(s))
    return _render(
        "appendix.md",
        weighted_cells=_weighted_cells(s),
        exact_rules=_exact_rules(s),
        antithetic=[f"{p} {fmt(r, 3)}" for p, r in antithetic_ratios(s).items()],
        best_gains=[
            f"{r['problem']} {r['scheme']} {fmt(r['gain_vs_mc'], 2)}x" for _, r in best.iterrows()
        ],
        absent=ABSENT,
        tables=tabs,
    )
