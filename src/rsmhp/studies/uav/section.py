"""UAV study, report section (paper Sec. III-B, Figs. 4-5): the Markdown tables, a short body
(what was run, symbols, findings, the paper-style CDFs each followed by its paired view) and
the appendix (model, tables), assembled from the statistics of :mod:`rsmhp.studies.uav.summarise`
and the claims of :mod:`rsmhp.studies.uav.claims`. The prose is in the templates beside this
module (``section.md``: body, ``section_appendix.md``, ``section_variant.md``: the model
variant note, ``section_paired_table.md``: the paired table's footnote); this module computes
and formats the values they insert."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from rsmhp.models.uav import methods as registry
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.models.uav.methods.pruned_tree import PrunedTree
from rsmhp.report.ledger import VERDICTS, Claim, Section
from rsmhp.report.markdown import fmt, fmt_ci, markdown_table, param_text
from rsmhp.report.palette import method_label
from rsmhp.report.templates import render
from rsmhp.studies.uav.claims import uav_claims
from rsmhp.studies.uav.summarise import family_rows, figure_notes, is_family

__all__ = ["FIGURES", "uav_section", "uav_tables"]

#: figure stems written by the figure rule and referenced by the report section, in the order
#: of the section: each paper-style CDF is followed by its paired view
FIGURES = ("uav_error_cdf_nt", "uav_paired_diff_nt", "uav_error_cdf_nbo", "uav_paired_diff")

#: the paper's figure each claim's comparison reproduces (named in the findings)
_PAPER_FIGURES = {"UAV-1": "Fig. 4", "UAV-2": "Fig. 5"}


def _render(template: str, **values: Any) -> str:
    """The template ``template`` beside this module filled with ``values``, without the line
    break that ends the template file."""
    return render("rsmhp.studies.uav", template, **values).removesuffix("\n")


def uav_tables(summary: pd.DataFrame, paired: pd.DataFrame) -> dict[str, str]:
    """Markdown tables keyed by file stem (``results/tables/<stem>.md``): per method, and the
    paired comparisons (a Wilcoxon p that is undefined prints as ``n/a``, explained below)."""
    methods = pd.DataFrame(
        {
            "method": summary["label"],
            "runs": summary["n_runs"].astype(int),
            "mean e (m)": summary["mean"],
            "CI low": summary["ci_low"],
            "CI high": summary["ci_high"],
            "median e (m)": summary["median"],
            "median CI low": summary["median_low"],
            "median CI high": summary["median_high"],
            "SD of e (m)": summary["sd"],
            "RMSE (m)": summary["mean_rmse"],
            "mean tr P̂": summary["mean_trace"],
            "planner s/run": summary["plan_seconds_per_run"],
        }
    )
    pairs = pd.DataFrame(
        {
            "comparison A − B": paired["comparison"],
            "purpose": paired["purpose"],
            "runs": paired["n_runs"].astype(int),
            "mean d (m)": paired["mean_diff"],
            "CI low": paired["ci_low"],
            "CI high": paired["ci_high"],
            "median d (m)": paired["median_diff"],
            "SD of d (m)": paired["sd_diff"],
            "runs d < 0": paired["n_better"].astype(int),
            "Wilcoxon p": paired["wilcoxon_p"],
        }
    )
    signed = ("mean d (m)", "CI low", "CI high", "median d (m)")
    ptable = _render(
        "section_paired_table.md",
        table=markdown_table(pairs, digits=3, missing="n/a", signed=signed),
        undefined_p=bool(paired["wilcoxon_p"].isna().any()),
    )
    return {"uav_methods": markdown_table(methods, digits=4), "uav_paired": ptable}


def _num(x: float) -> str:
    """A configuration number as given: integer-valued numbers without decimals (``1``, not
    ``1.00``), others with at most 3 significant digits and no trailing zeros."""
    xf = float(x)
    if xf.is_integer():
        return fmt(int(xf))
    out = fmt(xf)
    return out if "e" in out else out.rstrip("0").rstrip(".")


def _nums(section: Mapping[str, Any]) -> dict[str, Any]:
    """A configuration section with its numbers as :func:`_num` prints them (other values,
    e.g. names and nulls, as they are)."""
    return {
        key: _num(value)
        if isinstance(value, int | float) and not isinstance(value, bool)
        else value
        for key, value in section.items()
    }


@dataclass(frozen=True)
class Footprint:
    """The sensor footprint of a model variant: radius and planner width (m, formatted), how
    the truth detects (``hard`` or ``logistic``)."""

    radius: str
    detection: str
    width: str


def _variant_note(sensor: Mapping[str, Any]) -> str:
    """A sentence naming the model variant when the sensor is not the reconstruction's (empty
    otherwise); it starts with a space, to follow a sentence."""
    footprint = (
        Footprint(
            radius=_num(sensor["footprint_radius"]),
            detection=str(sensor.get("detection", "hard")),
            width=_num(sensor.get("footprint_width", 10)),
        )
        if sensor.get("footprint_radius") is not None
        else None
    )
    quadratic = sensor.get("noise_growth", "linear") != "linear"
    reference = _num(sensor.get("reference_distance", 100)) if quadratic else None
    return _render("section_variant.md", footprint=footprint, reference=reference)


@dataclass(frozen=True)
class Tree:
    """A pruned tree the run includes: draws per level ``N``, trajectories kept ``M``."""

    N: str
    M: str


@dataclass(frozen=True)
class KeyNumberText:
    """A claim's key number for the findings: mean paired difference and its CI (m,
    formatted) and the verdict."""

    id: str
    value: str
    ci: str
    verdict: str


@dataclass(frozen=True)
class PaperFigure:
    """A paper figure whose difference the run does not resolve (an equivalent claim)."""

    figure: str
    id: str


@dataclass(frozen=True)
class _Evidence:
    """What the section is assembled from: the summarise statistics (``summary``, ``paired``,
    ``runs``), the claims, the figure notes (:func:`rsmhp.studies.uav.summarise.figure_notes`),
    the tables of :func:`uav_tables`, the ``uav`` model config (``setting``), the bootstrap
    resamples and the equivalence margin (m)."""

    summary: pd.DataFrame
    claims: Sequence[Claim]
    notes: Mapping[str, tuple[float, float, str]]
    tables: Mapping[str, str]
    setting: Mapping[str, Any]
    n_boot: int
    margin: float


def _methods_run(summary: pd.DataFrame) -> dict[str, Any]:
    """The methods run, as the body names them: whether RS-MHP ran and its set of N_T values,
    each pruned tree, then the labels of any other registered family's members."""
    rs = family_rows(summary, MonteCarlo)
    described = (registry.baseline(), MonteCarlo, PrunedTree)
    other = ~np.logical_or.reduce([is_family(summary["method"], c) for c in described])
    return {
        "has_rsmhp": bool(len(rs)),
        "nt_set": "{" + ", ".join(str(int(n)) for n in rs["N_T"]) + "}",
        "trees": [
            Tree(N=str(int(t["N"])), M=str(int(t["M"])))
            for _, t in family_rows(summary, PrunedTree).iterrows()
        ],
        "other_methods": [method_label(m) for m in summary.loc[other, "method"]],
    }


def _findings(claims: Sequence[Claim], summary: pd.DataFrame, margin: float) -> dict[str, Any]:
    """The values of the body's findings: spread of the method means, key numbers, the
    equivalence margin Δ against the mean error ē and the run-to-run SD s (100 Δ/ē %, Δ/s),
    the median CI half-width h of the claims (and 100 h/ē %), the verdict counts."""
    mean_e, sd_e = float(summary["mean"].mean()), float(summary["sd"].median())
    half = float(np.median([(c.key.ci_high - c.key.ci_low) / 2 for c in claims] or [0.0]))
    return {
        "mean_min": fmt(summary["mean"].min(), 4),
        "mean_max": fmt(summary["mean"].max(), 4),
        "sd": fmt(sd_e, 2),
        "key_numbers": [
            KeyNumberText(
                id=c.id,
                value=fmt(c.key.value, 2, True),
                ci=fmt_ci(c.key.ci_low, c.key.ci_high, 2, True),
                verdict=c.verdict,
            )
            for c in claims
        ],
        "margin": param_text(margin),
        "margin_pct": fmt(100 * margin / mean_e, 2),
        "margin_sd": fmt(margin / sd_e, 2),
        "n_claims": len(claims),
        "n_equivalent": sum(c.verdict == "equivalent" for c in claims),
        "n_inconclusive": sum(c.verdict == "inconclusive" for c in claims),
        "half_width": fmt(half, 2),
        "half_width_pct": fmt(100 * half / mean_e, 2),
        "decided": [c for c in claims if c.verdict in VERDICTS[:2]],
        "unresolved": [
            PaperFigure(figure=_PAPER_FIGURES[c.id], id=c.id)
            for c in claims
            if c.verdict == "equivalent" and c.id in _PAPER_FIGURES
        ],
    }


def _figures(
    summary: pd.DataFrame, notes: Mapping[str, tuple[float, float, str]]
) -> dict[str, Any]:
    """The values of the four figure captions: the N_T values of the N_T figure, the largest
    RS-MHP of the NBO figure, and each figure's note on what its range leaves out."""
    rs = family_rows(summary, MonteCarlo)
    return {
        "nts": ", ".join(str(int(n)) for n in rs["N_T"]),
        "largest_rsmhp": method_label(rs["method"].iloc[-1]) if len(rs) else "RS-MHP",
        "notes": {stem: notes.get(stem, (0, 0, ""))[2] for stem in FIGURES},
    }


def _body(ev: _Evidence) -> str:
    sc, pl = ev.setting["scenario"], ev.setting["planner"]
    return _render(
        "section.md",
        n_runs=str(int(ev.summary["n_runs"].max())),
        steps=str(sc["steps"]),
        dt=_num(ev.setting["dt"]),
        horizon=str(pl["horizon"]),
        variant_note=_variant_note(ev.setting["sensor"]),
        n_boot=str(ev.n_boot),
        **_methods_run(ev.summary),
        **_findings(ev.claims, ev.summary, ev.margin),
        **_figures(ev.summary, ev.notes),
    )


def _appendix(ev: _Evidence) -> str:
    pl = ev.setting["planner"]
    return _render(
        "section_appendix.md",
        dt=_num(ev.setting["dt"]),
        aircraft=_nums(ev.setting["aircraft"]),
        target=_nums(ev.setting["target"]),
        sensor=_nums(ev.setting["sensor"]),
        tracker=_nums(ev.setting["tracker"]),
        scenario=_nums(ev.setting["scenario"]),
        horizon=str(pl["horizon"]),
        optimiser=str(pl.get("optimiser", "boxqn")),
        maxiter=str(pl["maxiter"]),
        maxfun=str(pl["maxfun"]),
        variant_note=_variant_note(ev.setting["sensor"]),
        methods_table=ev.tables["uav_methods"],
        paired_table=ev.tables["uav_paired"],
    )


def uav_section(
    summary: pd.DataFrame,
    paired: pd.DataFrame,
    tables: Mapping[str, str],
    setting: Mapping[str, Any],
    n_boot: int,
    runs: pd.DataFrame,
    margin: float,
) -> Section:
    """The UAV report section (order 20): a short body (what was run, symbols, findings, the
    paper-style CDFs each followed by its paired view) and an appendix (model, tables);
    ``margin`` is the claims' equivalence margin (m)."""
    claims = uav_claims(summary, paired, margin)
    ev = _Evidence(
        summary=summary,
        claims=claims,
        notes=figure_notes(runs, summary, paired),
        tables=tables,
        setting=setting,
        n_boot=n_boot,
        margin=margin,
    )
    return Section(
        key="uav",
        title="Case study 2: UAV target tracking (paper Sec. III-B, Figs. 4-5)",
        order=20,
        body=_body(ev),
        claims=claims,
        figures=[f"{f}.png" for f in FIGURES],
        appendix=_appendix(ev),
    )
