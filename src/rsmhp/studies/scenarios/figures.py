"""Figures of the scenarios study.

* ``scenarios_best`` (:func:`best_figure`, :mod:`rsmhp.studies.scenarios.best`): per group (planning
  budget, horizon, map scenario) a grid of cells, each coloured by the family of the method with
  the lowest closed-loop mean error there and labelled with its short name; solid when the best
  is clear (every other method's paired 95% t interval lies above 0), faded and hatched with the
  number of tied methods when it is not.
* ``scenarios_improvement`` (:func:`improvement_figure`,
  :mod:`rsmhp.studies.scenarios.summarise`): per method, the probability of beating NBO run by
  run, one marker per group of scenarios, with its 95% stratified bootstrap interval; the dashed
  line is 1/2 (no difference)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.colors import to_rgb
from matplotlib.patches import Patch, Rectangle

from rsmhp.models.uav import methods
from rsmhp.report.figures import theme
from rsmhp.report.palette import METHOD_COLOURS, member_colour, method_label
from rsmhp.studies.scenarios import FIGURES
from rsmhp.studies.scenarios.best import BUDGET, GROUPS, HORIZON, SCENARIO, short_label

__all__ = ["FIGURES", "best_figure", "family_colour", "improvement_figure", "short_label"]


_MARKERS = ("o", "s", "D", "^")


def improvement_figure(summary: pd.DataFrame) -> plt.Figure:
    """One row per method (ordered by its probability over all its scenarios), x the
    probability, a marker per group; :data:`rsmhp.studies.scenarios.summarise.SUMMARY_COLUMNS`."""
    if summary.empty:
        raise ValueError("improvement summary is empty")
    theme()
    groups = list(dict.fromkeys(summary["group"]))
    order = (
        summary.sort_values("scenarios").groupby("method", sort=False)["p_improve"].last()
        .sort_values().index.tolist()
    )  # fmt: skip
    fig, ax = plt.subplots(figsize=(6.4, 0.5 * len(order) + 1.4))
    ax.axvline(0.5, color="0.4", ls="--", lw=1.0)
    step = 0.6 / max(1, len(groups))
    for k, group in enumerate(groups):
        g = summary[summary["group"] == group].set_index("method")
        ms = [m for m in order if m in g.index]
        y = np.array([order.index(m) for m in ms]) + (k - (len(groups) - 1) / 2) * step
        p = g.loc[ms, "p_improve"].to_numpy(float)
        err = np.vstack([p - g.loc[ms, "low"].to_numpy(float),
                         g.loc[ms, "high"].to_numpy(float) - p])  # fmt: skip
        ax.errorbar(p, y, xerr=err, fmt=_MARKERS[k % len(_MARKERS)], color="0.25", ms=5,
                    capsize=2, lw=1.0, label=group, mfc="white" if k % 2 else "0.25")  # fmt: skip
    ax.set_yticks(range(len(order)), [method_label(m) for m in order])
    ax.set_xlabel("P(run beats NBO's paired run)")
    ax.legend(fontsize="small", loc="lower right")
    fig.tight_layout()
    return fig


# ------------------------------------------------------------------ the best family per cell

#: panel titles of the groups of :data:`rsmhp.studies.scenarios.best.GROUPS`
_TITLES = {
    BUDGET: "Equal compute: each family's tuned member and NBO per budget (confirmatory run)",
    HORIZON: "Long horizons: every method per planning horizon H",
    SCENARIO: "Scenarios: every method per sensitivity-map cell (H = 6)",
}
#: how much a tied cell's colour is mixed with white
_FADE = 0.6


def family_colour(family: str, member: str | None = None) -> str:
    """The palette colour of a registered ``family`` (its ``colour_key``, unshaded: every
    member of a family gets the same colour); else the colour of ``member``
    (:func:`rsmhp.report.palette.member_colour`), else grey."""
    fams = {c.family: c for c in methods.families()}
    if family in fams:
        key = fams[family].colour_key
        return key if str(key).startswith("#") else METHOD_COLOURS[key]
    try:
        return member_colour(methods.from_name(str(member)))
    except (ValueError, TypeError):
        return "#949494"


def _family_label(family: str) -> str:
    fams = {c.family: c for c in methods.families()}
    return fams[family].family_label if family in fams else str(family)


def _family_order(family: str) -> tuple[int, str]:
    fams = {c.family: c for c in methods.families()}
    return (fams[family].order if family in fams else 99, str(family))


def _fade(colour: str, mix: float = _FADE) -> tuple[float, float, float]:
    r, g, b = to_rgb(colour)
    return (r + mix * (1 - r), g + mix * (1 - g), b + mix * (1 - b))


def _ink(face) -> str:
    """Black or white text, whichever reads better on ``face`` (relative luminance)."""
    r, g, b = to_rgb(face)
    return "0.05" if 0.2126 * r + 0.7152 * g + 0.0722 * b > 0.45 else "white"


def _axis_text(group: str, value: float) -> str:
    if group == BUDGET:
        return f"{value:g} ms"
    if group == HORIZON:
        return f"H = {value:g}"
    if group == SCENARIO:
        return f"q = {value:g}"
    return f"{value:g}"


def _cell(ax: plt.Axes, x: int, y: int, r) -> None:
    """Cell (x, y) of a panel for the row ``r`` of the best-family table."""
    colour = family_colour(r.best_family, r.best_member)
    clear = bool(r.clear)
    face = colour if clear else _fade(colour)
    ax.add_patch(Rectangle((x, y), 1, 1, facecolor=face, lw=0))
    if not clear:
        ax.add_patch(Rectangle((x, y), 1, 1, facecolor="none", edgecolor=colour, hatch="////",
                               lw=0))  # fmt: skip
    ax.add_patch(Rectangle((x, y), 1, 1, facecolor="none", edgecolor="white", lw=2.5))
    label = short_label(r.best_member)
    # on a tied cell the text sits on a white box above the hatching
    box = None if clear else {"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none",
                              "alpha": 0.85}  # fmt: skip
    ink = _ink(face) if clear else "0.1"
    ax.text(x + 0.5, y + 0.4, label, ha="center", va="center",
            fontsize=7.5 if len(label) <= 12 else 6.5, color=ink,
            fontweight="bold" if clear else "normal", bbox=box)  # fmt: skip
    note = "clear" if clear else f"tied with {int(r.n_tied)}"
    ax.text(x + 0.5, y + 0.76, note, ha="center", va="center", fontsize=6.5, color=ink, bbox=box)


def _panel(ax: plt.Axes, group: str, cells: pd.DataFrame) -> None:
    models = list(dict.fromkeys(cells["model"]))
    values = sorted(set(cells["value"].astype(float)))
    at = {(r.model, float(r.value)): r for r in cells.itertuples(index=False)}
    for i, model in enumerate(models):
        for j, value in enumerate(values):
            r = at.get((model, value))
            if r is None:
                ax.add_patch(Rectangle((j, i), 1, 1, facecolor="0.93", edgecolor="white", lw=2))
                ax.text(j + 0.5, i + 0.5, "not run", ha="center", va="center", fontsize=7,
                        color="0.45")  # fmt: skip
                continue
            _cell(ax, j, i, r)
    ax.set_xlim(0, len(values))
    ax.set_ylim(len(models), 0)
    ax.set_xticks(np.arange(len(values)) + 0.5, [_axis_text(group, v) for v in values])
    runs = {m: sorted(set(cells.loc[cells["model"] == m, "runs"].astype(int))) for m in models}
    ax.set_yticks(np.arange(len(models)) + 0.5,
                  [f"{m}\n{'/'.join(map(str, runs[m]))} runs" for m in models])  # fmt: skip
    ax.tick_params(length=0, labelsize=8)
    ax.grid(False)
    for side in ax.spines.values():
        side.set_visible(False)
    ax.set_title(_TITLES.get(group, group), fontsize=8.5, loc="left")


def best_figure(best: pd.DataFrame) -> plt.Figure:
    """One panel per group of ``best`` (:data:`rsmhp.studies.scenarios.best.BEST_COLUMNS`,
    groups in the order of :data:`rsmhp.studies.scenarios.best.GROUPS`, absent groups left
    out): rows (model variant or footprint) × columns (budget, H or q), each cell in the
    colour of its best method's family with the method's short name (:func:`short_label`);
    solid with the name in bold when the best is clear, faded and hatched with the number of
    methods tied with it otherwise. A legend names the families and the two fills."""
    if best.empty:
        raise ValueError("best-family table is empty")
    theme()
    groups = [g for g in GROUPS if g in set(best["group"])]
    groups += [g for g in dict.fromkeys(best["group"]) if g not in groups]
    rows = [best.loc[best["group"] == g, "model"].nunique() for g in groups]
    fig, axes = plt.subplots(
        len(groups), 1, figsize=(7.2, height := 0.5 * sum(rows) + 0.75 * len(groups) + 0.7),
        gridspec_kw={"height_ratios": [r + 1.3 for r in rows]}, squeeze=False,
    )  # fmt: skip
    for ax, group in zip(axes[:, 0], groups, strict=True):
        _panel(ax, group, best[best["group"] == group])
        ax.set_xlabel(GROUPS.get(group, ("", ""))[1], fontsize=8, labelpad=2)
    fams = sorted(dict.fromkeys(best["best_family"]), key=_family_order)
    member = dict(zip(best["best_family"], best["best_member"], strict=True))
    handles = [Patch(facecolor=family_colour(f, member[f]), label=_family_label(f)) for f in fams]
    grey = "#808080"
    handles += [
        Patch(facecolor=grey, label="clear: every other method's paired 95% CI above 0"),
        Patch(facecolor=_fade(grey), edgecolor=grey, hatch="////", lw=0,
              label="tied: other methods' CIs reach 0 (count written)"),
    ]  # fmt: skip
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=7, frameon=False,
               bbox_to_anchor=(0.5, 0.0), handlelength=1.6, columnspacing=1.2)  # fmt: skip
    fig.tight_layout(rect=(0, 0.45 / height, 1, 1), h_pad=1.2)  # 0.45 in for the legend
    return fig
