r"""Which planning method gives the lowest closed-loop location error, cell by cell, and how
sure that answer is.

A *cell* is one set of paired closed-loop runs of several methods: method :math:`m`'s run
:math:`r` faces the same scenario draw (target path, sensor noise) as every other method's run
:math:`r` (the studies share seeds across methods), and :math:`e_{m,r}` is that run's mean
target location error (m). The cells come in three groups, each a grid of rows × columns
(:func:`best_runs`):

* ``budget``: the confirmatory equal-compute run (frontier study, confirm stream), per model
  variant and planning budget b (ms per step) the tuned member of every family at b
  (``config/tuned.yaml``; the preregistration's budgets) and NBO, the untuned baseline (one
  nominal trajectory per step, cheaper than every budget), at every b;
* ``horizon``: the long-horizon closed loop (horizon study, confirm stream), per model variant
  and planning horizon H, every method;
* ``scenario``: the sensitivity map (decision study, H = 6), per cell (footprint radius ×
  target manoeuvrability q), every method.

In each cell of :math:`n` runs (:func:`best_family`):

* the best method :math:`b = \arg\min_m \bar e_m`, :math:`\bar e_m = \frac1n\sum_r e_{m,r}`
  (equal means: the first in the cell's order);
* for every other method :math:`m` the paired differences :math:`d_r = e_{m,r} - e_{b,r}` and
  the 95% Student-t interval :math:`\bar d \pm t_{n-1,\,0.975}\, s_d/\sqrt n` (:math:`s_d`
  the sample SD of the :math:`d_r`, :func:`rsmhp.core.stats.mean_ci`). Since :math:`b` has
  the lowest mean, :math:`\bar d = \bar e_m - \bar e_b \ge 0`;
* :math:`m` is *tied* with the best when its interval does not lie entirely above 0 (its
  lower limit is at most 0: the data do not exclude that :math:`m` is as good or better);
* the best is *clear* when no method is tied (every interval lies above 0);
* the runner-up is the method with the next lowest mean (the smallest :math:`\bar d`).

Each interval is a per-comparison 95% interval (no multiplicity correction across the cell's
methods or across cells): "clear" is a descriptive flag, not a claim.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.core.stats import mean_ci
from rsmhp.models.uav import methods
from rsmhp.pipeline.protocol import tuned_configurations
from rsmhp.report.naming import depth_name

__all__ = [
    "BEST_COLUMNS",
    "BEST_RUN_COLUMNS",
    "BUDGET",
    "GROUPS",
    "HORIZON",
    "PAIRED_COLUMNS",
    "REQUIRED",
    "SCENARIO",
    "Best",
    "best_family",
    "best_runs",
    "budget_runs",
    "footprint_label",
    "horizon_runs",
    "rollout_of",
    "scenario_runs",
    "short_label",
]

BUDGET = "budget"
HORIZON = "horizon"
SCENARIO = "scenario"
#: the groups, in the order of the figure and the tables: group -> (what its rows are, what
#: its columns are)
GROUPS: dict[str, tuple[str, str]] = {
    BUDGET: ("model variant", "planning budget (ms per step)"),
    HORIZON: ("model variant", "planning horizon H (steps)"),
    SCENARIO: ("sensor footprint", "target manoeuvrability q (m²/s³)"),
}

#: the long per-run table :func:`best_family` reads: the cell is (``group``, ``model``,
#: ``value``): ``model`` the grid's row (model variant; footprint in the ``scenario`` group),
#: ``value`` its column (budget in ms, H or q); ``method`` is unique in its cell (a
#: configuration name in the ``budget`` group), ``member`` the registered method behind it (its
#: label and colour), ``family`` its family, ``plan_depth`` a tree search's mean plan depth
#: over the run's steps (empty for the other methods, and optional)
BEST_RUN_COLUMNS = [
    "group", "model", "value", "method", "member", "family", "run", "error", "plan_depth",
]  # fmt: skip
#: the columns :func:`best_family` cannot do without (``member`` defaults to ``method``,
#: ``family`` to ``method``)
REQUIRED = ["group", "model", "value", "method", "run", "error"]
#: one row per cell (:func:`best_family`); ``tied`` the tied methods joined by ``;``
BEST_COLUMNS = [
    "group", "model", "value", "runs", "methods", "best", "best_member", "best_label",
    "best_family", "best_depth", "best_mean", "runner_up", "runner_up_member", "runner_up_mean",
    "runner_up_diff",
    "runner_up_low", "runner_up_high", "tied", "n_tied", "clear",
]  # fmt: skip
#: one row per (cell, method other than the best): the paired difference method − best
PAIRED_COLUMNS = [
    "group", "model", "value", "best", "method", "member", "family", "mean", "mean_diff",
    "low", "high", "tied",
]  # fmt: skip

_CELL = ["group", "model", "value"]


@dataclass(frozen=True)
class Best:
    """What :func:`best_family` returns: ``cells`` (:data:`BEST_COLUMNS`, one row per cell)
    and ``paired`` (:data:`PAIRED_COLUMNS`, every other method of every cell)."""

    cells: pd.DataFrame
    paired: pd.DataFrame


def _cell_name(key: tuple) -> str:
    group, model, value = key
    return f"cell ({str(group)!r}, {str(model)!r}, value {float(value):g})"


def _check(runs: pd.DataFrame) -> pd.DataFrame:
    """``runs`` with ``member`` and ``family`` filled in, or ``ValueError`` naming what is
    missing or wrong."""
    missing = [c for c in REQUIRED if c not in runs.columns]
    if missing:
        raise ValueError(
            f"best_family: missing column(s) {missing} (required: {REQUIRED}); "
            f"found {list(runs.columns)}"
        )
    r = runs.copy()
    for col in ("member", "family"):
        if col not in r.columns:
            r[col] = r["method"]
    if "plan_depth" not in r.columns:
        r["plan_depth"] = np.nan
    r["plan_depth"] = pd.to_numeric(r["plan_depth"], errors="coerce").astype(float)
    for col in ("group", "model", "value", "method", "run"):
        n = int(r[col].isna().sum())
        if n:
            raise ValueError(f"best_family: column {col!r} has {n} missing value(s)")
    value = pd.to_numeric(r["value"], errors="coerce")
    if value.isna().any():
        bad = r.loc[value.isna(), "value"].iloc[0]
        raise ValueError(f"best_family: column 'value' must be numeric, got {bad!r}")
    r["value"] = value.astype(float)
    error = pd.to_numeric(r["error"], errors="coerce").astype(float)
    bad = ~np.isfinite(error.to_numpy())
    if bad.any():
        row = r[bad].iloc[0]
        raise ValueError(
            f"best_family: column 'error' is not a finite number at run {row['run']} of "
            f"{row['method']!r} in {_cell_name((row['group'], row['model'], row['value']))}: "
            f"{row['error']!r}"
        )
    r["error"] = error
    dup = r.duplicated([*_CELL, "method", "run"])
    if dup.any():
        row = r[dup].iloc[0]
        raise ValueError(
            f"best_family: run {row['run']} of {row['method']!r} appears twice in "
            f"{_cell_name((row['group'], row['model'], row['value']))}"
        )
    return r


def _paired(key: tuple, cell: pd.DataFrame) -> pd.DataFrame:
    """The cell's runs × methods table of errors (methods in order of appearance), or
    ``ValueError`` if its runs do not pair or are too few."""
    wide = cell.pivot(index="run", columns="method", values="error")
    wide = wide[list(dict.fromkeys(cell["method"]))].sort_index()
    holes = wide.isna()
    if holes.any().any():
        method = holes.any().idxmax()
        lacking = wide.index[holes[method]].tolist()
        raise ValueError(
            f"best_family: {_cell_name(key)}: runs {lacking} of {method!r} are missing but "
            f"other methods have them; runs pair by run index, so every method needs the "
            f"same runs"
        )
    if wide.shape[1] < 2:
        raise ValueError(
            f"best_family: {_cell_name(key)} has {wide.shape[1]} method "
            f"({', '.join(wide.columns)}); a best needs at least 2"
        )
    if wide.shape[0] < 2:
        raise ValueError(
            f"best_family: {_cell_name(key)} has {wide.shape[0]} run; a paired t interval "
            f"needs at least 2"
        )
    return wide


def best_family(runs: pd.DataFrame, level: float = 0.95) -> Best:
    """Per cell (``group``, ``model``, ``value``) of the long table ``runs``
    (:data:`BEST_RUN_COLUMNS`; :data:`REQUIRED` at least) the best method, its mean error,
    the paired difference of every other method from it with its ``level`` Student-t
    interval, the tied methods and whether the best is clear (module docstring). Cells keep
    their order of appearance. An empty table gives empty tables.

    Raises ``ValueError`` naming the column, cell, method or run when a column is missing,
    a key is missing, an error is not finite, a run appears twice, the runs do not pair (a
    method lacks a run another has), or a cell has fewer than 2 runs or 2 methods."""
    r = _check(runs)
    cells, paired = [], []
    for key, cell in r.groupby(_CELL, sort=False):
        wide = _paired(key, cell)
        first = cell.drop_duplicates("method").set_index("method")
        means = wide.mean(axis=0)
        order = sorted(range(len(means)), key=lambda k: (means.iloc[k], k))
        ranked = [means.index[k] for k in order]
        best = ranked[0]
        group, model, value = key
        tied, rows = [], []
        for m in ranked[1:]:
            d, low, high = mean_ci((wide[m] - wide[best]).to_numpy(float), level)
            is_tied = bool(low <= 0.0)
            if is_tied:
                tied.append(m)
            rows.append({"group": group, "model": model, "value": value, "best": best,
                           "method": m, "member": first.loc[m, "member"],
                           "family": first.loc[m, "family"], "mean": float(means[m]),
                           "mean_diff": d, "low": low, "high": high, "tied": is_tied})  # fmt: skip
        paired.extend(rows)
        second = rows[0]  # the runner-up: the next lowest mean
        member = first.loc[best, "member"]
        # a tree search's mean plan depth (the pursuit policy alone reports 0: no tree)
        depths = cell.loc[cell["method"] == best, "plan_depth"]
        is_tree = first.loc[best, "family"] == "dpw"
        depth = float(depths.mean()) if is_tree and depths.notna().all() else np.nan
        cells.append({
            "group": group, "model": model, "value": value, "runs": int(wide.shape[0]),
            "methods": int(wide.shape[1]), "best": best,
            "best_member": first.loc[best, "member"],
            "best_label": depth_name(short_label(member), depth, rollout_of(member), short=True),
            "best_family": first.loc[best, "family"], "best_depth": depth,
            "best_mean": float(means[best]), "runner_up": second["method"],
            "runner_up_member": second["member"], "runner_up_mean": second["mean"],
            "runner_up_diff": second["mean_diff"], "runner_up_low": second["low"],
            "runner_up_high": second["high"],
            "tied": ";".join(tied), "n_tied": len(tied), "clear": not tied,
        })  # fmt: skip
    return Best(pd.DataFrame(cells, columns=BEST_COLUMNS),
                pd.DataFrame(paired, columns=PAIRED_COLUMNS))  # fmt: skip


def rollout_of(member: str) -> str:
    """The rollout policy of a tree-search member (``pursuit`` for any other method: only a
    tree search has a measured plan depth to name it by)."""
    try:
        return str(getattr(methods.from_name(str(member)), "rollout", "pursuit"))
    except ValueError:
        return "pursuit"


def short_label(member: str) -> str:
    """A method's label short enough for a cell: its registry label (``RS-MHP N_T=256``,
    ``pruned tree N=4 M=256``, ``tree search 100 sims (k_a=2, ...)``) without ``N_T=``, the
    word ``sims`` and any parenthesis, a pruned tree as ``pruned 4×256``; the name itself if
    no family knows it."""
    try:
        text = methods.from_name(str(member)).label()
    except ValueError:
        return str(member)
    text = re.sub(r"\s*\(.*\)\s*$", "", text).replace("N_T=", "").replace(" sims", "")
    return re.sub(r"pruned tree N=(\d+) M=(\d+)", r"pruned \1×\2", text)


# ------------------------------------------------------------------ the three groups' runs


def _family(member: str) -> str:
    return methods.from_name(member).family


def _long(group: str, model, value, method, member, run, error, depth=None) -> pd.DataFrame:
    member = pd.Series(member, dtype=object).reset_index(drop=True)
    n = len(member)
    depth = np.full(n, np.nan) if depth is None else pd.Series(depth, dtype=float).to_numpy()
    return pd.DataFrame({
        "group": group, "model": pd.Series(model, dtype=object).reset_index(drop=True),
        "value": pd.Series(value, dtype=float).reset_index(drop=True),
        "method": pd.Series(method, dtype=object).reset_index(drop=True), "member": member,
        "family": member.map(_family),
        "run": pd.Series(run).astype(int).reset_index(drop=True),
        "error": pd.Series(error, dtype=float).reset_index(drop=True), "plan_depth": depth,
    }, columns=BEST_RUN_COLUMNS)  # fmt: skip


def _sorted(out: pd.DataFrame) -> pd.DataFrame:
    """Rows in model order of first appearance, then by value (stable)."""
    rank = {m: k for k, m in enumerate(dict.fromkeys(out["model"]))}
    return (
        out.sort_values(["value"], kind="stable")
        .sort_values("model", key=lambda s: s.map(rank), kind="stable")
        .reset_index(drop=True)
    )


def budget_runs(
    confirm: pd.DataFrame,
    tuned: Mapping[str, Any],
    budgets_ms: Sequence[float],
    baseline: str | None = None,
) -> pd.DataFrame:
    """The ``budget`` group (:data:`BEST_RUN_COLUMNS`) of the confirmatory runs ``confirm``
    (columns ``model``, ``config``, ``member``, ``run``, ``mean_error``;
    :data:`rsmhp.studies.frontier.simulate.CONFIG_RUN_COLUMNS`): per model and budget b of
    ``budgets_ms`` the runs of every family's tuned configuration at b (the tuned document
    ``tuned``, :func:`rsmhp.pipeline.protocol.tuned_configurations`) and of the ``baseline``
    configuration (default: the registry's baseline, NBO) at every b. A configuration the
    tuned file names but ``confirm`` lacks is refused, naming it."""
    base = methods.baseline_name() if baseline is None else baseline
    parts = []
    for model in dict.fromkeys(confirm["model"]):
        g = confirm[confirm["model"] == model]
        chosen = tuned_configurations(tuned, str(model))
        have = set(g["config"])
        for b in budgets_ms:
            names = [base, *(c.name for c in chosen.get(f"{float(b):g}", {}).values())]
            for name in dict.fromkeys(names):
                if name not in have:
                    raise ValueError(
                        f"budget_runs: configuration {name!r} (model {model!r}, budget "
                        f"{float(b):g} ms) has no confirmatory runs (found: {sorted(have)})"
                    )
                c = g[g["config"] == name]
                parts.append(_long(BUDGET, c["model"], np.full(len(c), float(b)), c["config"],
                                   c["member"], c["run"], c["mean_error"],
                                   c.get("plan_depth")))  # fmt: skip
    return _sorted(pd.concat(parts, ignore_index=True)) if parts else _empty()


def horizon_runs(closed: pd.DataFrame) -> pd.DataFrame:
    """The ``horizon`` group (:data:`BEST_RUN_COLUMNS`) of the long-horizon closed loop
    (columns ``model``, ``H``, ``method``, ``run``, ``mean_error``): one cell per (model, H)."""
    c = closed
    out = _long(HORIZON, c["model"], c["H"], c["method"], c["method"], c["run"], c["mean_error"],
                c.get("plan_depth"))  # fmt: skip
    return _sorted(out)


def footprint_label(radius: Any) -> str:
    """A sensor footprint radius as a row label: ``no footprint`` (NaN) or ``footprint 300 m``."""
    return "no footprint" if pd.isna(radius) else f"footprint {float(radius):g} m"


def scenario_runs(map_runs: pd.DataFrame) -> pd.DataFrame:
    """The ``scenario`` group (:data:`BEST_RUN_COLUMNS`) of the sensitivity map's runs
    (columns ``row_value``: the footprint radius, NaN for none; ``col_value``: the target's
    q; ``method``, ``run``, ``mean_error``): one cell per (radius, q), rows in the map's
    order."""
    m = map_runs
    rows = [footprint_label(v) for v in m["row_value"]]
    out = _long(SCENARIO, rows, m["col_value"], m["method"], m["method"], m["run"],
                m["mean_error"], m.get("plan_depth"))  # fmt: skip
    return _sorted(out)


def _empty() -> pd.DataFrame:
    return pd.DataFrame(columns=BEST_RUN_COLUMNS)


def best_runs(
    confirm: pd.DataFrame | None = None,
    tuned: Mapping[str, Any] | None = None,
    budgets_ms: Sequence[float] = (),
    closed: pd.DataFrame | None = None,
    map_runs: pd.DataFrame | None = None,
) -> pd.DataFrame:
    """The long table of all three groups (:func:`budget_runs`, :func:`horizon_runs`,
    :func:`scenario_runs`), in the order of :data:`GROUPS`; a group whose input is ``None``
    or empty (a study that is not configured, e.g. no preregistration) is left out."""
    parts = []
    if confirm is not None and len(confirm):
        if tuned is None:
            raise ValueError("best_runs: confirmatory runs need the tuned document 'tuned'")
        parts.append(budget_runs(confirm, tuned, budgets_ms))
    if closed is not None and len(closed):
        parts.append(horizon_runs(closed))
    if map_runs is not None and len(map_runs):
        parts.append(scenario_runs(map_runs))
    parts = [p for p in parts if len(p)]
    return pd.concat(parts, ignore_index=True) if parts else _empty()
