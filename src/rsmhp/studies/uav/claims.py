r"""UAV study, claims UAV-1..3: each a paired comparison of :mod:`rsmhp.studies.uav.summarise` whose
mean difference is the key number, judged by one verdict rule (:func:`paired_rule`, a
:func:`rsmhp.report.verdicts.ci_side` rule: its printed text and its evaluation are one object).

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

import numpy as np
import pandas as pd

from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.report.ledger import Claim, KeyNumber
from rsmhp.report.markdown import fmt, fmt_ci, param_text
from rsmhp.report.palette import method_label
from rsmhp.report.verdicts import Facts, Rule, ci_side
from rsmhp.studies.uav.summarise import PRUNING, TREND, baseline_name, family_rows, vs_baseline

__all__ = ["KEY", "key_comparisons", "paired_facts", "paired_rule", "short_name", "uav_claims"]

#: the key number of every UAV claim, as the rule names it (facts ``mean d_low/high``)
KEY = "mean d"

#: the setup every UAV claim is tested on
SETUP = "UAV reconstruction (Sec. III-B), closed loop"


def paired_rule(a: str, b: str, margin: float) -> Rule:
    """The rule of "``a`` has lower error than ``b``" (short method names, printed), with the
    equivalence margin ±``margin`` (m), fixed in the config before the run."""
    return ci_side(
        KEY,
        0.0,
        claimed="below",
        basis=f"d_r = e_r({a}) − e_r({b}), e_r = run r's average target location error (m); "
        "95% percentile bootstrap CI over runs",
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


def _stats(row: pd.Series) -> str:
    """Secondary numbers of one paired comparison (measured text)."""
    p = row["wilcoxon_p"]
    ptxt = f"Wilcoxon p = {fmt(p, 2)}" if np.isfinite(p) else "Wilcoxon p undefined (all d = 0)"
    return (
        f"{row['comparison']}: mean d {fmt(row['mean_diff'], 2, True)} "
        f"{fmt_ci(row['ci_low'], row['ci_high'], 2, True)} m, median d "
        f"{fmt(row['median_diff'], 2, True)} m, d < 0 in {int(row['n_better'])} of "
        f"{int(row['n_runs'])} runs, {ptxt}"
    )


def _alongside(rows: pd.DataFrame) -> str:
    return "; ".join(
        f"{r['comparison']}: {fmt(r['mean_diff'], 2, True)} "
        f"{fmt_ci(r['ci_low'], r['ci_high'], 2, True)} m"
        for _, r in rows.iterrows()
    )


def _dropped(row: pd.Series) -> str:
    """Runs left out of a paired comparison (a method without a result for them)."""
    n = int(row.get("n_missing", 0))
    return f"{n} run(s) without a result for both methods" if n else ""


def _claim(
    cid: str,
    claim: str,
    paper: str,
    row: pd.Series,
    measured: str,
    margin: float,
    dropped: str = "",
    contrary: str = "",
) -> Claim:
    """Claim ``cid`` whose key number is the mean difference of the paired ``row``."""
    a, b = short_name(row["method"]), short_name(row["baseline"])
    rule = paired_rule(a, b, margin)  # first: it checks the margin
    key = KeyNumber(
        name=f"mean d, e({a}) − e({b})",
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
    return Claim(
        id=cid,
        claim=claim,
        paper=paper,
        key=key,
        verdict=rule.verdict(paired_facts(row)),
        rule=rule.text(),
        measured=measured,
        dropped="; ".join(x for x in (dropped, _dropped(row)) if x),
        part="paper",
        setup=SETUP,
        contrary=contrary,
    )


def _pick(paired: pd.DataFrame, ab: tuple[str, str]) -> tuple[pd.Series, pd.Series]:
    """The row of comparison ``ab`` = (A, B) and the mask selecting it."""
    is_key = (paired["method"] == ab[0]) & (paired["baseline"] == ab[1])
    return paired[is_key].iloc[0], is_key


def _opposite(rows: pd.DataFrame) -> str:
    """The comparisons among ``rows`` whose CI lies above 0 (A significantly worse than B)."""
    return _alongside(rows[rows["ci_low"] > 0])


def _uav1(summary: pd.DataFrame, paired: pd.DataFrame, ab: tuple[str, str], margin: float) -> Claim:
    main, is_key = _pick(paired, ab)
    rs = family_rows(summary, MonteCarlo)
    trend = (paired["purpose"] == TREND) & ~is_key
    means = ", ".join(f"{r['label']} {fmt(r['mean'], 4)} m" for _, r in rs.iterrows())
    measured = f"{_stats(main)}; mean e: {means}"
    if trend.any():
        measured += f"; consecutive N_T (mean d, CI): {_alongside(paired[trend])}"
    nts = ", ".join(str(int(n)) for n in rs["N_T"])
    return _claim(
        "UAV-1",
        f"On the UAV reconstruction (closed loop), the average target location error falls "
        f"as N_T grows (N_T = {nts})",
        "Sec. III-B, Fig. 4: CDFs of the average location error improve gradually with "
        "N_T = 50, 100, 250 (H = 6)",
        main,
        measured,
        margin,
        contrary=_opposite(paired[trend]),
    )


def _uav2(paired: pd.DataFrame, ab: tuple[str, str], margin: float) -> Claim:
    main, is_key = _pick(paired, ab)
    others = (paired["purpose"] == vs_baseline()) & ~is_key
    measured = _stats(main)
    if others.any():
        measured += f"; other methods − NBO (mean d, CI): {_alongside(paired[others])}"
    return _claim(
        "UAV-2",
        f"On the UAV reconstruction (closed loop), RS-MHP ({short_name(main['method'])}) "
        "gives a lower average target location error than NBO",
        "Sec. III-B, Fig. 5: CDF of the average location error, RS-MHP better than NBO",
        main,
        measured,
        margin,
        contrary=_opposite(paired[others]),
    )


def _seconds(summary: pd.DataFrame, method: str) -> float:
    row = summary[summary["method"] == method]
    return float(row["plan_seconds_per_run"].iloc[0]) if len(row) else float("nan")


def _compute(summary: pd.DataFrame, pruned: str, flat: str) -> tuple[str, bool]:
    """Planning seconds per closed-loop run of the pruned tree and of N_T = M (machine
    dependent), and whether the pruned tree was the slower."""
    sp, sf = _seconds(summary, pruned), _seconds(summary, flat)
    if not (np.isfinite(sp) and np.isfinite(sf)):
        return "", False
    text = (
        f"compute: {method_label(pruned)} planned in {fmt(sp, 3)} s per closed-loop run, "
        f"{method_label(flat)} in {fmt(sf, 3)} s ({fmt(sp / sf, 3)}×; timings of this machine)"
    )
    return text, sp > sf


def _uav3(summary: pd.DataFrame, paired: pd.DataFrame, ab: tuple[str, str], margin: float) -> Claim:
    main, is_key = _pick(paired, ab)
    others = paired[(paired["purpose"] == PRUNING) & ~is_key]
    compute, slower = _compute(summary, main["baseline"], main["method"])
    contrary = [_opposite(paired[(paired["purpose"] == PRUNING) & ~is_key])]
    if slower:
        contrary.append(f"{compute}: the pruned tree did not save computation here")
    measured = _stats(main) + (f"; {compute}" if compute and not slower else "")
    return _claim(
        "UAV-3",
        "On the UAV reconstruction (closed loop), pruning degrades RS-MHP: independent "
        "trajectories N_T = M give a lower error than the pruned tree keeping M trajectories",
        "Sec. III-B, text after Fig. 4: the N_T trend suggests pruning would degrade "
        "RS-MHP but save computation (no experiment shown)",
        main,
        measured,
        margin,
        dropped=(
            "further pruned trees, reported but not the key number (the first one is): "
            + _alongside(others)
            if len(others)
            else ""
        ),
        contrary="; ".join(c for c in contrary if c),
    )


def uav_claims(summary: pd.DataFrame, paired: pd.DataFrame, margin: float) -> list[Claim]:
    """Claims UAV-1..3 by :func:`paired_rule` (those whose methods were run); ``margin`` is
    the equivalence margin (m, ``uav.analysis.equivalence_margin``)."""
    keys = key_comparisons(summary, paired)
    claims = []
    if "UAV-1" in keys:
        claims.append(_uav1(summary, paired, keys["UAV-1"], margin))
    if "UAV-2" in keys:
        claims.append(_uav2(paired, keys["UAV-2"], margin))
    if "UAV-3" in keys:
        claims.append(_uav3(summary, paired, keys["UAV-3"], margin))
    return claims
