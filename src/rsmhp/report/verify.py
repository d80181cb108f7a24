r"""Compare a run's claims with the committed reference, claim by claim (``make verify``).

The report rule writes every claim with its key number to ``results/paper/claims.json``;
``make publish`` copies it to the committed reference ``paper/claims.json``. For each claim
this module compares the reference and this run:

* **bitwise** key numbers (LQG, estimator and LQG-decision studies) agree within the
  floating-point tolerance :math:`|x - x_\mathrm{ref}| \le 10^{-9} \max(1, |x_\mathrm{ref}|)`:
  on the same machine and versions they are identical; elsewhere only summation order and
  vectorised math functions change, which moves them by about :math:`10^{-12}` relative.
* **statistical** key numbers (UAV closed loop and UAV decision study) agree when
  :math:`|x - x_\mathrm{ref}| \le z \sqrt{s_\mathrm{ref}^2 + s^2}`, with each standard error
  taken from its 95% CI, :math:`s = (\mathrm{hi} - \mathrm{lo}) / (2 \cdot 1.96)`, and
  :math:`z = \Phi^{-1}(1 - 0.05 / (2m))` Bonferroni-corrected over the ``m`` statistical
  claims: two independent runs of the same pipeline fall outside with probability <= 5%
  in all (a run on another machine shares the seeds, so it is closer than independent).
* the **verdict** must be the same, and so must the verdict of every statement of the paper
  (``statements`` of ``claims.json``, when both files have them).

The check fails (exit status 1) when a verdict flips, a number lies outside its tolerance,
a claim is missing or new, or a claim's key number was redefined (different name or unit:
publish a new reference with ``make publish`` after such a change).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pandas as pd
from scipy.stats import norm

from rsmhp.report.ledger import Claim
from rsmhp.report.markdown import fmt, markdown_table

__all__ = [
    "VerificationError",
    "compare",
    "load_claims",
    "load_statements",
    "main",
    "render",
    "statement_flips",
    "tolerance",
]

#: relative floating-point tolerance of bitwise-reproducible key numbers
BITWISE_RTOL = 1e-9

#: family-wise level of the statistical comparison
FAMILY_LEVEL = 0.05


class VerificationError(RuntimeError):
    """A run disagrees with the reference (a verdict flipped, a number moved too far)."""


def load_claims(path: str | os.PathLike) -> tuple[list[Claim], str]:
    """(claims, config hash) from a ``claims.json`` (``{"config sha256": ..., "claims": [...]}``);
    a clear ``ValueError`` if the file is missing or not of that form."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
        if not isinstance(data, dict) or not isinstance(data.get("claims"), list):
            raise TypeError("expected a JSON object with a list 'claims'")
        return [Claim.from_dict(c) for c in data["claims"]], str(data.get("config sha256", "?"))
    except FileNotFoundError:
        raise ValueError(f"{path}: not found") from None
    except (ValueError, TypeError, KeyError) as exc:
        raise ValueError(f"{path}: not a valid claims file ({exc})") from exc


def _se(c: Claim) -> float:
    return (c.key.ci_high - c.key.ci_low) / (2 * norm.ppf(0.975))


def tolerance(ref: Claim, run: Claim, n_statistical: int) -> float:
    """Allowed |run - reference| of the key number (see the module docstring)."""
    if ref.key.reproducible == "bitwise":
        return BITWISE_RTOL * max(1.0, abs(ref.key.value))
    z = norm.ppf(1 - FAMILY_LEVEL / (2 * max(n_statistical, 1)))
    return float(z * math.hypot(_se(ref), _se(run)))


def compare(
    reference: Sequence[Claim], run: Sequence[Claim], n_statistical: int | None = None
) -> pd.DataFrame:
    """One row per claim id (reference order, then claims new in this run): reference and
    run key numbers, difference, tolerance, both verdicts and a status, ``ok`` or the reason
    it fails. ``n_statistical``: the statistical claims the tolerance's family counts (default:
    those of ``reference``; a comparison of some claims passes the whole reference's)."""
    ref_by = {c.id: c for c in reference}
    run_by = {c.id: c for c in run}
    n_stat = (
        sum(c.key.reproducible == "statistical" for c in reference)
        if n_statistical is None
        else n_statistical
    )
    rows: list[dict[str, Any]] = []
    for cid in [*ref_by, *(c for c in run_by if c not in ref_by)]:
        ref, new = ref_by.get(cid), run_by.get(cid)
        row: dict[str, Any] = {"id": cid}
        some = ref or new
        row["key number"] = some.key.name + (f" ({some.key.unit})" if some.key.unit else "")
        row["reproducible"] = some.key.reproducible
        row["reference"] = ref.key.value if ref else math.nan
        row["this run"] = new.key.value if new else math.nan
        row["difference"] = row["this run"] - row["reference"]
        row["tolerance"] = math.nan
        row["verdict (reference)"] = ref.verdict if ref else "-"
        row["verdict (this run)"] = new.verdict if new else "-"
        if ref is None:
            row["status"] = "new in this run (publish a new reference)"
        elif new is None:
            row["status"] = "missing in this run"
        elif (ref.key.name, ref.key.unit, ref.key.reproducible) != (
            new.key.name,
            new.key.unit,
            new.key.reproducible,
        ):
            row["status"] = f"key number redefined (reference: {ref.key.name!r})"
        else:
            tol = tolerance(ref, new, n_stat)
            row["tolerance"] = tol
            problems = []
            if new.verdict != ref.verdict:
                problems.append("verdict flipped")
            if abs(row["difference"]) > tol:
                problems.append("outside tolerance")
            row["status"] = ", ".join(problems) or "ok"
        rows.append(row)
    return pd.DataFrame(rows)


def render(table: pd.DataFrame, reference: str, run: str) -> str:
    """Markdown report of a comparison: a summary line and the claim-by-claim table."""
    n_ok = int((table["status"] == "ok").sum())
    shown = table.copy()
    for col in ("reference", "this run", "difference", "tolerance"):
        shown[col] = [
            "-" if not math.isfinite(v) else fmt(v, 4, signed=col == "difference")
            for v in shown[col]
        ]
    verdict = "PASS" if n_ok == len(table) else "FAIL"
    return (
        f"# verify: {verdict}\n\nReference `{reference}`, this run `{run}`: {n_ok} of "
        f"{len(table)} claims agree (same verdict, key number within tolerance). Tolerances: "
        f"bitwise numbers {BITWISE_RTOL:g} x max(1, |reference|); statistical numbers "
        "z * sqrt(se_ref^2 + se_run^2), se from each 95% CI, z Bonferroni-corrected to a "
        f"family-wise {FAMILY_LEVEL:g}. '-' marks a value that does not exist (claim missing "
        "or redefined).\n\n" + markdown_table(shown) + "\n"
    )


def verify(reference: str | os.PathLike, run: str | os.PathLike) -> tuple[bool, str]:
    """Compare two claims files; (all agree, Markdown report). ``ValueError`` if they come
    from different configurations or were judged under different preregistrations (their
    ``preregistration.sha256``): nothing to compare claim by claim."""
    ref_claims, ref_hash = load_claims(reference)
    run_claims, run_hash = load_claims(run)
    if ref_hash != run_hash:
        raise ValueError(
            f"{run} comes from config sha256 {run_hash}, the reference {reference} from "
            f"{ref_hash}: verify compares runs of the same configuration (config/config.yaml "
            "without overrides for paper/claims.json)"
        )
    ref_pre, run_pre = load_preregistration(reference), load_preregistration(run)
    if ref_pre.get("sha256") != run_pre.get("sha256"):
        raise ValueError(
            f"{run} was judged under preregistration sha256 {run_pre.get('sha256')} "
            f"({run_pre.get('path')}), the reference {reference} under "
            f"{ref_pre.get('sha256')} ({ref_pre.get('path')}): verify compares runs of the "
            "same preregistration (restore the committed config/preregistration.yaml and "
            "config/tuned.yaml, or publish a new reference after a new preregistration)"
        )
    table = compare(ref_claims, run_claims)
    ok = bool((table["status"] == "ok").all())
    text = render(table, str(reference), str(run))
    flips = statement_flips(load_statements(reference), load_statements(run))
    if flips:
        ok = False
        text = text.replace("# verify: PASS", "# verify: FAIL", 1)
        text += "\nStatements of the paper whose verdict differs: " + "; ".join(flips) + "\n"
    return ok, text


def load_preregistration(path: str | os.PathLike) -> dict[str, str]:
    """The ``preregistration`` record of a ``claims.json`` (path, sha256, commit of the file
    the run was judged under); empty for a file without one (no confirmatory run)."""
    data = json.loads(Path(path).read_text(encoding="utf-8"))
    return dict(data.get("preregistration") or {})


def load_statements(path: str | os.PathLike) -> dict[str, str]:
    """Statement id -> verdict of a ``claims.json`` (empty for a file without statements,
    e.g. a reference written before the ledger had them)."""
    data = json.loads(Path(path).read_text(encoding="utf-8"))
    return {str(s["id"]): str(s["verdict"]) for s in data.get("statements", [])}


def statement_flips(reference: dict[str, str], run: dict[str, str]) -> list[str]:
    """``S5: mixed -> supported`` for every statement the two files judge differently, and
    statements present in only one of them (unless the reference has none at all)."""
    if not reference:  # a reference written before the ledger had statements
        return []
    out = []
    for sid in [*reference, *(k for k in run if k not in reference)]:
        a, b = reference.get(sid, "-"), run.get(sid, "-")
        if a != b:
            out.append(f"{sid}: {a} -> {b}")
    return out


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m rsmhp.report.verify [--reference paper/claims.json] [--run
    results/paper/claims.json] [--output results/verify.md]``: print the comparison, write it
    to ``--output``, exit 1 if any claim disagrees (2 for unreadable input)."""
    p = argparse.ArgumentParser(
        prog="python -m rsmhp.report.verify", description=__doc__.split("\n")[0]
    )
    p.add_argument("--reference", default="paper/claims.json")
    p.add_argument("--run", default="results/paper/claims.json")
    p.add_argument("--output", default=None, help="also write the Markdown report here")
    args = p.parse_args(argv)
    try:
        ok, text = verify(args.reference, args.run)
    except ValueError as exc:
        print(f"verify: {exc}", file=sys.stderr)
        return 2
    print(text)
    if args.output:
        Path(args.output).parent.mkdir(parents=True, exist_ok=True)
        Path(args.output).write_text(text, encoding="utf-8")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
