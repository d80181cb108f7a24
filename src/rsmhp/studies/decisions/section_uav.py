"""Decision study on the UAV, report section (order 31): the Markdown tables of the open-loop
regret and the sensitivity map, a short body (setting, findings, figures) and the appendix,
assembled from :mod:`rsmhp.studies.decisions.summarise_uav` and the claims of
:mod:`rsmhp.studies.decisions.claims_uav`. The prose is in the templates beside this module
(``section_uav.md``: body, ``section_uav_appendix.md``); this module computes and formats the
values they insert."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import pandas as pd

from rsmhp.models.uav.methods import baseline_name
from rsmhp.report.ledger import Claim, Section
from rsmhp.report.markdown import ci_cells, fmt, fmt_ci, markdown_table, param_text
from rsmhp.report.palette import method_label
from rsmhp.report.templates import render
from rsmhp.studies.decisions import FIGURES_UAV as FIGURES
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


def _render(template: str, **values: Any) -> str:
    """The template ``template`` beside this module filled with ``values``, without the line
    break that ends the template file."""
    return render("rsmhp.studies.decisions", template, **values).removesuffix("\n")


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
    """Markdown tables ``decisions_uav_regret`` and ``decisions_uav_map``: regrets and rates in
    percent, "unlimited" for a footprint radius that is null; an undefined Spearman correlation (the
    method's cost constant over the plans at every state) or Wilcoxon p-value (every paired
    difference 0) prints as "undefined"."""
    return {"decisions_uav_regret": _regret_table(summary), "decisions_uav_map": _map_table(map_df)}


@dataclass(frozen=True)
class Dec6:
    """DEC-6 for the findings: NBO − the largest RS-MHP (``label``) in relative regret (pp,
    formatted, with CI); NBO's mean relative regret and the part of it every method shares
    (the common optimiser budget), both in percent, ``None`` without an NBO row."""

    id: str
    label: str
    value: str
    ci: str
    verdict: str
    nbo_regret: str | None
    shared: str | None


@dataclass(frozen=True)
class Dec7:
    """A DEC-7 claim of model variant ``model``: the relative-regret difference (pp, with CI)
    and the belief states (of ``states``) where NBO's cost is constant over random plans
    (``None`` when there are none)."""

    id: str
    model: str
    value: str
    ci: str
    verdict: str
    constant_states: str | None
    states: str | None


@dataclass(frozen=True)
class Dec8:
    """A DEC-8 claim: the map's closed-loop error of ``method`` − NBO (m, with CI), with
    (``footprint``) or without a sensor footprint; ``contrary`` the evidence against it."""

    id: str
    footprint: bool
    method: str
    value: str
    ci: str
    verdict: str
    contrary: str


@dataclass(frozen=True)
class Margin:
    """The equivalence margin Δ (pp) against the share of regret every method loses to the
    common optimiser budget (``share`` %, ``ratio`` = share / Δ; ``None`` without a base
    model) and the lowest CI limit of the variants called better (``None`` if none is)."""

    margin: str
    share: str | None
    ratio: str | None
    lowest_better: str | None


def _dec6(c: Claim, regret: pd.DataFrame, summary: pd.DataFrame, base: str | None) -> Dec6:
    best_rs = largest_rsmhp(summary)
    k = c.key
    nbo = summary[(summary["model"] == base) & (summary["method"] == baseline_name())]
    return Dec6(
        id=c.id,
        label=method_label(best_rs) if best_rs else "RS-MHP",
        value=fmt(k.value, 2, True),
        ci=fmt_ci(k.ci_low, k.ci_high, 2, True),
        verdict=c.verdict,
        nbo_regret=None if nbo.empty else fmt(pp(nbo["mean_regret_rel"].iloc[0])),
        shared=None if nbo.empty else fmt(pp(optimiser_share(regret, str(base)))),
    )


def _dec7(cid: str, c: Claim, summary: pd.DataFrame) -> Dec7:
    k, model = c.key, cid[len("DEC-7-") :]
    s = summary[(summary["model"] == model) & (summary["method"] == baseline_name())]
    flat = not s.empty and int(s["spearman_random_undefined"].iloc[0]) > 0
    return Dec7(
        id=cid,
        model=model,
        value=fmt(k.value, 2, True),
        ci=fmt_ci(k.ci_low, k.ci_high, 2, True),
        verdict=c.verdict,
        constant_states=str(int(s["spearman_random_undefined"].iloc[0])) if flat else None,
        states=str(int(s["n_states"].iloc[0])) if flat else None,
    )


def _margin(
    margin: float, regret: pd.DataFrame, base: str | None, claims: Sequence[Claim]
) -> Margin:
    """Why the equivalence margin of DEC-6/DEC-7 is what it is (numbers of this run)."""
    share = (
        pp(optimiser_share(regret, str(base)))
        if base is not None and (regret["model"] == base).any()
        else None
    )
    effects = [
        c.key.ci_low for c in claims if c.verdict == "supported" and c.id.startswith("DEC-7-")
    ]
    return Margin(
        margin=param_text(margin),
        share=None if share is None else fmt(share),
        ratio=None if share is None else fmt(share / margin, 2),
        lowest_better=fmt(min(effects), 2) if effects else None,
    )


def _findings(
    claims: Sequence[Claim],
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    base: str | None,
    margin: float,
) -> dict[str, Any]:
    """The values of the findings paragraph, every number from the claims and the summary:
    DEC-6, the DEC-7 claims, DEC-8a/b, the margin (``None`` without DEC-6 and DEC-7)."""
    c = {cl.id: cl for cl in claims}
    dec8 = []
    for cid in ("DEC-8a", "DEC-8b"):
        if cid in c:
            k = c[cid].key
            dec8.append(
                Dec8(
                    id=cid,
                    footprint=cid == "DEC-8a",
                    method=k.name.split(" − ")[0],
                    value=fmt(k.value, 3, True),
                    ci=fmt_ci(k.ci_low, k.ci_high, 3, True),
                    verdict=c[cid].verdict,
                    contrary=c[cid].contrary,
                )
            )
    judged = any(cid == "DEC-6" or cid.startswith("DEC-7-") for cid in c)
    return {
        "dec6": _dec6(c["DEC-6"], regret, summary, base) if "DEC-6" in c else None,
        "dec7": [_dec7(cid, cl, summary) for cid, cl in c.items() if cid.startswith("DEC-7-")],
        "dec8": dec8,
        "margin": _margin(margin, regret, base, claims) if judged else None,
    }


@dataclass(frozen=True)
class Variant:
    """A model variant of the open-loop scoring: its name and its overrides of the
    reconstruction, each as "name value unit" (none: the reconstruction)."""

    name: str
    overrides: list[str]


def _variant(model: Mapping[str, Any]) -> Variant:
    """``Variant('footprint150', ['footprint radius 150 m'])`` for a ``decisions.uav.models``
    entry."""
    overrides = []
    for section, values in model.items():
        if section == "name":
            continue
        for key, value in values.items():
            name, unit = MAP_AXES.get(f"{section}.{key}", (f"{section}.{key}", ""))
            overrides.append(
                f"{name} {axis_value(f'{section}.{key}', value)}{' ' + unit if unit else ''}"
            )
    return Variant(name=str(model["name"]), overrides=overrides)


def _setting(cfg: Mapping[str, Any]) -> dict[str, Any]:
    """The values of the body's two paragraphs on what was run: open-loop scoring and the
    map."""
    ucfg, mcfg = cfg["uav"], cfg["map"]
    steps = [int(s) for s in ucfg["steps"]]
    rk, ck = mcfg["rows"]["key"], mcfg["cols"]["key"]
    return {
        "runs": str(int(ucfg["runs"])),
        "first_step": str(steps[0]),
        "last_step": str(steps[-1]),
        "n_eval": str(int(ucfg["n_eval"])),
        "variants": [_variant(m) for m in ucfg["models"]],
        "row_label": axis_label(rk),
        "row_set": "{" + ", ".join(axis_value(rk, v) for v in mcfg["rows"]["values"]) + "}",
        "col_label": axis_label(ck),
        "col_set": "{" + ", ".join(axis_value(ck, v) for v in mcfg["cols"]["values"]) + "}",
        "map_runs": str(int(mcfg["runs"])),
        "track_loss_error": param_text(mcfg["track_loss_error"]),
        "regret_floor": REGRET_FLOOR_TEXT,
    }


def _appendix(cfg: Mapping[str, Any], tables: Mapping[str, str]) -> str:
    ucfg, mcfg = cfg["uav"], cfg["map"]
    return _render(
        "section_uav_appendix.md",
        steps=", ".join(str(int(s)) for s in ucfg["steps"]),
        last_run=str(int(ucfg["runs"]) - 1),
        polish=str(int(ucfg["polish"])),
        random_starts=str(int(ucfg["random_starts"])),
        eval_maxiter=str(int(ucfg["eval_maxiter"])),
        n_random=str(int(ucfg["n_random"])),
        early_step=str(EARLY_STEP),
        regret_table=tables["decisions_uav_regret"],
        map_runs=str(int(mcfg["runs"])),
        regret_runs=str(int(mcfg["regret_runs"])),
        regret_steps=", ".join(str(int(s)) for s in mcfg["regret_steps"]),
        map_table=tables["decisions_uav_map"],
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
    margin = float(cfg["claims"]["equivalence_margin_pp"])
    body = _render(
        "section_uav.md",
        **_setting(cfg),
        **_findings(claims, regret, summary, base, margin),
    )
    return Section(
        key="decisions_uav",
        title="Decision quality: UAV open-loop regret and sensitivity map",
        order=31,
        body=body,
        claims=claims,
        figures=list(FIGURES),
        appendix=_appendix(cfg, tables),
    )
