r"""Decision study on the scalar LQG, claims DEC-1..DEC-5, each a
:class:`~rsmhp.report.claimspec.ClaimSpec`: a verdict rule of :data:`RULES`
(:mod:`rsmhp.report.verdicts`) evaluated on the facts of an evidence function of the per-cell
summary and the slope fits (:mod:`rsmhp.models.lqg.regret_summary`); the claims' sentences, key
number names and the words of the rules are the macros of ``claims_lqg.md`` beside this module
(:class:`~rsmhp.report.templates.Words`); the printed rule is the rule's own
:meth:`~rsmhp.report.verdicts.Rule.text`.

Key numbers (bitwise reproducible): DEC-1 the largest :math:`\bar\rho / J(u^*)` of NBO;
DEC-2 the uniform-mc slope whose CI reaches highest (the flattest, so the weakest evidence of
a fall); DEC-3 and DEC-5 the largest :math:`|z|` against the closed form; DEC-4 the largest
ratio over the (a, H) cells of the pruned tree's mean regret at the largest M to its lowest
mean regret over M (above 1: keeping more trajectories decides worse).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.models.lqg import oven as lqg
from rsmhp.models.lqg.regret_summary import (
    NO_Z_CELLS,
    WEIGHTED_MIN_P,
    ZCheck,
    independent_regret,
    max_rel_regret,
    pruned_shape,
    slopes,
    z_families,
)
from rsmhp.report.claimspec import ClaimSpec, Evidence
from rsmhp.report.ledger import Claim, KeyNumber
from rsmhp.report.markdown import fmt, param_text, range_text
from rsmhp.report.templates import Words
from rsmhp.report.verdicts import Case, Facts, Rule

__all__ = [
    "CLAIMS",
    "NBO_ROUNDING",
    "NBO_SEVERE",
    "RULES",
    "SETUP",
    "WORDS",
    "cell_text",
    "lqg_claims",
    "param_text",
    "range_text",
]

#: the words of the claims and rules (macros of ``claims_lqg.md`` beside this module)
WORDS = Words("rsmhp.studies.decisions", "claims_lqg.md")

#: DEC-1: NBO's regret / J(u*) at most this is rounding (exact optimum), at least
#: ``NBO_SEVERE`` is a sub-optimal choice
NBO_ROUNDING = 1e-9
NBO_SEVERE = 0.01

#: the setup of every claim here: the paper's oven model, open-loop controls chosen by each
#: method's sample-average cost (the paper studies cost estimates, not these choices)
SETUP = WORDS("setup")


def _cell(row: Mapping[str, Any]) -> dict[str, str]:
    """The (a, H) cell of a summary or scaling row, formatted (the ``cell`` macro's fields)."""
    return {"a": param_text(row["a"]), "H": str(int(row["H"]))}


def cell_text(row: pd.Series) -> str:
    """``a = 0.5, H = 2``: the (a, H) cell of a summary or scaling row."""
    return WORDS("cell", c=_cell(row))


def _power_of_ten(x: float) -> str:
    """``1e-9`` for 1e-9 (no zero-padded exponent)."""
    mantissa, exponent = f"{x:.0e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def _z_ok(f: Facts) -> bool:
    """max |z| within its Bonferroni limit (false when there is no cell: NaN)."""
    return f["max |z|"] <= f["z limit"]


def _dec2_supported(f: Facts) -> bool:
    """Every slope CI below 0 and containing −1, max |z| within its limit."""
    return (
        f["highest upper limit"] < 0
        and f["highest lower limit"] <= -1
        and f["lowest upper limit"] >= -1
        and _z_ok(f)
    )


RULES: dict[str, Rule] = {
    "DEC-1": Rule(
        cases=(
            Case(
                "not supported",
                WORDS("dec_1_rule_exact", rounding=_power_of_ten(NBO_ROUNDING)),
                lambda f: f["max NBO regret / J(u*)"] <= NBO_ROUNDING,
            ),
            Case(
                "supported",
                WORDS("dec_1_rule_severe", severe=f"{100 * NBO_SEVERE:g}"),
                lambda f: f["max NBO regret / J(u*)"] >= NBO_SEVERE,
            ),
        ),
        otherwise="inconclusive",
    ),
    "DEC-2": Rule(
        cases=(
            Case("supported", WORDS("dec_2_rule_supported"), _dec2_supported),
            Case(
                "not supported",
                WORDS("dec_2_rule_not"),
                lambda f: not f["highest upper limit"] < 0 or not _z_ok(f),
            ),
        ),
        otherwise="inconclusive",
    ),
    "DEC-3": Rule(
        basis=WORDS("dec_3_rule_basis"),
        cases=(Case("supported", WORDS("dec_3_rule_supported"), _z_ok),),
        otherwise="not supported",
    ),
    "DEC-4": Rule(
        basis=WORDS("dec_4_rule_basis"),
        cases=(
            Case("not supported", WORDS("dec_4_rule_rising"), lambda f: f["cells rising"] >= 1),
            Case(
                "supported",
                WORDS("dec_4_rule_falling"),
                lambda f: f["cells"] >= 1 and f["cells falling"] == f["cells"],
            ),
        ),
        otherwise="inconclusive",
    ),
    "DEC-5": Rule(
        cases=(Case("supported", WORDS("dec_5_rule_supported", min_p=str(WEIGHTED_MIN_P)), _z_ok),),
        otherwise="not supported",
    ),
}


def _z_facts(check: ZCheck) -> dict[str, float]:
    return {"max |z|": check.max_abs_z, "z limit": check.limit}


def _z_key(name: str, z: ZCheck) -> KeyNumber:
    """The largest |z| of a family of closed-form checks as a key number named ``name``."""
    return KeyNumber(name, z.max_abs_z, reproducible="bitwise", digits=3)


def _dec1(summary: pd.DataFrame) -> Evidence | None:
    """NBO's largest regret / J(u*) over the (a, H) cells (DEC-1)."""
    nbo = summary[summary["method"] == "nbo"]
    if nbo.empty:
        return None
    worst = float(nbo["rel_mean"].max())
    return Evidence(
        key=KeyNumber(
            WORDS("dec_1_key", cells=str(len(nbo))), worst, reproducible="bitwise", digits=2
        ),
        facts={"max NBO regret / J(u*)": worst},
        values={
            "severe": f"{100 * NBO_SEVERE:g}",
            "nbo_max": fmt(float(nbo["mean"].max()), 2),
            "others_max": fmt(max_rel_regret(summary, ("antithetic", "cubature")), 2),
        },
    )


def _dec2(scaling: pd.DataFrame, z: ZCheck) -> Evidence | None:
    """The uniform-mc slopes of mean regret in P and the z-scores against κ v_H / P (DEC-2)."""
    mc = slopes(scaling, "mc")
    if mc.empty:
        return None
    low, high = mc["low"].to_numpy(float), mc["high"].to_numpy(float)
    flat = mc.loc[mc["high"].idxmax()]
    return Evidence(
        key=KeyNumber(
            WORDS("dec_2_key", c=_cell(flat)),
            float(flat["slope"]),
            float(flat["low"]),
            float(flat["high"]),
            reproducible="bitwise",
            digits=3,
            null=0.0,
        ),
        facts={
            "highest upper limit": np.max(high),
            "highest lower limit": np.max(low),
            "lowest upper limit": np.min(high),
            **_z_facts(z),
        },
        values={
            "slopes": range_text(mc["slope"]),
            "cells": str(len(mc)),
            "contain": bool(((mc["low"] <= -1) & (mc["high"] >= -1)).all()),
            "max_z": fmt(z.max_abs_z, 3),
            "z_cells": str(z.cells),
            "limit": fmt(z.limit, 3),
        },
    )


def _dec3(
    summary: pd.DataFrame, scaling: pd.DataFrame, z: ZCheck, model: Mapping[str, Any]
) -> Evidence | None:
    """The uniform shared-draw tree's z-scores against κ v_H / N and its largest cell (DEC-3)."""
    tree = summary[(summary["method"] == "tree") & (summary["weighting"] == "uniform")]
    if tree.empty:
        return None
    big = tree.loc[tree["P"].idxmax()]
    ts = slopes(scaling, "tree")
    return Evidence(
        key=_z_key(WORDS("dec_3_key", cells=str(z.cells)), z),
        facts=_z_facts(z),
        values={
            "limit": fmt(z.limit, 3),
            "slopes": range_text(ts["slope"]) if not ts.empty else "",
            "big": {**_cell(big), "N": str(int(big["N"])), "P": str(int(big["P"]))},
            "mean": fmt(float(big["mean"])),
            "closed": fmt(independent_regret(big, model)),
        },
    )


def _shape(r: pd.Series) -> dict[str, str]:
    """A cell's pruned-tree regret at the smallest, best and largest M (``shape`` macro)."""
    return {
        **_cell(r),
        **{f"M_{w}": str(int(r[f"M_{w}"])) for w in ("first", "best", "last")},
        **{w: fmt(r[f"mean_{w}"], 3) for w in ("first", "best", "last")},
        "low_last": fmt(r["low_last"], 3),
        "high_best": fmt(r["high_best"], 3),
    }


def _unpruned(shape: pd.DataFrame) -> list[dict[str, str]]:
    """The unpruned tree's mean regret per cell, if it exists and lies above every pruned
    tree's (else none)."""
    with_tree = shape[np.isfinite(shape["tree_mean"])]
    if not (len(with_tree) and bool((with_tree["tree_mean"] > with_tree["mean_last"]).all())):
        return []
    return [{**_cell(r), "mean": fmt(r["tree_mean"], 3)} for _, r in with_tree.iterrows()]


def _dec4(summary: pd.DataFrame) -> Evidence | None:
    """The pruned tree's mean regret over M per (a, H) cell, N fixed (DEC-4)."""
    shape = pruned_shape(summary)
    if shape.empty:
        return None
    rising = shape[shape["rises"]]
    facts = {
        "cells": len(shape),
        "cells falling": int(shape["falls"].sum()),
        "cells rising": len(rising),
    }
    ratio = shape["mean_last"] / shape["mean_best"]
    pr = summary[(summary["method"] == "pruned") & (summary["weighting"] == "uniform")]
    have = set(zip(shape["a"].astype(float), shape["H"].astype(int), strict=True))
    run = sorted({(float(a), int(h)) for a, h in zip(pr["a"], pr["H"], strict=True)})
    return Evidence(
        key=KeyNumber(
            WORDS("dec_4_key", c=_cell(shape.loc[ratio.idxmax()])),
            float(ratio.max()),
            reproducible="bitwise",
            digits=3,
        ),
        facts=facts,
        values={
            "N": str(int(shape["N"].iloc[0])),
            "shapes": [_shape(r) for _, r in shape.iterrows()],
            "falling": str(facts["cells falling"]),
            "cells": str(len(shape)),
            "n_rising": str(len(rising)),
            "rising": [_shape(r) for _, r in rising.iterrows()],
            "trees": _unpruned(shape),
            "absent": [_cell({"a": a, "H": h}) for a, h in run if (a, h) not in have],
        },
    )


def _dec5(summary: pd.DataFrame, z: ZCheck) -> Evidence | None:
    """Likeliness-weighted mc's z-scores against the first-order closed form (DEC-5)."""
    w = summary[
        (summary["method"] == "mc")
        & (summary["weighting"] == "likeliness")
        & (summary["closed_kind"] == "asymptotic")
    ]
    wmc = w[w["P"] >= WEIGHTED_MIN_P]
    if wmc.empty:
        return None
    h_values = sorted(int(h) for h in wmc["H"].unique())
    small = w[w["P"] < WEIGHTED_MIN_P]
    return Evidence(
        key=_z_key(WORDS("dec_5_key", cells=str(z.cells), min_p=str(WEIGHTED_MIN_P)), z),
        facts=_z_facts(z),
        values={
            "limit": fmt(z.limit, 3),
            "ratios": [
                {"ratio": fmt(lqg.weighted_regret_ratio(h), 2), "H": str(h)} for h in h_values
            ],
            "small": str(len(small)),
            "min_p": str(WEIGHTED_MIN_P),
            "ps": [str(int(p)) for p in sorted(small["P"].unique())],
        },
    )


#: the claims by id, in the ledger's order; DEC-2, DEC-3 and DEC-5 check the simulation against
#: closed forms derived here (part "beyond")
CLAIMS: dict[str, ClaimSpec] = {
    cid: ClaimSpec(
        id=cid,
        setup=SETUP,
        evidence=evidence,
        words=WORDS,
        rule=RULES[cid],
        part=part,
        check=check,
    )
    for cid, evidence, part, check in (
        ("DEC-1", _dec1, "paper", False),
        ("DEC-2", _dec2, "beyond", True),
        ("DEC-3", _dec3, "beyond", True),
        ("DEC-4", _dec4, "paper", False),
        ("DEC-5", _dec5, "beyond", True),
    )
}


def lqg_claims(
    summary: pd.DataFrame, scaling: pd.DataFrame, model: Mapping[str, Any]
) -> list[Claim]:
    """Claims DEC-1..DEC-5 by :data:`RULES` from the per-cell summary and the slope fits
    (:mod:`rsmhp.models.lqg.regret_summary`); ``model`` is the ``lqg.model`` config section. A
    claim whose cells were not run is left out. Every key number is bitwise reproducible."""
    zfam = z_families(summary)
    evidence = {
        "DEC-1": _dec1(summary),
        "DEC-2": _dec2(scaling, zfam.get("DEC-2", NO_Z_CELLS)),
        "DEC-3": _dec3(summary, scaling, zfam.get("DEC-3", NO_Z_CELLS), model),
        "DEC-4": _dec4(summary),
        "DEC-5": _dec5(summary, zfam.get("DEC-5", NO_Z_CELLS)),
    }
    return [CLAIMS[cid].claim(ev) for cid, ev in evidence.items() if ev is not None]
