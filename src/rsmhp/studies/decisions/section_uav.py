"""Decision study on the UAV, report section (order 31): the Markdown tables of the open-loop
regret and the sensitivity map, a short body (setting, findings, figures) and the appendix,
assembled from :mod:`rsmhp.studies.decisions.summarise_uav` and the claims of
:mod:`rsmhp.studies.decisions.claims_uav`."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import pandas as pd

from rsmhp.models.uav.methods import baseline_name
from rsmhp.report.ledger import Claim, Section
from rsmhp.report.markdown import ci_cells, fmt, fmt_ci, markdown_table, param_text
from rsmhp.report.palette import method_label
from rsmhp.studies.decisions.claims_uav import pp, uav_claims
from rsmhp.studies.decisions.summarise_uav import (
    EARLY_STEP,
    MAP_AXES,
    REGRET_FLOOR_TEXT,
    axis_label,
    axis_value,
    base_model,
    largest_rsmhp,
    optimiser_share,
)

__all__ = ["FIGURES", "uav_decision_section", "uav_tables"]

#: figure stems of the section (the figure rule writes them; see decisions.smk)
FIGURES = ("dec_uav_regret", "dec_uav_map")


def _regret_table(summary: pd.DataFrame) -> str:
    s = pd.DataFrame(
        {
            "model": summary["model"],
            "method": summary["method"].map(method_label),
            "states": summary["n_states"].astype(int),
            "regret %": 100 * summary["mean_regret_rel"],
            "95% CI": ci_cells(summary["ci_low"], summary["ci_high"], 100),
            "median %": 100 * summary["median_regret_rel"],
            "states > 2 SE %": (100 * summary["frac_significant"]).round(1),
            "vs best method %": 100 * summary["mean_regret_methods_rel"],
            "early %": 100 * summary["early_regret_rel"],
            "late %": 100 * summary["late_regret_rel"],
            "Spearman random": summary["spearman_random"],
            "constant cost": summary["spearman_random_undefined"].astype(int),
            "Spearman local": summary["spearman_local"],
        }
    )
    return markdown_table(s, digits=3, missing="undefined")


def _map_table(map_df: pd.DataFrame) -> str:
    if map_df.empty:
        return "(no map cells)"
    row_key, col_key = map_df["row_key"].iloc[0], map_df["col_key"].iloc[0]
    m = pd.DataFrame(
        {
            axis_label(row_key): [axis_value(row_key, v) for v in map_df["row_value"]],
            axis_label(col_key): [axis_value(col_key, v) for v in map_df["col_value"]],
            "comparison": [
                " − ".join(method_label(x) for x in c.split(" − ")) for c in map_df["comparison"]
            ],
            "runs": map_df["n_runs"].astype(int),
            "mean diff (m)": map_df["mean_diff"],
            "95% CI (m)": ci_cells(map_df["ci_low"], map_df["ci_high"], 1, signed=True),
            "p": map_df["p_value"],
            "loss NBO %": (100 * map_df["loss_nbo"]).round(1),
            "loss method %": (100 * map_df["loss_method"]).round(1),
            "detect NBO %": (100 * map_df["detect_nbo"]).round(1),
            "detect method %": (100 * map_df["detect_method"]).round(1),
            "regret NBO %": 100 * map_df["regret_nbo"],
            "regret method %": 100 * map_df["regret_method"],
        }
    )
    return markdown_table(m, digits=3, missing="undefined", signed=("mean diff (m)",))


def uav_tables(summary: pd.DataFrame, map_df: pd.DataFrame) -> dict[str, str]:
    """Markdown tables ``dec_uav_regret`` and ``dec_uav_map``: regrets and rates in percent,
    "unlimited" for a footprint radius that is null; an undefined Spearman correlation (the
    method's cost constant over the plans at every state) or Wilcoxon p-value (every paired
    difference 0) prints as "undefined"."""
    return {"dec_uav_regret": _regret_table(summary), "dec_uav_map": _map_table(map_df)}


def _dec6_text(c: Claim, regret: pd.DataFrame, summary: pd.DataFrame, base: str | None) -> str:
    best_rs = largest_rsmhp(summary)
    label = method_label(best_rs) if best_rs else "RS-MHP"
    k = c.key
    nbo = summary[(summary["model"] == base) & (summary["method"] == baseline_name())]
    shared = ""
    if not nbo.empty:
        shared = (
            f"; of NBO's {fmt(pp(nbo['mean_regret_rel'].iloc[0]))}% mean relative regret, "
            f"{fmt(pp(optimiser_share(regret, str(base))))}% is shared by every method, "
            "the common optimiser budget"
        )
    return (
        f"In the reconstruction the relative regret of NBO − {label} is "
        f"{fmt(k.value, 2, True)} pp {fmt_ci(k.ci_low, k.ci_high, 2, True)}{shared} "
        f"(DEC-6 {c.verdict})."
    )


def _dec7_text(cid: str, c: Claim, summary: pd.DataFrame) -> str:
    k, model = c.key, cid[len("DEC-7-") :]
    s = summary[(summary["model"] == model) & (summary["method"] == baseline_name())]
    flat = (
        f"; NBO's single hypothesis makes its cost constant over random plans at "
        f"{int(s['spearman_random_undefined'].iloc[0])} of {int(s['n_states'].iloc[0])} "
        "states, where it cannot steer"
        if not s.empty and int(s["spearman_random_undefined"].iloc[0]) > 0
        else ""
    )
    return (
        f"In '{model}' it is {fmt(k.value, 2, True)} pp "
        f"{fmt_ci(k.ci_low, k.ci_high, 2, True)}{flat} ({cid} {c.verdict})."
    )


def _margin_text(margin: float, regret: pd.DataFrame, base: str | None, claims) -> str:
    """Why the equivalence margin of DEC-6/DEC-7 is what it is (numbers of this run)."""
    out = (
        f"The equivalence margin Δ = {param_text(margin)} pp (fixed in the config before the "
        "run, decisions.claims.equivalence_margin_pp)"
    )
    if base is not None and (regret["model"] == base).any():
        share = pp(optimiser_share(regret, str(base)))
        out += f" is {fmt(share / margin, 2)}× smaller than the {fmt(share)}% every method loses "
        out += "to the common optimiser budget"
    effects = [
        c.key.ci_low for c in claims if c.verdict == "supported" and c.id.startswith("DEC-7-")
    ]
    if effects:
        out += (
            f", and below the lower CI limit of every variant called better "
            f"({fmt(min(effects), 2)} pp): equivalence and 'better' are never said of effects "
            "of one size"
        )
    return out + "."


def _findings(
    claims: Sequence[Claim],
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    base: str | None,
    margin: float,
) -> str:
    """One short paragraph of results, every number from the claims and the summary."""
    c = {cl.id: cl for cl in claims}
    out = []
    if "DEC-6" in c:
        out.append(_dec6_text(c["DEC-6"], regret, summary, base))
    out += [_dec7_text(cid, cl, summary) for cid, cl in c.items() if cid.startswith("DEC-7-")]
    for cid, what in (("DEC-8a", "with a footprint"), ("DEC-8b", "without one")):
        if cid in c:
            k = c[cid].key
            out.append(
                f"On the map, {what}, the closed-loop error of {k.name.split(' − ')[0]} − NBO "
                "averages "
                f"{fmt(k.value, 3, True)} m {fmt_ci(k.ci_low, k.ci_high, 3, True)} "
                f"({cid} {c[cid].verdict})."
                + (f" Contrary: {c[cid].contrary}." if c[cid].contrary else "")
            )
    if any(cid == "DEC-6" or cid.startswith("DEC-7-") for cid in c):
        out.append(_margin_text(margin, regret, base, claims))
    return " ".join(out)


def _variant_text(model: Mapping[str, Any]) -> str:
    """``'footprint150' (footprint radius 150 m)``; the model without overrides is the
    reconstruction."""
    overrides = [
        (f"{section}.{key}", value)
        for section, values in model.items()
        if section != "name"
        for key, value in values.items()
    ]
    if not overrides:
        return f"'{model['name']}' (the reconstruction)"
    parts = []
    for key, value in overrides:
        name, unit = MAP_AXES.get(key, (key, ""))
        parts.append(f"{name} {axis_value(key, value)}{' ' + unit if unit else ''}")
    return f"'{model['name']}' ({', '.join(parts)})"


def _setting(cfg: Mapping[str, Any]) -> list[str]:
    """The body's two paragraphs on what was run: open-loop scoring and the map."""
    ucfg, mcfg = cfg["uav"], cfg["map"]
    steps = [int(s) for s in ucfg["steps"]]
    variants = "; ".join(_variant_text(m) for m in ucfg["models"])
    rk, ck = mcfg["rows"]["key"], mcfg["cols"]["key"]
    rows_txt = ", ".join(axis_value(rk, v) for v in mcfg["rows"]["values"])
    cols_txt = ", ".join(axis_value(ck, v) for v in mcfg["cols"]["values"])
    return [
        f"Open loop: at the belief states of {int(ucfg['runs'])} closed-loop NBO runs "
        f"(steps {steps[0]} to {steps[-1]}; a belief state is the tracker's estimate and "
        "covariance, step 0 the initial, most uncertain one) "
        "every method plans once, as in the closed loop, and each plan is scored on "
        f"{int(ucfg['n_eval'])} independent hypotheses drawn from the belief. **Relative "
        "regret** = (evaluation cost of the plan − that of the best plan found) / best, "
        "the best plan being the best of the methods' plans and of a multi-start "
        "optimisation of the evaluation cost. Differences of relative regret are in "
        "**percentage points (pp)**, paired per belief state, with 95% bootstrap CIs. N_T "
        "= trajectories RS-MHP samples. Model variants (this project's, not the paper's): "
        f"{variants}; a **footprint** is a horizontal radius (m) outside which the sensor "
        "measures nothing.",
        "",
        f"Sensitivity map: {axis_label(rk)} ∈ {{{rows_txt}}} × {axis_label(ck)} ∈ "
        f"{{{cols_txt}}}, {int(mcfg['runs'])} paired closed-loop runs per method and cell "
        "(the same scenarios and noise in every cell); **track loss** = final location "
        f"error above {param_text(mcfg['track_loss_error'])} m.",
    ]


_FIGURE_TEXT = [
    "![UAV open-loop regret](figures/dec_uav_regret.png)",
    "",
    "*Relative regret per belief state and method (log scale; values below "
    f"{REGRET_FLOOR_TEXT} drawn at {REGRET_FLOOR_TEXT}, counted in each panel); "
    "bottom: against the best of the methods' "
    "plans only.*",
    "",
    "![UAV sensitivity map](figures/dec_uav_map.png)",
    "",
    "*Closed-loop method − NBO average location error (m) per map cell, one panel per "
    "method (RS-MHP, each family at the planning budget); * marks a 95% CI excluding 0; "
    "track-loss rates NBO/method; colours span ±max |difference|, nothing clipped.*",
]


def _appendix(cfg: Mapping[str, Any], tables: Mapping[str, str]) -> str:
    ucfg, mcfg = cfg["uav"], cfg["map"]
    steps = [int(s) for s in ucfg["steps"]]
    return "\n".join(
        [
            f"Scoring (`decisions.uav`): steps {', '.join(str(s) for s in steps)} of runs 0 to "
            f"{int(ucfg['runs']) - 1}; the best plan found polishes the "
            f"{int(ucfg['polish'])} best plans and {int(ucfg['random_starts'])} random starts "
            f"with the planner's optimiser ({int(ucfg['eval_maxiter'])} iterations) on the "
            "evaluation cost. "
            "The standard error (SE) of a regret is paired over the evaluation hypotheses; "
            "'vs best method' isolates the part due to the cost approximation (the rest is "
            "the common optimiser budget stopping early). Spearman: rank correlation of the "
            f"method's cost with the evaluation cost over {int(ucfg['n_random'])} random plans "
            "('constant cost': states where the method's cost does not change over them, so "
            "the correlation is undefined and left out of the mean) or over local "
            "perturbations. A footprint has a hard edge in the truth; the planner uses the "
            "detection probability 1/(1 + exp((ρ − radius)/w)) at horizontal distance ρ and "
            "the expected update P⁺ = P⁻ − p_d K S Kᵀ (`rsmhp.models.uav.sensor`).",
            "",
            "Open-loop relative regret per model and method (percent of the best plan's cost; "
            f"CI: 95% bootstrap over belief states; early: steps ≤ {EARLY_STEP}):",
            "",
            tables["dec_uav_regret"],
            "",
            "Sensitivity map: mean paired difference of the closed-loop average location "
            f"error, method − NBO (m), over {int(mcfg['runs'])} runs; p: Wilcoxon signed-rank "
            "test ('undefined' if every difference is 0); track loss, detection rate and "
            f"open-loop relative regret (at the belief states of {int(mcfg['regret_runs'])} "
            f"NBO runs, steps {', '.join(str(int(s)) for s in mcfg['regret_steps'])}) in "
            "percent; 'unlimited': no footprint (the reconstruction's sensor); 'undefined' "
            "in a regret column: the cell has no open-loop regret states.",
            "",
            tables["dec_uav_map"],
        ]
    )


def uav_decision_section(
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    map_df: pd.DataFrame,
    groups: pd.DataFrame,
    tables: Mapping[str, str],
    cfg: Mapping[str, Any],
    seed: int,
    base_limited: bool = False,
) -> Section:
    """The decision study's UAV report section (order 31); ``cfg`` is the ``decisions``
    config section, ``groups`` :func:`rsmhp.studies.decisions.summarise_uav.summarize_map_groups`,
    ``base_limited`` whether the base config's sensor has a footprint."""
    n_boot = int(cfg["map"]["bootstrap"])
    claims = uav_claims(regret, summary, map_df, groups, cfg["claims"], seed, n_boot, base_limited)
    base = base_model(list(dict.fromkeys(regret["model"])))
    findings = _findings(
        claims, regret, summary, base, float(cfg["claims"]["equivalence_margin_pp"])
    )
    body = "\n".join([*_setting(cfg), "", findings, "", *_FIGURE_TEXT])
    return Section(
        key="decisions_uav",
        title="Decision quality: UAV open-loop regret and sensitivity map",
        order=31,
        body=body,
        claims=claims,
        figures=list(FIGURES),
        appendix=_appendix(cfg, tables),
    )
