r"""Equal-compute study, claims FR-1-<model>, FR-2-<model>, FR-3-<model>: each a key number
from :mod:`rsmhp.studies.frontier.summarise` and a verdict rule (:mod:`rsmhp.report.verdicts`)
evaluated on facts. The compared members are the config's budget members
(``frontier.budget.members``: one per family, the largest that fit the planning
budget per step in the study's first run); the rules' margins are
``frontier.claims``. All key numbers are statistical (closed loop, optimiser); all
claims are beyond the paper (part "beyond"), one per model variant of the study.

* **FR-1** (:func:`fr1_rule`): d = open-loop relative regret of RQMC − that of Monte Carlo
  (RS-MHP), both budget members, paired per belief state (pp). RQMC decides better:
  *equivalent* if the 95% bootstrap CI of mean d lies inside ±m (``margin_pp``), else
  *supported* below 0, *not supported* above 0, *inconclusive* otherwise.
* **FR-2** (:func:`fr2_rule`): d = regret of the sigma points − that of the Monte-Carlo
  member ``sigma_reference`` (pp). The sigma points decide as well as it, up to m: *supported*
  if the CI lies below +m (non-inferiority), *not supported* above +m, *inconclusive*
  otherwise.
* **FR-3** (:func:`fr3_rule`): d = closed-loop mean location error of the tree search
  (PFT-DPW) − that of Monte Carlo, both budget members, paired over runs (m). The tree
  search tracks better: *equivalent* inside ±``margin_m``, else *supported* below 0, *not
  supported* above 0, *inconclusive* otherwise. An open-loop regret pointing the other way is
  named as contrary evidence.

Timing enters no verdict (times differ across machines, decisions reproduce): each claim
states the members' measured milliseconds per step against the budget, and a member over
the budget, or a larger member of its family within it, is named as contrary evidence.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import pandas as pd

from rsmhp.models.uav import methods as registry
from rsmhp.models.uav.methods.base import Method
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.models.uav.methods.rqmc import RQMC
from rsmhp.models.uav.methods.sigma_points import SigmaPoints
from rsmhp.models.uav.methods.tree_search import TreeSearch
from rsmhp.report.ledger import Claim, KeyNumber
from rsmhp.report.markdown import fmt, fmt_ci, param_text
from rsmhp.report.palette import method_label
from rsmhp.report.verdicts import Rule, ci_side, decisive_p, non_inferior
from rsmhp.studies.frontier.summarise import Paired, budget_check, paired_difference

__all__ = [
    "KEY",
    "budget_member",
    "fr1_rule",
    "fr2_rule",
    "fr3_rule",
    "frontier_claims",
    "paired_facts",
]

#: the key number of every claim here, as the rules name it (facts ``mean d_low/high``)
KEY = "mean d"


def paired_facts(d: Paired) -> dict[str, float]:
    """The CI of a paired difference as the facts of the rules here."""
    return {f"{KEY}_low": float(d.low), f"{KEY}_high": float(d.high)}


def fr1_rule(margin_pp: float) -> Rule:
    """FR-1: RQMC's open-loop regret is below Monte Carlo's (equivalence margin ±m pp)."""
    return ci_side(
        KEY,
        0.0,
        claimed="below",
        basis="d = relative regret of RQMC − RS-MHP (budget members), paired per belief state (pp)",
        margin=margin_pp,
        margin_text=f"{param_text(margin_pp)} pp",
    )


def fr2_rule(margin_pp: float, reference: str) -> Rule:
    """FR-2: the sigma points decide at most m pp worse than ``reference`` (non-inferiority)."""
    return non_inferior(
        KEY,
        margin_pp,
        margin_text=f"{param_text(margin_pp)} pp",
        basis=f"d = relative regret of the sigma points − {method_label(reference)}, paired "
        "per belief state (pp)",
    )


def fr3_rule(margin_m: float) -> Rule:
    """FR-3: the tree search's closed-loop error is below Monte Carlo's (margin ±m m)."""
    return ci_side(
        KEY,
        0.0,
        claimed="below",
        basis="d = closed-loop mean location error of the tree search − RS-MHP (budget "
        "members), paired over runs (m)",
        margin=margin_m,
        margin_text=f"{param_text(margin_m)} m",
    )


def budget_member(members: Sequence[str], family: type[Method]) -> str | None:
    """The budget member of ``family`` (a registry class) in ``members``, if any."""
    hits = [m for m in members if isinstance(registry.from_name(m), family)]
    return hits[0] if hits else None


def _runs(d: Paired) -> int | None:
    """The runs the cluster-t CI of ``d`` rests on (its clusters: paired runs, also for the
    regret, whose belief states cluster in runs), as :attr:`KeyNumber.n`; ``None`` below 2."""
    return int(d.clusters) if d.clusters >= 2 else None


def _key(
    name: str, d: Paired, unit: str, null: float, p_value: float, margin: float | None
) -> KeyNumber:
    """The key number of an FR claim: ``d``'s mean and cluster-t CI over its runs, and the
    equivalence ``margin`` of a :func:`~rsmhp.report.verdicts.ci_side` rule (``None`` for a
    non-inferiority rule, whose margin is the ``null``)."""
    return KeyNumber(
        name,
        float(d.mean),
        float(d.low),
        float(d.high),
        unit=unit,
        reproducible="statistical",
        digits=3 if unit == "m" else 2,
        null=null,
        p_value=p_value,
        n=_runs(d),
        margin=margin,
    )


def _p_side(d: Paired, verdict: str, margin: float) -> float:
    """The p-value of a :func:`fr1_rule` / :func:`fr3_rule` verdict (claimed: below 0; inside
    ±margin for ``equivalent``): :func:`rsmhp.report.verdicts.decisive_p` on the cluster-t CI."""
    bounds = {
        "supported": [(0.0, "below")],
        "not supported": [(0.0, "above")],
        "equivalent": [(-margin, "above"), (margin, "below")],
    }.get(verdict, [(0.0, "below")])
    return decisive_p(verdict, d.mean, d.se, d.df, bounds)


def _p_noninferior(d: Paired, verdict: str, margin: float) -> float:
    """The p-value of an :func:`fr2_rule` verdict (below +margin, or above it)."""
    side = "above" if verdict == "not supported" else "below"
    return decisive_p(verdict, d.mean, d.se, d.df, [(margin, side)])


def _timing(check: pd.DataFrame, model: str, names: Sequence[str], budget: float) -> str:
    """``RQMC N_T=256 0.73 ms, RS-MHP N_T=256 0.49 ms per step (budget 1.25 ms)``."""
    c = check[check["model"] == model].set_index("member")
    parts = [
        f"{method_label(n)} {fmt(float(c.loc[n, 'plan_ms']), 3)} ms" for n in names if n in c.index
    ]
    return f"{', '.join(parts)} per step, median over runs (budget {param_text(budget)} ms)"


def _timing_contrary(check: pd.DataFrame, model: str, names: Sequence[str]) -> list[str]:
    """A member over the budget on this run, or a larger member of its family within it."""
    c = check[check["model"] == model].set_index("member")
    out = []
    for n in names:
        if n not in c.index:
            continue
        r = c.loc[n]
        if not bool(r["fits"]):
            out.append(f"{method_label(n)} took {fmt(float(r['plan_ms']), 3)} ms, over the budget")
        elif r["largest_fitting"] and r["largest_fitting"] != n:
            out.append(
                f"{method_label(str(r['largest_fitting']))} ({fmt(float(r['largest_ms']), 3)} "
                f"ms) also fits the budget on this run"
            )
    return out


def _diff_text(d: Paired, unit: str, digits: int = 3) -> str:
    return f"{fmt(d.mean, digits, True)} {unit} {fmt_ci(d.low, d.high, digits, True)}"


def _model_claims(
    model: str,
    runs: pd.DataFrame,
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    check: pd.DataFrame,
    members: Sequence[str],
    cfg: Mapping[str, Any],
    seed: int,
    n_boot: int,
) -> list[Claim]:
    rules = cfg["claims"]
    budget = float(cfg["budget"]["ms_per_step"])
    margin_pp, margin_m = float(rules["margin_pp"]), float(rules["margin_m"])
    mc = budget_member(members, MonteCarlo)
    rqmc = budget_member(members, RQMC)
    sigma = budget_member(members, SigmaPoints)
    dpw = budget_member(members, TreeSearch)
    ref = str(rules["sigma_reference"])
    run_methods = set(summary.loc[summary["model"] == model, "method"])
    setup = f"UAV '{model}', budget {param_text(budget)} ms per step"
    src = "Beyond the paper (its UAV study compares NBO, RS-MHP and pruning only): "
    out: list[Claim] = []

    def diff(table: pd.DataFrame, a: str, b: str, measure: str) -> Paired:
        return paired_difference(table, model, a, b, measure, seed, n_boot)

    if mc and rqmc and {mc, rqmc} <= run_methods:
        d = diff(regret, rqmc, mc, "regret")
        e = diff(runs, rqmc, mc, "error")
        rule = fr1_rule(margin_pp)
        verdict = rule.verdict(paired_facts(d))
        out.append(
            Claim(
                f"FR-1-{model}",
                f"On '{model}', within the planning budget, {method_label(rqmc)} chooses better "
                f"plans than {method_label(mc)} (lower open-loop regret)",
                src + "the estimator study's variance reduction of scrambled Sobol' points, "
                "tested as a planner at equal compute",
                _key(
                    f"regret {method_label(rqmc)} − {method_label(mc)}, paired mean",
                    d,
                    "pp",
                    0.0,
                    _p_side(d, verdict, margin_pp),
                    margin_pp,
                ),
                verdict,
                rule.text(),
                measured=f"{d.n} belief states; closed loop {method_label(rqmc)} − "
                f"{method_label(mc)} = {_diff_text(e, 'm')} over {e.n} paired runs; "
                f"{_timing(check, model, [rqmc, mc], budget)}",
                part="beyond",
                setup=setup,
                contrary="; ".join(_timing_contrary(check, model, [rqmc, mc])),
            )
        )
    if sigma and ref in run_methods and sigma in run_methods:
        d = diff(regret, sigma, ref, "regret")
        e = diff(runs, sigma, ref, "error")
        rule = fr2_rule(margin_pp, ref)
        verdict = rule.verdict(paired_facts(d))
        out.append(
            Claim(
                f"FR-2-{model}",
                f"On '{model}', the sigma points decide as well as {method_label(ref)}, up to "
                f"{param_text(margin_pp)} pp of open-loop regret",
                src + "a deterministic cubature set of the joint belief in place of random "
                "hypotheses",
                _key(
                    f"regret sigma points − {method_label(ref)}, paired mean",
                    d,
                    "pp",
                    margin_pp,
                    _p_noninferior(d, verdict, margin_pp),
                    None,
                ),
                verdict,
                rule.text(),
                measured=f"{d.n} belief states; closed loop sigma points − {method_label(ref)} "
                f"= {_diff_text(e, 'm')} over {e.n} paired runs; "
                f"{_timing(check, model, [sigma, ref], budget)}",
                part="beyond",
                setup=setup,
                contrary="; ".join(_timing_contrary(check, model, [sigma])),
            )
        )
    if mc and dpw and {mc, dpw} <= run_methods:
        e = diff(runs, dpw, mc, "error")
        d = diff(regret, dpw, mc, "regret")
        rule = fr3_rule(margin_m)
        verdict = rule.verdict(paired_facts(e))
        s = summary[summary["model"] == model].set_index("method")
        # the open-loop regret scores all H steps of a plan, also those below the depth the
        # tree search reached (its tail comes from the rollout policy): it is reported, not
        # named as contrary evidence to a closed-loop claim
        contrary = _timing_contrary(check, model, [dpw, mc])
        out.append(
            Claim(
                f"FR-3-{model}",
                f"On '{model}', within the planning budget, {method_label(dpw)} (PFT-DPW) tracks "
                f"better than {method_label(mc)} (lower closed-loop error)",
                src + "the paper calls RS-MHP a Monte-Carlo tree search but never compares it "
                "with the progressive-widening tree search used for continuous belief spaces",
                _key(
                    f"error {method_label(dpw)} − {method_label(mc)}, paired mean",
                    e,
                    "m",
                    0.0,
                    _p_side(e, verdict, margin_m),
                    margin_m,
                ),
                verdict,
                rule.text(),
                measured=f"{e.n} paired runs; mean error {fmt(float(s.loc[dpw, 'mean_error']))} "
                f"vs {fmt(float(s.loc[mc, 'mean_error']))} m; track lost in "
                f"{fmt(100 * float(s.loc[dpw, 'lost_rate']), 3)}% vs "
                f"{fmt(100 * float(s.loc[mc, 'lost_rate']), 3)}% of runs; open-loop relative "
                f"regret {method_label(dpw)} − {method_label(mc)} = {_diff_text(d, 'pp', 2)} "
                f"over {d.n} belief states (all H steps of each plan scored, also those below "
                f"the tree's depth); {_timing(check, model, [dpw, mc], budget)}",
                part="beyond",
                setup=setup,
                contrary="; ".join(contrary),
            )
        )
    return out


def frontier_claims(
    runs: pd.DataFrame,
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    cfg: Mapping[str, Any],
    seed: int,
) -> list[Claim]:
    """FR-1..3 per model of ``summary`` (module doc), in the config's model order. ``runs``
    and ``regret``: the study's tables of every model; ``summary``:
    :func:`rsmhp.studies.frontier.summarise.summarize_frontier`; ``cfg``: ``frontier``."""
    for key in ("budget", "claims", "bootstrap"):
        if key not in cfg:
            raise ValueError(f"frontier lacks {key!r} (the config schema fills it)")
    members = list(cfg["budget"]["members"])
    if summary.empty or not members:
        return []
    check = budget_check(summary, members, float(cfg["budget"]["ms_per_step"]))
    n_boot = int(cfg["bootstrap"])
    out: list[Claim] = []
    for model in dict.fromkeys(summary["model"]):
        out += _model_claims(model, runs, regret, summary, check, members, cfg, seed, n_boot)
    return out


# ------------------------------------------------------------------------ the protocol

#: the tests a preregistered FR claim may use
CONFIRM_TESTS = ("superiority", "non-inferiority")


def confirm_rule(test: str, a: str, b: str, budget_ms: float, margin_m: float) -> Rule:
    """The rule of a preregistered FR claim: d = closed-loop mean location error of the tuned
    member ``a`` − that of ``b`` at ``budget_ms`` per step, paired over runs (95% t
    interval). ``superiority``: equivalent inside ±margin, supported below 0, not supported
    above 0; ``non-inferiority``: supported below +margin, not supported above it."""
    basis = (
        f"d = closed-loop mean location error, tuned {a} − {b} at {param_text(budget_ms)} ms "
        "per step, paired over runs (m; 95% t interval)"
    )
    text = f"{param_text(margin_m)} m"
    if test == "superiority":
        return ci_side(KEY, 0.0, claimed="below", basis=basis, margin=margin_m, margin_text=text)
    if test == "non-inferiority":
        return non_inferior(KEY, margin_m, margin_text=text, basis=basis)
    raise ValueError(f"test: {test!r} (allowed: {', '.join(CONFIRM_TESTS)})")


def _label(families: Mapping[str, str], family: str) -> str:
    return families.get(family, family)


def confirm_claims(
    runs: pd.DataFrame,
    summary: pd.DataFrame,
    lad: pd.DataFrame,
    prereg: Mapping[str, Any],
    chosen: Mapping[str, Mapping[str, Mapping[str, Any]]],
    prereg_sha: str,
) -> list[Claim]:
    """The preregistered FR claims (``prereg["claims"]``: id -> family, against, test,
    margin_m) on every model of ``prereg["models"]`` at its headline budget, from the
    confirmatory run: ``runs`` (:data:`rsmhp.studies.frontier.simulate.CONFIG_RUN_COLUMNS`),
    ``summary`` (:func:`rsmhp.studies.frontier.summarise.summarize_configs`), ``lad``
    (:func:`rsmhp.studies.frontier.summarise.ladder`), ``chosen`` (model -> budget text -> family ->
    :class:`rsmhp.pipeline.protocol.Configuration`). Each claim names the preregistration (its
    sha256) in its rule; a member over the budget on this run's times, and a budget of the
    ladder where the difference lies on the other side, are contrary evidence. Claims whose
    families have no member at the headline budget are left out and said so."""
    from rsmhp.studies.frontier.summarise import paired_configs, prob_improvement

    labels = {c.family: c.family_label for c in registry.families()}
    b = float(prereg["headline_budget_ms"])
    out: list[Claim] = []
    s = summary.set_index(["model", "config"])
    for model in prereg["models"]:
        per = chosen.get(model, {}).get(f"{b:g}", {})
        wide = runs[runs["model"] == model].pivot(
            index="run", columns="config", values="mean_error"
        )
        for cid, spec in prereg["claims"].items():
            fam, ref = spec["family"], spec["against"]
            if fam not in per or ref not in per:
                continue
            a_cfg, b_cfg = per[fam], per[ref]
            d = paired_configs(runs, model, a_cfg.name, b_cfg.name)
            margin = float(spec["margin_m"])
            rule = confirm_rule(spec["test"], _label(labels, fam), _label(labels, ref), b, margin)
            verdict = rule.verdict(paired_facts(d))
            p = (
                _p_side(d, verdict, margin)
                if spec["test"] == "superiority"
                else _p_noninferior(d, verdict, margin)
            )
            pi = prob_improvement(wide[a_cfg.name].to_numpy(), wide[b_cfg.name].to_numpy())
            ra, rb = s.loc[(model, a_cfg.name)], s.loc[(model, b_cfg.name)]
            contrary = []
            for name, r in ((a_cfg.label(), ra), (b_cfg.label(), rb)):
                # the tuning rule's cost: the larger of the timed median and the closed
                # loop's own mean time per step
                for what, col in (("timed", "plan_ms"), ("in closed loop", "loop_ms")):
                    if float(r[col]) > b:
                        contrary.append(
                            f"{name} took {fmt(float(r[col]), 3)} ms per step {what}, over "
                            "the budget"
                        )
            # the other budgets of the ladder whose CI lies where this verdict says it does
            # not: better where the verdict is "not supported", worse where "supported",
            # outside the margin where "equivalent", off 0 either way where "inconclusive"
            other = lad[(lad["model"] == model) & (lad["family"] == fam) & (lad["budget_ms"] != b)]
            bound = 0.0 if spec["test"] == "superiority" else margin
            for r in other.itertuples(index=False):
                lo_, hi_ = r.diff_mc_low, r.diff_mc_high
                better, worse = hi_ < bound, lo_ > bound
                if verdict == "equivalent":
                    against = lo_ < -margin or hi_ > margin
                elif verdict == "supported":
                    against = lo_ > bound
                elif verdict == "not supported":
                    against = hi_ < bound
                else:
                    against = better or worse
                if against:
                    how = "better" if r.diff_mc < 0 else "worse"
                    contrary.append(
                        f"at {param_text(r.budget_ms)} ms it tracks {how}: "
                        f"{fmt(r.diff_mc, 3, True)} m {fmt_ci(lo_, hi_, 3, True)}"
                    )
            depth = ""
            if a_cfg.family == "dpw":
                depth = (
                    f"; the tree search's plans follow its tree for "
                    f"{fmt(float(ra['plan_depth']), 3)} of H steps on average (deepest node "
                    f"{fmt(float(ra['max_depth']), 3)}, {fmt(float(ra['root_actions']), 3)} root "
                    f"actions, {fmt(100 * float(ra['frac_depth1']), 3)}% of simulations leave "
                    "the tree at depth 1)"
                )
            claim_text = (
                f"On '{model}', at {param_text(b)} ms of planning per step, the tuned "
                f"{_label(labels, fam)} member "
                + (
                    f"tracks better than the tuned {_label(labels, ref)} member (lower "
                    "closed-loop error)"
                    if spec["test"] == "superiority"
                    else f"tracks as well as the tuned {_label(labels, ref)} member, up to "
                    f"{param_text(margin)} m of closed-loop error"
                )
            )
            out.append(
                Claim(
                    f"{cid}-{model}",
                    claim_text,
                    "Beyond the paper (its UAV study compares NBO, RS-MHP and pruning only): "
                    + str(spec.get("why", "")),
                    KeyNumber(
                        f"error, tuned {_label(labels, fam)} − {_label(labels, ref)}, paired mean",
                        float(d.mean),
                        float(d.low),
                        float(d.high),
                        unit="m",
                        reproducible="statistical",
                        digits=3,
                        null=0.0 if spec["test"] == "superiority" else margin,
                        p_value=p,
                        n=_runs(d),
                        # a superiority rule's equivalence margin; a non-inferiority rule's
                        # margin is the null
                        margin=margin if spec["test"] == "superiority" else None,
                    ),
                    verdict,
                    rule.text() + f" (preregistered, sha256 {prereg_sha[:12]})",
                    measured=(
                        f"{a_cfg.label()} against {b_cfg.label()}: "
                        f"{d.n} paired runs on the confirmatory stream; mean error "
                        f"{fmt(float(ra['mean_error']))} vs {fmt(float(rb['mean_error']))} m; "
                        f"probability of improvement {fmt(pi[0], 3)} "
                        f"{fmt_ci(pi[1], pi[2], 3)}; {a_cfg.label()} "
                        f"{fmt(float(ra['plan_ms']), 3)} ms and "
                        f"{fmt(float(ra['work_per_step']), 3)} model steps per step, "
                        f"{b_cfg.label()} {fmt(float(rb['plan_ms']), 3)} ms and "
                        f"{fmt(float(rb['work_per_step']), 3)} model steps (interleaved timing, "
                        f"median); in closed loop {fmt(float(ra['loop_ms']), 3)} and "
                        f"{fmt(float(rb['loop_ms']), 3)} ms per step (mean over runs){depth}"
                    ),
                    part="beyond",
                    setup=f"UAV '{model}', confirmatory stream, {param_text(b)} ms per step",
                    contrary="; ".join(contrary),
                )
            )
    return out
