r"""Decision-quality study, UAV half: regret summaries, sensitivity map, claims with their
verdict rules, tables and the report section. The LQG half is split by stage into
:mod:`rsmhp.analysis.decisions_lqg` (statistics), :mod:`rsmhp.claims.decisions_lqg`
(claims) and :mod:`rsmhp.narrative.decisions_lqg` (section).

UAV (:mod:`rsmhp.experiments.decisions_uav`)
--------------------------------------------
Relative regret of a plan at a belief state = (evaluation cost of the plan − that of the best
plan found) / best. Paired differences per belief state, :math:`d = \mathrm{rr}(B) -
\mathrm{rr}(A)`, are summarised by their mean with a 95% percentile bootstrap CI over belief
states (``job_rng(seed, "decisions_bootstrap", ...)``), reported in percentage points (pp).
DEC-6 is an equivalence test: the CI must lie inside :math:`\pm` :data:`EQUIVALENCE_MARGIN`.

Sensitivity map: per cell and comparison, :math:`d_r = e_r(\text{RS-MHP}) - e_r(\text{NBO})`
of the closed-loop average location error over paired runs r, mean with a bootstrap CI and the
Wilcoxon signed-rank p-value. DEC-8a/b pool a group of cells (with / without a footprint):
:math:`\bar d_r = \frac{1}{|C|}\sum_{c \in C} d_{c,r}` per run (the runs share scenario and
noise across cells), its mean with a bootstrap CI over runs is the key number. The rules are
:data:`UAV_RULES`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd
from scipy import stats as sps

from rsmhp.ledger import Claim, KeyNumber, Section
from rsmhp.markdown import fmt, fmt_ci, markdown_table
from rsmhp.narrative.decisions_lqg import FIGURES as LQG_FIGURES
from rsmhp.palette import method_label
from rsmhp.seeding import job_rng
from rsmhp.stats import bootstrap_ci

__all__ = [
    "EQUIVALENCE_MARGIN",
    "LQG_FIGURES",
    "MAP_COLUMNS",
    "MAP_GROUP_COLUMNS",
    "REGRET_FLOOR_PCT",
    "REGRET_FLOOR_TEXT",
    "UAV_FIGURES",
    "UAV_RULES",
    "UAV_SUMMARY_COLUMNS",
    "axis_label",
    "axis_value",
    "summarize_map",
    "summarize_map_groups",
    "summarize_uav_regret",
    "uav_claims",
    "uav_decision_section",
    "uav_tables",
]

#: figure stems of the UAV section (the figure rule writes them; see decisions.smk);
#: ``LQG_FIGURES`` is re-exported from :mod:`rsmhp.narrative.decisions_lqg` for decisions.smk
UAV_FIGURES = ("dec_uav_regret", "dec_uav_map")


def _range(values: pd.Series, digits: int = 3, signed: bool = False) -> str:
    lo, hi = float(values.min()), float(values.max())
    if lo == hi:
        return fmt(lo, digits, signed)
    return f"{fmt(lo, digits, signed)} to {fmt(hi, digits, signed)}"


def _param(x: float | int) -> str:
    """A configuration value as text: whole numbers without decimals, others with the fewest
    significant digits that give the value back exactly (``0.25``, not ``0.250``)."""
    xf = float(x)
    if xf.is_integer():
        return fmt(int(xf))
    for digits in range(1, 16):
        text = fmt(xf, digits)
        if float(text) == xf:
            return text
    return fmt(xf, 6)


def _by_verdict(claims: Sequence[Claim]) -> dict[str, Claim]:
    return {c.id: c for c in claims}


# ---------------------------------------------------------------------------- UAV study

UAV_SUMMARY_COLUMNS = [
    "model",
    "method",
    "N_T",
    "n_states",
    "mean_regret_rel",
    "ci_low",
    "ci_high",
    "median_regret_rel",
    "frac_significant",
    "mean_regret_methods_rel",
    "early_regret_rel",
    "late_regret_rel",
    "spearman_random",
    "spearman_random_undefined",
    "spearman_local",
]
MAP_COLUMNS = [
    "cell",
    "row_key",
    "row_value",
    "col_key",
    "col_value",
    "comparison",
    "n_runs",
    "mean_diff",
    "ci_low",
    "ci_high",
    "p_value",
    "loss_nbo",
    "loss_method",
    "detect_nbo",
    "detect_method",
    "regret_nbo",
    "regret_method",
]
MAP_GROUP_COLUMNS = [
    "limited",
    "comparison",
    "n_cells",
    "n_runs",
    "mean_diff",
    "ci_low",
    "ci_high",
    "n_below",
    "n_above",
    "cell_min",
    "cell_max",
    "loss_nbo",
    "loss_method",
    "regret_nbo",
    "regret_method",
]
#: the UAV regret figure draws relative regrets (percent) below this at it (log scale); the
#: caption quotes the same floor
REGRET_FLOOR_PCT = 1e-4
REGRET_FLOOR_TEXT = "10⁻⁴ %"
EARLY_STEP = 4  # belief states at steps <= 4 are "early" (high uncertainty)
EQUIVALENCE_MARGIN = 0.005  # DEC-6: 0.5 percentage points of relative regret, fixed a priori

UAV_RULES = {
    "DEC-6": "d = relative regret of NBO − that of RS-MHP with the largest N_T, paired per "
    "belief state of the reconstruction: supported (equivalent) if the 95% bootstrap CI of "
    "mean d lies inside ±0.5 percentage points, not supported if entirely outside, "
    "inconclusive otherwise",
    "DEC-7": "d = relative regret of NBO − that of RS-MHP with the largest N_T, paired per "
    "belief state of the model variant: supported if the 95% bootstrap CI of mean d lies "
    "above 0, not supported if below 0, inconclusive otherwise",
    "DEC-8": "d = closed-loop average location error of RS-MHP (first N_T of the map) − NBO, "
    "paired over runs. Supported if d's 95% bootstrap CI is below 0 in every cell of the "
    "group and for d averaged over its cells; not supported if above 0 in some cell or on "
    "average; inconclusive otherwise",
}

#: the map's axes: (name, unit) for labels
MAP_AXES = {
    "sensor.footprint_radius": ("footprint radius", "m"),
    "sensor.footprint_width": ("footprint edge width w", "m"),
    "sensor.reference_distance": ("sensor reference distance", "m"),
    "target.q": ("target manoeuvrability q", "m²/s³"),
    "tracker.p0_pos_sd": ("initial position sd", "m"),
    "tracker.p0_vel_sd": ("initial velocity sd", "m/s"),
}


def axis_label(key: str) -> str:
    """``"footprint radius (m)"`` for a map axis key (the key itself if unknown)."""
    name, unit = MAP_AXES.get(key, (key, ""))
    return f"{name} ({unit})" if unit else name


def axis_value(key: str, value: Any) -> str:
    """A map axis value as text: a null footprint radius is ``"unlimited"`` (the
    reconstruction's sensor); other null values (none in the schema) ``"base config"``."""
    if value is None or (isinstance(value, float) and not np.isfinite(value)) or pd.isna(value):
        return "unlimited" if key == "sensor.footprint_radius" else "base config"
    return _param(value)


def _regret_key(method: str, m: float, lo: float, hi: float, null: float | None) -> KeyNumber:
    """Key number of DEC-6/DEC-7: paired mean of NBO's − ``method``'s relative regret (pp)
    with its bootstrap CI; ``null`` 0 for a difference claim, None for equivalence."""
    return KeyNumber(
        f"NBO − {method_label(method)} relative regret, paired mean",
        _pp(m),
        _pp(lo),
        _pp(hi),
        unit="pp",
        reproducible="statistical",
        digits=2,
        null=null,
    )


def _boot_mean(x: np.ndarray, seed: int, n_boot: int, **key: Any) -> tuple[float, float]:
    """Percentile-bootstrap 95% CI of the mean of ``x``, resampled from a stream keyed on
    ``key``; NaNs for fewer than 2 values."""
    x = np.asarray(x, dtype=float)
    if x.size < 2:
        return float("nan"), float("nan")
    return bootstrap_ci(x, job_rng(seed, "decisions_bootstrap", **key), n_boot, 0.95)


def summarize_uav_regret(df: pd.DataFrame, seed: int, n_boot: int) -> pd.DataFrame:
    """Per (model, method): relative regret (regret / best cost) over belief states with a
    bootstrap CI, the share of states where the regret exceeds 2 standard errors, the regret
    against the methods' best plan only, early (step <= 4) and late means, mean Spearman
    correlations (random plans; NaN where the method's cost is constant, counted)."""
    rows = []
    for (model, method), g in df.groupby(["model", "method"], sort=False):
        rel = g["regret_rel"].to_numpy(float)
        lo, hi = _boot_mean(rel, seed, n_boot, model=model, method=method)
        sp = g["spearman_random"].to_numpy(float)
        sl = g["spearman_local"].to_numpy(float)
        rows.append(
            {
                "model": model,
                "method": method,
                "N_T": int(g["N_T"].iloc[0]),
                "n_states": len(g),
                "mean_regret_rel": float(rel.mean()),
                "ci_low": lo,
                "ci_high": hi,
                "median_regret_rel": float(np.median(rel)),
                "frac_significant": float(np.mean(g["regret"] > 2 * g["regret_se"])),
                "mean_regret_methods_rel": float((g["regret_methods"] / g["best_cost"]).mean()),
                "early_regret_rel": float(g.loc[g["step"] <= EARLY_STEP, "regret_rel"].mean()),
                "late_regret_rel": float(g.loc[g["step"] > EARLY_STEP, "regret_rel"].mean()),
                "spearman_random": float(np.nanmean(sp)) if np.isfinite(sp).any() else np.nan,
                "spearman_random_undefined": int(np.isnan(sp).sum()),
                "spearman_local": float(np.nanmean(sl)) if np.isfinite(sl).any() else np.nan,
            }
        )
    return pd.DataFrame(rows, columns=UAV_SUMMARY_COLUMNS)


def _method_order(method: str) -> tuple[int, int, str]:
    """RS-MHP by N_T first, then trees (by name)."""
    if method.startswith("rsmhp_nt"):
        return (0, int(method[len("rsmhp_nt") :]), method)
    return (1, 0, method)


def _paired_errors(runs: pd.DataFrame, cell: str, method: str) -> pd.Series:
    """d_r = mean_error(method) − mean_error(nbo) per run of ``cell`` (runs both have)."""
    g = runs[runs["cell"] == cell]
    wide = g.pivot(index="run", columns="method", values="mean_error")
    pair = wide[[method, "nbo"]].dropna()
    return pair[method] - pair["nbo"]


def summarize_map(
    runs: pd.DataFrame, regret: pd.DataFrame, cfg: Mapping[str, Any], seed: int, n_boot: int
) -> pd.DataFrame:
    """One row per (cell, RS-MHP or tree method vs NBO): paired closed-loop difference of
    the average location error with a bootstrap CI and the Wilcoxon signed-rank p-value
    (NaN where every difference is 0), track-loss rates, detection rates, mean open-loop
    relative regret."""
    rows = []
    for cell, g in runs.groupby("cell", sort=False):
        others = [m for m in g["method"].unique() if m != "nbo"]
        reg = regret[regret["model"] == cell]
        for method in sorted(others, key=_method_order):
            d = _paired_errors(g, cell, method).to_numpy(float)
            lo, hi = _boot_mean(d, seed, n_boot, cell=cell, method=method)
            p = float(sps.wilcoxon(d).pvalue) if np.any(d != 0) else float("nan")
            by = {m: g[g["method"] == m] for m in (method, "nbo")}
            rows.append(
                {
                    "cell": cell,
                    "row_key": cfg["rows"]["key"],
                    "row_value": g["row_value"].iloc[0],
                    "col_key": cfg["cols"]["key"],
                    "col_value": g["col_value"].iloc[0],
                    "comparison": f"{method} − nbo",
                    "n_runs": int(d.size),
                    "mean_diff": float(d.mean()),
                    "ci_low": lo,
                    "ci_high": hi,
                    "p_value": p,
                    "loss_nbo": float(by["nbo"]["lost"].mean()),
                    "loss_method": float(by[method]["lost"].mean()),
                    "detect_nbo": float(by["nbo"]["detect_rate"].mean()),
                    "detect_method": float(by[method]["detect_rate"].mean()),
                    "regret_nbo": float(reg.loc[reg["method"] == "nbo", "regret_rel"].mean()),
                    "regret_method": float(reg.loc[reg["method"] == method, "regret_rel"].mean()),
                }
            )
    return pd.DataFrame(rows, columns=MAP_COLUMNS)


def _limited(map_df: pd.DataFrame, base_limited: bool = False) -> pd.Series:
    """Whether each map row's cell has a finite footprint: the axis value where an axis is
    ``sensor.footprint_radius`` (``null`` = unlimited), else the base config's sensor."""
    out = pd.Series(bool(base_limited), index=map_df.index)
    for key, val in (("row_key", "row_value"), ("col_key", "col_value")):
        on_axis = map_df[key] == "sensor.footprint_radius"
        out = out.where(~on_axis, map_df[val].notna())
    return out


def summarize_map_groups(
    runs: pd.DataFrame,
    map_df: pd.DataFrame,
    seed: int,
    n_boot: int,
    base_limited: bool = False,
) -> pd.DataFrame:
    r"""One row per (group, comparison), the groups being the cells with a limited footprint
    (``limited`` True) and those without. Per run r the difference averaged over the group's
    cells, :math:`\bar d_r = \frac{1}{|C|}\sum_{c} d_{c,r}` (the runs share scenario and
    noise across cells, so resampling runs keeps the cells' correlation); its mean with a 95%
    bootstrap CI over runs; the number of cells whose own CI lies below / above 0; mean
    track-loss rates and open-loop relative regrets over the cells."""
    rows = []
    if map_df.empty:
        return pd.DataFrame(rows, columns=MAP_GROUP_COLUMNS)
    limited = _limited(map_df, base_limited)
    for comp in dict.fromkeys(map_df["comparison"]):
        method = comp.split(" ")[0]
        for flag in (True, False):
            grp = map_df[(map_df["comparison"] == comp) & (limited == flag)]
            if grp.empty:
                continue
            d = pd.concat(
                {c: _paired_errors(runs, c, method) for c in grp["cell"]}, axis=1
            ).dropna()
            dbar = d.mean(axis=1).to_numpy(float)
            lo, hi = _boot_mean(
                dbar, seed, n_boot, statistic="map_group", limited=flag, method=method
            )
            rows.append(
                {
                    "limited": flag,
                    "comparison": comp,
                    "n_cells": len(grp),
                    "n_runs": int(dbar.size),
                    "mean_diff": float(dbar.mean()) if dbar.size else float("nan"),
                    "ci_low": lo,
                    "ci_high": hi,
                    "n_below": int((grp["ci_high"] < 0).sum()),
                    "n_above": int((grp["ci_low"] > 0).sum()),
                    "cell_min": float(grp["mean_diff"].min()),
                    "cell_max": float(grp["mean_diff"].max()),
                    "loss_nbo": float(grp["loss_nbo"].mean()),
                    "loss_method": float(grp["loss_method"].mean()),
                    "regret_nbo": float(grp["regret_nbo"].mean()),
                    "regret_method": float(grp["regret_method"].mean()),
                }
            )
    return pd.DataFrame(rows, columns=MAP_GROUP_COLUMNS)


def _paired_regret(
    df: pd.DataFrame, model: str, a: str, b: str, seed: int, n_boot: int
) -> tuple[float, float, float, int]:
    """Mean over belief states of regret_rel(b) − regret_rel(a) with its bootstrap CI."""
    g = df[df["model"] == model].pivot_table(
        index=["run", "step"], columns="method", values="regret_rel"
    )
    d = (g[b] - g[a]).to_numpy(float)
    lo, hi = _boot_mean(d, seed, n_boot, model=model, a=a, b=b, statistic="paired_regret")
    return float(d.mean()), lo, hi, int(d.size)


def _ci_verdict(lo: float, hi: float) -> str:
    return "supported" if lo > 0 else "not supported" if hi < 0 else "inconclusive"


def _pp(x: float) -> float:
    """A fraction in percentage points (finite Python float)."""
    return float(100.0 * x)


def _best_rsmhp(summary: pd.DataFrame) -> str | None:
    rs = summary[summary["method"].str.startswith("rsmhp")]
    return str(rs.sort_values("N_T")["method"].iloc[-1]) if not rs.empty else None


def _base_model(models: Sequence[str]) -> str | None:
    return "paper" if "paper" in models else (models[0] if models else None)


def _optimiser_share(regret: pd.DataFrame, model: str) -> float:
    """Mean relative regret of the best method's plan against the best plan found (the same
    for every method at a state): regret_rel − regret_methods / best_cost."""
    g = regret[regret["model"] == model]
    share = g["regret_rel"] - g["regret_methods"] / g["best_cost"]
    return float(share.groupby([g["run"], g["step"]]).first().mean())


def uav_claims(
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    map_df: pd.DataFrame,
    groups: pd.DataFrame,
    seed: int,
    n_boot: int,
) -> list[Claim]:
    """Claims DEC-6, DEC-7-<model>, DEC-8a/b by :data:`UAV_RULES`; ``groups`` is
    :func:`summarize_map_groups`. Every key number is statistical (closed loop, optimiser)."""
    claims: list[Claim] = []
    models = list(dict.fromkeys(regret["model"]))
    best_rs = _best_rsmhp(summary)
    base = _base_model(models)
    nbo = summary[(summary["model"] == base) & (summary["method"] == "nbo")]
    if not nbo.empty and best_rs is not None:
        r = nbo.iloc[0]
        m, lo, hi, n = _paired_regret(regret, base, best_rs, "nbo", seed, n_boot)
        margin = EQUIVALENCE_MARGIN
        verdict = (
            "supported"
            if -margin < lo and hi < margin
            else "not supported"
            if lo >= margin or hi <= -margin
            else "inconclusive"
        )
        sp = r["spearman_random"]
        sp_txt = (
            f"; Spearman rank correlation of NBO's cost with the evaluation cost over random "
            f"plans {fmt(float(sp), 3)}"
            if np.isfinite(sp)
            else ""
        )
        claims.append(
            Claim(
                "DEC-6",
                f"Reconstruction ('{base}'): NBO decides as well as {method_label(best_rs)} "
                f"(relative regrets within ±{_param(_pp(margin))} pp)",
                "Not in the paper; explains why the closed-loop comparisons (Fig. 5, UAV "
                "claims) cannot separate the methods",
                _regret_key(best_rs, m, lo, hi, null=None),
                verdict,
                UAV_RULES["DEC-6"],
                measured=f"{n} belief states; NBO's mean relative regret "
                f"{fmt(_pp(r['mean_regret_rel']))}%, of which "
                f"{fmt(_pp(r['mean_regret_methods_rel']), 2)} pp against the best method's "
                f"plan: every method shares {fmt(_pp(_optimiser_share(regret, base)), 3)}% "
                "from the common optimiser budget (the multi-start on the evaluation cost "
                f"finds better plans){sp_txt}",
            )
        )
    if best_rs is not None:
        for model in models:
            if model == base:
                continue
            m, lo, hi, n = _paired_regret(regret, model, best_rs, "nbo", seed, n_boot)
            s_nbo = summary[(summary["model"] == model) & (summary["method"] == "nbo")].iloc[0]
            s_rs = summary[(summary["model"] == model) & (summary["method"] == best_rs)].iloc[0]
            claims.append(
                Claim(
                    f"DEC-7-{model}",
                    f"Model variant '{model}': {method_label(best_rs)} decides better than "
                    "NBO (lower open-loop relative regret)",
                    "Sec. II: NBO may generate severely sub-optimal controls; tested on a "
                    "model variant (not the paper's model)",
                    _regret_key(best_rs, m, lo, hi, null=0.0),
                    _ci_verdict(lo, hi),
                    UAV_RULES["DEC-7"],
                    measured=f"{n} belief states; mean relative regret NBO "
                    f"{fmt(_pp(s_nbo['mean_regret_rel']))}% vs {method_label(best_rs)} "
                    f"{fmt(_pp(s_rs['mean_regret_rel']))}%; NBO's cost is constant over "
                    f"random plans at {int(s_nbo['spearman_random_undefined'])} of "
                    f"{int(s_nbo['n_states'])} states",
                )
            )
    if not map_df.empty and not groups.empty:
        comps = list(dict.fromkeys(map_df["comparison"]))
        comp = comps[0]
        method = comp.split(" ")[0]
        others = ", ".join(c.replace(" − nbo", "") for c in comps[1:])
        row_key, col_key = map_df["row_key"].iloc[0], map_df["col_key"].iloc[0]
        for cid, flag, label in (
            ("DEC-8a", True, "With a limited sensor footprint"),
            ("DEC-8b", False, "Without a footprint (the reconstruction's sensor)"),
        ):
            sel = groups[(groups["comparison"] == comp) & (groups["limited"] == flag)]
            if sel.empty:
                continue
            g = sel.iloc[0]
            n_cells = int(g["n_cells"])
            cells = _range(pd.Series([g["cell_min"], g["cell_max"]]), 3, True)
            regret_txt = (
                f", open-loop relative regret {fmt(_pp(g['regret_nbo']), 2)}% vs "
                f"{fmt(_pp(g['regret_method']), 2)}%"
                if np.isfinite(g["regret_nbo"]) and np.isfinite(g["regret_method"])
                else ""
            )
            verdict = (
                "supported"
                if int(g["n_below"]) == n_cells and g["ci_high"] < 0
                else "not supported"
                if int(g["n_above"]) > 0 or g["ci_low"] > 0
                else "inconclusive"
            )
            claims.append(
                Claim(
                    cid,
                    f"{label}, {method_label(method)} has lower closed-loop error than NBO in "
                    "every map cell",
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
                    verdict,
                    UAV_RULES["DEC-8"],
                    measured=f"{axis_label(row_key)} × {axis_label(col_key)}, "
                    f"{int(g['n_runs'])} paired runs per cell; CI below 0 in "
                    f"{int(g['n_below'])} of {n_cells} cells, above 0 in {int(g['n_above'])}; "
                    f"cell means {cells} m; track loss NBO "
                    f"{fmt(_pp(g['loss_nbo']), 2)}% vs {fmt(_pp(g['loss_method']), 2)}%"
                    f"{regret_txt} (means over the cells)",
                    dropped=(
                        f"the map's other comparison ({others} − nbo) is not used: the rule "
                        "fixes the first RS-MHP N_T of the map before the run (appendix table)"
                        if others
                        else ""
                    ),
                )
            )
    return claims


def uav_tables(summary: pd.DataFrame, map_df: pd.DataFrame) -> dict[str, str]:
    """Markdown tables ``dec_uav_regret`` and ``dec_uav_map``: regrets and rates in percent,
    "unlimited" for a footprint radius that is null; an undefined Spearman correlation (the
    method's cost constant over the plans at every state) or Wilcoxon p-value (every paired
    difference 0) prints as "undefined"."""
    s = pd.DataFrame(
        {
            "model": summary["model"],
            "method": summary["method"].map(method_label),
            "states": summary["n_states"].astype(int),
            "regret %": 100 * summary["mean_regret_rel"],
            "95% CI": [
                fmt_ci(100 * lo, 100 * hi, 3) if np.isfinite(lo) else "undefined"
                for lo, hi in zip(summary["ci_low"], summary["ci_high"], strict=True)
            ],
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
    if map_df.empty:
        m_text = "(no map cells)"
    else:
        row_key, col_key = map_df["row_key"].iloc[0], map_df["col_key"].iloc[0]
        m = pd.DataFrame(
            {
                axis_label(row_key): [axis_value(row_key, v) for v in map_df["row_value"]],
                axis_label(col_key): [axis_value(col_key, v) for v in map_df["col_value"]],
                "comparison": [
                    f"{method_label(c.split(' ')[0])} − NBO" for c in map_df["comparison"]
                ],
                "runs": map_df["n_runs"].astype(int),
                "mean diff (m)": map_df["mean_diff"],
                "95% CI (m)": [
                    fmt_ci(lo, hi, 3, signed=True) if np.isfinite(lo) else "undefined"
                    for lo, hi in zip(map_df["ci_low"], map_df["ci_high"], strict=True)
                ],
                "p": map_df["p_value"],
                "loss NBO %": (100 * map_df["loss_nbo"]).round(1),
                "loss RS-MHP %": (100 * map_df["loss_method"]).round(1),
                "detect NBO %": (100 * map_df["detect_nbo"]).round(1),
                "detect RS-MHP %": (100 * map_df["detect_method"]).round(1),
                "regret NBO %": 100 * map_df["regret_nbo"],
                "regret RS-MHP %": 100 * map_df["regret_method"],
            }
        )
        m_text = markdown_table(m, digits=3, missing="undefined", signed=("mean diff (m)",))
    return {
        "dec_uav_regret": markdown_table(s, digits=3, missing="undefined"),
        "dec_uav_map": m_text,
    }


def _uav_findings(
    claims: Sequence[Claim], regret: pd.DataFrame, summary: pd.DataFrame, base: str | None
) -> str:
    """One short paragraph of results, every number from the claims and the summary."""
    c = _by_verdict(claims)
    best_rs = _best_rsmhp(summary)
    label = method_label(best_rs) if best_rs else "RS-MHP"
    out = []
    if "DEC-6" in c:
        k = c["DEC-6"].key
        nbo = summary[(summary["model"] == base) & (summary["method"] == "nbo")]
        shared = ""
        if not nbo.empty:
            shared = (
                f"; of NBO's {fmt(_pp(nbo['mean_regret_rel'].iloc[0]))}% mean relative regret, "
                f"{fmt(_pp(_optimiser_share(regret, str(base))))}% is shared by every method, "
                "the common optimiser budget"
            )
        out.append(
            f"In the reconstruction the relative regret of NBO − {label} is "
            f"{fmt(k.value, 2, True)} pp {fmt_ci(k.ci_low, k.ci_high, 2, True)}{shared} "
            f"(DEC-6 {c['DEC-6'].verdict})."
        )
    for cid, cl in c.items():
        if cid.startswith("DEC-7-"):
            k, model = cl.key, cid[len("DEC-7-") :]
            s = summary[(summary["model"] == model) & (summary["method"] == "nbo")]
            flat = (
                f"; NBO's single hypothesis makes its cost constant over random plans at "
                f"{int(s['spearman_random_undefined'].iloc[0])} of {int(s['n_states'].iloc[0])} "
                "states, where it cannot steer"
                if not s.empty and int(s["spearman_random_undefined"].iloc[0]) > 0
                else ""
            )
            out.append(
                f"In '{model}' it is {fmt(k.value, 2, True)} pp "
                f"{fmt_ci(k.ci_low, k.ci_high, 2, True)}{flat} ({cid} {cl.verdict})."
            )
    for cid, what in (("DEC-8a", "with a footprint"), ("DEC-8b", "without one")):
        if cid in c:
            k = c[cid].key
            out.append(
                f"On the map, {what}, the closed-loop error of {k.name.split(' − ')[0]} − NBO "
                "averages "
                f"{fmt(k.value, 3, True)} m {fmt_ci(k.ci_low, k.ci_high, 3, True)} "
                f"({cid} {c[cid].verdict})."
            )
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


def uav_decision_section(
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    map_df: pd.DataFrame,
    groups: pd.DataFrame,
    tables: Mapping[str, str],
    cfg: Mapping[str, Any],
    seed: int,
) -> Section:
    """The decision study's UAV report section (order 31); ``cfg`` is the ``decisions``
    config section, ``groups`` :func:`summarize_map_groups`."""
    ucfg, mcfg = cfg["uav"], cfg["map"]
    n_boot = int(mcfg["bootstrap"])
    claims = uav_claims(regret, summary, map_df, groups, seed, n_boot)
    base = _base_model(list(dict.fromkeys(regret["model"])))
    steps = [int(s) for s in ucfg["steps"]]
    variants = "; ".join(_variant_text(m) for m in ucfg["models"])
    rk, ck = mcfg["rows"]["key"], mcfg["cols"]["key"]
    rows_txt = ", ".join(axis_value(rk, v) for v in mcfg["rows"]["values"])
    cols_txt = ", ".join(axis_value(ck, v) for v in mcfg["cols"]["values"])
    body = "\n".join(
        [
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
            f"error above {_param(mcfg['track_loss_error'])} m.",
            "",
            _uav_findings(claims, regret, summary, base),
            "",
            "![UAV open-loop regret](figures/dec_uav_regret.png)",
            "",
            "*Relative regret per belief state and method (log scale; values below "
            f"{REGRET_FLOOR_TEXT} drawn at {REGRET_FLOOR_TEXT}, counted in each panel); "
            "bottom: against the best of the methods' "
            "plans only.*",
            "",
            "![UAV sensitivity map](figures/dec_uav_map.png)",
            "",
            "*Closed-loop RS-MHP − NBO average location error (m) per map cell; an asterisk "
            "marks a 95% CI excluding 0; track-loss rates NBO/RS-MHP; colours span ±max "
            "|difference|, nothing clipped.*",
        ]
    )
    appendix = "\n".join(
        [
            f"Scoring (`decisions.uav`): steps {', '.join(str(s) for s in steps)} of runs 0 to "
            f"{int(ucfg['runs']) - 1}; the best plan found polishes the "
            f"{int(ucfg['polish'])} best plans and {int(ucfg['random_starts'])} random starts "
            f"with L-BFGS-B ({int(ucfg['eval_maxiter'])} iterations) on the evaluation cost. "
            "The standard error (SE) of a regret is paired over the evaluation hypotheses; "
            "'vs best method' isolates the part due to the cost approximation (the rest is "
            "the common optimiser budget stopping early). Spearman: rank correlation of the "
            f"method's cost with the evaluation cost over {int(ucfg['n_random'])} random plans "
            "('constant cost': states where the method's cost does not change over them, so "
            "the correlation is undefined and left out of the mean) or over local "
            "perturbations. A footprint has a hard edge in the truth; the planner uses the "
            "detection probability 1/(1 + exp((ρ − radius)/w)) at horizontal distance ρ and "
            "the expected update P⁺ = P⁻ − p_d K S Kᵀ (`rsmhp.uav.sensor`).",
            "",
            "Open-loop relative regret per model and method (percent of the best plan's cost; "
            f"CI: 95% bootstrap over belief states; early: steps ≤ {EARLY_STEP}):",
            "",
            tables["dec_uav_regret"],
            "",
            "Sensitivity map: mean paired difference of the closed-loop average location "
            f"error, RS-MHP − NBO (m), over {int(mcfg['runs'])} runs; p: Wilcoxon signed-rank "
            "test ('undefined' if every difference is 0); track loss, detection rate and "
            f"open-loop relative regret (at the belief states of {int(mcfg['regret_runs'])} "
            f"NBO runs, steps {', '.join(str(int(s)) for s in mcfg['regret_steps'])}) in "
            "percent; 'unlimited': no footprint (the reconstruction's sensor); 'undefined' "
            "in a regret column: the cell has no open-loop regret states.",
            "",
            tables["dec_uav_map"],
        ]
    )
    return Section(
        key="decisions_uav",
        title="Decision quality: UAV open-loop regret and sensitivity map",
        order=31,
        body=body,
        claims=claims,
        figures=list(UAV_FIGURES),
        appendix=appendix,
    )
