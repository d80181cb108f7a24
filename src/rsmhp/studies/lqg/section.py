"""LQG study (paper Sec. III-A, Fig. 3), report section: the Markdown tables, the short main
text with the four figures and the appendix, assembled into a :class:`rsmhp.report.ledger.Section`
from the claims of :mod:`rsmhp.studies.lqg.claims` and the statistics of
:mod:`rsmhp.studies.lqg.summarise`. The prose lives in the templates ``section.md`` (main text)
and ``appendix.md`` beside this module (:func:`rsmhp.report.templates.render`); this module
computes and formats the values they print.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.models.lqg import oven as lqg
from rsmhp.report.ledger import Claim, Section
from rsmhp.report.markdown import fmt, fmt_ci, markdown_table
from rsmhp.report.templates import render
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
    "LinearText",
    "ModelText",
    "NboRunText",
    "ResultsText",
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

#: the package whose ``section.md`` and ``appendix.md`` hold the prose
_TEMPLATES = "rsmhp.studies.lqg"


def _render(template: str, **values: Any) -> str:
    """``template`` filled with ``values``; the file's final newline is not part of the
    section text."""
    return render(_TEMPLATES, template, **values).removesuffix("\n")


def _p_text(summary: pd.DataFrame) -> str:
    """The P grid in words: ``P = 100, 200, ..., 10000`` (even steps) or ``P ∈ {...}``."""
    p_grid = sorted(summary["P"].astype(int))
    step = p_grid[1] - p_grid[0] if len(p_grid) > 1 else 0
    if len(p_grid) > 3 and np.all(np.diff(p_grid) == step):
        return f"P = {p_grid[0]}, {p_grid[1]}, ..., {p_grid[-1]}"
    return "P ∈ {" + ", ".join(str(p) for p in p_grid) + "}"


@dataclass(frozen=True)
class ModelText:
    """The oven model of the convergence run, printed: the constants a, x_0, r, T, σ, the
    open-loop controls u = (u_0, ..., u_{H-1}) (comma-separated) and the horizon H = len(u)."""

    a: str
    x0: str
    r: str
    target: str
    sigma: str
    u: str
    horizon: int

    @classmethod
    def of(cls, conv: pd.DataFrame) -> ModelText:
        """The model stamped in the convergence table ``conv``."""
        u, model = model_from_table(conv)
        return cls(
            a=eps_label(model.a),
            x0=eps_label(model.x0),
            r=eps_label(model.r),
            target=eps_label(model.target),
            sigma=eps_label(model.sigma),
            u=", ".join(eps_label(v) for v in u),
            horizon=len(u),
        )


@dataclass(frozen=True)
class NboRunText:
    """The NBO-error run, printed: ``n_a`` values of a × ``n_h`` of H, each cell ``replicates``
    replicates of P = ``p`` trajectories under the constant control u_k = ``u``; ``limit`` is
    the Bonferroni limit of |z| over its cells (LQG-1)."""

    n_a: int
    n_h: int
    replicates: int
    p: int
    u: str
    limit: str

    @classmethod
    def of(cls, nbo: pd.DataFrame) -> NboRunText:
        """The run summarised in the NBO-error summary ``nbo``."""
        return cls(
            n_a=nbo["a"].nunique(),
            n_h=nbo["H"].nunique(),
            replicates=int(nbo["n_replicates"].iloc[0]),
            p=int(nbo["P"].iloc[0]),
            u=eps_label(nbo["u_value"].iloc[0]),
            limit=fmt(nbo_z_limit(len(nbo)), 3),
        )


@dataclass(frozen=True)
class LinearText:
    """The linear-cost check of Prop. 3 (LIN-1), printed: its key number and verdict."""

    name: str
    value: str
    verdict: str


@dataclass(frozen=True)
class ResultsText:
    """The numbers of the results paragraph, printed.

    Closed forms J, J_NBO, Var(g) and the NBO error J - J_NBO = r σ² Σ_{n<H} (1-a)^{2n};
    the OLS slope of log RMSE vs log P with its 95% CI (LQG-2); the RMSE at the largest P
    = ``p`` and the NBO error in RMSEs; the largest |z| of the NBO-error checks over
    ``nbo_checks`` checks (LQG-1); the exceedance test of |J_P - J| ≥ ε over ``cheb_cells``
    (P, ε) cells, ``cheb_departing`` of them departing, smallest adjusted p ``cheb_min_p``,
    and the largest ratio of the exact probability to the Chebyshev bound where that bound
    is below 1 (``cheb_bound_ratio``, None where it is nowhere below 1) (LQG-3); the weighted
    average with its CI and its limit J(σ²/2) (LQG-4); the linear-cost check (LIN-1, None
    without one)."""

    j: str
    j_nbo: str
    var_g: str
    slope: str
    slope_ci: str
    rmse: str
    p: int
    nbo_error: str
    nbo_error_in_rmse: str
    nbo_max_z: str
    nbo_checks: int
    cheb_cells: int
    cheb_departing: int
    cheb_min_p: str
    cheb_bound_ratio: str | None
    weighted: str
    weighted_limit: str
    linear: LinearText | None


def _results(
    summary: pd.DataFrame,
    nbo: pd.DataFrame,
    conv: pd.DataFrame,
    eps_values: Sequence[float],
    claims: Mapping[str, Claim],
) -> ResultsText:
    """Closed forms, the RMSE slope (LQG-2), the NBO-error check (LQG-1), the Chebyshev
    cells (LQG-3), the weighted estimate (LQG-4) and the linear-cost check (LIN-1)."""
    u, model = model_from_table(conv)
    last = summary.iloc[-1]
    var_g = lqg.cost_variance(u, **model.closed_form_args())
    nbo_err = float(last["J_exact"] - last["J_nbo"])
    fit = fig3_check(summary).fit
    sd = ci_digits(fit.low, fit.high)
    test = chebyshev_check(summary, eps_values).test
    c1, c4, lin = claims["LQG-1"], claims["LQG-4"], claims.get("LIN-1")
    kd = c4.key.digits
    return ResultsText(
        j=fmt_exact(last["J_exact"], 4),
        j_nbo=fmt_exact(last["J_nbo"], 4),
        var_g=fmt_exact(var_g, 4),
        slope=fmt(fit.slope, sd),
        slope_ci=fmt_ci(fit.low, fit.high, sd),
        rmse=fmt(last["rmse"], 3),
        p=int(last["P"]),
        nbo_error=fmt_exact(nbo_err, 4),
        nbo_error_in_rmse=fmt(abs(nbo_err) / float(last["rmse"]), 2),
        nbo_max_z=fmt(c1.key.value, 3),
        nbo_checks=len(nbo) + 1,
        cheb_cells=test.cells,
        cheb_departing=test.departing,
        cheb_min_p=fmt(test.min_p, 3),
        cheb_bound_ratio=(
            fmt(test.max_exact_ratio, 2) if np.isfinite(test.max_exact_ratio) else None
        ),
        weighted=f"{fmt(c4.key.value, kd)} {fmt_ci(c4.key.ci_low, c4.key.ci_high, kd)}",
        weighted_limit=fmt_exact(last["weighted_limit"], kd),
        linear=(
            None
            if lin is None
            else LinearText(name=lin.key.name, value=fmt(lin.key.value, 3), verdict=lin.verdict)
        ),
    )


def _body(
    summary: pd.DataFrame,
    nbo: pd.DataFrame,
    conv: pd.DataFrame,
    eps_values: Sequence[float],
    claims: Mapping[str, Claim],
) -> str:
    """The main text (``section.md``): the model, the paper's setting and what we ran; the
    results; the four figures with their captions."""
    return _render(
        "section.md",
        model=ModelText.of(conv),
        nbo_run=NboRunText.of(nbo),
        p_text=_p_text(summary),
        replicates=int(summary.iloc[-1]["n_replicates"]),
        results=_results(summary, nbo, conv, eps_values, claims),
        z_clipped=int((nbo["z"].abs() > NBO_Z_CLIP).sum()),
        z_clip=fmt(NBO_Z_CLIP, 1),
    )


def _appendix(conv: pd.DataFrame, nbo: pd.DataFrame, tables: Mapping[str, str]) -> str:
    """Model constants, the weighted-estimator derivation and the four tables
    (``appendix.md``)."""
    return _render(
        "appendix.md",
        model=ModelText.of(conv),
        nbo_run=NboRunText.of(nbo),
        tables={stem: tables[stem] for stem in TABLES},
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
    return Section(
        key="lqg",
        title="Case study 1: scalar LQG (paper Sec. III-A, Fig. 3)",
        order=10,
        body=_body(summary, nbo, conv, eps_values, by_id),
        claims=claims,
        figures=[f"{f}.png" for f in FIGURES],
        appendix=_appendix(conv, nbo, tables),
    )
