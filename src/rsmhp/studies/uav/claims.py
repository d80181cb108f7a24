r"""UAV study, claims UAV-1..3: each a :class:`~rsmhp.report.claimspec.ClaimSpec`, a paired
comparison of :mod:`rsmhp.studies.uav.summarise` whose mean difference is the key number, judged
by one verdict rule (:func:`paired_rule`, a :func:`rsmhp.report.verdicts.ci_side` rule: its
printed text and its evaluation are one object); the claims' sentences, the key number's name
and the rule's basis are the macros of ``claims.md`` beside this module
(:class:`~rsmhp.report.templates.Words`).

For a claim "A has lower error than B" with :math:`d_r = e_r(A) - e_r(B)` and the 95%
bootstrap CI :math:`[l, h]` of :math:`\bar d`: *equivalent* if :math:`-m < l` and
:math:`h < m` (whatever the difference is, it is smaller than the margin m fixed in the config
before the run, ``uav.analysis.equivalence_margin``), else *supported* if :math:`h < 0` (the
CI lies entirely below 0), *not supported* if :math:`l > 0` (entirely above 0),
*inconclusive* otherwise (a difference of m or more is still compatible with the data).
Comparisons of the same kind whose CI lies on the opposite side are named as contrary
evidence; for UAV-3 also the planning time, where the pruned tree was the slower.

The claims are the paper's, about specific families (referenced through their classes):

* **UAV-1** (Fig. 4: error falls as N_T grows): A = RS-MHP (:class:`MonteCarlo`) with the
  largest N_T, B = RS-MHP with the smallest N_T (consecutive N_T pairs are reported
  alongside, not used in the verdict).
* **UAV-2** (Fig. 5: RS-MHP beats NBO): A = RS-MHP with the largest N_T, B = the baseline
  (NBO; the other methods are reported alongside).
* **UAV-3** (Sec. III-B remark: pruning degrades RS-MHP): A = RS-MHP with N_T = M
  (non-overlapping), B = the pruned tree keeping M trajectories; only if both were run.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.report.claimspec import ClaimSpec, Evidence
from rsmhp.report.ledger import Claim, KeyNumber
from rsmhp.report.markdown import fmt, fmt_ci, param_text
from rsmhp.report.palette import method_label
from rsmhp.report.templates import Words
from rsmhp.report.verdicts import Facts, Rule, ci_side
from rsmhp.studies.uav.summarise import PRUNING, TREND, baseline_name, family_rows, vs_baseline

__all__ = [
    "CLAIMS",
    "KEY",
    "SETUP",
    "WORDS",
    "key_comparisons",
    "paired_facts",
    "paired_rule",
    "short_name",
    "uav_claims",
]

#: the words of the claims and the rule (macros of ``claims.md`` beside this module)
WORDS = Words("rsmhp.studies.uav", "claims.md")

#: the key number of every UAV claim, as the rule names it (facts ``mean d_low/high``)
KEY = "mean d"

#: the setup every UAV claim is tested on
SETUP = WORDS("setup")


def paired_rule(a: str, b: str, margin: float) -> Rule:
    """The rule of "``a`` has lower error than ``b``" (short method names, printed), with the
    equivalence margin ±``margin`` (m), from the config (set after a first published result:
    :mod:`rsmhp.report.disclosures`)."""
    return ci_side(
        KEY,
        0.0,
        claimed="below",
        basis=WORDS("paired_rule_basis", a=a, b=b),
        margin=margin,
        margin_text=f"{param_text(margin)} m",
    )


def _paired_units(row: pd.Series) -> int | None:
    """The runs the CI of one paired comparison rests on (``n_runs``: runs with a result for
    both methods, the pairs the bootstrap resamples); ``None`` below 2 (no CI of a mean)."""
    n = int(row["n_runs"])
    return n if n >= 2 else None


def paired_facts(row: pd.Series) -> Facts:
    """The facts :func:`paired_rule` is evaluated on: the CI of one paired comparison."""
    return {f"{KEY}_low": float(row["ci_low"]), f"{KEY}_high": float(row["ci_high"])}


def key_comparisons(summary: pd.DataFrame, paired: pd.DataFrame) -> dict[str, tuple[str, str]]:
    """Claim id -> (A, B), the comparison whose mean paired difference is the claim's key
    number (module doc); claims whose methods were not run are absent."""
    rs = family_rows(summary, MonteCarlo)["method"].tolist()
    have = set(zip(paired["method"], paired["baseline"], strict=True))
    base = baseline_name()
    out = {}
    if len(rs) >= 2 and (rs[-1], rs[0]) in have:
        out["UAV-1"] = (rs[-1], rs[0])
    if rs and (rs[-1], base) in have:
        out["UAV-2"] = (rs[-1], base)
    prune = paired[paired["purpose"] == PRUNING]
    if len(prune):
        out["UAV-3"] = (prune["method"].iloc[0], prune["baseline"].iloc[0])
    return out


def short_name(method: str) -> str:
    """``N_T=250``, ``NBO``, ``tree N=8 M=100``: short names for key-number labels."""
    return method_label(method).replace("RS-MHP ", "").replace("pruned tree", "tree")


def _stats(row: pd.Series) -> dict[str, str | None]:
    """Secondary numbers of one paired comparison (the ``stats`` macro; ``p`` ``None``: the
    Wilcoxon p-value is undefined, every d = 0)."""
    p = row["wilcoxon_p"]
    return {
        "comparison": row["comparison"],
        "mean": fmt(row["mean_diff"], 2, True),
        "ci": fmt_ci(row["ci_low"], row["ci_high"], 2, True),
        "median": fmt(row["median_diff"], 2, True),
        "better": str(int(row["n_better"])),
        "runs": str(int(row["n_runs"])),
        "p": fmt(p, 2) if np.isfinite(p) else None,
    }


def _alongside(rows: pd.DataFrame) -> list[dict[str, str]]:
    """Comparisons reported alongside the key number: mean d and CI (``alongside`` macro)."""
    return [
        {
            "comparison": r["comparison"],
            "mean": fmt(r["mean_diff"], 2, True),
            "ci": fmt_ci(r["ci_low"], r["ci_high"], 2, True),
        }
        for _, r in rows.iterrows()
    ]


def _opposite(rows: pd.DataFrame) -> list[dict[str, str]]:
    """The comparisons among ``rows`` whose CI lies above 0 (A significantly worse than B)."""
    return _alongside(rows[rows["ci_low"] > 0])


def _evidence(row: pd.Series, margin: float, values: dict[str, Any]) -> Evidence:
    """The evidence of a claim whose key number is the mean difference of the paired ``row``:
    its rule (first: it checks the margin), key number, facts, and the ``values`` of its
    texts with the key comparison (``main``) and the runs left out of it (``missing``)."""
    a, b = short_name(row["method"]), short_name(row["baseline"])
    rule = paired_rule(a, b, margin)
    key = KeyNumber(
        name=WORDS("key", a=a, b=b),
        value=float(row["mean_diff"]),
        ci_low=float(row["ci_low"]),
        ci_high=float(row["ci_high"]),
        unit="m",
        reproducible="statistical",
        digits=2,
        null=0.0,
        n=_paired_units(row),
        margin=float(margin),
    )
    missing = int(row.get("n_missing", 0))
    values = {**values, "main": _stats(row), "missing": str(missing) if missing else ""}
    return Evidence(key=key, facts=paired_facts(row), values=values, rule=rule)


def _pick(paired: pd.DataFrame, ab: tuple[str, str]) -> tuple[pd.Series, pd.Series]:
    """The row of comparison ``ab`` = (A, B) and the mask selecting it."""
    is_key = (paired["method"] == ab[0]) & (paired["baseline"] == ab[1])
    return paired[is_key].iloc[0], is_key


def _uav1(
    summary: pd.DataFrame, paired: pd.DataFrame, ab: tuple[str, str], margin: float
) -> Evidence:
    """RS-MHP with the largest − the smallest N_T; consecutive N_T alongside (UAV-1)."""
    main, is_key = _pick(paired, ab)
    rs = family_rows(summary, MonteCarlo)
    trend = paired[(paired["purpose"] == TREND) & ~is_key]
    values = {
        "nts": ", ".join(str(int(n)) for n in rs["N_T"]),
        "means": [{"label": r["label"], "mean": fmt(r["mean"], 4)} for _, r in rs.iterrows()],
        "trend": _alongside(trend),
        "opposite": _opposite(trend),
    }
    return _evidence(main, margin, values)


def _uav2(
    summary: pd.DataFrame, paired: pd.DataFrame, ab: tuple[str, str], margin: float
) -> Evidence:
    """RS-MHP with the largest N_T − NBO; the other methods − NBO alongside (UAV-2)."""
    main, is_key = _pick(paired, ab)
    others = paired[(paired["purpose"] == vs_baseline()) & ~is_key]
    values = {
        "short": short_name(main["method"]),
        "others": _alongside(others),
        "opposite": _opposite(others),
    }
    return _evidence(main, margin, values)


def _seconds(summary: pd.DataFrame, method: str) -> float:
    row = summary[summary["method"] == method]
    return float(row["plan_seconds_per_run"].iloc[0]) if len(row) else float("nan")


def _compute(summary: pd.DataFrame, pruned: str, flat: str) -> tuple[dict[str, str] | None, bool]:
    """Planning seconds per closed-loop run of the pruned tree and of N_T = M (machine
    dependent; the ``compute`` macro, ``None`` without both), and whether the pruned tree was
    the slower."""
    sp, sf = _seconds(summary, pruned), _seconds(summary, flat)
    if not (np.isfinite(sp) and np.isfinite(sf)):
        return None, False
    timing = {
        "pruned": method_label(pruned),
        "pruned_s": fmt(sp, 3),
        "flat": method_label(flat),
        "flat_s": fmt(sf, 3),
        "ratio": fmt(sp / sf, 3),
    }
    return timing, sp > sf


def _uav3(
    summary: pd.DataFrame, paired: pd.DataFrame, ab: tuple[str, str], margin: float
) -> Evidence:
    """RS-MHP with N_T = M − the pruned tree keeping M; planning time alongside (UAV-3)."""
    main, is_key = _pick(paired, ab)
    others = paired[(paired["purpose"] == PRUNING) & ~is_key]
    timing, slower = _compute(summary, main["baseline"], main["method"])
    values = {
        "timing": timing,
        "slower": slower,
        "others": _alongside(others),
        "opposite": _opposite(others),
    }
    return _evidence(main, margin, values)


#: the claims by id, in the ledger's order; each evidence function takes (summary, paired,
#: (A, B), margin) and brings its rule (the margin is the run's)
CLAIMS: dict[str, ClaimSpec] = {
    cid: ClaimSpec(id=cid, setup=SETUP, evidence=evidence, words=WORDS)
    for cid, evidence in (("UAV-1", _uav1), ("UAV-2", _uav2), ("UAV-3", _uav3))
}


def uav_claims(summary: pd.DataFrame, paired: pd.DataFrame, margin: float) -> list[Claim]:
    """Claims UAV-1..3 by :func:`paired_rule` (those whose methods were run); ``margin`` is
    the equivalence margin (m, ``uav.analysis.equivalence_margin``)."""
    keys = key_comparisons(summary, paired)
    return [
        spec.build(summary, paired, keys[cid], margin)
        for cid, spec in CLAIMS.items()
        if cid in keys
    ]
