"""Every verdict a claim has had, and the fragility line of a verdict that moved.

The committed file ``paper/history.csv`` keeps, per claim, the verdicts and key numbers of
earlier judgements of the same claim id, one row each, of three kinds:

* ``implementation``: a published run (``make publish`` adds one row per claim, labelled
  with the run's commit): a verdict that moved here moved with a change of code, rule or
  config;
* ``machine``: the same code on an emulated other CPU (``make portability``; ``against``
  holds the verdict of the native run of that drill);
* ``stream``: the same claim on another seed stream (the exploratory runs, a superseded
  confirmatory stream).

A verdict is *fragile* when the current verdict, the verdicts of its rows and their
``against`` verdicts are not all the same; the report prints a line for it
(:func:`fragility`). The file is an input of the report rule, so a new row reruns only the
report.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path

import pandas as pd

from rsmhp.report.ledger import CLAIM_OUTCOMES, Claim
from rsmhp.report.markdown import fmt

__all__ = ["COLUMNS", "KINDS", "add_claims", "fragility", "load_history", "main"]

#: the columns of ``paper/history.csv``
COLUMNS = ("claim", "kind", "label", "date", "verdict", "value", "ci_low", "ci_high", "against")
#: the kinds of earlier judgement, in the order a fragility line names them
KINDS = ("implementation", "machine", "stream")
_KIND_TEXT = {
    "implementation": "published runs",
    "machine": "another machine",
    "stream": "another seed stream",
}


def load_history(path: str | os.PathLike | None) -> pd.DataFrame:
    """The history table (empty without a file); refuses unknown columns, kinds or
    verdicts, naming the row."""
    if path is None or not Path(path).exists():
        return pd.DataFrame(columns=list(COLUMNS))
    try:
        df = pd.read_csv(path, dtype={"label": str, "date": str, "against": str})
    except (OSError, ValueError) as exc:
        raise ValueError(f"{path}: not a readable history table ({exc})") from exc
    if tuple(df.columns) != COLUMNS:
        raise ValueError(f"{path}: columns must be {list(COLUMNS)}, got {list(df.columns)}")
    for i, row in df.iterrows():
        if row["kind"] not in KINDS:
            raise ValueError(
                f"{path} row {i + 2}: kind must be one of {KINDS}, got {row['kind']!r}"
            )
        for col in ("verdict", "against"):
            v = row[col]
            if isinstance(v, str) and v not in CLAIM_OUTCOMES:
                raise ValueError(
                    f"{path} row {i + 2}: {col} must be one of {CLAIM_OUTCOMES}, got {v!r}"
                )
        if not isinstance(row["verdict"], str):
            raise ValueError(f"{path} row {i + 2}: verdict is missing")
    df["against"] = df["against"].where(df["against"].notna(), None)
    return df


def add_claims(
    history: pd.DataFrame,
    claims: Iterable[dict],
    *,
    kind: str,
    label: str,
    date: str,
    against: dict[str, str] | None = None,
) -> pd.DataFrame:
    """``history`` with one row per claim (records as in ``claims.json``); a row with the
    same claim, kind and label is replaced (publishing the same run twice adds nothing)."""
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    if not label.strip():
        raise ValueError("label must name the run (e.g. its commit)")
    rows = []
    for c in claims:
        k = c["key"]
        rows.append(
            {
                "claim": c["id"],
                "kind": kind,
                "label": label,
                "date": date,
                "verdict": c["verdict"],
                "value": k["value"],
                "ci_low": k.get("ci_low"),
                "ci_high": k.get("ci_high"),
                "against": (against or {}).get(c["id"]),
            }
        )
    new = pd.DataFrame(rows, columns=list(COLUMNS))
    keep = ~(
        (history["kind"] == kind)
        & (history["label"] == label)
        & history["claim"].isin(new["claim"])
    )
    out = pd.concat([history[keep], new], ignore_index=True) if len(history) else new
    return out[list(COLUMNS)]


def _sign(value: float, null: float) -> int:
    return 0 if value == null else (1 if value > null else -1)


def _runs(labels: Sequence[str], verdicts: Sequence[str]) -> str:
    """``"inconclusive (a to c, 3 runs) → equivalent (d to now, 4 runs)"``: consecutive
    equal verdicts merged."""
    groups: list[list] = []
    for lab, v in zip(labels, verdicts, strict=True):
        if groups and groups[-1][0] == v:
            groups[-1][1].append(lab)
        else:
            groups.append([v, [lab]])
    parts = []
    for v, labs in groups:
        span = labs[0] if len(labs) == 1 else f"{labs[0]} to {labs[-1]}, {len(labs)} runs"
        parts.append(f"{v} ({span})")
    return " → ".join(parts)


def fragility(claim: Claim, history: pd.DataFrame, run: str | None = None) -> str:
    """The fragility line of ``claim`` (empty when every verdict it has had agrees): per
    kind of earlier judgement, the verdicts in order; with a ``null`` of 0, whether the key
    number changed sign. ``run``: this run's label (its commit, 7 characters): a published
    row of this very run (``make publish`` adds one) is this run, not an earlier one."""
    rows = history[history["claim"] == claim.id]
    if run:
        rows = rows[~((rows["kind"] == "implementation") & (rows["label"] == run[:7]))]
    if rows.empty:
        return ""
    seen = set(rows["verdict"]) | {v for v in rows["against"] if isinstance(v, str)}
    if seen <= {claim.verdict}:
        return ""
    parts = []
    for kind in KINDS:
        r = rows[rows["kind"] == kind]
        if r.empty:
            continue
        if kind == "implementation":
            r = r.sort_values("date", kind="stable")
            labels = [*r["label"], "this run"]
            verdicts = [*r["verdict"], claim.verdict]
            if len(set(verdicts)) > 1:
                parts.append(f"{_KIND_TEXT[kind]}: {_runs(labels, verdicts)}")
        else:
            for _, row in r.iterrows():
                base = row["against"] if isinstance(row["against"], str) else claim.verdict
                if row["verdict"] != base:
                    parts.append(
                        f"{_KIND_TEXT[kind]} ({row['label']}): {row['verdict']} where "
                        f"{'the native run' if kind == 'machine' else 'this stream'} gave {base}"
                    )
    k = claim.key
    if k.null == 0.0:
        flips = [
            (v, lab)
            for v, lab in zip(rows["value"], rows["label"], strict=True)
            if isinstance(v, float) and math.isfinite(v) and _sign(v, 0.0) * _sign(k.value, 0.0) < 0
        ]
        if flips:
            v, lab = flips[-1]
            parts.append(
                f"key number changed sign ({fmt(v, k.digits, True)} in {lab}, "
                f"{fmt(k.value, k.digits, True)} now)"
            )
    return "; ".join(parts)


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m rsmhp.report.history add CLAIMS --kind K --label L [--date D]
    [--against NATIVE_CLAIMS] [--history paper/history.csv]``: add a run's claims."""
    ap = argparse.ArgumentParser(prog="python -m rsmhp.report.history", description=main.__doc__)
    sub = ap.add_subparsers(dest="cmd", required=True)
    add = sub.add_parser("add", help="add the claims of a claims.json as rows")
    add.add_argument("claims", help="a claims.json (results/paper/claims.json)")
    add.add_argument("--kind", required=True, choices=KINDS)
    add.add_argument("--label", help="what the run was (default: its commit, 7 characters)")
    add.add_argument("--date", default=pd.Timestamp.now("UTC").strftime("%Y-%m-%d %H:%M"))
    add.add_argument("--against", help="claims.json of the run compared with (machine drill)")
    add.add_argument("--history", default="paper/history.csv")
    a = ap.parse_args(argv)
    try:
        data = json.loads(Path(a.claims).read_text(encoding="utf-8"))
        claims = data["claims"] if isinstance(data, dict) else data
        commit = data.get("commit") if isinstance(data, dict) else None
        label = a.label or str(commit or "")[:7]
        if not label:
            raise ValueError(f"{a.claims} names no commit: give --label")
        against = None
        if a.against:
            ref = json.loads(Path(a.against).read_text(encoding="utf-8"))
            against = {c["id"]: c["verdict"] for c in ref["claims"]}
        out = add_claims(
            load_history(a.history), claims, kind=a.kind, label=label, date=a.date, against=against
        )
    except (OSError, ValueError, KeyError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    Path(a.history).parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(f"{a.history}.tmp")
    out.to_csv(tmp, index=False)
    os.replace(tmp, a.history)
    print(f"{a.history}: {len(claims)} rows of {a.kind} {label!r} ({len(out)} rows in all)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
