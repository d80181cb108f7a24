r"""Decision-quality study on the UAV (:mod:`rsmhp.models.uav.scoring`), statistics:
open-loop regret summaries, the sensitivity map and its groups, paired differences with
bootstrap CIs. Numbers only: the claims DEC-6, DEC-7-<model>, DEC-8a/b are in
:mod:`rsmhp.studies.decisions.claims_uav`, the prose and tables in
:mod:`rsmhp.studies.decisions.section_uav`.

Relative regret of a plan at a belief state = (evaluation cost of the plan − that of the best
plan found) / best. Paired differences per belief state, :math:`d = \mathrm{rr}(B) -
\mathrm{rr}(A)` with B the baseline (NBO), are summarised by their mean with a 95% percentile
bootstrap CI over belief states (``job_rng(seed, "decisions_bootstrap", ...)``;
:func:`paired_regret`).

Sensitivity map: per cell and comparison of a method with the baseline,
:math:`d_r = e_r(\text{method}) - e_r(\text{NBO})` of the closed-loop average location error
over paired runs r, mean with a bootstrap CI and the Wilcoxon signed-rank p-value
(:func:`summarize_map`; the methods in the registry's order). A group of cells (with /
without a footprint) pools :math:`\bar d_r = \frac{1}{|C|}\sum_{c \in C} d_{c,r}` per run (the
runs share scenario and noise across cells), its mean with a bootstrap CI over runs
(:func:`summarize_map_groups`).

The baseline is the registry's (:func:`rsmhp.models.uav.methods.baseline`); the columns named
``*_nbo`` hold its numbers.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple

import numpy as np
import pandas as pd
from scipy import stats as sps

from rsmhp.core.seeding import job_rng
from rsmhp.core.stats import mean_bootstrap_ci
from rsmhp.models.uav import methods as registry
from rsmhp.models.uav.methods import baseline_name, is_family
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.report.markdown import param_text

__all__ = [
    "EARLY_STEP",
    "MAP_AXES",
    "MAP_COLUMNS",
    "MAP_GROUP_COLUMNS",
    "REGRET_FLOOR_PCT",
    "REGRET_FLOOR_TEXT",
    "UAV_SUMMARY_COLUMNS",
    "PairedRegret",
    "axis_label",
    "axis_value",
    "base_model",
    "largest_rsmhp",
    "limited_cells",
    "optimiser_share",
    "paired_errors",
    "paired_regret",
    "summarize_map",
    "summarize_map_groups",
    "summarize_uav_regret",
]

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
    return param_text(value)


def _boot_mean(x: np.ndarray, seed: int, n_boot: int, **key: Any) -> tuple[float, float]:
    """Percentile-bootstrap 95% CI of the mean of ``x``, resampled from a stream keyed on
    ``key``; NaNs for fewer than 2 values."""
    return mean_bootstrap_ci(x, job_rng(seed, "decisions_bootstrap", **key), n_boot)


# ---------------------------------------------------------------------------- open-loop regret


def _regret_row(g: pd.DataFrame, lo: float, hi: float) -> dict[str, Any]:
    rel = g["regret_rel"].to_numpy(float)
    sp = g["spearman_random"].to_numpy(float)
    sl = g["spearman_local"].to_numpy(float)
    return {
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


def summarize_uav_regret(df: pd.DataFrame, seed: int, n_boot: int) -> pd.DataFrame:
    """Per (model, method): relative regret (regret / best cost) over belief states with a
    bootstrap CI, the share of states where the regret exceeds 2 standard errors, the regret
    against the methods' best plan only, early (step <= 4) and late means, mean Spearman
    correlations (random plans; NaN where the method's cost is constant, counted)."""
    rows = []
    for (model, method), g in df.groupby(["model", "method"], sort=False):
        rel = g["regret_rel"].to_numpy(float)
        lo, hi = _boot_mean(rel, seed, n_boot, model=model, method=method)
        rows.append({"model": model, "method": method, **_regret_row(g, lo, hi)})
    return pd.DataFrame(rows, columns=UAV_SUMMARY_COLUMNS)


class PairedRegret(NamedTuple):
    """Mean over belief states of the baseline's relative regret − a method's, its 95%
    bootstrap CI and the number of states."""

    mean: float
    low: float
    high: float
    n: int


def paired_regret(
    df: pd.DataFrame, model: str, method: str, seed: int, n_boot: int
) -> PairedRegret:
    """regret_rel(baseline) − regret_rel(``method``) per belief state of ``model``: mean and
    bootstrap CI (stream keyed on model, ``a`` = method, ``b`` = baseline)."""
    base = baseline_name()
    g = df[df["model"] == model].pivot_table(
        index=["run", "step"], columns="method", values="regret_rel"
    )
    d = (g[base] - g[method]).to_numpy(float)
    lo, hi = _boot_mean(d, seed, n_boot, model=model, a=method, b=base, statistic="paired_regret")
    return PairedRegret(float(d.mean()), lo, hi, int(d.size))


def largest_rsmhp(summary: pd.DataFrame) -> str | None:
    """RS-MHP (:class:`MonteCarlo`) with the largest N_T in ``summary``, if any was run."""
    rs = summary.loc[is_family(summary["method"], MonteCarlo)]
    return str(rs.sort_values("N_T")["method"].iloc[-1]) if not rs.empty else None


def base_model(models: Sequence[str]) -> str | None:
    """The reconstruction's model: ``paper`` if present, else the first."""
    return "paper" if "paper" in models else (models[0] if models else None)


def optimiser_share(regret: pd.DataFrame, model: str) -> float:
    """Mean relative regret of the best method's plan against the best plan found (the same
    for every method at a state): regret_rel − regret_methods / best_cost."""
    g = regret[regret["model"] == model]
    share = g["regret_rel"] - g["regret_methods"] / g["best_cost"]
    return float(share.groupby([g["run"], g["step"]]).first().mean())


# ---------------------------------------------------------------------------- sensitivity map


def paired_errors(runs: pd.DataFrame, cell: str, method: str) -> pd.Series:
    """d_r = mean_error(method) − mean_error(baseline) per run of ``cell`` (runs both have)."""
    base = baseline_name()
    g = runs[runs["cell"] == cell]
    wide = g.pivot(index="run", columns="method", values="mean_error")
    pair = wide[[method, base]].dropna()
    return pair[method] - pair[base]


def _map_row(
    g: pd.DataFrame, reg: pd.DataFrame, method: str, d: np.ndarray, ci: tuple[float, float]
) -> dict[str, Any]:
    """Rates and regrets of ``method`` and the baseline in one cell, and the paired ``d``."""
    base = baseline_name()
    by = {m: g[g["method"] == m] for m in (method, base)}
    return {
        "comparison": f"{method} − {base}",
        "n_runs": int(d.size),
        "mean_diff": float(d.mean()),
        "ci_low": ci[0],
        "ci_high": ci[1],
        "p_value": float(sps.wilcoxon(d).pvalue) if np.any(d != 0) else float("nan"),
        "loss_nbo": float(by[base]["lost"].mean()),
        "loss_method": float(by[method]["lost"].mean()),
        "detect_nbo": float(by[base]["detect_rate"].mean()),
        "detect_method": float(by[method]["detect_rate"].mean()),
        "regret_nbo": float(reg.loc[reg["method"] == base, "regret_rel"].mean()),
        "regret_method": float(reg.loc[reg["method"] == method, "regret_rel"].mean()),
    }


def summarize_map(
    runs: pd.DataFrame, regret: pd.DataFrame, cfg: Mapping[str, Any], seed: int, n_boot: int
) -> pd.DataFrame:
    """One row per (cell, method other than the baseline; registry order): paired closed-loop
    difference of the average location error to the baseline with a bootstrap CI and the
    Wilcoxon signed-rank p-value (NaN where every difference is 0), track-loss rates,
    detection rates, mean open-loop relative regret."""
    rows = []
    base = baseline_name()
    for cell, g in runs.groupby("cell", sort=False):
        others = registry.sort_names(m for m in g["method"].unique() if m != base)
        reg = regret[regret["model"] == cell]
        for method in others:
            d = paired_errors(g, cell, method).to_numpy(float)
            ci = _boot_mean(d, seed, n_boot, cell=cell, method=method)
            where = {
                "cell": cell,
                "row_key": cfg["rows"]["key"],
                "row_value": g["row_value"].iloc[0],
                "col_key": cfg["cols"]["key"],
                "col_value": g["col_value"].iloc[0],
            }
            rows.append({**where, **_map_row(g, reg, method, d, ci)})
    return pd.DataFrame(rows, columns=MAP_COLUMNS)


def limited_cells(map_df: pd.DataFrame, base_limited: bool = False) -> pd.Series:
    """Whether each map row's cell has a finite footprint: the axis value where an axis is
    ``sensor.footprint_radius`` (``null`` = unlimited), else the base config's sensor."""
    out = pd.Series(bool(base_limited), index=map_df.index)
    for key, val in (("row_key", "row_value"), ("col_key", "col_value")):
        on_axis = map_df[key] == "sensor.footprint_radius"
        out = out.where(~on_axis, map_df[val].notna())
    return out


def _group_row(
    grp: pd.DataFrame, dbar: np.ndarray, ci: tuple[float, float]
) -> dict[str, float | int]:
    """A group's pooled ``dbar`` (per run) and its cells' counts, ranges and mean rates."""
    return {
        "n_cells": len(grp),
        "n_runs": int(dbar.size),
        "mean_diff": float(dbar.mean()) if dbar.size else float("nan"),
        "ci_low": ci[0],
        "ci_high": ci[1],
        "n_below": int((grp["ci_high"] < 0).sum()),
        "n_above": int((grp["ci_low"] > 0).sum()),
        "cell_min": float(grp["mean_diff"].min()),
        "cell_max": float(grp["mean_diff"].max()),
        "loss_nbo": float(grp["loss_nbo"].mean()),
        "loss_method": float(grp["loss_method"].mean()),
        "regret_nbo": float(grp["regret_nbo"].mean()),
        "regret_method": float(grp["regret_method"].mean()),
    }


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
    limited = limited_cells(map_df, base_limited)
    for comp in dict.fromkeys(map_df["comparison"]):
        method = comp.split(" ")[0]
        for flag in (True, False):
            grp = map_df[(map_df["comparison"] == comp) & (limited == flag)]
            if grp.empty:
                continue
            d = pd.concat({c: paired_errors(runs, c, method) for c in grp["cell"]}, axis=1)
            dbar = d.dropna().mean(axis=1).to_numpy(float)
            ci = _boot_mean(dbar, seed, n_boot, statistic="map_group", limited=flag, method=method)
            rows.append({"limited": flag, "comparison": comp, **_group_row(grp, dbar, ci)})
    return pd.DataFrame(rows, columns=MAP_GROUP_COLUMNS)
