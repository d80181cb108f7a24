r"""The comparison protocol of the equal-compute study: seed streams kept apart, planner
configurations, tuning at budgets each family fills, and the preregistration that fixes the
confirmatory run before it is made.

Streams
-------
Every random number of a study comes from :func:`rsmhp.core.seeding.job_rng` with a root seed. The
protocol gives each purpose its own root, :func:`stream_seed`: ``exploratory`` is the config's
``seed`` itself (the runs published up to 76a0c01, where the comparisons were chosen), ``tune``
and ``confirm`` are derived from it by a hash, so their scenarios, noises and hypotheses share
nothing with each other or with the exploratory runs. Tuning sees only ``tune``; the published
verdicts come only from ``confirm``.

Configurations
--------------
A :class:`Configuration` is a registered planning method (its member name, e.g. ``rsmhp_nt256``
or ``dpw_s300_ka2_ko0p5_ao0``) with the optimiser budget of a sampled-cost planner: at most
``maxiter`` iterations (``maxfun`` = 2 maxiter + 1 evaluations), ``restarts`` further
optimisations from fixed starts (:func:`rsmhp.models.uav.planner.restart_starts`) and the
``start`` of the first optimisation (``"warm"``, the shifted previous plan, or ``"pursuit"``,
the pursuit policy's plan at the belief: :data:`rsmhp.models.uav.planner.STARTS`). The random
stream of a plan is the method's (its ``job_key``): the configurations of one method plan over
the same hypotheses, so their differences are the optimiser's alone. NBO is a sampled-cost
planner too (one nominal hypothesis) and takes the same knobs.

Tuning rule (:func:`select`)
----------------------------
A candidate's cost per step is the larger of two wall-clock times on the tuning machine: the
median of its interleaved timing (the same belief states for every candidate) and the mean
planning time per step of its own closed-loop tuning runs. The second counts what the
closed loop spends: a planner that tracks the target optimises harder there (more iterations
per restart) than at the timing's belief states, up to 13 times the median on
``footprint150`` (the first confirmatory run, preregistration ``b0974d7f``, budgeted on the
median alone). For every model, family and budget b (ms per step): among the family's
candidates whose cost is at most b, the one with the lowest mean closed-loop location error
over the tuning runs; ties go to the candidate with less work (model steps per step), then to
the first in candidate order. A family with no candidate within b has no member at b. The
baseline family (NBO) is tuned like the others, with the same (maxiter, restarts, start)
grid; its candidates include the untuned reference ``nbo`` (the default budget), which
stays the tables' reference (:func:`tuning_configurations` runs it once, first). A family
without a cost estimate (tree search, pursuit policy) has no optimiser knobs: its members are
candidates as they are.

Preregistration (:class:`Preregistration`)
-----------------------------------------
``config/preregistration.yaml``, written and committed after tuning and before the
confirmatory run: the stream, the tuned file it copies its members from (with its SHA-256),
the budgets, run counts with the power calculation behind them, the claims with their rules
and margins, and the family of Holm's correction. The report and ``claims.json`` carry the
file's SHA-256 and the commit that added it; ``make verify`` refuses a run whose
preregistration differs from the committed one.
"""

from __future__ import annotations

import dataclasses
import hashlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import yaml

from rsmhp.core import guards
from rsmhp.models.uav import methods
from rsmhp.models.uav.methods.base import Method
from rsmhp.models.uav.planner import STARTS

__all__ = [
    "CONFIRM_STREAMS",
    "DRY_RUN_STREAM",
    "PLACEHOLDER_STREAM",
    "STREAMS",
    "Configuration",
    "Preregistration",
    "budget_cost",
    "candidate_stats",
    "candidates",
    "confirm_plan",
    "file_commit",
    "file_sha256",
    "select",
    "stream_seed",
    "tuning_configurations",
]

#: the seed streams of the protocol (:func:`stream_seed`)
STREAMS = ("exploratory", "tune", "confirm", "confirm2")

#: the streams a preregistration may name: ``confirm`` (first confirmatory run) and
#: ``confirm2`` (the second, after the budget rule changed: a stream its design never saw)
CONFIRM_STREAMS = ("confirm", "confirm2")
#: the stream a preregistration holds until the issue that runs it names one: the workflow
#: refuses to run it (:meth:`Preregistration.load`)
PLACEHOLDER_STREAM = "<named by the run issue>"
#: a dry run's stand-in for a stream not yet named (``snakemake -n --config
#: dry_run_stream=dry-run``): the workflow refuses it outside a dry run, so no job ever draws
#: from it
DRY_RUN_STREAM = "dry-run"


def stream_seed(seed: int, stream: str) -> int:
    """The root seed of ``stream``: ``seed`` itself for ``exploratory``; for the others
    (``tune``, ``confirm``, ``confirm2``) the first 63 bits of BLAKE2b-64 of
    ``"<seed>/<stream>"`` (independent of ``seed`` and of each other as far as any test can
    tell)."""
    seed = guards.nonneg_int("seed", seed)
    if stream not in (*STREAMS, DRY_RUN_STREAM):
        raise ValueError(f"stream: {stream!r} (allowed: {', '.join(STREAMS)})")
    if stream == "exploratory":
        return seed
    digest = hashlib.blake2b(f"{seed}/{stream}".encode(), digest_size=8).digest()
    return int.from_bytes(digest, "little") & (2**63 - 1)


@dataclass(frozen=True)
class Configuration:
    """A planning method (``member``: a registered method's name) with its optimiser budget:
    ``maxiter`` iterations (``None``: the ``uav.planner`` default), ``restarts`` and the
    ``start`` of the first optimisation (:data:`rsmhp.models.uav.planner.STARTS`)."""

    member: str
    maxiter: int | None = None
    restarts: int = 0
    start: str = "warm"

    def __post_init__(self) -> None:
        methods.from_name(self.member)  # refuses an unknown member, naming the families
        if self.maxiter is not None:
            object.__setattr__(self, "maxiter", guards.positive_int("maxiter", self.maxiter))
        object.__setattr__(self, "restarts", guards.integer("restarts", self.restarts, minimum=0))
        if self.start not in STARTS:
            raise ValueError(
                f"configuration {self.member!r}: start {self.start!r} (allowed: "
                f"{', '.join(map(repr, STARTS))})"
            )
        if not self.method.estimates_cost and (
            self.maxiter is not None or self.restarts or self.start != "warm"
        ):
            raise ValueError(
                f"configuration {self.member!r}: maxiter, restarts and start apply to "
                f"sampled-cost planners only, got maxiter={self.maxiter}, "
                f"restarts={self.restarts}, start={self.start!r}"
            )

    @property
    def method(self) -> Method:
        return methods.from_name(self.member)

    @property
    def family(self) -> str:
        return self.method.family

    @property
    def name(self) -> str:
        """``member`` alone for the default budget and start (``maxiter`` None, ``restarts``
        0, ``start`` ``"warm"``); else ``member[/it<maxiter>]/r<restarts>`` (``/it...`` only
        when ``maxiter`` is set), followed by ``/<start>`` when the start is not ``"warm"``:
        ``rsmhp_nt64/it30/r3``, ``rsmhp_nt64/r2``, ``nbo/it30/r3/pursuit``,
        ``rsmhp_nt64/r0/pursuit``. A warm start adds nothing, so every name written before
        ``start`` existed is unchanged."""
        if self.maxiter is None and self.restarts == 0 and self.start == "warm":
            return self.member
        it = "" if self.maxiter is None else f"/it{self.maxiter}"
        start = "" if self.start == "warm" else f"/{self.start}"
        return f"{self.member}{it}/r{self.restarts}{start}"

    def label(self) -> str:
        extra = []
        if self.maxiter is not None:
            extra.append(f"{self.maxiter} it")
        if self.restarts:
            extra.append(f"{self.restarts} restarts")
        if self.start != "warm":
            extra.append(f"{self.start} start")
        return methods.from_name(self.member).label() + (f" ({', '.join(extra)})" if extra else "")

    def setup(self, base: Any) -> Any:
        """``base`` (a :class:`rsmhp.models.uav.simulation.UAVSetup`) with this optimiser budget
        and start."""
        p = base.planner
        maxiter = p.maxiter if self.maxiter is None else self.maxiter
        maxfun = p.maxfun if self.maxiter is None else 2 * self.maxiter + 1
        planner = dataclasses.replace(
            p, maxiter=maxiter, maxfun=maxfun, restarts=self.restarts, start=self.start
        )
        return dataclasses.replace(base, planner=planner)

    def spec(self) -> dict[str, Any]:
        """``{"member", "maxiter", "restarts"}``, and ``"start"`` when it is not ``"warm"``
        (so the spec of a warm-start configuration, a rule's param, is what it was before
        ``start`` existed)."""
        out = {"member": self.member, "maxiter": self.maxiter, "restarts": self.restarts}
        if self.start != "warm":
            out["start"] = self.start
        return out

    @classmethod
    def from_spec(cls, spec: Mapping[str, Any]) -> Configuration:
        unknown = set(spec) - {"member", "maxiter", "restarts", "start"}
        if unknown or "member" not in spec:
            raise ValueError(
                f"configuration {dict(spec)!r}: needs 'member', may have 'maxiter', "
                f"'restarts' and 'start' (unknown: {sorted(unknown)})"
            )
        return cls(
            str(spec["member"]),
            spec.get("maxiter"),
            int(spec.get("restarts", 0)),
            str(spec.get("start", "warm")),
        )


def tuning_configurations(tuning: Mapping[str, Any]) -> list[Configuration]:
    """Everything the tuning runs: the untuned baseline ``nbo`` first (the tables' reference),
    then :func:`candidates` of ``tuning["candidates"]`` (``frontier.tuning``) but that one
    (each configuration once). The reference is also a candidate of its family:
    :func:`select` groups by family, so it competes with the tuned NBO configurations."""
    reference = Configuration(methods.baseline()().name)
    return [reference, *(c for c in candidates(tuning["candidates"]) if c != reference)]


def candidates(cfg: Mapping[str, Any]) -> list[Configuration]:
    """The tuning candidates of ``frontier.tuning.candidates``: every member of its
    ``methods`` block, the baseline family's (NBO) included; a sampled-cost member once per
    (maxiter, restarts, start) of ``optimiser`` (``start``: optional, default
    ``["warm"]``); a member without a cost estimate (tree search: its budget is its
    simulations and constants; pursuit policy) once, as it is. Table order, then maxiter,
    then restarts, then start."""
    block = cfg["methods"]
    opt = cfg["optimiser"]
    starts = opt.get("start", ["warm"])
    out: list[Configuration] = []
    for m in methods.from_config(block, "frontier.tuning.candidates.methods").values():
        if m.estimates_cost:
            out += [
                Configuration(m.name, int(it), int(r), str(st))
                for it in opt["maxiter"]
                for r in opt["restarts"]
                for st in starts
            ]
        else:
            out.append(Configuration(m.name))
    return out


def budget_cost(timed_ms, loop_ms):
    """The planning cost per step a budget counts (ms): the larger of the median interleaved
    time and the closed loop's own mean time per step (module docstring). Floats or arrays;
    NaN in one of them gives the other."""
    return np.fmax(timed_ms, loop_ms)


def candidate_stats(quality: pd.DataFrame, timing: pd.DataFrame) -> pd.DataFrame:
    """What the tuning rule reads of each candidate, indexed by (``model``, ``config``):
    ``mean_error`` (mean over its closed-loop runs), ``work_per_step`` (median),
    ``closed_loop_ms`` (mean planning ms per step of its runs), ``timing_ms`` (median of its
    interleaved timing) and ``cost_ms`` = :func:`budget_cost` of the two; NaN where a
    candidate has no rows of one kind. ``quality`` and ``timing`` as :func:`select` takes
    them."""
    q = quality.groupby(["model", "config"], sort=False).agg(
        mean_error=("mean_error", "mean"),
        work_per_step=("work_per_step", "median"),
        closed_loop_ms=("plan_ms", "mean"),
    )
    t = timing.groupby(["model", "config"], sort=False)["ms"].median().rename("timing_ms")
    out = q.join(t, how="outer")
    out["cost_ms"] = budget_cost(out["timing_ms"], out["closed_loop_ms"])
    return out


#: the columns of the tuning selection (:func:`select`)
SELECTION_COLUMNS = [
    "model",
    "family",
    "budget_ms",
    "config",
    "member",
    "maxiter",
    "restarts",
    "start",
    "plan_ms",
    "work_per_step",
    "mean_error",
    "timing_ms",
    "closed_loop_ms",
    "fitting",
]


def select(
    quality: pd.DataFrame,
    timing: pd.DataFrame,
    configs: Sequence[Configuration],
    budgets_ms: Sequence[float],
) -> pd.DataFrame:
    """The tuning rule of the module docstring: one row per (model, family, budget) with a
    candidate within the budget (:data:`SELECTION_COLUMNS`: ``plan_ms`` = the cost the rule
    compares with the budget, max(``timing_ms``, ``closed_loop_ms``); ``fitting`` = how many
    of the family's candidates fitted). ``quality``: closed-loop rows with ``model``,
    ``config``, ``run``, ``mean_error``, ``work_per_step``, ``plan_ms`` (the run's planning
    ms per step); ``timing``: rows with ``model``, ``config``, ``ms`` (interleaved calls). A
    configuration without rows is refused, naming it."""
    missing = {"model", "config", "run", "mean_error", "work_per_step", "plan_ms"} - set(quality)
    if missing:
        raise ValueError(f"tuning: closed-loop rows lack columns {sorted(missing)}")
    order = {c.name: i for i, c in enumerate(configs)}
    by_name = {c.name: c for c in configs}
    q = candidate_stats(quality, timing)
    rows = []
    for model in dict.fromkeys(quality["model"]):
        for c in configs:
            for what, col in (("closed-loop", "mean_error"), ("timing", "timing_ms")):
                if (model, c.name) not in q.index or pd.isna(q.loc[(model, c.name), col]):
                    raise ValueError(f"tuning: no {what} rows of {c.name!r} on {model!r}")
        cost = {c.name: float(q.loc[(model, c.name), "cost_ms"]) for c in configs}
        for family in dict.fromkeys(c.family for c in configs):
            fam = [c.name for c in configs if c.family == family]
            for b in budgets_ms:
                fit = [n for n in fam if cost[n] <= b]
                if not fit:
                    continue
                best = min(
                    fit,
                    key=lambda n: (
                        q.loc[(model, n), "mean_error"],
                        q.loc[(model, n), "work_per_step"],
                        order[n],
                    ),
                )
                c = by_name[best]
                rows.append(
                    {
                        "model": model,
                        "family": family,
                        "budget_ms": float(b),
                        "config": best,
                        "member": c.member,
                        "maxiter": c.maxiter,
                        "restarts": c.restarts,
                        "start": c.start,
                        "plan_ms": cost[best],
                        "work_per_step": float(q.loc[(model, best), "work_per_step"]),
                        "mean_error": float(q.loc[(model, best), "mean_error"]),
                        "timing_ms": float(q.loc[(model, best), "timing_ms"]),
                        "closed_loop_ms": float(q.loc[(model, best), "closed_loop_ms"]),
                        "fitting": len(fit),
                    }
                )
    return pd.DataFrame(rows, columns=SELECTION_COLUMNS)


def file_sha256(path: str | Path) -> str:
    """SHA-256 (hex) of a file's bytes."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def tuned_document(selection: pd.DataFrame, provenance: Mapping[str, Any]) -> dict[str, Any]:
    """The tuned file's content: ``provenance`` and, per model and budget (ms, as text), each
    family's chosen configuration (its :meth:`Configuration.spec`: ``start`` only when it is
    not ``"warm"``) with its tuning numbers."""
    chosen: dict[str, dict[str, dict[str, Any]]] = {}
    for r in selection.itertuples(index=False):
        at = chosen.setdefault(str(r.model), {}).setdefault(f"{r.budget_ms:g}", {})
        start = getattr(r, "start", "warm")
        at[str(r.family)] = {
            "member": str(r.member),
            "maxiter": None if pd.isna(r.maxiter) else int(r.maxiter),
            "restarts": int(r.restarts),
            **({} if start == "warm" else {"start": str(start)}),
            "tuning": {
                "plan_ms": round(float(r.plan_ms), 4),
                "timing_ms": round(float(r.timing_ms), 4),
                "closed_loop_ms": round(float(r.closed_loop_ms), 4),
                "work_per_step": round(float(r.work_per_step), 1),
                "mean_error": round(float(r.mean_error), 4),
                "candidates_within_budget": int(r.fitting),
            },
        }
    return {"provenance": dict(provenance), "chosen": chosen}


def tuned_configurations(doc: Mapping[str, Any], model: str) -> dict[str, dict[str, Configuration]]:
    """Budget (text) -> family -> :class:`Configuration` of ``model`` in a tuned document."""
    if model not in doc.get("chosen", {}):
        raise ValueError(
            f"tuned file: no configurations for model {model!r} "
            f"(tuned: {', '.join(doc.get('chosen', {})) or 'none'})"
        )
    return {
        b: {f: Configuration.from_spec({k: v for k, v in e.items() if k != "tuning"})
            for f, e in fams.items()}
        for b, fams in doc["chosen"][model].items()
    }  # fmt: skip


def load_yaml(path: str | Path, what: str) -> dict[str, Any]:
    """A YAML mapping from ``path``; a missing file or bad YAML is refused naming it."""
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"{what}: {p} does not exist")
    try:
        doc = yaml.safe_load(p.read_text(encoding="utf-8"))
    except yaml.YAMLError as exc:
        raise ValueError(f"{what}: {p} is not valid YAML ({exc})") from None
    if not isinstance(doc, dict):
        raise ValueError(f"{what}: {p} must hold a mapping, got {type(doc).__name__}")
    return doc


@dataclass(frozen=True)
class Preregistration:
    """The preregistration file (module docstring): ``path``, its ``sha256`` and content."""

    path: str
    sha256: str
    doc: Mapping[str, Any]

    REQUIRED = ("stream", "tuned", "models", "budgets_ms", "headline_budget_ms", "runs", "claims")
    #: what a version-3 preregistration adds (issue 43): the budget tolerance, each claim's
    #: comparator rule and secondaries, the power of every claim under its own rule, the
    #: paper's claims and the scope rule of "the paper's setups"
    REQUIRED_V3 = ("budget_tolerance", "comparator_rule", "secondaries", "power", "paper_claims",
                   "scope", "horizon", "holm")  # fmt: skip

    @classmethod
    def load(
        cls,
        path: str | Path,
        tuned_path: str | Path | None = None,
        dry_run_stream: str | None = None,
    ) -> Preregistration:
        """Read and check the file: every required key (and, for ``version: 3``, those of
        :data:`REQUIRED_V3`), a confirmatory stream, budgets and models that the tuned file has,
        and (given ``tuned_path``) the tuned file's SHA-256 equal to the one recorded. A
        stream that is still :data:`PLACEHOLDER_STREAM` is refused unless ``dry_run_stream``
        is :data:`DRY_RUN_STREAM` (a dry run's stand-in, which the content then holds). Every
        problem is named; nothing is run."""
        doc = load_yaml(path, "preregistration")
        missing = [k for k in cls.REQUIRED if k not in doc]
        if doc.get("version", 2) == 3:
            missing += [k for k in cls.REQUIRED_V3 if k not in doc]
        if missing:
            raise ValueError(f"preregistration {path}: missing {', '.join(missing)}")
        if doc.get("version", 2) == 3:
            from rsmhp.pipeline.power_design import power_problems

            bad = power_problems(doc["power"])
            if bad:
                raise ValueError(f"preregistration {path}: " + "; ".join(bad))
        if dry_run_stream is not None and dry_run_stream != DRY_RUN_STREAM:
            raise ValueError(
                f"dry_run_stream: {dry_run_stream!r} (allowed: {DRY_RUN_STREAM!r}, and only in a "
                "dry run)"
            )
        if doc["stream"] == PLACEHOLDER_STREAM:
            if dry_run_stream is None:
                raise ValueError(
                    f"preregistration {path}: stream is still {PLACEHOLDER_STREAM!r}: the "
                    "workflow runs no confirmatory job until the issue that runs it names the "
                    "stream (in a commit of its own); to list the jobs: snakemake -n --config "
                    f"dry_run_stream={DRY_RUN_STREAM}"
                )
            doc = {**doc, "stream": dry_run_stream}
        elif dry_run_stream is not None:
            raise ValueError(
                f"preregistration {path}: dry_run_stream is set but the stream is named "
                f"({doc['stream']!r}): the stand-in is for a preregistration whose stream is "
                f"still {PLACEHOLDER_STREAM!r}"
            )
        if doc["stream"] not in (*CONFIRM_STREAMS, DRY_RUN_STREAM):
            raise ValueError(
                f"preregistration {path}: stream {doc['stream']!r} (allowed: "
                f"{', '.join(map(repr, CONFIRM_STREAMS))}: the verdicts come from a "
                "confirmatory stream only)"
            )
        runs = doc["runs"]
        per = runs if isinstance(runs, dict) else dict.fromkeys(doc["models"], runs)
        bad = {
            m: n
            for m, n in per.items()
            if not (isinstance(n, int) and not isinstance(n, bool) and 2 <= n <= 100000)
        }
        if bad or set(per) != set(doc["models"]):
            raise ValueError(
                f"preregistration {path}: runs {runs!r} (allowed: an integer 2..100000, or one "
                f"per model of {doc['models']})"
            )
        if doc["headline_budget_ms"] not in doc["budgets_ms"]:
            raise ValueError(
                f"preregistration {path}: headline_budget_ms {doc['headline_budget_ms']!r} is "
                f"not one of budgets_ms {doc['budgets_ms']}"
            )
        if tuned_path is not None:
            want = doc["tuned"].get("sha256")
            got = file_sha256(tuned_path)
            if want != got:
                raise ValueError(
                    f"preregistration {path}: it was written for a tuned file with sha256 "
                    f"{want}, but {tuned_path} has {got}: the members would not be the "
                    "preregistered ones (rerun the tuning only with a new preregistration)"
                )
        return cls(str(path), file_sha256(path), doc)

    def runs(self, model: str) -> int:
        """The confirmatory runs of ``model``."""
        r = self.doc["runs"]
        return int(r[model] if isinstance(r, dict) else r)

    def configurations(self, tuned: Mapping[str, Any], model: str) -> list[Configuration]:
        """Every configuration the confirmatory run needs on ``model``: the baseline, then the
        tuned member of every family at every preregistered budget (each once)."""
        per = tuned_configurations(tuned, model)
        out = [Configuration(methods.baseline()().name)]
        for b in self.doc["budgets_ms"]:
            for c in per.get(f"{float(b):g}", {}).values():
                if c not in out:
                    out.append(c)
        return out


def power_runs(sd: float, effect: float, power: float = 0.8, cap: int | None = None) -> dict:
    """Runs of a paired comparison for ``power`` at ``effect`` given the per-run ``sd`` of
    the paired difference (:func:`rsmhp.core.stats.runs_for_power`), and, with a ``cap`` below
    that, the power the capped run count gives (:func:`rsmhp.core.stats.t_power`)."""
    from rsmhp.core.stats import runs_for_power, t_power

    n = runs_for_power(sd, effect, power=power)
    out = {"sd": sd, "effect": effect, "power": power, "runs": n}
    if cap is not None and n > cap:
        out.update(capped_runs=int(cap), power_at_cap=float(t_power(cap, sd, effect)))
    return out


def file_commit(path: str | Path) -> str:
    """The last commit that changed ``path`` (``git log -1``), ``"uncommitted"`` if the file
    differs from it or was never committed, ``"unknown"`` outside a git checkout (or without
    git). ``path`` is resolved first (``a/b/../c`` is ``a/c``); a file that does not exist is
    refused, naming it (a wrong path must not pass as "outside git")."""
    import subprocess

    p = Path(path).resolve()
    if not p.is_file():
        raise FileNotFoundError(f"file_commit: {path} (resolved: {p}) does not exist")
    out = []
    for cmd in (["git", "log", "-1", "--format=%H", "--", p.name],
                ["git", "status", "--porcelain", "--", p.name]):  # fmt: skip
        try:
            res = subprocess.run(cmd, cwd=p.parent, capture_output=True, text=True, timeout=60)
        except (OSError, subprocess.SubprocessError):
            return "unknown"
        if res.returncode != 0:
            return "unknown"  # not a git checkout
        out.append(res.stdout.strip())
    commit, dirty = out
    return commit if commit and not dirty else "uncommitted"


def confirm_plan(
    basedir: str | Path, frontier: Mapping[str, Any], dry_run_stream: str | None = None
) -> dict[str, Any] | None:
    """What the workflow's confirmatory rules need (JSON-ready, the rules' params): the
    preregistration (content, path, sha256; the commit that added it is looked up by the
    rule when it runs, :func:`file_commit`, so that a copy of the workflow outside git does
    not rerun anything), the tuned file (content, sha256), and
    per model its runs and configurations; ``None`` when ``frontier`` has no model
    or the preregistration file does not exist (the report then has no FR claims). A
    preregistration that does not fit the tuned file, or names a model outside
    ``frontier.models``, is refused naming both. ``dry_run_stream``: see
    :meth:`Preregistration.load`."""
    if not frontier.get("models"):
        return None
    conf = frontier["confirm"]
    base = Path(basedir)
    pre_path, tuned_path = base / conf["preregistration"], base / conf["tuned"]
    if not pre_path.is_file():
        return None
    pre = Preregistration.load(pre_path, tuned_path, dry_run_stream)
    tuned = load_yaml(tuned_path, "tuned file")
    outside = [m for m in pre.doc["models"] if m not in frontier["models"]]
    if outside:
        raise ValueError(
            f"preregistration {conf['preregistration']}: models {outside} are not in "
            f"frontier.models ({list(frontier['models'])})"
        )
    models = list(pre.doc["models"])
    return {
        "preregistration": dict(pre.doc),
        "path": str(conf["preregistration"]),
        "sha256": pre.sha256,
        "stream": str(pre.doc["stream"]),
        "tuned": tuned,
        "tuned_sha256": file_sha256(tuned_path),
        "models": models,
        "runs": {m: pre.runs(m) for m in models},
        "plans": {m: [c.spec() for c in pre.configurations(tuned, m)] for m in models},
    }
