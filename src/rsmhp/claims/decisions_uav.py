r"""Decision study on the UAV, claims DEC-6, DEC-7-<model>, DEC-8a/b: each a key number from
:mod:`rsmhp.analysis.decisions_uav` and a verdict rule (:mod:`rsmhp.verdicts`) evaluated on
facts; the rule's printed text and its evaluation are one object. Every key number is
statistical (closed loop, optimiser).

* **DEC-6** (equivalence, :data:`DEC6_RULE`): d = relative regret of NBO − that of RS-MHP
  (:class:`MonteCarlo`) with the largest N_T, paired per belief state of the reconstruction,
  in percentage points (pp). *supported* if the 95% bootstrap CI of mean d lies inside
  :math:`\pm` :data:`EQUIVALENCE_MARGIN` (0.5 pp, fixed before the run), *not supported* if it
  lies entirely outside, *inconclusive* otherwise.
* **DEC-7-<model>** (:data:`DEC7_RULE`): the same d on each model variant; *supported* if the
  CI lies above 0, *not supported* if below 0, *inconclusive* otherwise.
* **DEC-8a/b** (:data:`DEC8_RULE`): d = closed-loop average location error of RS-MHP (the
  first N_T of the map) − NBO, paired over runs, for the cells with (a) / without (b) a
  footprint: *supported* if d's CI lies below 0 in every cell of the group and for d averaged
  over its cells, *not supported* if above 0 in some cell or on average, *inconclusive*
  otherwise.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from rsmhp.analysis.decisions_uav import (
    axis_label,
    base_model,
    largest_rsmhp,
    optimiser_share,
    paired_regret,
)
from rsmhp.analysis.uav import baseline_name, is_family
from rsmhp.ledger import Claim, KeyNumber
from rsmhp.markdown import fmt, param_text, range_text
from rsmhp.palette import method_label
from rsmhp.uav.methods.monte_carlo import MonteCarlo
from rsmhp.verdicts import Case, Facts, Rule, ci_side

__all__ = [
    "DEC6_RULE",
    "DEC7_RULE",
    "DEC8_RULE",
    "EQUIVALENCE_MARGIN",
    "KEY",
    "ci_facts",
    "map_comparison",
    "map_facts",
    "pp",
    "range_text",
    "uav_claims",
]

EQUIVALENCE_MARGIN = 0.005  # DEC-6: 0.5 percentage points of relative regret, fixed a priori

#: the key number of every claim here, as the rules name it (facts ``mean d_low/high``)
KEY = "mean d"
_LO, _HI = f"{KEY}_low", f"{KEY}_high"


def pp(x: float) -> float:
    """A fraction in percentage points (finite Python float)."""
    return float(100.0 * x)


_MARGIN = pp(EQUIVALENCE_MARGIN)
_MARGIN_TEXT = f"±{param_text(_MARGIN)} percentage points"
_REGRET_D = "d = relative regret of NBO − that of RS-MHP with the largest N_T, paired per belief"

DEC6_RULE = Rule(
    basis=f"{_REGRET_D} state of the reconstruction (pp)",
    cases=(
        Case(
            "supported",
            f"the 95% bootstrap CI of {KEY} lies inside {_MARGIN_TEXT} (equivalent)",
            lambda f: -_MARGIN < f[_LO] and f[_HI] < _MARGIN,
        ),
        Case(
            "not supported",
            "it lies entirely outside that margin",
            lambda f: f[_LO] >= _MARGIN or f[_HI] <= -_MARGIN,
        ),
    ),
    otherwise="inconclusive",
)

DEC7_RULE = ci_side(
    KEY,
    0.0,
    claimed="above",
    basis=f"{_REGRET_D} state of the model variant (pp); 95% bootstrap CI",
)

DEC8_RULE = Rule(
    basis="d = closed-loop average location error of RS-MHP (first N_T of the map) − NBO, "
    "paired over runs; 95% bootstrap CIs",
    cases=(
        Case(
            "supported",
            "d's CI lies below 0 in every cell of the group and for d averaged over its cells",
            lambda f: f["cells below 0"] == f["cells"] and f[_HI] < 0,
        ),
        Case(
            "not supported",
            "it lies above 0 in some cell or on average",
            lambda f: f["cells above 0"] > 0 or f[_LO] > 0,
        ),
    ),
    otherwise="inconclusive",
)


def ci_facts(key: KeyNumber) -> Facts:
    """The CI of a key number as the facts of :data:`DEC6_RULE` and :data:`DEC7_RULE`."""
    return {_LO: float(key.ci_low), _HI: float(key.ci_high)}


def map_facts(group: pd.Series) -> Facts:
    """The facts of :data:`DEC8_RULE` from a row of ``summarize_map_groups``."""
    return {
        _LO: float(group["ci_low"]),
        _HI: float(group["ci_high"]),
        "cells": int(group["n_cells"]),
        "cells below 0": int(group["n_below"]),
        "cells above 0": int(group["n_above"]),
    }


def _regret_key(method: str, m: float, lo: float, hi: float, null: float | None) -> KeyNumber:
    """Key number of DEC-6/DEC-7: paired mean of NBO's − ``method``'s relative regret (pp)
    with its bootstrap CI; ``null`` 0 for a difference claim, None for equivalence."""
    return KeyNumber(
        f"NBO − {method_label(method)} relative regret, paired mean",
        pp(m),
        pp(lo),
        pp(hi),
        unit="pp",
        reproducible="statistical",
        digits=2,
        null=null,
    )


def _dec6(
    regret: pd.DataFrame, summary: pd.DataFrame, base: str, best_rs: str, seed: int, n_boot: int
) -> Claim | None:
    nbo = summary[(summary["model"] == base) & (summary["method"] == baseline_name())]
    if nbo.empty:
        return None
    r = nbo.iloc[0]
    d = paired_regret(regret, base, best_rs, seed, n_boot)
    key = _regret_key(best_rs, d.mean, d.low, d.high, null=None)
    sp = r["spearman_random"]
    sp_txt = (
        f"; Spearman rank correlation of NBO's cost with the evaluation cost over random "
        f"plans {fmt(float(sp), 3)}"
        if np.isfinite(sp)
        else ""
    )
    return Claim(
        "DEC-6",
        f"Reconstruction ('{base}'): NBO decides as well as {method_label(best_rs)} "
        f"(relative regrets within ±{param_text(_MARGIN)} pp)",
        "Not in the paper; explains why the closed-loop comparisons (Fig. 5, UAV "
        "claims) cannot separate the methods",
        key,
        DEC6_RULE.verdict(ci_facts(key)),
        DEC6_RULE.text(),
        measured=f"{d.n} belief states; NBO's mean relative regret "
        f"{fmt(pp(r['mean_regret_rel']))}%, of which "
        f"{fmt(pp(r['mean_regret_methods_rel']), 2)} pp against the best method's "
        f"plan: every method shares {fmt(pp(optimiser_share(regret, base)), 3)}% "
        "from the common optimiser budget (the multi-start on the evaluation cost "
        f"finds better plans){sp_txt}",
    )


def _dec7(
    regret: pd.DataFrame, summary: pd.DataFrame, model: str, best_rs: str, seed: int, n_boot: int
) -> Claim:
    d = paired_regret(regret, model, best_rs, seed, n_boot)
    in_model = summary[summary["model"] == model]
    s_nbo = in_model[in_model["method"] == baseline_name()].iloc[0]
    s_rs = in_model[in_model["method"] == best_rs].iloc[0]
    key = _regret_key(best_rs, d.mean, d.low, d.high, null=0.0)
    return Claim(
        f"DEC-7-{model}",
        f"Model variant '{model}': {method_label(best_rs)} decides better than "
        "NBO (lower open-loop relative regret)",
        "Sec. II: NBO may generate severely sub-optimal controls; tested on a "
        "model variant (not the paper's model)",
        key,
        DEC7_RULE.verdict(ci_facts(key)),
        DEC7_RULE.text(),
        measured=f"{d.n} belief states; mean relative regret NBO "
        f"{fmt(pp(s_nbo['mean_regret_rel']))}% vs {method_label(best_rs)} "
        f"{fmt(pp(s_rs['mean_regret_rel']))}%; NBO's cost is constant over "
        f"random plans at {int(s_nbo['spearman_random_undefined'])} of "
        f"{int(s_nbo['n_states'])} states",
    )


def map_comparison(map_df: pd.DataFrame) -> tuple[str, list[str]] | None:
    """The map comparison DEC-8 rests on, the first with an RS-MHP method (the first N_T of
    the map, fixed before the run), and the methods of the other comparisons; None if the
    map has no RS-MHP comparison."""
    comps = list(dict.fromkeys(map_df["comparison"]))
    methods = pd.Series([c.split(" − ")[0] for c in comps], dtype=object)
    rs = [c for c, ok in zip(comps, is_family(methods, MonteCarlo), strict=True) if ok]
    if not rs:
        return None
    return rs[0], [c.split(" − ")[0] for c in comps if c != rs[0]]


def _dec8_claim(cid: str, label: str, g: pd.Series, map_df: pd.DataFrame, others: str) -> Claim:
    method = g["comparison"].split(" − ")[0]
    n_cells = int(g["n_cells"])
    cells = range_text(pd.Series([g["cell_min"], g["cell_max"]]), 3, True)
    regret_txt = (
        f", open-loop relative regret {fmt(pp(g['regret_nbo']), 2)}% vs "
        f"{fmt(pp(g['regret_method']), 2)}%"
        if np.isfinite(g["regret_nbo"]) and np.isfinite(g["regret_method"])
        else ""
    )
    row_key, col_key = map_df["row_key"].iloc[0], map_df["col_key"].iloc[0]
    return Claim(
        cid,
        f"{label}, {method_label(method)} has lower closed-loop error than NBO in every map cell",
        "Sec. III-B, Fig. 5: RS-MHP tracks better than NBO; here on model variants "
        "(not the paper's model)",
        KeyNumber(
            f"{method_label(method)} − NBO average location error, paired "
            f"mean over {n_cells} cells",
            float(g["mean_diff"]),
            float(g["ci_low"]),
            float(g["ci_high"]),
            unit="m",
            reproducible="statistical",
            digits=3,
            null=0.0,
        ),
        DEC8_RULE.verdict(map_facts(g)),
        DEC8_RULE.text(),
        measured=f"{axis_label(row_key)} × {axis_label(col_key)}, "
        f"{int(g['n_runs'])} paired runs per cell; CI below 0 in "
        f"{int(g['n_below'])} of {n_cells} cells, above 0 in {int(g['n_above'])}; "
        f"cell means {cells} m; track loss NBO "
        f"{fmt(pp(g['loss_nbo']), 2)}% vs {fmt(pp(g['loss_method']), 2)}%"
        f"{regret_txt} (means over the cells)",
        dropped=(
            f"the map's other comparison ({others} − {baseline_name()}) is not used: the rule "
            "fixes the first RS-MHP N_T of the map before the run (appendix table)"
            if others
            else ""
        ),
    )


def _dec8(map_df: pd.DataFrame, groups: pd.DataFrame) -> list[Claim]:
    chosen = None if map_df.empty or groups.empty else map_comparison(map_df)
    if chosen is None:
        return []
    comp, other_methods = chosen
    claims = []
    for cid, flag, label in (
        ("DEC-8a", True, "With a limited sensor footprint"),
        ("DEC-8b", False, "Without a footprint (the reconstruction's sensor)"),
    ):
        sel = groups[(groups["comparison"] == comp) & (groups["limited"] == flag)]
        if not sel.empty:
            claims.append(_dec8_claim(cid, label, sel.iloc[0], map_df, ", ".join(other_methods)))
    return claims


def uav_claims(
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    map_df: pd.DataFrame,
    groups: pd.DataFrame,
    seed: int,
    n_boot: int,
) -> list[Claim]:
    """Claims DEC-6, DEC-7-<model>, DEC-8a/b (module doc); ``groups`` is
    :func:`rsmhp.analysis.decisions_uav.summarize_map_groups`."""
    claims: list[Claim] = []
    models: Sequence[str] = list(dict.fromkeys(regret["model"]))
    best_rs = largest_rsmhp(summary)
    base = base_model(models)
    if best_rs is not None:
        dec6 = _dec6(regret, summary, base, best_rs, seed, n_boot) if base is not None else None
        claims += [dec6] if dec6 is not None else []
        claims += [_dec7(regret, summary, m, best_rs, seed, n_boot) for m in models if m != base]
    return claims + _dec8(map_df, groups)
