"""Equal-compute study of the planners, report section (order 32): the Markdown tables of the
frontier and of the budget check, a short body (setting, findings, figure) and the appendix,
assembled from :mod:`rsmhp.studies.frontier.summarise` and the claims of
:mod:`rsmhp.studies.frontier.claims`; likewise the confirmatory section of the protocol (order
32). Every number is read from the tables or the claims. The prose is in the templates beside
this module (``section.md`` and ``appendix.md``: the exploratory design; ``confirm.md`` and
``confirm_appendix.md``: the confirmatory run), filled with the values computed here."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import pandas as pd

from rsmhp.models.uav import methods as registry
from rsmhp.models.uav.methods.tree_search import ALPHA_A, ALPHA_O, C_UCB, K_A, K_O
from rsmhp.report.ledger import Claim, Section
from rsmhp.report.markdown import ci_cells, fmt, fmt_ci, markdown_table, param_text
from rsmhp.report.palette import method_label
from rsmhp.report.templates import render
from rsmhp.studies.frontier import CONFIRM_TABLES, TABLES
from rsmhp.studies.frontier.claims import frontier_claims
from rsmhp.studies.frontier.figures import FIGURES
from rsmhp.studies.frontier.summarise import budget_check

__all__ = [
    "CONFIRM_TABLES",
    "FIGURES",
    "TABLES",
    "ConfirmInputs",
    "FrontierInputs",
    "confirm_section",
    "confirm_tables",
    "frontier_section",
    "frontier_tables",
]


def _frontier_table(summary: pd.DataFrame) -> str:
    t = pd.DataFrame(
        {
            "model": summary["model"],
            "method": summary["method"].map(method_label),
            "ms/step": summary["plan_ms"],
            "ms range": ci_cells(summary["plan_lo_ms"], summary["plan_hi_ms"]),
            "model steps/step": summary["work_per_step"].round(0),
            "iterations": summary["mean_nit"],
            "converged %": (100 * summary["converged_rate"]).round(1),
            "runs": summary["runs"].astype(int),
            "error (m)": summary["mean_error"],
            "− NBO (m)": summary["error_diff"],
            "95% CI (m)": ci_cells(
                summary["error_diff_low"], summary["error_diff_high"], signed=True
            ),
            "lost %": (100 * summary["lost_rate"]).round(1),
            "states": summary["states"].astype(int),
            "regret %": summary["regret_pct"],
            "− NBO (pp)": summary["regret_diff_pp"],
            "95% CI (pp)": ci_cells(
                summary["regret_diff_pp_low"], summary["regret_diff_pp_high"], signed=True
            ),
        }
    )
    return markdown_table(t, digits=3, missing="undefined", signed=("− NBO (m)", "− NBO (pp)"))


def _budget_table(check: pd.DataFrame, summary: pd.DataFrame) -> str:
    per = summary.set_index(["model", "method"])["work_per_step"]
    pairs = zip(check["model"], check["member"], strict=True)
    work = [float(per.get(pair, float("nan"))) for pair in pairs]
    t = pd.DataFrame(
        {
            "model": check["model"],
            "family": [registry.from_name(m).family_label for m in check["member"]],
            "budget member": check["member"].map(method_label),
            "ms/step": check["plan_ms"],
            "model steps/step": pd.Series(work).round(0),
            "within budget": ["yes" if f else "no" for f in check["fits"]],
            "largest member within budget (this run)": [
                method_label(m) if m else "none" for m in check["largest_fitting"]
            ],
        }
    )
    return markdown_table(t, digits=3, missing="not recorded")


def frontier_tables(summary: pd.DataFrame, cfg: Mapping[str, Any]) -> dict[str, str]:
    """Markdown tables ``frontier_exploratory`` (every model and method: planning ms per step,
    closed-loop error and its paired difference with NBO, track loss, open-loop relative
    regret and its paired difference) and ``frontier_budget`` (each budget member against
    the budget on this run's times); ``cfg``: ``frontier``."""
    budget = cfg["budget"]
    check = budget_check(summary, list(budget["members"]), float(budget["ms_per_step"]))
    return {
        "frontier_exploratory": _frontier_table(summary),
        "frontier_budget": (_budget_table(check, summary) if len(check) else "(no budget members)"),
    }


def _render(template: str, **values: Any) -> str:
    """``template`` (a file beside this module) filled with ``values``, without the newline
    that ends the file."""
    return render(__package__, template, **values).removesuffix("\n")


def _family_labels() -> dict[str, str]:
    return {c.family: c.family_label for c in registry.families()}


@dataclass(frozen=True)
class FrontierInputs:
    """What the exploratory section is built from: the closed-loop ``runs``, the open-loop
    ``regret``, their ``summary`` (:func:`rsmhp.studies.frontier.summarise.summarize_frontier`),
    the Markdown ``tables`` (:func:`frontier_tables`), ``cfg`` = ``frontier``, the
    root ``seed`` and ``horizon`` = the planners' H (``uav.planner.horizon``)."""

    runs: pd.DataFrame
    regret: pd.DataFrame
    summary: pd.DataFrame
    tables: Mapping[str, str]
    cfg: Mapping[str, Any]
    seed: int
    horizon: int


@dataclass(frozen=True)
class ClaimResult:
    """One comparison's key number as printed: ``'<name>' <value> <ci> (<verdict>)``."""

    name: str
    value: str
    ci: str
    verdict: str


@dataclass(frozen=True)
class Comparison:
    """The comparisons of one claim family (``FR-1``): what it compares and every result."""

    claims: str
    compared: str
    results: list[ClaimResult]


@dataclass(frozen=True)
class ClosedLoop:
    """One model's closed-loop tally against NBO: members with the CI of their paired
    difference below 0 (``better``) or above 0 (``worse``) out of ``members``, per family
    (``"RS-MHP 3/3, sigma points 1/1"``, empty when none), and the planning ms per step."""

    model: str
    runs: int
    members: int
    better: int
    better_families: str
    worse: int
    worse_families: str
    nbo_ms: str
    fastest_ms: str
    slowest_ms: str


#: (claim id prefix, what it compares) of the findings paragraph
_COMPARED = (
    ("FR-1-", "RQMC − RS-MHP open-loop regret"),
    ("FR-2-", "sigma points − RS-MHP regret"),
    ("FR-3-", "tree search − RS-MHP closed-loop error"),
)


def _per_family(rows: pd.DataFrame, of: pd.DataFrame) -> str:
    """``RS-MHP 3/3, sigma points 1/1``: members of ``rows`` per family, of those in ``of``."""
    labels = _family_labels()
    return ", ".join(
        f"{labels.get(f, f)} {int((rows['family'] == f).sum())}/{int((of['family'] == f).sum())}"
        for f in dict.fromkeys(rows["family"])
    )


def _comparisons(claims: Sequence[Claim]) -> list[Comparison]:
    out = []
    for prefix, compared in _COMPARED:
        sel = [c for c in claims if c.id.startswith(prefix)]
        if sel:
            results = [
                ClaimResult(
                    name=c.id[len(prefix) :],
                    value=fmt(c.key.value, c.key.digits, True)
                    + (" m" if c.key.unit == "m" else " pp"),
                    ci=fmt_ci(c.key.ci_low, c.key.ci_high, c.key.digits, True),
                    verdict=c.verdict,
                )
                for c in sel
            ]
            out.append(Comparison(prefix[:-1], compared, results))
    return out


def _closed_loop(summary: pd.DataFrame) -> list[ClosedLoop]:
    base = registry.baseline()().name
    out = []
    for model, s in summary.groupby("model", sort=False):
        others = s[s["method"] != base].dropna(subset=["error_diff_high"])
        better = others[others["error_diff_high"] < 0]
        worse = others[others["error_diff_low"] > 0]
        out.append(
            ClosedLoop(
                model=str(model),
                runs=int(s["runs"].iloc[0]),
                members=len(others),
                better=len(better),
                better_families=_per_family(better, others),
                worse=len(worse),
                worse_families=_per_family(worse, others),
                nbo_ms=fmt(float(s.loc[s["method"] == base, "plan_ms"].iloc[0]), 2),
                fastest_ms=fmt(float(others["plan_ms"].min()), 2),
                slowest_ms=fmt(float(others["plan_ms"].max()), 2),
            )
        )
    return out


def _body(inputs: FrontierInputs, claims: Sequence[Claim]) -> str:
    cfg, summary = inputs.cfg, inputs.summary
    labels = _family_labels()
    return _render(
        "section.md",
        families=", ".join(labels.get(f, f) for f in dict.fromkeys(summary["family"])),
        models=", ".join(repr(m) for m in cfg["models"]),
        runs=int(cfg["runs"]),
        regret_runs=int(cfg["regret_runs"]),
        budget_ms=param_text(float(cfg["budget"]["ms_per_step"])),
        members=", ".join(method_label(m) for m in cfg["budget"]["members"]),
        comparisons=_comparisons(claims),
        closed_loop=_closed_loop(summary),
    )


def _appendix(inputs: FrontierInputs) -> str:
    cfg, horizon = inputs.cfg, inputs.horizon
    return _render(
        "appendix.md",
        track_loss_error=param_text(cfg["track_loss_error"]),
        bootstrap=int(cfg["bootstrap"]),
        frontier_table=inputs.tables["frontier_exploratory"],
        budget_ms=param_text(float(cfg["budget"]["ms_per_step"])),
        budget_table=inputs.tables["frontier_budget"],
        sigma_points=8 * (horizon + 1),
        horizon=horizon,
        dimension=4 * (horizon + 1),
        c_ucb=str(C_UCB),
        k_a=f"{K_A:g}",
        alpha_a=str(ALPHA_A),
        k_o=f"{K_O:g}",
        alpha_o=str(ALPHA_O),
    )


def frontier_section(inputs: FrontierInputs) -> Section:
    """The exploratory equal-compute design's report section (order 33, only with
    ``frontier.exploratory``). Its comparisons FR-1..3 were chosen on the data
    that judge them: they are printed as exploratory findings, never as claims of the
    ledger (the ledger's FR claims come from the confirmatory run)."""
    claims = frontier_claims(inputs.runs, inputs.regret, inputs.summary, inputs.cfg, inputs.seed)
    return Section(
        key="frontier_exploratory",
        title="Planners at equal compute: the exploratory design",
        order=33,
        body=_body(inputs, claims),
        claims=[],
        figures=list(FIGURES),
        appendix=_appendix(inputs),
    )


# ------------------------------------------------------------------------ the protocol


def _config_table(summary: pd.DataFrame) -> str:
    t = pd.DataFrame(
        {
            "model": summary["model"],
            "configuration": summary["config"],
            "ms/step": summary["plan_ms"],
            "ms range": ci_cells(summary["plan_lo_ms"], summary["plan_hi_ms"]),
            "closed-loop ms/step": summary["loop_ms"],
            "model steps/step": summary["work_per_step"].round(0),
            "iterations (sims)": summary["mean_nit"],
            "converged %": (100 * summary["converged_rate"]).round(1),
            "tree depth of plan": summary["plan_depth"],
            "deepest node": summary["max_depth"],
            "root actions": summary["root_actions"],
            "runs": summary["runs"].astype(int),
            "error (m)": summary["mean_error"],
            "− NBO (m)": summary["error_diff"],
            "95% CI (m)": ci_cells(
                summary["error_diff_low"], summary["error_diff_high"], signed=True
            ),
            "lost %": (100 * summary["lost_rate"]).round(1),
        }
    )
    return markdown_table(t, digits=3, missing="—", signed=("− NBO (m)",))


def _ladder_table(lad: pd.DataFrame) -> str:
    labels = {c.family: c.family_label for c in registry.families()}
    t = pd.DataFrame(
        {
            "model": lad["model"],
            "budget (ms)": lad["budget_ms"],
            "family": lad["family"].map(lambda f: labels.get(f, f)),
            "tuned configuration": lad["config"],
            "ms/step": lad["plan_ms"],
            "closed-loop ms/step": lad["loop_ms"],
            "within": ["yes" if w else "no" for w in lad["within_budget"]],
            "model steps/step": lad["work_per_step"].round(0),
            "error (m)": lad["mean_error"],
            "− Monte Carlo (m)": lad["diff_mc"],
            "95% CI": ci_cells(lad["diff_mc_low"], lad["diff_mc_high"], signed=True),
            "P(improvement)": lad["p_improve"],
            "95% CI ": ci_cells(lad["p_improve_low"], lad["p_improve_high"]),
        }
    )
    return markdown_table(t, digits=3, missing="—", signed=("− Monte Carlo (m)",))


def _tuning_table(tuned: Mapping[str, Any]) -> str:
    labels = {c.family: c.family_label for c in registry.families()}
    rows = []
    for model, per in tuned.get("chosen", {}).items():
        for b, fams in per.items():
            for fam, e in fams.items():
                t = e.get("tuning", {})
                rows.append(
                    {
                        "model": model,
                        "budget (ms)": float(b),
                        "family": labels.get(fam, fam),
                        "member": e["member"],
                        "maxiter": "—" if e.get("maxiter") is None else int(e["maxiter"]),
                        "restarts": int(e.get("restarts", 0)),
                        "tuning ms/step": t.get("plan_ms", float("nan")),
                        "timed": t.get("timing_ms", float("nan")),
                        "closed loop": t.get("closed_loop_ms", float("nan")),
                        "tuning error (m)": t.get("mean_error", float("nan")),
                        "candidates within budget": t.get("candidates_within_budget", 0),
                    }
                )
    if not rows:
        return "(no tuned configurations)"
    return markdown_table(pd.DataFrame(rows), digits=4, missing="—")


def confirm_tables(
    summary: pd.DataFrame, lad: pd.DataFrame, tuned: Mapping[str, Any]
) -> dict[str, str]:
    """Markdown tables of the confirmatory section: ``frontier_confirm`` (every configuration:
    both compute units, optimiser and depth statistics, error and its difference with NBO),
    ``frontier_confirm_ladder`` (per model, budget and family: the tuned member against Monte
    Carlo's) and ``frontier_confirm_tuning`` (what the tuning chose, with its tuning numbers)."""
    return {
        "frontier_confirm": _config_table(summary),
        "frontier_confirm_ladder": _ladder_table(lad),
        "frontier_confirm_tuning": _tuning_table(tuned),
    }


@dataclass(frozen=True)
class ConfirmInputs:
    """What the confirmatory section is built from: the per-configuration ``summary``
    (:func:`rsmhp.studies.frontier.summarise.summarize_configs`), the ladder ``lad``
    (:func:`rsmhp.studies.frontier.summarise.ladder`), the FR ``claims``, the Markdown
    ``tables`` (:func:`confirm_tables`), ``prereg`` the preregistration's content and
    ``prereg_meta`` its ``path``, ``sha256`` and ``commit``, ``tuned`` the tuned file,
    ``exploratory`` the FR and HZ claims published at 76a0c01 (kept, not counted) and
    ``superseded`` an earlier confirmatory run's record (``what``, ``preregistration``,
    ``claims``: kept, not counted), if any."""

    summary: pd.DataFrame
    lad: pd.DataFrame
    claims: Sequence[Claim]
    tables: Mapping[str, str]
    prereg: Mapping[str, Any]
    prereg_meta: Mapping[str, str]
    tuned: Mapping[str, Any]
    exploratory: Sequence[Mapping[str, Any]]
    superseded: Mapping[str, Any] | None = None


@dataclass(frozen=True)
class Tuning:
    """The tuning run as the setting names it (its ``provenance`` in the tuned file; ``?``
    where the file lacks an entry)."""

    candidates: str
    runs_per_candidate: str
    date: str
    commit: str


@dataclass(frozen=True)
class RunCount:
    """The preregistered number of confirmatory runs on one model."""

    model: str
    runs: str


@dataclass(frozen=True)
class Preregistration:
    """The preregistration as the setting names it: file, hashes, budgets, run counts."""

    path: str
    sha256: str
    commit: str
    budgets_ms: str
    headline_ms: str
    runs: list[RunCount]
    power_text: str
    stream: str


@dataclass(frozen=True)
class ConfirmedClaim:
    """One preregistered claim's key number (m) before Holm's correction."""

    id: str
    value: str
    ci: str
    verdict: str


@dataclass(frozen=True)
class Spent:
    """What the members at the claims' budget spent on one model in closed loop: ``spent``
    (``"RS-MHP 1.9, RQMC 2.1"``, ms per step) and the families over the budget (``over``,
    empty when all are within it)."""

    model: str
    spent: str
    over: str


@dataclass(frozen=True)
class Rung:
    """One budget of a model: the family with the lowest mean error, and the families whose
    difference with Monte Carlo has its CI below 0 (``below``, empty when none)."""

    budget_ms: str
    family: str
    error: str
    below: str


@dataclass(frozen=True)
class BestPerBudget:
    """The rungs of one model's ladder."""

    model: str
    rungs: list[Rung]


@dataclass(frozen=True)
class TreeDepths:
    """The tuned tree searches' depth statistics (ranges over configurations)."""

    configurations: int
    plan_depth_min: str
    plan_depth_max: str
    max_depth_min: str
    max_depth_max: str


@dataclass(frozen=True)
class Superseded:
    """An earlier confirmatory run: its preregistration, what changed, its claims' table."""

    sha256: str
    commit: str
    what: str
    table: str


def _best_per_budget(lad: pd.DataFrame) -> list[BestPerBudget]:
    labels = _family_labels()
    out = []
    for model, g in lad.groupby("model", sort=False):
        rungs = []
        for b, f in g.groupby("budget_ms", sort=True):
            best = f.loc[f["mean_error"].idxmin()]
            clear = f[(f["diff_mc_high"] < 0)]
            rungs.append(
                Rung(
                    budget_ms=param_text(float(b)),
                    family=labels.get(best["family"], best["family"]),
                    error=fmt(float(best["mean_error"]), 3),
                    below=", ".join(labels.get(x, x) for x in clear["family"]),
                )
            )
        out.append(BestPerBudget(str(model), rungs))
    return out


def _exploratory_table(exploratory: Sequence[Mapping[str, Any]]) -> str:
    if not exploratory:
        return "(none)"
    t = pd.DataFrame(
        {
            "claim": [c["id"] for c in exploratory],
            "key number": [
                f"{fmt(c['key']['value'], 3, True)} {c['key'].get('unit', '')}".strip()
                + (
                    f" {fmt_ci(c['key']['ci_low'], c['key']['ci_high'], 3, True)}"
                    if c["key"].get("ci_low") is not None
                    else ""
                )
                for c in exploratory
            ],
            "verdict then": [c["verdict"] for c in exploratory],
        }
    )
    return markdown_table(t)


def _headline_compute(lad: pd.DataFrame, budget: float) -> list[Spent]:
    """What the members at the claims' budget spent in this run's closed loop (ms per step,
    the mean over runs), and which of them went over the budget on the tuning rule's cost."""
    labels = _family_labels()
    return [
        Spent(
            model=str(model),
            spent=", ".join(
                f"{labels.get(r.family, r.family)} {fmt(float(r.loop_ms), 3)}"
                for r in g.itertuples()
            ),
            over=", ".join(
                labels.get(r.family, r.family) for r in g.itertuples() if not r.within_budget
            ),
        )
        for model, g in lad[lad["budget_ms"] == budget].groupby("model", sort=False)
    ]


def _tuning(tuned: Mapping[str, Any]) -> Tuning:
    prov = tuned.get("provenance", {})
    return Tuning(
        candidates=str(prov.get("candidates", "?")),
        runs_per_candidate=str(prov.get("runs per candidate", "?")),
        date=str(prov.get("date (UTC)", "?")),
        commit=str(prov.get("commit", "?"))[:10],
    )


def _preregistration(prereg: Mapping[str, Any], meta: Mapping[str, str]) -> Preregistration:
    runs = prereg["runs"]
    per = runs if isinstance(runs, Mapping) else dict.fromkeys(prereg["models"], runs)
    return Preregistration(
        path=meta["path"],
        sha256=meta["sha256"][:12],
        commit=meta["commit"][:10],
        budgets_ms=", ".join(param_text(float(b)) for b in prereg["budgets_ms"]),
        headline_ms=param_text(float(prereg["headline_budget_ms"])),
        runs=[RunCount(str(m), str(per[m])) for m in prereg["models"]],
        power_text=str(prereg.get("power_text", "")),
        stream=str(prereg.get("stream", "confirm")),
    )


def _tree_depths(summary: pd.DataFrame) -> TreeDepths | None:
    dpw = summary[summary["family"] == "dpw"]
    if not len(dpw):
        return None
    return TreeDepths(
        configurations=len(dpw),
        plan_depth_min=fmt(float(dpw["plan_depth"].min()), 3),
        plan_depth_max=fmt(float(dpw["plan_depth"].max()), 3),
        max_depth_min=fmt(float(dpw["max_depth"].min()), 3),
        max_depth_max=fmt(float(dpw["max_depth"].max()), 3),
    )


def _superseded(sup: Mapping[str, Any] | None) -> Superseded | None:
    if not sup:
        return None
    pre = sup.get("preregistration", {})
    return Superseded(
        sha256=str(pre.get("sha256", "?"))[:12],
        commit=str(pre.get("commit", "?"))[:10],
        what=str(sup.get("what", "")),
        table=_exploratory_table(sup.get("claims", [])),
    )


def confirm_section(inputs: ConfirmInputs) -> Section:
    """The equal-compute study's report section (order 32) from the confirmatory run of the
    protocol (:mod:`rsmhp.pipeline.protocol`); the FR claims are the ledger's, the exploratory
    and superseded claims are printed in the appendix (kept, not counted)."""
    fr = [c for c in inputs.claims if c.id.startswith("FR-")]
    superseded = _superseded(inputs.superseded)
    body = _render(
        "confirm.md",
        tuning=_tuning(inputs.tuned),
        prereg=_preregistration(inputs.prereg, inputs.prereg_meta),
        claims=[
            ConfirmedClaim(
                id=c.id,
                value=fmt(c.key.value, 3, True),
                ci=fmt_ci(c.key.ci_low, c.key.ci_high, 3, True),
                verdict=c.verdict,
            )
            for c in fr
        ],
        compute=_headline_compute(inputs.lad, float(inputs.prereg["headline_budget_ms"])),
        superseded=superseded,
    )
    appendix = _render(
        "confirm_appendix.md",
        config_table=inputs.tables["frontier_confirm"],
        ladder_table=inputs.tables["frontier_confirm_ladder"],
        tuning_table=inputs.tables["frontier_confirm_tuning"],
        best=_best_per_budget(inputs.lad),
        tree=_tree_depths(inputs.summary),
        exploratory_table=_exploratory_table(inputs.exploratory),
        superseded=superseded,
    )
    return Section(
        key="frontier",
        title="Planners at equal compute (confirmatory)",
        order=32,
        body=body,
        claims=list(inputs.claims),
        figures=["frontier_confirm"],
        appendix=appendix,
    )
