r"""UAV horizon study, claims HZ-1-<model>, HZ-2-<model> and HZ-3-<model>: each a key number from
:mod:`rsmhp.studies.horizon.summarise_uav` and a verdict rule (:mod:`rsmhp.report.verdicts`).
All claims are beyond the paper (part "beyond"): the paper plans at H = 6 only. Key numbers are
statistical (sampled hypotheses, optimiser-free but random). H_lo and H_hi are the smallest and
largest horizons of ``horizon.uav.H``.

* **HZ-1** (:func:`hz1_rule`): g = relative RMSE of NBO's cost estimate at H_hi − at H_lo
  (:func:`rsmhp.studies.horizon.summarise_uav.rmse_growth`, the same belief states at both). NBO's
  cost approximation error grows with H: *supported* if the 95% cluster-t CI of g (jackknife over
  runs, t with runs − 1 df) lies above 0, *not supported* below 0, *inconclusive* otherwise.
* **HZ-3** (:func:`hz3_rule`, one model: ``horizon.uav.claims.closed_model``): D = (closed-loop
  mean error of the Monte-Carlo member − NBO's at H_hi) − (the same at H_lo), paired over
  runs (the same scenarios at both H; m). The advantage of sampling over NBO grows with H:
  *supported* if the 95% Student-t CI of D over runs lies below 0, *not supported* above 0,
  *inconclusive* otherwise. Both planners of the closed loop run at the optimiser budget of
  ``uav.planner`` (the same at every H), so D carries each planner's optimisation
  error besides its cost-approximation error; the measured text says which budget
  (:func:`budget_text`) and points to the section that splits the two
  (:mod:`rsmhp.studies.horizon.section_optimiser`).
* **HZ-2** (:func:`hz2_rule`): d = g(pruned tree) − g(Monte Carlo with N_T = M), the
  members fixed in ``horizon.uav.claims``, from the smallest H at which the tree is pruned
  (N^(H+1) > M leaves, so it keeps M trajectories, as many as Monte Carlo) to H_hi. The
  pruned tree's error grows with H more than Monte Carlo's: *supported* if the cluster-t CI
  of d lies above 0, *not supported* below 0, *inconclusive* otherwise.

The primary test of each of HZ-1..HZ-3 is the t-test of 0 that its CI inverts; its p-value,
for the report's Holm correction over the FR and HZ claims
(:func:`rsmhp.report.verdicts.holm_correct`), is the key number's ``p_value``:
:func:`rsmhp.report.verdicts.decisive_p` of the verdict, i.e. the two-sided t-test p-value of 0 for
``supported`` and ``not supported`` (below 0.05 exactly when the CI excludes 0), and for
``inconclusive`` the doubled one-sided p-value towards the claimed side (1 when the estimate
lies on the other side). It is also printed in the claim's ``measured`` text, next to the
percentile-bootstrap CI over runs that the cluster-t CI replaced and the verdict that
bootstrap CI would give (:func:`horizon_evidence`, :class:`PrimaryTest`).

Oven LQG (:func:`lqg_horizon_claims`; exact oracle, ``horizon.lqg``):

* **HZ-4** (:func:`hz4_rule`): d = growth of the relative RMSE of the pruned tree
  (``horizon.lqg.claims.pruned``: N draws per level, M kept) from the first simulated H at
  which it is pruned (:math:`N^H > M`) to the largest − that of Monte Carlo with n = M, at
  the oven model's a (:func:`rsmhp.studies.horizon.summarise_lqg.pruned_growth`). *Supported* if the
  95% CI of d lies above 0, *not supported* below 0, *inconclusive* otherwise.
* **HZ-5** (:data:`HZ5_RULE`): uniform Monte Carlo's mean regret follows its closed form
  :math:`\kappa_H v_H / P` at every simulated (a, H, P), up to the longest horizon:
  *supported* if max |z| is within the Bonferroni limit (95% family-wise), *not supported*
  otherwise.

Each claim is a :class:`rsmhp.report.claimspec.ClaimSpec` (:data:`HZ_1` .. :data:`HZ_5`): an
evidence function of the study's tables (:func:`hz1_evidence` .. :func:`hz5_evidence`: the
key number, the facts its rule reads and the preformatted values of its texts) and the words
of ``claims.md`` beside this module (:data:`WORDS`: the claims' sentences, the rules' bases,
the key numbers' names and the setups).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from rsmhp.models.lqg.regret_summary import ZCheck, z_families
from rsmhp.models.uav import methods as registry
from rsmhp.report.claimspec import ClaimSpec, Evidence
from rsmhp.report.ledger import Claim, KeyNumber
from rsmhp.report.markdown import fmt, fmt_ci
from rsmhp.report.palette import method_label
from rsmhp.report.templates import Words
from rsmhp.report.verdicts import Case, Rule, ci_side, decisive_p
from rsmhp.studies.horizon.section_optimiser import TITLE as SPLIT_TITLE
from rsmhp.studies.horizon.simulate_lqg import pruned_from
from rsmhp.studies.horizon.summarise_lqg import pruned_growth
from rsmhp.studies.horizon.summarise_uav import Advantage, Growth, advantage_growth, rmse_growth

__all__ = [
    "HZ5_RULE",
    "HZ_1",
    "HZ_2",
    "HZ_3",
    "HZ_4",
    "HZ_5",
    "KEY",
    "WORDS",
    "PrimaryTest",
    "budget_text",
    "horizon_claims",
    "horizon_evidence",
    "hz1_evidence",
    "hz1_rule",
    "hz2_evidence",
    "hz2_rule",
    "hz3_evidence",
    "hz3_rule",
    "hz4_evidence",
    "hz4_rule",
    "hz5_evidence",
    "lqg_horizon_claims",
]

KEY = "g"

#: the claims' sentences, rule texts, key-number names and setups (``claims.md``)
WORDS = Words("rsmhp.studies.horizon", "claims.md")


class PrimaryTest(NamedTuple):
    """A claim of HZ-1..HZ-3 with its primary test: ``p_value``, the claim's
    ``key.p_value`` (the t-test of 0 behind the verdict with ``df`` degrees of freedom,
    :func:`_verdict_p`); ``[boot_low, boot_high]``, the 95% percentile-bootstrap CI over runs
    in the key number's unit (the interval the cluster-t CI replaced) and ``boot_verdict``,
    the verdict the claim's rule gives on it."""

    claim: Claim
    p_value: float
    df: int
    boot_low: float
    boot_high: float
    boot_verdict: str


def _verdict_p(verdict: str, estimate: float, se: float, df: int, claimed: str) -> float:
    """The p-value behind a verdict of the CI rule "above (or below, ``claimed``) 0"
    (:func:`rsmhp.report.verdicts.decisive_p`): the two-sided t-test p-value of 0 for ``supported``
    and ``not supported``; for ``inconclusive`` the claimed side's (1 if the estimate lies on
    the other)."""
    other = "below" if claimed == "above" else "above"
    side = other if verdict == "not supported" else claimed
    return decisive_p(verdict, estimate, se, df, [(0.0, side)])


def _tested(
    rule: Rule, name: str, t: Growth | Advantage, claimed: str, scale: float
) -> tuple[float, dict[str, float], dict[str, Any]]:
    """The primary test of an estimate ``t`` with a cluster-t CI ``[t.low, t.high]`` under a
    :func:`~rsmhp.report.verdicts.ci_side` rule of ``name``: its p-value (:func:`_verdict_p`),
    the facts (the CI; also ``p_value``, ``df`` and the bootstrap CI ``boot_low``,
    ``boot_high`` times ``scale``, the key number's unit) and the values of the test's text
    (``p``, ``df``, ``boot_ci`` and ``boot_verdict``, the rule's verdict on the bootstrap CI)."""
    facts = {f"{name}_low": t.low, f"{name}_high": t.high}
    p = _verdict_p(rule.verdict(facts), t.mean, t.se, t.df, claimed)
    boot_low, boot_high = scale * t.boot_low, scale * t.boot_high
    boot_verdict = rule.verdict({f"{name}_low": t.boot_low, f"{name}_high": t.boot_high})
    facts |= {"p_value": p, "df": t.df, "boot_low": boot_low, "boot_high": boot_high}
    values = {
        "p": fmt(p, 3),
        "df": t.df,
        "boot_ci": fmt_ci(boot_low, boot_high, 3, True),
        "boot_verdict": boot_verdict,
    }
    return p, facts, values


def _primary_test(spec: ClaimSpec, ev: Evidence) -> PrimaryTest:
    """The claim of ``spec`` on ``ev`` (an evidence of :func:`_tested`) with its primary test."""
    f = ev.facts
    return PrimaryTest(
        spec.claim(ev),
        f["p_value"],
        int(f["df"]),
        f["boot_low"],
        f["boot_high"],
        ev.values["boot_verdict"],
    )


def budget_text(planner: Mapping[str, Any] | None) -> str:
    """The optimiser budget of ``uav.planner`` in words (``maxiter 30, maxfun 60, no
    restarts``); '' without it."""
    if not planner:
        return ""
    return WORDS(
        "budget",
        maxiter=int(planner["maxiter"]),
        maxfun=int(planner["maxfun"]),
        restarts=int(planner.get("restarts", 0) or 0),
    )


def _units(n: int) -> int | None:
    """The independent units (runs, replicates) a CI rests on, as :attr:`KeyNumber.n`;
    ``None`` below 2 (no CI of a mean)."""
    return int(n) if int(n) >= 2 else None


def _key(name: str, g: Growth, p_value: float) -> KeyNumber:
    """The key number of HZ-1/HZ-2: ``g`` in pp with its cluster-t CI over ``g.runs`` runs
    (the clusters: the belief states of a run are not independent)."""
    return KeyNumber(
        name,
        100 * g.mean,
        100 * g.low,
        100 * g.high,
        unit="pp",
        reproducible="statistical",
        digits=2,
        null=0.0,
        p_value=p_value,
        n=_units(g.runs),
    )


def _pct(x: float) -> str:
    """A relative RMSE ``x`` in percent, three significant digits."""
    return fmt(100 * x, 3)


# ------------------------------------------------------------------ HZ-1


def hz1_rule(h_lo: int, h_hi: int) -> Rule:
    """HZ-1: NBO's relative RMSE is larger at H_hi than at H_lo."""
    return ci_side(KEY, 0.0, claimed="above", basis=WORDS("hz_1_basis", h_lo=h_lo, h_hi=h_hi))


def hz1_evidence(
    approx: pd.DataFrame, model: str, nbo: str, h_lo: int, h_hi: int, seed: int, n_boot: int
) -> Evidence:
    """HZ-1 on ``model``: g = relative RMSE of ``nbo`` at ``h_hi`` − at ``h_lo``
    (:func:`rsmhp.studies.horizon.summarise_uav.rmse_growth`), in pp."""
    g = rmse_growth(approx, model, nbo, h_lo, h_hi, seed, n_boot)
    rule = hz1_rule(h_lo, h_hi)
    p, facts, test = _tested(rule, KEY, g, "above", 100.0)
    return Evidence(
        key=_key(WORDS("hz_1_key", h_lo=h_lo, h_hi=h_hi), g, p),
        facts=facts,
        rule=rule,
        values={
            "model": model,
            "h_lo": h_lo,
            "h_hi": h_hi,
            "n": g.n,
            "runs": g.runs,
            "lo": _pct(g.lo_value),
            "hi": _pct(g.hi_value),
            "diff": fmt(100 * g.mean, 3, True),
            "ci": fmt_ci(100 * g.low, 100 * g.high, 3, True),
            **test,
        },
    )


HZ_1 = ClaimSpec(
    id="HZ-1-{model}",
    setup=WORDS("uav_states_setup"),
    evidence=hz1_evidence,
    words=WORDS,
    texts="hz_1",
    part="beyond",
)

# ------------------------------------------------------------------ HZ-2


def hz2_rule(tree: str, mc: str, h_lo: int, h_hi: int) -> Rule:
    """HZ-2: the pruned tree's RMSE grows more from H_lo to H_hi than Monte Carlo's."""
    basis = WORDS("hz_2_basis", tree=method_label(tree), mc=method_label(mc), h_lo=h_lo, h_hi=h_hi)
    return ci_side(KEY, 0.0, claimed="above", basis=basis)


def hz2_evidence(
    approx: pd.DataFrame,
    model: str,
    tree: str,
    mc: str,
    h_lo: int,
    h_hi: int,
    seed: int,
    n_boot: int,
) -> Evidence:
    """HZ-2 on ``model``: d = growth of the relative RMSE of ``tree`` from ``h_lo`` (its first
    pruned horizon) to ``h_hi`` − that of ``mc``, in pp."""
    d = rmse_growth(approx, model, tree, h_lo, h_hi, seed, n_boot, minus=mc)
    g_mc = rmse_growth(approx, model, mc, h_lo, h_hi, seed, n_boot)
    rule = hz2_rule(tree, mc, h_lo, h_hi)
    p, facts, test = _tested(rule, KEY, d, "above", 100.0)
    names = {"tree": method_label(tree), "mc": method_label(mc), "h_lo": h_lo, "h_hi": h_hi}
    return Evidence(
        key=_key(WORDS("hz_2_key", **names), d, p),
        facts=facts,
        rule=rule,
        values={
            **names,
            "model": model,
            "n": d.n,
            "runs": d.runs,
            "tree_lo": _pct(d.lo_value),
            "tree_hi": _pct(d.hi_value),
            "mc_lo": _pct(g_mc.lo_value),
            "mc_hi": _pct(g_mc.hi_value),
            **test,
        },
    )


HZ_2 = ClaimSpec(
    id="HZ-2-{model}",
    setup=WORDS("uav_states_setup"),
    evidence=hz2_evidence,
    words=WORDS,
    texts="hz_2",
    part="beyond",
)

# ------------------------------------------------------------------ HZ-3


def hz3_rule(mc: str, h_lo: int, h_hi: int) -> Rule:
    """HZ-3: the closed-loop advantage of ``mc`` over NBO is larger at H_hi than at H_lo."""
    basis = WORDS("hz_3_basis", mc=method_label(mc), h_lo=h_lo, h_hi=h_hi)
    return ci_side("D", 0.0, claimed="below", basis=basis)


def hz3_evidence(closed: pd.DataFrame, model: str, mc: str, h_lo: int, h_hi: int, seed: int,
                 n_boot: int, planner: Mapping[str, Any] | None = None) -> Evidence:  # fmt: skip
    """HZ-3 on ``model``: D = closed-loop advantage change of ``mc`` over NBO from ``h_lo`` to
    ``h_hi`` (:func:`rsmhp.studies.horizon.summarise_uav.advantage_growth`, m); ``planner``:
    ``uav.planner`` (the budget the measured text names)."""
    a = advantage_growth(closed, model, mc, h_lo, h_hi, seed, n_boot)
    rule = hz3_rule(mc, h_lo, h_hi)
    p, facts, test = _tested(rule, "D", a, "below", 1.0)
    key = KeyNumber(WORDS("hz_3_key", h_lo=h_lo, h_hi=h_hi), a.mean, a.low, a.high, unit="m",
                    reproducible="statistical", digits=3, null=0.0, p_value=p,
                    n=_units(a.n))  # fmt: skip
    values = {
        "model": model,
        "mc": method_label(mc),
        "h_lo": h_lo,
        "h_hi": h_hi,
        "n": a.n,
        "d_lo": fmt(a.d_lo, 3, True),
        "d_hi": fmt(a.d_hi, 3, True),
        "half": fmt((a.high - a.low) / 2, 2),
        "sd": fmt(a.sd, 3),
        "runs_needed": f"{int(a.runs_needed)}" if math.isfinite(a.runs_needed) else "",
        "budget": budget_text(planner),
        "split_title": SPLIT_TITLE,
        **test,
    }
    return Evidence(key=key, facts=facts, values=values, rule=rule)


HZ_3 = ClaimSpec(
    id="HZ-3-{model}",
    setup=WORDS("hz_3_setup"),
    evidence=hz3_evidence,
    words=WORDS,
    texts="hz_3",
    part="beyond",
)


def _hz3(closed: pd.DataFrame, model: str, mc: str, h_lo: int, h_hi: int, seed: int,
         n_boot: int, planner: Mapping[str, Any] | None = None) -> Claim:  # fmt: skip
    """HZ-3's claim (:func:`hz3_evidence`, same arguments)."""
    return HZ_3.build(closed, model, mc, h_lo, h_hi, seed, n_boot, planner)


# ------------------------------------------------------------------ HZ-1..HZ-3 of a run


def horizon_claims(
    approx: pd.DataFrame,
    summary: pd.DataFrame,
    cfg: Mapping[str, Any],
    seed: int,
    closed: pd.DataFrame | None = None,
    planner: Mapping[str, Any] | None = None,
) -> list[Claim]:
    """HZ-1 and HZ-2 per model of ``summary``, HZ-3 on the configured model (module doc).
    ``approx``: the cost-approximation rows of every (model, H); ``summary``:
    :func:`rsmhp.studies.horizon.summarise_uav.summarize_approx`; ``cfg``: ``horizon.uav``;
    ``closed``:
    the closed-loop rows (:data:`rsmhp.studies.horizon.simulate_uav.CLOSED_COLUMNS`); ``planner``:
    ``uav.planner`` (its maxiter, maxfun and restarts: HZ-3's measured text)."""
    return [e.claim for e in horizon_evidence(approx, summary, cfg, seed, closed, planner)]


def horizon_evidence(
    approx: pd.DataFrame,
    summary: pd.DataFrame,
    cfg: Mapping[str, Any],
    seed: int,
    closed: pd.DataFrame | None = None,
    planner: Mapping[str, Any] | None = None,
) -> list[PrimaryTest]:
    """The claims of :func:`horizon_claims` (same arguments), each with its primary test's
    p-value and the percentile-bootstrap CI it replaced (:class:`PrimaryTest`): HZ-1 where
    NBO ran, HZ-2 from the tree's first pruned horizon where both members ran, then HZ-3."""
    hs = sorted(int(h) for h in summary["H"].unique()) if not summary.empty else []
    if len(hs) < 2:
        return []
    h_lo, h_hi, n_boot = hs[0], hs[-1], int(cfg["bootstrap"])
    nbo = registry.baseline()().name
    rules = cfg.get("claims", {}) or {}
    tree, mc = rules.get("tree"), rules.get("monte_carlo")
    tree_lo = _pruned_from(tree, hs) if tree else None
    out: list[PrimaryTest] = []
    for model in dict.fromkeys(summary["model"]):
        present = set(summary.loc[summary["model"] == model, "method"])
        if nbo in present:
            ev = hz1_evidence(approx, model, nbo, h_lo, h_hi, seed, n_boot)
            out.append(_primary_test(HZ_1, ev))
        if tree and mc and {tree, mc} <= present and tree_lo is not None and tree_lo < h_hi:
            ev = hz2_evidence(approx, model, tree, mc, tree_lo, h_hi, seed, n_boot)
            out.append(_primary_test(HZ_2, ev))
    out += _hz3_claims(closed, cfg, mc, seed, n_boot, planner)
    return out


def _pruned_from(tree: str, hs: list[int]) -> int | None:
    """The smallest horizon of ``hs`` at which ``tree`` has more than M leaves (N^(H+1) > M,
    so it is pruned and keeps M trajectories), or None."""
    m = registry.from_name(tree)
    pruned = [h for h in hs if m.n_branch ** (h + 1) > m.max_keep]
    return pruned[0] if pruned else None


def _hz3_claims(
    closed: pd.DataFrame | None,
    cfg: Mapping[str, Any],
    mc: str | None,
    seed: int,
    n_boot: int,
    planner: Mapping[str, Any] | None = None,
) -> list[PrimaryTest]:
    """HZ-3 on ``horizon.uav.claims.closed_model``, between the smallest and largest H of the
    closed-loop rows (none if either is missing)."""
    model = (cfg.get("claims", {}) or {}).get("closed_model") or ""
    if closed is None or closed.empty or not model or not mc:
        return []
    sel = closed[closed["model"] == model]
    hs = sorted(int(h) for h in sel["H"].unique())
    if len(hs) < 2 or mc not in set(sel["method"]):
        return []
    ev = hz3_evidence(closed, model, mc, hs[0], hs[-1], seed, n_boot, planner)
    return [_primary_test(HZ_3, ev)]


# ------------------------------------------------------------------ HZ-4, HZ-5 (oven LQG)


def hz4_rule(N: int, M: int, h_lo: int, h_hi: int) -> Rule:
    """HZ-4: the pruned tree's relative RMSE grows more from H_lo to H_hi than Monte Carlo's
    with as many trajectories (oven LQG, exact J)."""
    basis = WORDS("hz_4_basis", N=N, M=M, h_lo=h_lo, h_hi=h_hi)
    return ci_side(KEY, 0.0, claimed="above", basis=basis)


def hz4_evidence(est: pd.DataFrame, a_model: float, N: int, M: int, h_lo: int, h_hi: int,
                 seed: int, n_boot: int) -> Evidence:  # fmt: skip
    """HZ-4 at the oven model's ``a_model``: d = growth of the pruned tree's (N, M) relative
    RMSE from ``h_lo`` to ``h_hi`` − that of Monte Carlo with n = M
    (:func:`rsmhp.studies.horizon.summarise_lqg.pruned_growth`), in pp."""
    g = pruned_growth(est, a_model, N, M, h_lo, h_hi, seed, n_boot)
    # the bootstrap resamples each of the four cells' independent replicates: n is the
    # replicates per cell (the smallest cell)
    key = KeyNumber(WORDS("hz_4_key", h_lo=h_lo, h_hi=h_hi), 100 * g.mean, 100 * g.low,
                    100 * g.high, unit="pp", reproducible="statistical", digits=2, null=0.0,
                    n=_units(g.replicates))  # fmt: skip
    values = {
        "a": f"{a_model:g}",
        "N": N,
        "M": M,
        "h_lo": h_lo,
        "h_hi": h_hi,
        "replicates": g.replicates,
        "tree_lo": _pct(g.pruned_lo),
        "tree_hi": _pct(g.pruned_hi),
        "mc_lo": _pct(g.mc_lo),
        "mc_hi": _pct(g.mc_hi),
        "mc_growth": fmt(100 * g.mc_growth, 3, True),
        "mc_ci": fmt_ci(100 * g.mc_growth_low, 100 * g.mc_growth_high, 3, True),
        "leaves": f"{float(N) ** h_hi:.1e}",
    }
    facts = {f"{KEY}_low": g.low, f"{KEY}_high": g.high}
    return Evidence(key=key, facts=facts, values=values, rule=hz4_rule(N, M, h_lo, h_hi))


HZ_4 = ClaimSpec(
    id="HZ-4", setup=WORDS("hz_4_setup"), evidence=hz4_evidence, words=WORDS, part="beyond"
)

HZ5_RULE = Rule(
    basis=WORDS("hz_5_basis"),
    cases=(
        Case(
            "supported",
            WORDS("hz_5_rule_supported"),
            lambda f: f["max |z|"] <= f["z limit"],
        ),
    ),
    otherwise="not supported",
)


def hz5_evidence(regret_summary: pd.DataFrame, z: ZCheck) -> Evidence:
    """HZ-5: the family ``z`` (``DEC-2`` of :func:`rsmhp.models.lqg.regret_summary.z_families`)
    of uniform Monte Carlo's mean regret against its closed form, and how close the closed
    form is to its limit at the largest H."""
    mc = regret_summary[
        (regret_summary["method"] == "mc") & (regret_summary["weighting"] == "uniform")
    ]
    h_hi = int(mc["H"].max())
    far = mc[mc["H"] == h_hi]
    gap = float(np.max(np.abs(far["closed_form"] / far["limit"] - 1.0)))
    return Evidence(
        key=KeyNumber(
            WORDS("hz_5_key", cells=z.cells), z.max_abs_z, reproducible="bitwise", digits=3
        ),
        facts={"max |z|": z.max_abs_z, "z limit": z.limit},
        values={
            "h_hi": h_hi,
            "limit": fmt(z.limit, 3),
            "gap": fmt(100 * gap, 2),
            "hs": ", ".join(str(int(h)) for h in sorted(mc["H"].unique())),
            "a_values": ", ".join(f"{a:g}" for a in sorted(mc["a"].unique())),
            "ps": ", ".join(str(int(p)) for p in sorted(mc["P"].unique())),
        },
    )


HZ_5 = ClaimSpec(
    id="HZ-5",
    setup=WORDS("hz_5_setup"),
    evidence=hz5_evidence,
    words=WORDS,
    rule=HZ5_RULE,
    part="beyond",
    check=True,
)


def lqg_horizon_claims(
    est: pd.DataFrame,
    regret_summary: pd.DataFrame,
    cfg: Mapping[str, Any],
    a_model: float,
    seed: int,
) -> list[Claim]:
    """HZ-4 (at ``a_model``, the oven model's a) and HZ-5 (module doc). ``est``: the estimator
    rows of :func:`rsmhp.studies.horizon.simulate_lqg.run_lqg_estimators`; ``regret_summary``:
    :func:`rsmhp.studies.horizon.summarise_lqg.summarize_lqg_horizon_regret`; ``cfg``:
    ``horizon.lqg``."""
    out: list[Claim] = []
    hs = sorted(int(h) for h in cfg.get("sim_H", []) or [])
    tree = (cfg.get("claims", {}) or {}).get("pruned", {}) or {}
    a_sim = [float(a) for a in cfg.get("sim_a", []) or []]
    if tree and hs and float(a_model) in a_sim and not est.empty:
        N, M = int(tree["N"]), int(tree["M"])
        h_lo = pruned_from(N, M, hs)
        if h_lo is not None and h_lo < hs[-1]:
            n_boot = int(cfg["bootstrap"])
            out.append(HZ_4.build(est, a_model, N, M, h_lo, hs[-1], seed, n_boot))
    z = z_families(regret_summary).get("DEC-2") if not regret_summary.empty else None
    if z is not None:
        out.append(HZ_5.build(regret_summary, z))
    return out
