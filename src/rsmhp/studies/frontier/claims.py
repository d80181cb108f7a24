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

Each claim is a :class:`rsmhp.report.claimspec.ClaimSpec` (:data:`FR_1` .. :data:`FR_3`, and
:data:`FR_CONFIRM` for the preregistered claims of the confirmatory run): an evidence function
(:func:`fr1_evidence` .. :func:`fr3_evidence`, :func:`confirm_evidence`: the key number, the
facts its rule reads and the preformatted values of its texts) and the words of ``claims.md``
beside this module (:data:`WORDS`: the claims' sentences, contrary evidence, the rules' bases,
the key numbers' names and the setups).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import pandas as pd

from rsmhp.models.uav import methods as registry
from rsmhp.models.uav.methods.base import Method
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.models.uav.methods.rqmc import RQMC
from rsmhp.models.uav.methods.sigma_points import SigmaPoints
from rsmhp.models.uav.methods.tree_search import TreeSearch
from rsmhp.report.claimspec import ClaimSpec, Evidence
from rsmhp.report.ledger import OVER_BUDGET, Claim, KeyNumber
from rsmhp.report.markdown import fmt, fmt_ci, param_text
from rsmhp.report.naming import depth_name
from rsmhp.report.palette import method_label
from rsmhp.report.templates import Words
from rsmhp.report.verdicts import Case, Rule, ci_side, decisive_p, non_inferior
from rsmhp.studies.frontier.summarise import (
    Paired,
    budget_check,
    paired_configs,
    paired_difference,
    prob_improvement,
)

if TYPE_CHECKING:
    from rsmhp.pipeline.protocol import Configuration

__all__ = [
    "CONFIRM_TESTS",
    "FR_1",
    "FR_2",
    "FR_3",
    "FR_CONFIRM",
    "KEY",
    "WORDS",
    "Comparison",
    "ExploratoryRun",
    "PreregisteredRule",
    "budget_member",
    "confirm_claims",
    "confirm_evidence",
    "confirm_rule",
    "fr1_evidence",
    "fr1_rule",
    "fr2_evidence",
    "fr2_rule",
    "fr3_evidence",
    "fr3_rule",
    "frontier_claims",
    "paired_facts",
]

#: the key number of every claim here, as the rules name it (facts ``mean d_low/high``)
KEY = "mean d"

#: the claims' sentences, rule bases, key-number names and setups (``claims.md``)
WORDS = Words("rsmhp.studies.frontier", "claims.md")


def paired_facts(d: Paired) -> dict[str, float]:
    """The CI of a paired difference as the facts of the rules here."""
    return {f"{KEY}_low": float(d.low), f"{KEY}_high": float(d.high)}


def fr1_rule(margin_pp: float) -> Rule:
    """FR-1: RQMC's open-loop regret is below Monte Carlo's (equivalence margin ±m pp)."""
    return ci_side(
        KEY,
        0.0,
        claimed="below",
        basis=WORDS("fr_1_basis"),
        margin=margin_pp,
        margin_text=f"{param_text(margin_pp)} pp",
    )


def fr2_rule(margin_pp: float, reference: str) -> Rule:
    """FR-2: the sigma points decide at most m pp worse than ``reference`` (non-inferiority)."""
    return non_inferior(
        KEY,
        margin_pp,
        margin_text=f"{param_text(margin_pp)} pp",
        basis=WORDS("fr_2_basis", reference=method_label(reference)),
    )


def fr3_rule(margin_m: float) -> Rule:
    """FR-3: the tree search's closed-loop error is below Monte Carlo's (margin ±m m)."""
    return ci_side(
        KEY,
        0.0,
        claimed="below",
        basis=WORDS("fr_3_basis"),
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


def _diff_text(d: Paired, unit: str, digits: int = 3) -> str:
    """``+1.23 unit [+0.50, +2.00]``: a paired difference with its CI."""
    return f"{fmt(d.mean, digits, True)} {unit} {fmt_ci(d.low, d.high, digits, True)}"


# ------------------------------------------------------------ the exploratory run: FR-1..3


@dataclass(frozen=True, eq=False)
class ExploratoryRun:
    """What the FR claims of one ``model`` read from the exploratory run: its ``runs`` and
    ``regret`` tables (every model), ``summary``
    (:func:`rsmhp.studies.frontier.summarise.summarize_frontier`), the budget ``check``
    (:func:`rsmhp.studies.frontier.summarise.budget_check`), the planning ``budget`` (ms per
    step) and the bootstrap's ``seed`` and ``n_boot``."""

    runs: pd.DataFrame
    regret: pd.DataFrame
    summary: pd.DataFrame
    check: pd.DataFrame
    model: str
    budget: float
    seed: int
    n_boot: int

    def diff(self, table: pd.DataFrame, a: str, b: str, measure: str) -> Paired:
        """d = ``measure`` of ``a`` − that of ``b`` on the model, paired
        (:func:`rsmhp.studies.frontier.summarise.paired_difference`)."""
        return paired_difference(table, self.model, a, b, measure, self.seed, self.n_boot)

    def timing(self, names: Sequence[str]) -> dict[str, Any]:
        """The members' median planning ms per step against the budget (the ``timing``
        macro's values)."""
        c = self.check[self.check["model"] == self.model].set_index("member")
        members = [
            {"label": method_label(n), "ms": fmt(float(c.loc[n, "plan_ms"]), 3)}
            for n in names
            if n in c.index
        ]
        return {"members": members, "budget": param_text(self.budget)}

    def contrary(self, names: Sequence[str]) -> list[dict[str, Any]]:
        """A member over the budget on this run (``over``), or a larger member of its family
        within it (the ``timing_contrary`` macro's values)."""
        c = self.check[self.check["model"] == self.model].set_index("member")
        out: list[dict[str, Any]] = []
        for n in names:
            if n not in c.index:
                continue
            r = c.loc[n]
            if not bool(r["fits"]):
                out.append(
                    {"over": True, "label": method_label(n), "ms": fmt(float(r["plan_ms"]), 3)}
                )
            elif r["largest_fitting"] and r["largest_fitting"] != n:
                label, ms = method_label(str(r["largest_fitting"])), float(r["largest_ms"])
                out.append({"over": False, "label": label, "ms": fmt(ms, 3)})
        return out

    def values(self) -> dict[str, Any]:
        """The values every FR claim's id and setup read."""
        return {"model": self.model, "budget": param_text(self.budget)}


def fr1_evidence(run: ExploratoryRun, rqmc: str, mc: str, margin_pp: float) -> Evidence:
    """FR-1: d = open-loop relative regret of ``rqmc`` − ``mc`` (pp), paired per belief
    state; the closed-loop difference beside it."""
    d = run.diff(run.regret, rqmc, mc, "regret")
    e = run.diff(run.runs, rqmc, mc, "error")
    rule = fr1_rule(margin_pp)
    p = _p_side(d, rule.verdict(paired_facts(d)), margin_pp)
    names = {"rqmc": method_label(rqmc), "mc": method_label(mc)}
    return Evidence(
        key=_key(WORDS("fr_1_key", **names), d, "pp", 0.0, p, margin_pp),
        facts=paired_facts(d),
        rule=rule,
        values={
            **run.values(),
            **names,
            **run.timing([rqmc, mc]),
            "states": d.n,
            "error": _diff_text(e, "m"),
            "runs": e.n,
            "contrary": run.contrary([rqmc, mc]),
        },
    )


def fr2_evidence(run: ExploratoryRun, sigma: str, ref: str, margin_pp: float) -> Evidence:
    """FR-2: d = open-loop relative regret of ``sigma`` − ``ref`` (pp), paired per belief
    state, against the non-inferiority margin; the closed-loop difference beside it."""
    d = run.diff(run.regret, sigma, ref, "regret")
    e = run.diff(run.runs, sigma, ref, "error")
    rule = fr2_rule(margin_pp, ref)
    p = _p_noninferior(d, rule.verdict(paired_facts(d)), margin_pp)
    reference = method_label(ref)
    return Evidence(
        key=_key(WORDS("fr_2_key", reference=reference), d, "pp", margin_pp, p, None),
        facts=paired_facts(d),
        rule=rule,
        values={
            **run.values(),
            **run.timing([sigma, ref]),
            "reference": reference,
            "margin": param_text(margin_pp),
            "states": d.n,
            "error": _diff_text(e, "m"),
            "runs": e.n,
            "contrary": run.contrary([sigma]),
        },
    )


def fr3_evidence(run: ExploratoryRun, dpw: str, mc: str, margin_m: float) -> Evidence:
    """FR-3: d = closed-loop mean location error of ``dpw`` − ``mc`` (m), paired over runs;
    the open-loop regret difference beside it (reported, no contrary evidence: it scores plan
    steps below the tree's depth too)."""
    e = run.diff(run.runs, dpw, mc, "error")
    d = run.diff(run.regret, dpw, mc, "regret")
    rule = fr3_rule(margin_m)
    p = _p_side(e, rule.verdict(paired_facts(e)), margin_m)
    s = run.summary[run.summary["model"] == run.model].set_index("method")
    names = {"dpw": method_label(dpw), "mc": method_label(mc)}
    return Evidence(
        key=_key(WORDS("fr_3_key", **names), e, "m", 0.0, p, margin_m),
        facts=paired_facts(e),
        rule=rule,
        values={
            **run.values(),
            **names,
            **run.timing([dpw, mc]),
            "runs": e.n,
            "error_dpw": fmt(float(s.loc[dpw, "mean_error"])),
            "error_mc": fmt(float(s.loc[mc, "mean_error"])),
            "lost_dpw": fmt(100 * float(s.loc[dpw, "lost_rate"]), 3),
            "lost_mc": fmt(100 * float(s.loc[mc, "lost_rate"]), 3),
            "regret": _diff_text(d, "pp", 2),
            "states": d.n,
            "contrary": run.contrary([dpw, mc]),
        },
    )


def _explore_spec(n: int, evidence: Any) -> ClaimSpec:
    return ClaimSpec(
        id=f"FR-{n}-{{model}}",
        setup=WORDS("explore_setup"),
        evidence=evidence,
        words=WORDS,
        texts=f"fr_{n}",
        part="beyond",
    )


FR_1 = _explore_spec(1, fr1_evidence)
FR_2 = _explore_spec(2, fr2_evidence)
FR_3 = _explore_spec(3, fr3_evidence)


def frontier_claims(
    runs: pd.DataFrame,
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    cfg: Mapping[str, Any],
    seed: int,
) -> list[Claim]:
    """FR-1..3 per model of ``summary`` (module doc), in the config's model order. ``runs``
    and ``regret``: the study's tables of every model; ``summary``:
    :func:`rsmhp.studies.frontier.summarise.summarize_frontier`; ``cfg``: ``frontier``. A
    claim whose members are not both budget members that ran is left out."""
    for key in ("budget", "claims", "bootstrap"):
        if key not in cfg:
            raise ValueError(f"frontier lacks {key!r} (the config schema fills it)")
    members = list(cfg["budget"]["members"])
    if summary.empty or not members:
        return []
    budget, rules = float(cfg["budget"]["ms_per_step"]), cfg["claims"]
    check = budget_check(summary, members, budget)
    margin_pp, margin_m = float(rules["margin_pp"]), float(rules["margin_m"])
    mc, rqmc, sigma, dpw = (
        budget_member(members, family) for family in (MonteCarlo, RQMC, SigmaPoints, TreeSearch)
    )
    ref = str(rules["sigma_reference"])
    out: list[Claim] = []
    for model in dict.fromkeys(summary["model"]):
        run = ExploratoryRun(
            runs, regret, summary, check, model, budget, seed, int(cfg["bootstrap"])
        )
        ran = set(summary.loc[summary["model"] == model, "method"])
        if mc and rqmc and {mc, rqmc} <= ran:
            out.append(FR_1.build(run, rqmc, mc, margin_pp))
        if sigma and {sigma, ref} <= ran:
            out.append(FR_2.build(run, sigma, ref, margin_pp))
        if mc and dpw and {mc, dpw} <= ran:
            out.append(FR_3.build(run, dpw, mc, margin_m))
    return out


# ------------------------------------------------------------------------ the protocol

#: the tests a preregistered FR claim may use
CONFIRM_TESTS = ("superiority", "non-inferiority")


@dataclass(frozen=True)
class PreregisteredRule(Rule):
    """A rule fixed in a preregistration: its text ends with ``note`` (which one, by its
    sha256), after the rule's own text."""

    note: str = ""

    def text(self) -> str:
        """The rule's text, then its note."""
        return f"{super().text()} {self.note}" if self.note else super().text()


def confirm_rule(test: str, a: str, b: str, budget_ms: float, margin_m: float) -> Rule:
    """The rule of a preregistered FR claim: d = closed-loop mean location error of the tuned
    member ``a`` − that of ``b`` at ``budget_ms`` per step, paired over runs (95% t
    interval). ``superiority``: equivalent inside ±margin, supported below 0, not supported
    above 0; ``non-inferiority``: supported below +margin, not supported above it."""
    basis = WORDS("confirm_basis", a=a, b=b, budget=param_text(budget_ms))
    text = f"{param_text(margin_m)} m"
    if test == "superiority":
        return ci_side(KEY, 0.0, claimed="below", basis=basis, margin=margin_m, margin_text=text)
    if test == "non-inferiority":
        return non_inferior(KEY, margin_m, margin_text=text, basis=basis)
    raise ValueError(f"test: {test!r} (allowed: {', '.join(CONFIRM_TESTS)})")


@dataclass(frozen=True, eq=False)
class Comparison:
    """One preregistered FR claim ``cid`` (``spec``: family, against, test, margin_m, why)
    on ``model`` at the headline budget ``budget_ms``: the tuned configurations ``a`` (of
    the family) and ``b`` (of the one it is compared against), their family labels, and the
    preregistration's sha256 ``sha``."""

    cid: str
    model: str
    spec: Mapping[str, Any]
    budget_ms: float
    a: Configuration
    b: Configuration
    labels: tuple[str, str]
    sha: str
    #: the preregistration's ``secondaries`` (version 3) and the model's tuned configurations
    #: (budget text -> family -> Configuration) they are read from; ``None``: none
    #: preregistered (the claim then shows every other comparator member, post hoc)
    secondaries: Mapping[str, Any] | None = None
    chosen: Mapping[str, Mapping[str, Configuration]] | None = None
    #: the preregistration's ``budget_tolerance`` (version 3): a compared member whose mean
    #: closed-loop time per step exceeds (1 + tolerance) x the budget makes the claim
    #: ``over budget`` (no verdict); ``None``: no such rule
    tolerance: float | None = None

    def over_budget(self, summary: pd.DataFrame) -> bool:
        """Whether a compared member spent more than the tolerance allows (``summary``
        indexed by model and config, ``loop_ms`` the closed loop's mean time per step)."""
        if self.tolerance is None:
            return False
        limit = self.budget_ms * (1.0 + float(self.tolerance))
        return any(float(summary.loc[(self.model, x.name), "loop_ms"]) > limit
                   for x in (self.a, self.b))  # fmt: skip

    @property
    def superiority(self) -> bool:
        return self.spec["test"] == "superiority"

    @property
    def margin(self) -> float:
        return float(self.spec["margin_m"])

    def rule(self) -> PreregisteredRule:
        """:func:`confirm_rule` with the preregistration's note."""
        r = confirm_rule(self.spec["test"], *self.labels, self.budget_ms, self.margin)
        note = WORDS("confirm_note", sha=self.sha[:12])
        cases = r.cases
        if self.tolerance is not None:
            limit = param_text(self.budget_ms * (1.0 + float(self.tolerance)))
            when = WORDS("over_budget_when", limit=limit, tolerance=f"{float(self.tolerance):.0%}")
            over = Case(OVER_BUDGET, when, lambda f: f.get("over_budget", 0.0) > 0)
            cases = (over, *cases)
        return PreregisteredRule(cases=cases, otherwise=r.otherwise, basis=r.basis, note=note)


def _over_budget(c: Comparison, summary: pd.DataFrame) -> list[dict[str, Any]]:
    """Each configuration over the budget, timed and in the closed loop: the tuning rule's
    cost is the larger of the timed median and the closed loop's mean time per step."""
    out = []
    for cfg in (c.a, c.b):
        r = summary.loc[(c.model, cfg.name)]
        for kind, col in (("timed", "plan_ms"), ("loop", "loop_ms")):
            if float(r[col]) > c.budget_ms:
                out.append({"kind": kind, "label": cfg.label(), "ms": fmt(float(r[col]), 3)})
    return out


def _ladder_against(c: Comparison, lad: pd.DataFrame, verdict: str) -> list[dict[str, Any]]:
    """The other budgets of the ladder whose CI lies where ``verdict`` says it does not:
    better where the verdict is "not supported", worse where "supported", outside the margin
    where "equivalent", off 0 either way where "inconclusive"."""
    fam = c.spec["family"]
    other = lad[
        (lad["model"] == c.model) & (lad["family"] == fam) & (lad["budget_ms"] != c.budget_ms)
    ]
    bound = 0.0 if c.superiority else c.margin
    out = []
    for r in other.itertuples(index=False):
        lo, hi = r.diff_mc_low, r.diff_mc_high
        if _against_verdict(verdict, lo, hi, c.margin, bound):
            diff, ci = fmt(r.diff_mc, 3, True), fmt_ci(lo, hi, 3, True)
            budget = param_text(r.budget_ms)
            out.append(
                {
                    "kind": "ladder",
                    "budget": budget,
                    "better": r.diff_mc < 0,
                    "diff": diff,
                    "ci": ci,
                }
            )
    return out


def _against_verdict(verdict: str, lo: float, hi: float, margin: float, bound: float) -> bool:
    """Whether a CI [lo, hi] of d lies where ``verdict`` says it does not: above ``bound``
    where the verdict is "supported", below it where "not supported", outside ±margin where
    "equivalent", off ``bound`` either way where "inconclusive"."""
    return {
        "equivalent": lo < -margin or hi > margin,
        "supported": lo > bound,
        "not supported": hi < bound,
    }.get(verdict, hi < bound or lo > bound)


def _configuration(row: Any) -> Configuration:
    """The configuration of a confirmatory run's row (member, maxiter or NaN, restarts)."""
    from rsmhp.pipeline.protocol import Configuration

    maxiter = None if pd.isna(row.maxiter) else int(row.maxiter)
    start = "pursuit" if str(row.config).endswith("/pursuit") else "warm"
    if not Configuration(str(row.member)).method.estimates_cost:
        return Configuration(str(row.member))
    return Configuration(str(row.member), maxiter, int(row.restarts), start)


def comparator_members(
    c: Comparison, runs: pd.DataFrame, summary: pd.DataFrame, verdict: str
) -> list[dict[str, Any]]:
    """The claim's family member against every other member of the comparator's family the
    run holds on the claim's model (other budgets' members of the ladder; a secondary result
    computed after the data, not preregistered): per member its label, closed-loop time per
    step (``loop``, and ``over`` when above the budget), d = error of ``c.a`` − that member
    paired over runs with its 95% t interval, and ``opposite`` when that interval lies where
    the claim's verdict says it does not (the sign depends on which member is compared)."""
    rows = runs[(runs["model"] == c.model) & (runs["family"] == c.b.family)]
    firsts = rows.drop_duplicates("config").sort_values("config")
    bound = 0.0 if c.superiority else c.margin
    out = []
    for row in firsts.itertuples(index=False):
        if row.config == c.b.name:
            continue
        d = paired_configs(runs, c.model, c.a.name, str(row.config))
        loop = float(summary.loc[(c.model, row.config), "loop_ms"])
        out.append(
            {
                "label": _configuration(row).label(),
                "loop": fmt(loop, 3),
                "over": loop > c.budget_ms,
                "better": float(d.mean) < 0,
                "diff": fmt(float(d.mean), 3, True),
                "ci": fmt_ci(float(d.low), float(d.high), 3, True),
                "opposite": _against_verdict(verdict, d.low, d.high, c.margin, bound),
                "loop_ms": loop,
            }
        )
    return sorted(out, key=lambda m: m["loop_ms"])


def preregistered_secondaries(
    c: Comparison, runs: pd.DataFrame, summary: pd.DataFrame, verdict: str
) -> list[dict[str, Any]]:
    """The claim's preregistered secondary results (``c.secondaries``, version 3): its member
    against the comparator family's tuned member at every budget of
    ``against_comparator_budgets_ms`` (but the claim's own comparator) and against the tuned
    member of every family of ``against_families`` at the headline budget (but the claim's
    own family); per comparison what :func:`comparator_members` gives. A budget or family
    without a tuned member is left out; a tuned member without confirmatory runs is refused,
    naming it."""
    if not c.secondaries or c.chosen is None:
        return []
    targets: list[Configuration] = []
    for b in c.secondaries.get("against_comparator_budgets_ms", []):
        cfg = c.chosen.get(f"{float(b):g}", {}).get(c.b.family)
        if cfg is not None and cfg != c.b and cfg not in targets:
            targets.append(cfg)
    head = c.chosen.get(f"{c.budget_ms:g}", {})
    for fam in c.secondaries.get("against_families", []):
        cfg = head.get(fam)
        if cfg is not None and fam != c.a.family and cfg not in targets:
            targets.append(cfg)
    have = set(runs.loc[runs["model"] == c.model, "config"])
    bound = 0.0 if c.superiority else c.margin
    out = []
    for cfg in targets:
        if cfg.name not in have:
            raise ValueError(
                f"{c.cid} on {c.model!r}: the preregistered secondary {cfg.name!r} has no "
                "confirmatory runs"
            )
        d = paired_configs(runs, c.model, c.a.name, cfg.name)
        loop = float(summary.loc[(c.model, cfg.name), "loop_ms"])
        out.append({
            "label": cfg.label(), "loop": fmt(loop, 3), "over": loop > c.budget_ms,
            "better": float(d.mean) < 0, "diff": fmt(float(d.mean), 3, True),
            "ci": fmt_ci(float(d.low), float(d.high), 3, True),
            "opposite": _against_verdict(verdict, d.low, d.high, c.margin, bound),
            "loop_ms": loop,
        })  # fmt: skip
    return out


def _depth(row: pd.Series) -> dict[str, str]:
    """The tree search's depths: how far its plans follow its tree (``fr_confirm_measured``)."""
    return {
        "plan_depth": fmt(float(row["plan_depth"]), 3),
        "max_depth": fmt(float(row["max_depth"]), 3),
        "root_actions": fmt(float(row["root_actions"]), 3),
        "depth1": fmt(100 * float(row["frac_depth1"]), 3),
    }


def confirm_evidence(
    c: Comparison, runs: pd.DataFrame, summary: pd.DataFrame, lad: pd.DataFrame
) -> Evidence:
    """A preregistered FR claim on the confirmatory run: d = closed-loop mean location error
    of ``c.a`` − ``c.b``, paired over runs (``runs``), with the probability of improvement;
    the configurations' times (``summary`` indexed by model and config); the contrary
    evidence of the budget and of the ladder ``lad``."""
    d = paired_configs(runs, c.model, c.a.name, c.b.name)
    rule = c.rule()
    over = c.over_budget(summary)
    facts = {**paired_facts(d), "over_budget": float(over)}
    verdict = rule.verdict(facts)
    if over:  # no verdict: no p-value either, so it stays out of Holm's family
        p = None
    elif c.superiority:
        p = _p_side(d, verdict, c.margin)
    else:
        p = _p_noninferior(d, verdict, c.margin)
    wide = runs[runs["model"] == c.model].pivot(index="run", columns="config", values="mean_error")
    pi = prob_improvement(wide[c.a.name].to_numpy(), wide[c.b.name].to_numpy())
    ra, rb = summary.loc[(c.model, c.a.name)], summary.loc[(c.model, c.b.name)]
    family, against = c.labels
    label_a = c.a.label()
    if c.a.family == "dpw":  # named by its measured plan depth (rsmhp.report.naming)
        depth, rollout = float(ra["plan_depth"]), c.a.method.rollout
        family, label_a = (depth_name(x, depth, rollout) for x in (family, label_a))
    prereg = bool(c.secondaries)
    members = (preregistered_secondaries if prereg else comparator_members)(
        c, runs, summary, verdict
    )
    # a superiority rule's equivalence margin; a non-inferiority rule's margin is the null
    key = KeyNumber(WORDS("confirm_key", family=family, against=against), float(d.mean),
                    float(d.low), float(d.high), unit="m", reproducible="statistical", digits=3,
                    null=0.0 if c.superiority else c.margin, p_value=p, n=_runs(d),
                    margin=c.margin if c.superiority else None)  # fmt: skip
    values = {
        "cid": c.cid,
        "model": c.model,
        "budget": param_text(c.budget_ms),
        "family": family,
        "against": against,
        "test": c.spec["test"],
        "margin": param_text(c.margin),
        "why": str(c.spec.get("why", "")),
        "a": label_a,
        "b": c.b.label(),
        "runs": d.n,
        "error_a": fmt(float(ra["mean_error"])),
        "error_b": fmt(float(rb["mean_error"])),
        "improve": fmt(pi[0], 3),
        "improve_ci": fmt_ci(pi[1], pi[2], 3),
        "ms_a": fmt(float(ra["plan_ms"]), 3),
        "work_a": fmt(float(ra["work_per_step"]), 3),
        "ms_b": fmt(float(rb["plan_ms"]), 3),
        "work_b": fmt(float(rb["work_per_step"]), 3),
        "loop_a": fmt(float(ra["loop_ms"]), 3),
        "loop_b": fmt(float(rb["loop_ms"]), 3),
        "depth": _depth(ra) if c.a.family == "dpw" else None,
        "members": members,
        "prereg": prereg,
        "contrary": _over_budget(c, summary)
        + _ladder_against(c, lad, verdict)
        + [
            {"kind": "member", "against": against, "prereg": prereg, **m}
            for m in members
            if m["opposite"]
        ],
    }
    return Evidence(key=key, facts=facts, values=values, rule=rule)


FR_CONFIRM = ClaimSpec(
    id="{cid}-{model}",
    setup=WORDS("confirm_setup"),
    evidence=confirm_evidence,
    words=WORDS,
    texts="fr_confirm",
    part="beyond",
)


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
    labels = {c.family: c.family_label for c in registry.families()}
    b = float(prereg["headline_budget_ms"])
    s = summary.set_index(["model", "config"])
    out: list[Claim] = []
    for model in prereg["models"]:
        per = chosen.get(model, {}).get(f"{b:g}", {})
        for cid, spec in prereg["claims"].items():
            fam, ref = spec["family"], spec["against"]
            if fam in per and ref in per:
                pair = (labels.get(fam, fam), labels.get(ref, ref))
                c = Comparison(cid, model, spec, b, per[fam], per[ref], pair, prereg_sha,
                               prereg.get("secondaries"), chosen.get(model, {}),
                               prereg.get("budget_tolerance"))  # fmt: skip
                out.append(FR_CONFIRM.build(c, runs, s, lad))
    return out
