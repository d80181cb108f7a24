"""Equal-compute study of the planners, report section (order 32): the Markdown tables of the
frontier and of the budget check, a short body (setting, findings, figure) and the appendix,
assembled from :mod:`rsmhp.studies.frontier.summarise` and the claims of
:mod:`rsmhp.studies.frontier.claims`. Every number is read from the tables or the claims."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import pandas as pd

from rsmhp.models.uav import methods as registry
from rsmhp.models.uav.methods.tree_search import ALPHA_A, ALPHA_O, C_UCB, K_A, K_O
from rsmhp.report.ledger import Claim, Section
from rsmhp.report.markdown import ci_cells, fmt, fmt_ci, markdown_table, param_text
from rsmhp.report.palette import method_label
from rsmhp.studies.frontier.claims import frontier_claims
from rsmhp.studies.frontier.figures import FIGURES
from rsmhp.studies.frontier.summarise import budget_check

__all__ = ["FIGURES", "TABLES", "frontier_section", "frontier_tables"]

#: table stems of the section (the summary rule writes them; see frontier.smk)
TABLES = ("dec_frontier", "dec_frontier_budget")


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
    """Markdown tables ``dec_frontier`` (every model and method: planning ms per step,
    closed-loop error and its paired difference with NBO, track loss, open-loop relative
    regret and its paired difference) and ``dec_frontier_budget`` (each budget member against
    the budget on this run's times); ``cfg``: ``decisions.frontier``."""
    budget = cfg["budget"]
    check = budget_check(summary, list(budget["members"]), float(budget["ms_per_step"]))
    return {
        "dec_frontier": _frontier_table(summary),
        "dec_frontier_budget": (
            _budget_table(check, summary) if len(check) else "(no budget members)"
        ),
    }


def _setting(cfg: Mapping[str, Any], summary: pd.DataFrame) -> str:
    members = [method_label(m) for m in cfg["budget"]["members"]]
    fams = list(dict.fromkeys(summary["family"]))
    labels = {c.family: c.family_label for c in registry.families()}
    return (
        f"Every planner family ({', '.join(labels.get(f, f) for f in fams)}) at several sizes "
        f"on {', '.join(repr(m) for m in cfg['models'])}: {int(cfg['runs'])} paired "
        "closed-loop runs per method, the planning milliseconds per step measured in the same "
        "one-thread job (median over runs), and the open-loop relative regret at the belief "
        f"states of {int(cfg['regret_runs'])} NBO runs, scored as in the decision study "
        "(methods: README, 'Planning methods'; the tree search is PFT-DPW over Kalman "
        "beliefs). Claims FR-1..3 compare one member per family at the **planning budget** "
        f"of {param_text(float(cfg['budget']['ms_per_step']))} ms per step: "
        f"{', '.join(members)} (fixed in the config as the largest members within the "
        "budget in a first run of the study; checked against this run's times in the "
        "appendix)."
    )


#: (claim id prefix, what it compares) of the findings paragraph
_COMPARED = (
    ("FR-1-", "RQMC − RS-MHP open-loop regret"),
    ("FR-2-", "sigma points − RS-MHP regret"),
    ("FR-3-", "tree search − RS-MHP closed-loop error"),
)


def _per_family(rows: pd.DataFrame, of: pd.DataFrame) -> str:
    """``RS-MHP 3/3, sigma points 1/1``: members of ``rows`` per family, of those in ``of``."""
    labels = {c.family: c.family_label for c in registry.families()}
    return ", ".join(
        f"{labels.get(f, f)} {int((rows['family'] == f).sum())}/{int((of['family'] == f).sum())}"
        for f in dict.fromkeys(rows["family"])
    )


def _findings(claims: Sequence[Claim], summary: pd.DataFrame) -> str:
    out = []
    for prefix, lead in _COMPARED:
        sel = [c for c in claims if c.id.startswith(prefix)]
        if not sel:
            continue
        parts = []
        for c in sel:
            k, unit = c.key, " m" if c.key.unit == "m" else " pp"
            parts.append(
                f"'{c.id[len(prefix) :]}' {fmt(k.value, k.digits, True)}{unit} "
                f"{fmt_ci(k.ci_low, k.ci_high, k.digits, True)} ({c.verdict})"
            )
        out.append(f"{prefix[:-1]} ({lead} at the budget): " + "; ".join(parts) + ".")
    base = registry.baseline()().name
    for model, s in summary.groupby("model", sort=False):
        others = s[s["method"] != base].dropna(subset=["error_diff_high"])
        better = others[others["error_diff_high"] < 0]
        worse = others[others["error_diff_low"] > 0]
        out.append(
            f"Closed loop against NBO on '{model}' ({int(s['runs'].iloc[0])} paired runs): "
            f"{len(better)} of {len(others)} members better (CI below 0"
            + (f": {_per_family(better, others)}" if len(better) else "")
            + f"), {len(worse)} worse"
            + (f" ({_per_family(worse, others)})" if len(worse) else "")
            + f"; NBO plans in {fmt(float(s.loc[s['method'] == base, 'plan_ms'].iloc[0]), 2)} "
            f"ms per step, the others in {fmt(float(others['plan_ms'].min()), 2)} to "
            f"{fmt(float(others['plan_ms'].max()), 2)} ms."
        )
    return " ".join(out)


_FIGURE = [
    "![Planner frontier](figures/dec_frontier.png)",
    "",
    "*Decision quality against planning milliseconds per step (log scale), one line per "
    "family through its members; top: open-loop relative regret − NBO's (pp), bottom: "
    "closed-loop mean location error − NBO's (m), below 0 better than NBO; bars: 95% "
    "bootstrap CIs; dotted: the planning budget of FR-1..3.*",
]


def _appendix(cfg: Mapping[str, Any], tables: Mapping[str, str], horizon: int) -> str:
    return "\n".join(
        [
            "Per model and method: planning ms per step (median over runs, one thread, "
            "measured on this machine: the one column of this study that differs across "
            "machines and reruns), mean location error over runs and its paired difference "
            f"with NBO, track loss (final error above {param_text(cfg['track_loss_error'])} "
            "m), open-loop relative regret (%) and its paired difference with NBO at the same "
            "belief states (pp); CIs: 95% percentile bootstrap over runs or states "
            f"({int(cfg['bootstrap'])} resamples).",
            "",
            tables["dec_frontier"],
            "",
            f"Budget members against the budget of "
            f"{param_text(float(cfg['budget']['ms_per_step']))} ms per step on this run's "
            "times (a member over the budget, or a larger member within it, is named as "
            "contrary evidence of the claims that use it):",
            "",
            tables["dec_frontier_budget"],
            "",
            f"Methods: **RQMC**, scrambled Sobol' points through the normal quantile, a fresh "
            "scramble per planning step; **antithetic**, pairs (w, −w); **sigma points**, the "
            f"{8 * (horizon + 1)} equally weighted cubature points ±√n e_i of the joint "
            f"Gaussian of the target belief and the {horizon} steps of process noise (n = "
            f"{4 * (horizon + 1)}); **tree search**, PFT-DPW over Kalman beliefs (a belief "
            "node's children are sampled controls, its observation children sampled "
            "measurements, both widened progressively; reward −tr P), with a budget in "
            "simulations per planning step. "
            "Tree search constants (`rsmhp.models.uav.methods.tree_search`, chosen before "
            f"any run): "
            f"UCB exploration c = {C_UCB} on per-step rewards −tr P / tr P̂ of the root, action "
            f"widening k_a = {K_A:g}, α_a = {ALPHA_A}, observation widening k_o = {K_O:g}, "
            f"α_o = {ALPHA_O} (members may set their own: `_ka`, `_ko`, `_ao`, `_c` in the "
            "name); the first action at each depth is the warm start's, the second the "
            "pursuit policy's (steer to the estimate, close the range); rollouts and the plan "
            "beyond the most visited path follow the pursuit policy.",
        ]
    )


def frontier_section(
    runs: pd.DataFrame,
    regret: pd.DataFrame,
    summary: pd.DataFrame,
    tables: Mapping[str, str],
    cfg: Mapping[str, Any],
    seed: int,
    horizon: int,
) -> Section:
    """The exploratory equal-compute design's report section (order 33, only with
    ``decisions.frontier.exploratory``); ``cfg`` is ``decisions.frontier``, ``horizon`` the
    planners' H (``uav.planner.horizon``). Its comparisons FR-1..3 were chosen on the data
    that judge them: they are printed as exploratory findings, never as claims of the
    ledger (the ledger's FR claims come from the confirmatory run)."""
    claims = frontier_claims(runs, regret, summary, cfg, seed)
    body = "\n".join(
        [
            "**Exploratory design** (published up to 76a0c01; its comparisons were chosen on "
            "the data that judge them, so nothing here is counted). " + _setting(cfg, summary),
            "",
            "Exploratory comparisons (not claims): " + _findings(claims, summary),
            "",
            *_FIGURE,
        ]
    )
    return Section(
        key="decisions_frontier_exploratory",
        title="Planners at equal compute: the exploratory design",
        order=33,
        body=body,
        claims=[],
        figures=list(FIGURES),
        appendix=_appendix(cfg, tables, horizon),
    )


# ------------------------------------------------------------------------ the protocol

#: table stems of the confirmatory section (rule frontier_confirm_summary)
CONFIRM_TABLES = ("dec_confirm", "dec_confirm_ladder", "dec_confirm_tuning")


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
    """Markdown tables of the confirmatory section: ``dec_confirm`` (every configuration:
    both compute units, optimiser and depth statistics, error and its difference with NBO),
    ``dec_confirm_ladder`` (per model, budget and family: the tuned member against Monte
    Carlo's) and ``dec_confirm_tuning`` (what the tuning chose, with its tuning numbers)."""
    return {
        "dec_confirm": _config_table(summary),
        "dec_confirm_ladder": _ladder_table(lad),
        "dec_confirm_tuning": _tuning_table(tuned),
    }


def _best_per_budget(lad: pd.DataFrame) -> str:
    labels = {c.family: c.family_label for c in registry.families()}
    out = []
    for model, g in lad.groupby("model", sort=False):
        parts = []
        for b, f in g.groupby("budget_ms", sort=True):
            best = f.loc[f["mean_error"].idxmin()]
            clear = f[(f["diff_mc_high"] < 0)]
            parts.append(
                f"{param_text(float(b))} ms: {labels.get(best['family'], best['family'])} "
                f"({fmt(float(best['mean_error']), 3)} m"
                + (
                    f"; below Monte Carlo's CI-wise: "
                    f"{', '.join(labels.get(x, x) for x in clear['family'])})"
                    if len(clear)
                    else "; no family below Monte Carlo CI-wise)"
                )
            )
        out.append(f"'{model}': " + "; ".join(parts))
    return (
        "Lowest mean closed-loop error per budget (descriptive, not a claim): "
        + ". ".join(out)
        + "."
    )


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


def _headline_compute(lad: pd.DataFrame, budget: float) -> str:
    """What the members at the claims' budget spent in this run's closed loop (ms per step,
    the mean over runs), and which of them went over the budget on the tuning rule's cost."""
    at = lad[lad["budget_ms"] == budget]
    if at.empty:
        return ""
    labels = {c.family: c.family_label for c in registry.families()}
    parts = []
    for model, g in at.groupby("model", sort=False):
        spent = ", ".join(
            f"{labels.get(r.family, r.family)} {fmt(float(r.loop_ms), 3)}" for r in g.itertuples()
        )
        over = [labels.get(r.family, r.family) for r in g.itertuples() if not r.within_budget]
        parts.append(
            f"'{model}': {spent}"
            + (f" (over the budget here: {', '.join(over)})" if over else " (all within it)")
        )
    return (
        f"Closed-loop ms per step at {param_text(budget)} ms (mean over runs): {'; '.join(parts)}. "
    )


def _superseded_text(sup: Mapping[str, Any]) -> list[str]:
    pre = sup.get("preregistration", {})
    return [
        "",
        f"An earlier confirmatory run (preregistration sha256 {str(pre.get('sha256', '?'))[:12]}, "
        f"commit {str(pre.get('commit', '?'))[:10]}; superseded, not counted): "
        f"{sup.get('what', '')}",
        "",
        _exploratory_table(sup.get("claims", [])),
    ]


def confirm_section(
    summary: pd.DataFrame,
    lad: pd.DataFrame,
    claims: Sequence[Claim],
    tables: Mapping[str, str],
    prereg: Mapping[str, Any],
    prereg_meta: Mapping[str, str],
    tuned: Mapping[str, Any],
    exploratory: Sequence[Mapping[str, Any]],
    superseded: Mapping[str, Any] | None = None,
) -> Section:
    """The equal-compute study's report section (order 32) from the confirmatory run of the
    protocol (:mod:`rsmhp.pipeline.protocol`): ``prereg`` the preregistration's content and
    ``prereg_meta`` its path, sha256 and commit; ``tuned`` the tuned file; ``exploratory``
    the FR and HZ claims published at 76a0c01 (kept, not counted); ``superseded`` an earlier
    confirmatory run's record (``what``, ``preregistration``, ``claims``: kept, not
    counted)."""
    prov = tuned.get("provenance", {})
    runs = prereg["runs"]
    per = runs if isinstance(runs, Mapping) else dict.fromkeys(prereg["models"], runs)
    runs_text = ", ".join(f"{per[m]} on '{m}'" for m in prereg["models"])
    setting = (
        "A comparison at equal compute in three steps (`rsmhp.pipeline.protocol`). **Tuning**, "
        f"on a seed stream of its own: {prov.get('candidates', '?')} candidate configurations "
        "(every sampled-cost member with every optimiser budget: iterations and restarts; "
        "tree searches with several widening and UCB constants) in "
        f"{prov.get('runs per candidate', '?')} closed-loop runs each and in an interleaved "
        "timing; per model, family and budget the rule picks the lowest tuning error among "
        "the candidates whose cost per step is within the budget, the cost being the larger "
        "of the median interleaved time and the mean time per step of the candidate's own "
        f"closed-loop tuning runs ({prov.get('date (UTC)', '?')}, commit "
        f"{str(prov.get('commit', '?'))[:10]}; `config/tuned.yaml`). **Preregistration**: "
        f"`{prereg_meta['path']}` (sha256 {prereg_meta['sha256'][:12]}, commit "
        f"{prereg_meta['commit'][:10]}) fixes the members, budgets "
        f"({', '.join(param_text(float(b)) for b in prereg['budgets_ms'])} ms of planning per "
        f"step, wall clock on the tuning machine; the claims at "
        f"{param_text(float(prereg['headline_budget_ms']))} ms), the rules and the run counts "
        f"({runs_text}; {prereg.get('power_text', '')}) before the **confirmatory run**, on "
        f"a stream of its own ('{prereg.get('stream', 'confirm')}'), which gives every number "
        "below. Times are remeasured here "
        "(interleaved, round robin, a job holding the cores); model steps (one step of one "
        "covariance recursion) do not depend on the machine."
    )
    fr = [c for c in claims if c.id.startswith("FR-")]
    found = "; ".join(
        f"{c.id} {fmt(c.key.value, 3, True)} m {fmt_ci(c.key.ci_low, c.key.ci_high, 3, True)} "
        f"({c.verdict})"
        for c in fr
    )
    body = "\n".join(
        [
            setting,
            "",
            (f"Preregistered claims (before Holm's correction): {found}. " if fr else "")
            + (
                "Holm (ledger) spans the FR and HZ claims with a p-value; HZ-4 and HZ-5 have "
                "none (narrower than preregistered). "
                if fr
                else ""
            )
            + _headline_compute(lad, float(prereg["headline_budget_ms"]))
            + (
                "A first confirmatory run (budgeted on timed medians) is superseded: appendix, "
                "not counted."
                if superseded
                else ""
            ),
            "",
            "![Confirmatory ladder](figures/dec_confirm.png)",
            "",
            "*Tuned members along the budget ladder, one line per family: closed-loop error − "
            "NBO's against planning ms per step as the budget counts it (top: max of timed "
            "median and closed-loop mean; hollow: the latter) and model steps per step "
            "(middle); "
            "probability of improvement over the Monte-Carlo member at the same budget "
            "(bottom); bars: 95% t CIs over runs.*",
        ]
    )
    dpw = summary[summary["family"] == "dpw"]
    appendix = "\n".join(
        [
            "Every configuration of the confirmatory run: interleaved planning ms per step "
            "(median over the timed belief states; range of the per-pass medians), the "
            "closed loop's own planning ms per step (median over runs of a run's mean, "
            "measured beside another job: a run's mean includes the slow steps the median "
            "of the timing hides), model steps per step, optimiser iterations (summed over "
            "restarts; simulations for the tree search) and "
            "converged share (sampled-cost planners), the tree search's depth statistics "
            "(steps of the plan taken from the tree, deepest node, root actions; means over "
            "steps and runs), mean error and its difference with NBO (95% t CI over runs).",
            "",
            tables["dec_confirm"],
            "",
            "The ladder: per model, budget and family the tuned configuration against the "
            "Monte-Carlo member at the same budget (difference and probability of "
            "improvement, 95% t CIs over runs; within: its time on this run within the "
            "budget).",
            "",
            tables["dec_confirm_ladder"],
            "",
            "What the tuning chose (tuning stream; the numbers the rule saw):",
            "",
            tables["dec_confirm_tuning"],
            "",
            _best_per_budget(lad),
            "",
            (
                f"Tree search: {len(dpw)} tuned configurations; their plans take "
                f"{fmt(float(dpw['plan_depth'].min()), 3)} to "
                f"{fmt(float(dpw['plan_depth'].max()), 3)} of their steps from the tree "
                f"(deepest nodes {fmt(float(dpw['max_depth'].min()), 3)} to "
                f"{fmt(float(dpw['max_depth'].max()), 3)}), the rest from the pursuit "
                "rollout policy (steer to the estimate, close the range). Constants in the "
                "member names (`_ka`, `_ko`, `_ao`, `_c`: action and observation widening, "
                "UCB; defaults c = 0.5, k_a = 4, α_a = 0.25, k_o = 4, α_o = 0.25)."
                if len(dpw)
                else "No tree search was tuned into the ladder."
            ),
            "",
            "Exploratory results published at 76a0c01 (chosen and judged on one stream; "
            "kept for the record, not counted):",
            "",
            _exploratory_table(exploratory),
            *(_superseded_text(superseded) if superseded else []),
        ]
    )
    return Section(
        key="decisions_frontier",
        title="Planners at equal compute (confirmatory)",
        order=32,
        body=body,
        claims=list(claims),
        figures=["dec_confirm"],
        appendix=appendix,
    )
