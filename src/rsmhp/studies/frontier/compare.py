r"""A new planner against the published reference, paired run by run, without rerunning the
reference (``make compare PLUGIN_METHODS=...``).

The new methods run on the confirmatory design's scenarios (same models, runs, seed stream;
:mod:`rsmhp.studies.frontier.reference` refuses any other). For every new method, model and
reference configuration (NBO, and each family's tuned member at each budget of the ladder)
the paired difference over the runs r = 1..n

.. math:: d_r = e_r(\text{new}) - e_r(\text{reference}),

with :math:`e_r` the closed-loop mean target location error (m) of run r, has the 95%
Student-t interval :math:`\bar d \pm t_{n-1,0.975}\, s_d/\sqrt n` and a verdict by the
preregistered margin Δ of the FR claims (:func:`compare_rule`): **equivalent** if the CI lies
inside ±Δ, **better** if it lies below 0, **worse** if above 0, **inconclusive** otherwise.
These are descriptive comparisons of a planner that was not preregistered: no Holm
correction, no claim of the report.

Budgets: the reference's members were tuned to wall-clock budgets on the reference machine;
the new method's planning time per step is measured here (``plan_ms``, mean over its runs),
so "within the budget" compares times of two machines and is printed as such.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.ticker import NullFormatter, ScalarFormatter

from rsmhp.core.stats import mean_ci
from rsmhp.report.markdown import fmt, fmt_ci, markdown_table
from rsmhp.report.verdicts import Rule, ci_side

__all__ = ["COMPARE_COLUMNS", "VERDICT_WORDS", "compare_figure", "compare_markdown",
           "compare_rule", "paired_comparison"]  # fmt: skip

#: one row per (model, new method, reference configuration at a budget)
COMPARE_COLUMNS = [
    "model", "method", "budget_ms", "family", "config", "runs", "new_mean", "ref_mean",
    "new_ms", "ref_ms", "mean_diff", "low", "high", "verdict",
]  # fmt: skip
#: the rule's verdicts in the comparison's words
VERDICT_WORDS = {
    "supported": "better",
    "not supported": "worse",
    "equivalent": "equivalent",
    "inconclusive": "inconclusive",
}


def compare_rule(margin_m: float) -> Rule:
    """d = e(new) − e(reference) per run (m), 95% t CI: equivalent inside ±Δ, better
    (``supported``) below 0, worse (``not supported``) above 0, inconclusive otherwise."""
    return ci_side(
        "d",
        0.0,
        claimed="below",
        margin=margin_m,
        margin_text=f"{margin_m:g} m",
        basis="d = closed-loop mean location error of the new method − the reference "
        "configuration's, paired over runs (m; 95% t interval)",
    )


def _paired(new: pd.DataFrame, ref: pd.DataFrame, what: str) -> pd.DataFrame:
    a = new.set_index("run")["mean_error"]
    b = ref.set_index("run")["mean_error"]
    if set(a.index) != set(b.index):
        only_new = sorted(set(a.index) - set(b.index))[:5]
        only_ref = sorted(set(b.index) - set(a.index))[:5]
        raise ValueError(
            f"{what}: the runs do not pair (only the new method has runs {only_new}, only the "
            f"reference {only_ref}): run the new method on the reference's runs"
        )
    return pd.DataFrame({"new": a, "ref": b.loc[a.index]})


def paired_comparison(
    new: pd.DataFrame,
    reference: pd.DataFrame,
    ladder: Sequence[Mapping[str, Any]],
    margin_m: float,
    baseline: str = "nbo",
    level: float = 0.95,
) -> pd.DataFrame:
    """:data:`COMPARE_COLUMNS` for every new configuration in ``new`` (the confirmatory
    run's columns: model, config, run, mean_error, plan_ms) against ``baseline`` and every
    ladder entry (model, budget_ms, family, config) of its model in ``reference``."""
    rule = compare_rule(margin_m)
    lad = pd.DataFrame(list(ladder), columns=["model", "budget_ms", "family", "config"])
    rows = []
    for (model, method), n in new.groupby(["model", "config"], sort=False):
        targets = [(np.nan, "nbo", baseline)] + [
            (r.budget_ms, r.family, r.config)
            for r in lad[lad["model"] == model].sort_values(["budget_ms", "family"]).itertuples()
        ]
        for budget, family, config in targets:
            ref = reference[(reference["model"] == model) & (reference["config"] == config)]
            if ref.empty:
                raise ValueError(f"reference: no runs of {config!r} on {model!r}")
            p = _paired(n, ref, f"{method} vs {config} on {model}")
            d, low, high = mean_ci((p["new"] - p["ref"]).to_numpy(float), level)
            verdict = rule.verdict({"d_low": low, "d_high": high})
            rows.append({
                "model": model, "method": method, "budget_ms": budget, "family": family,
                "config": config, "runs": len(p), "new_mean": float(p["new"].mean()),
                "ref_mean": float(p["ref"].mean()), "new_ms": float(n["plan_ms"].mean()),
                "ref_ms": float(ref["plan_ms"].mean()), "mean_diff": d, "low": low,
                "high": high, "verdict": VERDICT_WORDS[verdict],
            })  # fmt: skip
    return pd.DataFrame(rows, columns=COMPARE_COLUMNS)


def compare_markdown(
    table: pd.DataFrame,
    meta: Mapping[str, Any],
    margin_m: float,
    plugins: Mapping[str, str],
) -> str:
    """The comparison report: what was compared with what, the rule, one table per model
    and new method (every reference configuration, its budget, paired difference and
    verdict) and a count of verdicts."""
    pre = str(meta.get("preregistration", {}).get("sha256", "?"))[:12]
    stream = meta.get("scenario", {}).get("config", {}).get("stream", "?")
    lines = [
        "# New planners against the published reference",
        "",
        f"Reference: the confirmatory run of commit `{str(meta.get('commit', '?'))[:12]}` "
        f"(preregistration sha256 `{pre}`, stream `{stream}`), read from "
        "its committed per-run table; not rerun. The new methods ran here on the same "
        "scenarios (the scenario code and config fingerprints match), so each run is paired "
        "with the same run of every reference configuration.",
        "",
        "Methods from packages: "
        + (", ".join(f"`{f}` ({d})" for f, d in sorted(plugins.items())) or "none")
        + ".",
        "",
        f"Verdict rule: {compare_rule(margin_m).text()}; 'supported' reads **better**, 'not "
        "supported' **worse**. Descriptive: no Holm correction, no claim of the report. "
        "Planning ms per step: the new method's measured here, the reference's on the "
        "reference machine (its budgets are wall clock there).",
        "",
    ]
    for (model, method), g in table.groupby(["model", "method"], sort=False):
        counts = g["verdict"].value_counts()
        lines += [
            f"## {method} on '{model}' ({int(g['runs'].iloc[0])} paired runs, "
            f"{fmt(g['new_ms'].iloc[0], 3)} ms per step here, mean error "
            f"{fmt(g['new_mean'].iloc[0], 4)} m)",
            "",
            ", ".join(f"{int(counts.get(v, 0))} {v}" for v in VERDICT_WORDS.values()) + ".",
            "",
        ]
        cells = pd.DataFrame({
            "budget (ms)": ["–" if np.isnan(b) else fmt(b, 3) for b in g["budget_ms"]],
            "reference": [f"{f}: {c}" for f, c in zip(g["family"], g["config"], strict=True)],
            "ref ms/step": [fmt(x, 3) for x in g["ref_ms"]],
            "ref error (m)": [fmt(x, 4) for x in g["ref_mean"]],
            "d = new − ref (m) [95% CI]": [
                f"{fmt(d, 3, True)} {fmt_ci(lo, hi, 3, True)}"
                for d, lo, hi in zip(g["mean_diff"], g["low"], g["high"], strict=True)
            ],
            "verdict": list(g["verdict"]),
        })  # fmt: skip
        lines += [markdown_table(cells), ""]
    return "\n".join(lines)


def compare_figure(
    table: pd.DataFrame, reference: pd.DataFrame, ladder: Sequence[Mapping[str, Any]]
) -> plt.Figure:
    """Per model: the reference's tuned members along the budget ladder (mean closed-loop
    error against mean planning ms per step, one line per family) and NBO, with each new
    method drawn in as a star at its own measured ms per step."""
    lad = pd.DataFrame(list(ladder), columns=["model", "budget_ms", "family", "config"])
    models = list(dict.fromkeys(table["model"]))
    fig, axes = plt.subplots(1, len(models), figsize=(5.2 * len(models), 4), squeeze=False)
    for ax, model in zip(axes[0], models, strict=True):
        ref = reference[reference["model"] == model]
        means = ref.groupby("config")[["mean_error", "plan_ms"]].mean()
        for family, g in lad[lad["model"] == model].groupby("family", sort=True):
            g = g.sort_values("budget_ms")
            pts = means.loc[g["config"]]
            ax.plot(pts["plan_ms"], pts["mean_error"], "o-", ms=4, lw=1, label=family)
        if "nbo" in means.index:
            ax.scatter(means.loc["nbo", "plan_ms"], means.loc["nbo", "mean_error"], marker="s",
                       color="k", label="nbo", zorder=3)  # fmt: skip
        for method, g in table[table["model"] == model].groupby("method", sort=False):
            x, y = g["new_ms"].iloc[0], g["new_mean"].iloc[0]
            ax.scatter(x, y, marker="*", s=180, color="crimson", edgecolor="k", zorder=4,
                       label=f"{method} (new)")  # fmt: skip
        ax.set_xscale("log")
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("planning ms per step (reference: its machine; new: this one)")
        ax.set_ylabel("closed-loop mean location error (m)")
        ax.set_title(f"'{model}'")
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig
