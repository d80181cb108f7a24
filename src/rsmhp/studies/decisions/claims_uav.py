r"""Decision study on the UAV, claims DEC-6, DEC-7-<model>, DEC-8a/b: each a key number from
:mod:`rsmhp.studies.decisions.summarise_uav` and a verdict rule (:mod:`rsmhp.report.verdicts`)
evaluated on facts; the rule's printed text and its evaluation are one object. Every key number is
statistical (closed loop, optimiser).

* **DEC-6** (the reconstruction, part "paper") and **DEC-7-<model>** (each model variant,
  part "beyond"), both by :func:`regret_rule`: d = relative regret of NBO − that of RS-MHP
  (:class:`MonteCarlo`) with the largest N_T, paired per belief state, in percentage points
  (pp). *equivalent* if the 95% bootstrap CI of mean d lies inside ±m (m fixed in the config
  before the run, ``decisions.claims.equivalence_margin_pp``), else *supported* if it lies
  above 0, *not supported* if below 0, *inconclusive* otherwise.
* **DEC-8a/b** (:data:`DEC8_RULE`): d = closed-loop average location error of RS-MHP (the
  map method fixed in the config, ``decisions.claims.map_method``) − NBO, paired over runs,
  for the cells with (a) / without (b) a footprint: *supported* if d's CI lies below 0 in
  every cell of the group and for d averaged over its cells, *not supported* if above 0 in
  some cell or on average, *inconclusive* otherwise. Every cell where some RS-MHP member of
  the map is significantly worse than NBO is named as contrary evidence.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.models.uav import methods as registry
from rsmhp.models.uav.methods import baseline_name, is_family
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.report.ledger import Claim, KeyNumber
from rsmhp.report.markdown import fmt, fmt_ci, param_text, range_text
from rsmhp.report.palette import method_label
from rsmhp.report.verdicts import Case, Facts, Rule, ci_side
from rsmhp.studies.decisions.summarise_uav import (
    PairedRegret,
    axis_label,
    base_model,
    largest_rsmhp,
    limited_cells,
    optimiser_share,
    paired_regret,
)

__all__ = [
    "DEC8_RULE",
    "KEY",
    "ci_facts",
    "map_comparison",
    "map_contrary",
    "map_facts",
    "pp",
    "range_text",
    "regret_rule",
    "uav_claims",
]

#: the key number of every claim here, as the rules name it (facts ``mean d_low/high``)
KEY = "mean d"
_LO, _HI = f"{KEY}_low", f"{KEY}_high"


def pp(x: float) -> float:
    """A fraction in percentage points (finite Python float)."""
    return float(100.0 * x)


_REGRET_D = "d = relative regret of NBO − that of RS-MHP with the largest N_T, paired per belief"


def regret_rule(margin_pp: float, setting: str) -> Rule:
    """The rule of DEC-6 (``setting`` "the reconstruction") and DEC-7 (a model variant):
    RS-MHP decides better than NBO, with the equivalence margin ±``margin_pp``."""
    return ci_side(
        KEY,
        0.0,
        claimed="above",
        basis=f"{_REGRET_D} state of {setting} (pp); 95% bootstrap CI",
        margin=margin_pp,
        margin_text=f"{param_text(margin_pp)} pp",
    )


DEC8_RULE = Rule(
    basis="d = closed-loop average location error of the map method fixed in the config "
    "(decisions.claims.map_method) − NBO, "
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
    """The CI of a key number as the facts of :func:`regret_rule`."""
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


def _units(n: int) -> int | None:
    """The number of paired units (belief states, runs) a bootstrap CI of a mean rests on,
    as :attr:`KeyNumber.n`; ``None`` below 2 (no CI of a mean)."""
    return int(n) if int(n) >= 2 else None


def _regret_key(method: str, d: PairedRegret, margin_pp: float) -> KeyNumber:
    """Key number of DEC-6/DEC-7: paired mean of NBO's − ``method``'s relative regret (pp)
    with its bootstrap CI over the ``d.n`` paired belief states, and the rule's margin."""
    return KeyNumber(
        f"NBO − {method_label(method)} relative regret, paired mean",
        pp(d.mean),
        pp(d.low),
        pp(d.high),
        unit="pp",
        reproducible="statistical",
        digits=2,
        null=0.0,
        n=_units(d.n),
        margin=margin_pp,
    )


def _margin_note(margin_pp: float, share: float) -> str:
    return (
        f"margin ±{param_text(margin_pp)} pp fixed in the config (decisions.claims); the "
        f"optimiser alone leaves every method {fmt(pp(share), 3)}% above the best plan found"
    )


def _dec6(
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    base: str,
    best_rs: str,
    margin_pp: float,
    seed: int,
    n_boot: int,
) -> Claim | None:
    nbo = summary[(summary["model"] == base) & (summary["method"] == baseline_name())]
    if nbo.empty:
        return None
    r = nbo.iloc[0]
    rule = regret_rule(margin_pp, "the reconstruction")  # first: it checks the margin
    d = paired_regret(regret, base, best_rs, seed, n_boot)
    key = _regret_key(best_rs, d, margin_pp)
    sp = r["spearman_random"]
    sp_txt = (
        f"; Spearman rank correlation of NBO's cost with the evaluation cost over random "
        f"plans {fmt(float(sp), 3)}"
        if np.isfinite(sp)
        else ""
    )
    return Claim(
        "DEC-6",
        f"On the UAV reconstruction, {method_label(best_rs)} chooses better plans than NBO "
        "(lower open-loop relative regret)",
        "Sec. II: NBO may generate severely sub-optimal controls (tested here on open-loop "
        "plans of the paper's UAV setup)",
        key,
        rule.verdict(ci_facts(key)),
        rule.text(),
        measured=f"{d.n} belief states; NBO's mean relative regret "
        f"{fmt(pp(r['mean_regret_rel']))}%, of which "
        f"{fmt(pp(r['mean_regret_methods_rel']), 2)} pp against the best method's "
        f"plan; {_margin_note(margin_pp, optimiser_share(regret, base))} (the multi-start on "
        f"the evaluation cost finds better plans){sp_txt}",
        part="paper",
        setup=f"UAV reconstruction '{base}' (Sec. III-B), open-loop plans",
    )


def _dec7(
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    model: str,
    best_rs: str,
    margin_pp: float,
    seed: int,
    n_boot: int,
) -> Claim:
    rule = regret_rule(margin_pp, "the model variant")  # first: it checks the margin
    d = paired_regret(regret, model, best_rs, seed, n_boot)
    in_model = summary[summary["model"] == model]
    s_nbo = in_model[in_model["method"] == baseline_name()].iloc[0]
    s_rs = in_model[in_model["method"] == best_rs].iloc[0]
    key = _regret_key(best_rs, d, margin_pp)
    return Claim(
        f"DEC-7-{model}",
        f"On the UAV variant '{model}', {method_label(best_rs)} chooses better plans than "
        "NBO (lower open-loop relative regret)",
        "Sec. II: NBO may generate severely sub-optimal controls; tested on a "
        "model variant (not the paper's model)",
        key,
        rule.verdict(ci_facts(key)),
        rule.text(),
        measured=f"{d.n} belief states; mean relative regret NBO "
        f"{fmt(pp(s_nbo['mean_regret_rel']))}% vs {method_label(best_rs)} "
        f"{fmt(pp(s_rs['mean_regret_rel']))}%; NBO's cost is constant over "
        f"random plans at {int(s_nbo['spearman_random_undefined'])} of "
        f"{int(s_nbo['n_states'])} states; "
        f"{_margin_note(margin_pp, optimiser_share(regret, model))}",
        part="beyond",
        setup=f"UAV variant '{model}', open-loop plans",
    )


def map_comparison(map_df: pd.DataFrame, method: str = "") -> tuple[str, list[str]] | None:
    """The map comparison DEC-8 rests on, ``"<method> − nbo"`` (``method`` fixed in the
    config before the run, ``decisions.claims.map_method``; empty: the first RS-MHP member of
    the map), and the methods of the other comparisons; None if the map has no RS-MHP
    comparison. A configured method the map did not run is refused."""
    comps = list(dict.fromkeys(map_df["comparison"]))
    methods = [c.split(" − ")[0] for c in comps]
    rs = [
        c
        for c, ok in zip(
            comps, is_family(pd.Series(methods, dtype=object), MonteCarlo), strict=True
        )
        if ok
    ]
    if method:
        if method not in methods:
            raise ValueError(
                f"decisions.claims.map_method = {method!r} is not a compared method of the "
                f"map (allowed: {', '.join(methods)})"
            )
        chosen = comps[methods.index(method)]
    elif rs:
        chosen = rs[0]
    else:
        return None
    return chosen, [m for c, m in zip(comps, methods, strict=True) if c != chosen]


def map_contrary(map_df: pd.DataFrame, limited: pd.Series, flag: bool, method: str) -> str:
    """Every (cell, comparison) of the group (``limited == flag``) whose 95% CI of method −
    NBO lies above 0 (significantly worse than NBO), for every method of the map of the same
    family as ``method`` (the compared one: e.g. every RS-MHP N_T)."""
    methods = pd.Series([c.split(" − ")[0] for c in map_df["comparison"]], index=map_df.index)
    family = type(registry.from_name(method))
    rows = map_df[(limited == flag) & (map_df["ci_low"] > 0) & is_family(methods, family)]
    return "; ".join(
        f"{_cell_name(r)}: {method_label(r['comparison'].split(' − ')[0])} − NBO = "
        f"{fmt(r['mean_diff'], 3, True)} {fmt_ci(r['ci_low'], r['ci_high'], 3, True)} m"
        for _, r in rows.iterrows()
    )


def _cell_name(r: pd.Series) -> str:
    def one(key: str, val: object) -> str:
        unlimited = key == "sensor.footprint_radius" and pd.isna(val)
        return f"{axis_label(key)} {'unlimited' if unlimited else param_text(float(val))}"

    return f"{one(r['row_key'], r['row_value'])}, {one(r['col_key'], r['col_value'])}"


def _dec8_claim(
    cid: str, label: str, g: pd.Series, map_df: pd.DataFrame, others: str, contrary: str
) -> Claim:
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
            # no n: the rule needs every cell of the group, so no one number of runs
            # decides it (the runs per cell are in the measured text)
        ),
        DEC8_RULE.verdict(map_facts(g)),
        DEC8_RULE.text(),
        measured=f"{axis_label(row_key)} × {axis_label(col_key)}, "
        f"{int(g['n_runs'])} paired runs per cell; CI below 0 in "
        f"{int(g['n_below'])} of {n_cells} cells, above 0 in {int(g['n_above'])}; "
        f"cell means {cells} m; track loss NBO "
        f"{fmt(pp(g['loss_nbo']), 2)}% vs {fmt(pp(g['loss_method']), 2)}%"
        f"{regret_txt} (means over the cells); the compared method, {method_label(method)}, "
        "is fixed in the config before the run (decisions.claims.map_method)",
        dropped=(
            f"the map's other comparisons ({others} − {method_label(baseline_name())}) are not "
            "the key "
            "number; cells where one of them lies on the opposite side are named as contrary"
            if others
            else ""
        ),
        part="beyond",
        setup=f"UAV sensitivity map ({axis_label(row_key)} × {axis_label(col_key)}), "
        + ("cells with a footprint" if cid == "DEC-8a" else "cells without a footprint"),
        contrary=contrary,
    )


def _dec8(
    map_df: pd.DataFrame, groups: pd.DataFrame, method: str, base_limited: bool
) -> list[Claim]:
    chosen = None if map_df.empty or groups.empty else map_comparison(map_df, method)
    if chosen is None:
        return []
    comp, other_methods = chosen
    limited = limited_cells(map_df, base_limited)
    claims = []
    for cid, flag, label in (
        ("DEC-8a", True, "With a limited sensor footprint"),
        ("DEC-8b", False, "Without a footprint (the reconstruction's sensor)"),
    ):
        sel = groups[(groups["comparison"] == comp) & (groups["limited"] == flag)]
        if not sel.empty:
            others = ", ".join(method_label(m) for m in other_methods)
            contrary = map_contrary(map_df, limited, flag, comp.split(" − ")[0])
            claims.append(_dec8_claim(cid, label, sel.iloc[0], map_df, others, contrary))
    return claims


def uav_claims(
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    map_df: pd.DataFrame,
    groups: pd.DataFrame,
    rules: Mapping[str, Any],
    seed: int,
    n_boot: int,
    base_limited: bool = False,
) -> list[Claim]:
    """Claims DEC-6, DEC-7-<model>, DEC-8a/b (module doc); ``groups`` is
    :func:`rsmhp.studies.decisions.summarise_uav.summarize_map_groups`, ``rules`` the
    ``decisions.claims`` config (equivalence margin, the map method of DEC-8)."""
    missing = [k for k in ("equivalence_margin_pp", "map_method") if k not in rules]
    if missing:
        raise ValueError(f"decisions.claims lacks {missing} (the config schema fills defaults)")
    margin = float(rules["equivalence_margin_pp"])
    claims: list[Claim] = []
    models: Sequence[str] = list(dict.fromkeys(regret["model"]))
    best_rs = largest_rsmhp(summary)
    base = base_model(models)
    if best_rs is not None:
        if base is not None:
            dec6 = _dec6(regret, summary, base, best_rs, margin, seed, n_boot)
            claims += [dec6] if dec6 is not None else []
        claims += [
            _dec7(regret, summary, m, best_rs, margin, seed, n_boot) for m in models if m != base
        ]
    return claims + _dec8(map_df, groups, str(rules.get("map_method", "")), base_limited)
