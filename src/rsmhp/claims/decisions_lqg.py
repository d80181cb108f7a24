r"""Decision study on the scalar LQG, claims DEC-1..DEC-5: each a key number and a verdict
rule (:data:`RULES`, :mod:`rsmhp.verdicts`) evaluated on facts from
:mod:`rsmhp.analysis.decisions_lqg`; the printed rule is the rule's own
:meth:`~rsmhp.verdicts.Rule.text`.

Key numbers (bitwise reproducible): DEC-1 the largest :math:`\bar\rho / J(u^*)` of NBO;
DEC-2 the uniform-mc slope whose CI reaches highest (the flattest, so the weakest evidence of
a fall); DEC-3 and DEC-5 the largest :math:`|z|` against the closed form; DEC-4 the
pruned-tree slope whose CI reaches lowest (the steepest fall the data admit).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from rsmhp import lqg
from rsmhp.analysis.decisions_lqg import (
    NO_Z_CELLS,
    WEIGHTED_MIN_P,
    ZCheck,
    cells_without_slope,
    independent_regret,
    max_rel_regret,
    slopes,
    z_families,
)
from rsmhp.ledger import Claim, KeyNumber
from rsmhp.markdown import fmt, param_text, range_text
from rsmhp.verdicts import Case, Facts, Rule

__all__ = [
    "NBO_ROUNDING",
    "NBO_SEVERE",
    "PRUNED_FLAT",
    "RULES",
    "cell_text",
    "lqg_claims",
    "param_text",
    "range_text",
]

#: DEC-1: NBO's regret / J(u*) at most this is rounding (exact optimum), at least
#: ``NBO_SEVERE`` is a sub-optimal choice
NBO_ROUNDING = 1e-9
NBO_SEVERE = 0.01

#: DEC-4: a slope of mean regret in M above this (CI and all) means "no useful improvement":
#: 10x more kept trajectories lower the regret by less than 21%, a tenth of the 1/P rate
PRUNED_FLAT = -0.1


def cell_text(row: pd.Series) -> str:
    """``a = 0.5, H = 2``: the (a, H) cell of a summary or scaling row."""
    return f"a = {param_text(row['a'])}, H = {int(row['H'])}"


def _power_of_ten(x: float) -> str:
    """``1e-9`` for 1e-9 (no zero-padded exponent)."""
    mantissa, exponent = f"{x:.0e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def _z_ok(f: Facts) -> bool:
    """max |z| within its Bonferroni limit (false when there is no cell: NaN)."""
    return f["max |z|"] <= f["z limit"]


RULES: dict[str, Rule] = {
    "DEC-1": Rule(
        cases=(
            Case(
                "not supported",
                f"NBO's regret is at most {_power_of_ten(NBO_ROUNDING)} × J(u*) in every "
                "(a, H) cell (zero up to rounding)",
                lambda f: f["max NBO regret / J(u*)"] <= NBO_ROUNDING,
            ),
            Case(
                "supported",
                f"it reaches {100 * NBO_SEVERE:g}% of J(u*) in some cell",
                lambda f: f["max NBO regret / J(u*)"] >= NBO_SEVERE,
            ),
        ),
        otherwise="inconclusive",
    ),
    "DEC-2": Rule(
        cases=(
            Case(
                "supported",
                "every (a, H) slope of mean uniform-mc regret in P has a 95% CI below 0 that "
                "contains −1 and max |z| against κ v_H / P is within the Bonferroni limit "
                "(95% family-wise)",
                lambda f: (
                    f["highest upper limit"] < 0
                    and f["highest lower limit"] <= -1
                    and f["lowest upper limit"] >= -1
                    and _z_ok(f)
                ),
            ),
            Case(
                "not supported",
                "some slope CI reaches 0 or max |z| exceeds the limit",
                lambda f: not f["highest upper limit"] < 0 or not _z_ok(f),
            ),
        ),
        otherwise="inconclusive",
    ),
    "DEC-3": Rule(
        basis="max |z| of the uniform shared-draw tree cells against κ v_H / N",
        cases=(Case("supported", "it is within the Bonferroni limit (95% family-wise)", _z_ok),),
        otherwise="not supported",
    ),
    "DEC-4": Rule(
        cases=(
            Case(
                "supported",
                "every (a, H) slope of mean pruned-tree regret in M has a 95% CI below 0",
                lambda f: f["cells falling"] == f["cells"],
            ),
            Case(
                "not supported",
                f"none has and every CI lies above −{-PRUNED_FLAT:g} (10× more M lowers regret "
                f"by < {100 * (1 - 10**PRUNED_FLAT):.0f}%, a tenth of the 1/P rate)",
                lambda f: f["cells falling"] == 0 and f["lowest lower limit"] > PRUNED_FLAT,
            ),
        ),
        otherwise="inconclusive",
    ),
    "DEC-5": Rule(
        cases=(
            Case(
                "supported",
                "max |z| of the likeliness-weighted mc cells with P ≥ "
                f"{WEIGHTED_MIN_P} against κ v_H (4/3)^{{H/2}}/(3P) is within the Bonferroni "
                "limit and (4/3)^{H/2}/3 < 1 (weighted beats uniform) for every H run",
                lambda f: _z_ok(f) and f["largest ratio"] < 1.0,
            ),
        ),
        otherwise="not supported",
    ),
}


def _z_facts(check: ZCheck) -> dict[str, float]:
    return {"max |z|": check.max_abs_z, "z limit": check.limit}


def _slope_key(row: pd.Series, name: str) -> KeyNumber:
    return KeyNumber(
        name,
        float(row["slope"]),
        float(row["low"]),
        float(row["high"]),
        reproducible="bitwise",
        digits=3,
        null=0.0,
    )


def _dec1(summary: pd.DataFrame) -> Claim | None:
    nbo = summary[summary["method"] == "nbo"]
    if nbo.empty:
        return None
    worst = float(nbo["rel_mean"].max())
    rule = RULES["DEC-1"]
    return Claim(
        "DEC-1",
        "NBO, by ignoring the noise, chooses severely sub-optimal controls (scalar "
        "LQG, open-loop controls)",
        "Sec. II: NBO ignores the uncertainty of the state evolution and may generate "
        "severely sub-optimal controls",
        KeyNumber(
            f"max NBO regret / J(u*) over {len(nbo)} (a, H) cells",
            worst,
            reproducible="bitwise",
            digits=2,
        ),
        rule.verdict({"max NBO regret / J(u*)": worst}),
        rule.text(),
        measured=f"NBO's regret is at most {fmt(float(nbo['mean'].max()), 2)} (cost "
        "units): J − J_NBO = r v_H does not depend on u, so NBO's minimiser is the "
        "exact optimum (certainty equivalence); antithetic pairs and cubature points "
        "also have regret at most "
        f"{fmt(max_rel_regret(summary, ('antithetic', 'cubature')), 2)} × J(u*)",
    )


def _dec2(scaling: pd.DataFrame, z: ZCheck) -> Claim | None:
    mc = slopes(scaling, "mc")
    if mc.empty:
        return None
    low, high = mc["low"].to_numpy(float), mc["high"].to_numpy(float)
    facts = {
        "highest upper limit": np.max(high),
        "highest lower limit": np.max(low),
        "lowest upper limit": np.min(high),
        **_z_facts(z),
    }
    contains = bool(((mc["low"] <= -1) & (mc["high"] >= -1)).all())
    flat = mc.loc[mc["high"].idxmax()]
    rule = RULES["DEC-2"]
    return Claim(
        "DEC-2",
        "Monte Carlo (independent trajectories) chooses better controls as P grows; "
        "derived: mean regret κ v_H / P",
        "Not in the paper (it studies cost estimates, not the controls chosen); closed "
        "form derived here",
        _slope_key(flat, f"flattest slope of mean regret in P ({cell_text(flat)})"),
        rule.verdict(facts),
        rule.text(),
        measured=f"slopes {range_text(mc['slope'])} over {len(mc)} (a, H) cells, CIs "
        f"{'all contain' if contains else 'do not all contain'} −1; simulated vs "
        f"closed-form mean: max |z| = {fmt(z.max_abs_z, 3)} over {z.cells} cells (Bonferroni "
        f"limit {fmt(z.limit, 3)})",
    )


def _dec3(
    summary: pd.DataFrame, scaling: pd.DataFrame, z: ZCheck, model: Mapping[str, Any]
) -> Claim | None:
    tree = summary[(summary["method"] == "tree") & (summary["weighting"] == "uniform")]
    if tree.empty:
        return None
    big = tree.loc[tree["P"].idxmax()]
    ts = slopes(scaling, "tree")
    in_n = f"; slopes in N {range_text(ts['slope'])}" if not ts.empty else ""
    rule = RULES["DEC-3"]
    return Claim(
        "DEC-3",
        "A tree with N shared draws per level decides like N independent "
        "trajectories, not N^H: mean regret κ v_H / N",
        "Not in the paper (Sec. II builds the N^H-leaf tree); closed form derived here",
        KeyNumber(
            f"max |z| vs κ v_H / N over {z.cells} tree cells",
            z.max_abs_z,
            reproducible="bitwise",
            digits=3,
        ),
        rule.verdict(_z_facts(z)),
        rule.text(),
        measured=f"Bonferroni limit {fmt(z.limit, 3)}{in_n}; e.g. {cell_text(big)}, "
        f"N = {int(big['N'])} ({int(big['P'])} leaves): mean regret "
        f"{fmt(float(big['mean']))} vs {fmt(independent_regret(big, model))} (closed form) for "
        f"{int(big['P'])} independent trajectories",
        dropped="likeliness-weighted trees (no closed form; in the appendix table)",
    )


def _dec4(summary: pd.DataFrame, scaling: pd.DataFrame) -> Claim | None:
    pr = slopes(scaling, "pruned")
    if pr.empty:
        return None
    n_fall = int((pr["high"] < 0).sum())
    facts = {
        "cells": len(pr),
        "cells falling": n_fall,
        "lowest lower limit": np.min(pr["low"].to_numpy(float)),
    }
    steep = pr.loc[pr["low"].idxmin()]
    absent = ", ".join(
        f"(a = {param_text(a)}, H = {h})"
        for a, h in cells_without_slope(summary, scaling, "pruned", "uniform")
    )
    n_pruned = int(summary.loc[summary["method"] == "pruned", "N"].max())
    rule = RULES["DEC-4"]
    return Claim(
        "DEC-4",
        "Keeping more trajectories (larger M, N fixed) in the pruned tree improves its decisions",
        "Sec. III-B: pruning to M trajectories degrades performance but saves "
        "computation (so a larger M should decide better)",
        _slope_key(steep, f"steepest slope of mean regret in M ({cell_text(steep)})"),
        rule.verdict(facts),
        rule.text(),
        measured=f"N = {n_pruned}; slopes in M {range_text(pr['slope'], signed=True)}; CI "
        f"below 0 in {n_fall} of {len(pr)} (a, H) cells; lowest CI limit "
        f"{fmt(float(pr['low'].min()), 3, True)}",
        dropped=(f"{absent}: fewer than 3 values of M below N^H (no slope)" if absent else ""),
    )


def _dec5(summary: pd.DataFrame, z: ZCheck) -> Claim | None:
    w = summary[
        (summary["method"] == "mc")
        & (summary["weighting"] == "likeliness")
        & (summary["closed_kind"] == "asymptotic")
    ]
    wmc = w[w["P"] >= WEIGHTED_MIN_P]
    if wmc.empty:
        return None
    h_values = sorted(int(h) for h in wmc["H"].unique())
    ratios = [lqg.weighted_regret_ratio(h) for h in h_values]
    small = w[w["P"] < WEIGHTED_MIN_P]
    rule = RULES["DEC-5"]
    return Claim(
        "DEC-5",
        "Likeliness weighting chooses controls consistently and better than uniform; "
        "derived: κ v_H (4/3)^{H/2}/(3P)",
        "Not in the paper (Sec. II ranks trajectories by likeliness to prune); "
        "first-order closed form derived here",
        KeyNumber(
            f"max |z| vs first-order closed form over {z.cells} cells (P ≥ {WEIGHTED_MIN_P})",
            z.max_abs_z,
            reproducible="bitwise",
            digits=3,
        ),
        rule.verdict({**_z_facts(z), "largest ratio": max(ratios)}),
        rule.text(),
        measured=f"Bonferroni limit {fmt(z.limit, 3)}; derived ratio to uniform mc "
        + ", ".join(f"{fmt(r, 2)} (H = {h})" for h, r in zip(h_values, ratios, strict=True)),
        dropped=(
            f"{len(small)} cells with P < {WEIGHTED_MIN_P} "
            f"(P = {', '.join(str(int(p)) for p in sorted(small['P'].unique()))}): the "
            "closed form is first order in 1/P"
            if not small.empty
            else ""
        ),
    )


def lqg_claims(
    summary: pd.DataFrame, scaling: pd.DataFrame, model: Mapping[str, Any]
) -> list[Claim]:
    """Claims DEC-1..DEC-5 by :data:`RULES` from the per-cell summary and the slope fits
    (:mod:`rsmhp.analysis.decisions_lqg`); ``model`` is the ``lqg.model`` config section. A
    claim whose cells were not run is left out. Every key number is bitwise reproducible."""
    zfam = z_families(summary)
    claims: Sequence[Claim | None] = (
        _dec1(summary),
        _dec2(scaling, zfam.get("DEC-2", NO_Z_CELLS)),
        _dec3(summary, scaling, zfam.get("DEC-3", NO_Z_CELLS), model),
        _dec4(summary, scaling),
        _dec5(summary, zfam.get("DEC-5", NO_Z_CELLS)),
    )
    return [c for c in claims if c is not None]
