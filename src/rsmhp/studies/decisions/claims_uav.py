r"""Decision study on the UAV, claims DEC-6, DEC-7-<model>, DEC-8a/b, each a
:class:`~rsmhp.report.claimspec.ClaimSpec`: a key number from
:mod:`rsmhp.studies.decisions.summarise_uav` and a verdict rule (:mod:`rsmhp.report.verdicts`)
evaluated on facts, the rule's printed text and its evaluation one object; the claims'
sentences, key-number names and the words of the rules are the macros of ``claims_uav.md``
beside this module (:class:`~rsmhp.report.templates.Words`). Every key number is statistical
(closed loop, optimiser).

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
from rsmhp.report.claimspec import ClaimSpec, Evidence
from rsmhp.report.ledger import Claim, KeyNumber
from rsmhp.report.markdown import fmt, fmt_ci, param_text, range_text
from rsmhp.report.palette import method_label
from rsmhp.report.templates import Words
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
    "WORDS",
    "ci_facts",
    "map_comparison",
    "map_contrary",
    "map_facts",
    "pp",
    "range_text",
    "regret_rule",
    "uav_claims",
]

#: the words of the claims and rules (macros of ``claims_uav.md`` beside this module)
WORDS = Words("rsmhp.studies.decisions", "claims_uav.md")

#: the key number of every claim here, as the rules name it (facts ``mean d_low/high``)
KEY = "mean d"
_LO, _HI = f"{KEY}_low", f"{KEY}_high"


def pp(x: float) -> float:
    """A fraction in percentage points (finite Python float)."""
    return float(100.0 * x)


def regret_rule(margin_pp: float, setting: str) -> Rule:
    """The rule of DEC-6 (``setting`` "the reconstruction") and DEC-7 (a model variant):
    RS-MHP decides better than NBO, with the equivalence margin ±``margin_pp``."""
    return ci_side(
        KEY,
        0.0,
        claimed="above",
        basis=WORDS("regret_rule_basis", setting=setting),
        margin=margin_pp,
        margin_text=f"{param_text(margin_pp)} pp",
    )


DEC8_RULE = Rule(
    basis=WORDS("dec_8_rule_basis"),
    cases=(
        Case(
            "supported",
            WORDS("dec_8_rule_supported"),
            lambda f: f["cells below 0"] == f["cells"] and f[_HI] < 0,
        ),
        Case(
            "not supported",
            WORDS("dec_8_rule_not"),
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
        WORDS("regret_key", label=method_label(method)),
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


def _regret_evidence(
    regret: pd.DataFrame,
    model: str,
    best_rs: str,
    margin_pp: float,
    setting: str,
    seed: int,
    n_boot: int,
) -> Evidence:
    """The evidence of DEC-6/DEC-7 on ``model`` (its rule's ``setting`` in words) with the
    values both claims' texts share; the rule first: it checks the margin."""
    rule = regret_rule(margin_pp, setting)
    d = paired_regret(regret, model, best_rs, seed, n_boot)
    key = _regret_key(best_rs, d, margin_pp)
    values = {
        "label": method_label(best_rs),
        "states": str(d.n),
        "margin": param_text(margin_pp),
        "share": fmt(pp(optimiser_share(regret, model)), 3),
    }
    return Evidence(key=key, facts=ci_facts(key), values=values, rule=rule)


def _dec6(
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    base: str,
    best_rs: str,
    margin_pp: float,
    seed: int,
    n_boot: int,
) -> Evidence | None:
    """NBO − the largest RS-MHP in open-loop relative regret on the reconstruction (DEC-6)."""
    nbo = summary[(summary["model"] == base) & (summary["method"] == baseline_name())]
    if nbo.empty:
        return None
    r = nbo.iloc[0]
    ev = _regret_evidence(regret, base, best_rs, margin_pp, WORDS("dec_6_setting"), seed, n_boot)
    sp = r["spearman_random"]
    values = {
        **ev.values,
        "base": base,
        "nbo_regret": fmt(pp(r["mean_regret_rel"])),
        "vs_methods": fmt(pp(r["mean_regret_methods_rel"]), 2),
        "spearman": fmt(float(sp), 3) if np.isfinite(sp) else "",
    }
    return Evidence(key=ev.key, facts=ev.facts, values=values, rule=ev.rule)


def _dec7(
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    model: str,
    best_rs: str,
    margin_pp: float,
    seed: int,
    n_boot: int,
) -> Evidence:
    """NBO − the largest RS-MHP in open-loop relative regret on a model variant (DEC-7)."""
    ev = _regret_evidence(regret, model, best_rs, margin_pp, WORDS("dec_7_setting"), seed, n_boot)
    in_model = summary[summary["model"] == model]
    s_nbo = in_model[in_model["method"] == baseline_name()].iloc[0]
    s_rs = in_model[in_model["method"] == best_rs].iloc[0]
    values = {
        **ev.values,
        "model": model,
        "nbo_regret": fmt(pp(s_nbo["mean_regret_rel"])),
        "rs_regret": fmt(pp(s_rs["mean_regret_rel"])),
        "constant": str(int(s_nbo["spearman_random_undefined"])),
        "all_states": str(int(s_nbo["n_states"])),
    }
    return Evidence(key=ev.key, facts=ev.facts, values=values, rule=ev.rule)


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


def _axis(key: str, value: object) -> dict[str, str | None]:
    """One axis of a map cell: its label and value (``None``: a footprint radius that is null,
    no footprint; the ``map_cell`` macro)."""
    unlimited = key == "sensor.footprint_radius" and pd.isna(value)
    return {"label": axis_label(key), "value": None if unlimited else param_text(float(value))}


def _contrary_cells(
    map_df: pd.DataFrame, limited: pd.Series, flag: bool, method: str
) -> list[dict[str, Any]]:
    """The records of :func:`map_contrary` (the ``dec_8_contrary`` macro's)."""
    methods = pd.Series([c.split(" − ")[0] for c in map_df["comparison"]], index=map_df.index)
    family = type(registry.from_name(method))
    rows = map_df[(limited == flag) & (map_df["ci_low"] > 0) & is_family(methods, family)]
    return [
        {
            "row": _axis(r["row_key"], r["row_value"]),
            "col": _axis(r["col_key"], r["col_value"]),
            "label": method_label(r["comparison"].split(" − ")[0]),
            "mean": fmt(r["mean_diff"], 3, True),
            "ci": fmt_ci(r["ci_low"], r["ci_high"], 3, True),
        }
        for _, r in rows.iterrows()
    ]


def map_contrary(map_df: pd.DataFrame, limited: pd.Series, flag: bool, method: str) -> str:
    """Every (cell, comparison) of the group (``limited == flag``) whose 95% CI of method −
    NBO lies above 0 (significantly worse than NBO), for every method of the map of the same
    family as ``method`` (the compared one: e.g. every RS-MHP N_T)."""
    return WORDS("dec_8_contrary", contrary=_contrary_cells(map_df, limited, flag, method))


def _dec8_evidence(
    g: pd.Series,
    map_df: pd.DataFrame,
    footprint: bool,
    others: list[str],
    contrary: list[dict[str, Any]],
) -> Evidence:
    """DEC-8a (``footprint``) or DEC-8b from the group row ``g`` of ``summarize_map_groups``:
    the compared method − NBO in closed-loop average location error over the group's cells,
    the map's ``others`` compared methods and the ``contrary`` cells."""
    label = method_label(g["comparison"].split(" − ")[0])
    n_cells = int(g["n_cells"])
    regret = bool(np.isfinite(g["regret_nbo"]) and np.isfinite(g["regret_method"]))
    key = KeyNumber(
        WORDS("dec_8_key", label=label, cells=str(n_cells)),
        float(g["mean_diff"]),
        float(g["ci_low"]),
        float(g["ci_high"]),
        unit="m",
        reproducible="statistical",
        digits=3,
        null=0.0,
        # no n: the rule needs every cell of the group, so no one number of runs
        # decides it (the runs per cell are in the measured text)
    )
    values = {
        "footprint": footprint,
        "label": label,
        "row": axis_label(map_df["row_key"].iloc[0]),
        "col": axis_label(map_df["col_key"].iloc[0]),
        "runs": str(int(g["n_runs"])),
        "below": str(int(g["n_below"])),
        "cells": str(n_cells),
        "above": str(int(g["n_above"])),
        "means": range_text(pd.Series([g["cell_min"], g["cell_max"]]), 3, True),
        "loss_nbo": fmt(pp(g["loss_nbo"]), 2),
        "loss_method": fmt(pp(g["loss_method"]), 2),
        "regret_nbo": fmt(pp(g["regret_nbo"]), 2) if regret else "",
        "regret_method": fmt(pp(g["regret_method"]), 2) if regret else "",
        "others": [method_label(m) for m in others],
        "baseline": method_label(baseline_name()),
        "contrary": contrary,
    }
    return Evidence(key=key, facts=map_facts(g), values=values)


def _dec8(
    map_df: pd.DataFrame, groups: pd.DataFrame, method: str, base_limited: bool
) -> list[Claim]:
    """DEC-8a (cells with a footprint) and DEC-8b (without), each if the group was run."""
    chosen = None if map_df.empty or groups.empty else map_comparison(map_df, method)
    if chosen is None:
        return []
    comp, other_methods = chosen
    limited = limited_cells(map_df, base_limited)
    claims = []
    for flag in (True, False):
        sel = groups[(groups["comparison"] == comp) & (groups["limited"] == flag)]
        if not sel.empty:
            contrary = _contrary_cells(map_df, limited, flag, comp.split(" − ")[0])
            ev = _dec8_evidence(sel.iloc[0], map_df, flag, other_methods, contrary)
            claims.append(DEC8[flag].claim(ev))
    return claims


#: DEC-6 on the reconstruction (its name in the setup)
DEC6 = ClaimSpec(
    id="DEC-6",
    setup=WORDS("dec_6_setup", base="{base}"),
    evidence=_dec6,
    words=WORDS,
)

#: DEC-7 on each model variant (its name in the id and the setup)
DEC7 = ClaimSpec(
    id="DEC-7-{model}",
    setup=WORDS("dec_7_setup", model="{model}"),
    evidence=_dec7,
    words=WORDS,
    texts="dec_7",
    part="beyond",
)

#: DEC-8a (cells with a footprint, key ``True``) and DEC-8b (without), on the map's axes
DEC8 = {
    flag: ClaimSpec(
        id=cid,
        setup=WORDS("dec_8_setup", row="{row}", col="{col}", footprint=flag),
        evidence=_dec8_evidence,
        words=WORDS,
        rule=DEC8_RULE,
        texts="dec_8",
        part="beyond",
    )
    for cid, flag in (("DEC-8a", True), ("DEC-8b", False))
}


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
            claims += [DEC6.claim(dec6)] if dec6 is not None else []
        claims += [
            DEC7.claim(_dec7(regret, summary, m, best_rs, margin, seed, n_boot))
            for m in models
            if m != base
        ]
    return claims + _dec8(map_df, groups, str(rules.get("map_method", "")), base_limited)
