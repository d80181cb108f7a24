"""The ledger fields of claims UAV-1..3 (rsmhp.studies.uav.claims) on small synthetic runs:
``n`` is the number of runs the paired comparison's CI rests on (runs with a result for both
methods, counted in the input), ``margin`` the equivalence margin its rule prints, and no
UAV claim is a check of our own machinery. Every macro of the claims' template is used."""

from __future__ import annotations

import ast
import inspect
from importlib import resources
from types import ModuleType

import jinja2
import numpy as np
import pandas as pd
import pytest
from jinja2 import nodes

from rsmhp.report.claimspec import TEXT_FIELDS, ClaimSpec
from rsmhp.report.templates import CONTINUATION
from rsmhp.studies.uav import claims as uav_claims
from rsmhp.studies.uav import summarise as analysis

METHODS = {  # method: (family, N_T, N, M)
    "nbo": ("nbo", 1, 0, 0),
    "rsmhp_nt5": ("rsmhp", 5, 0, 0),
    "rsmhp_nt20": ("rsmhp", 20, 0, 0),
    "tree_n3_m20": ("tree", 20, 3, 20),
}
N_RUNS = 9


def _runs(missing: dict[str, list[int]]) -> pd.DataFrame:
    """Closed-loop rows of every method over ``N_RUNS`` runs, less the runs ``missing[method]``
    (a method without a result for them)."""
    rng = np.random.default_rng(5)
    base = rng.normal(12.0, 2.0, N_RUNS)
    rows = [
        {"method": m, "family": fam, "N_T": nt, "N": n, "M": mm, "run": r, "seed": 7,
         "mean_error": base[r] + rng.normal(0.0, 0.2), "rmse": 14.0, "final_error": 11.0,
         "mean_trace": 240.0, "mean_nit": 4.0, "plan_seconds": 0.01}
        for m, (fam, nt, n, mm) in METHODS.items()
        for r in range(N_RUNS)
        if r not in missing.get(m, [])
    ]  # fmt: skip
    return pd.DataFrame(rows)


def _paired_runs(runs: pd.DataFrame, a: str, b: str) -> int:
    """Runs of ``runs`` with a result for both ``a`` and ``b``, counted by hand."""
    have = runs.groupby("method")["run"].apply(set)
    return len(have[a] & have[b])


@pytest.mark.parametrize("margin", [0.25, 0.4])
def test_n_is_the_paired_runs_and_margin_the_rules(margin):
    runs = _runs({"nbo": [2], "tree_n3_m20": [0, 4, 7]})
    summary = analysis.summarize_methods(runs, 7, 200)
    paired = analysis.paired_differences(runs, 7, 200)
    claims = {c.id: c for c in uav_claims.uav_claims(summary, paired, margin)}
    want = {
        "UAV-1": ("rsmhp_nt20", "rsmhp_nt5"),
        "UAV-2": ("rsmhp_nt20", "nbo"),
        "UAV-3": ("rsmhp_nt20", "tree_n3_m20"),
    }
    assert set(claims) == set(want)
    for cid, (a, b) in want.items():
        c = claims[cid]
        assert not c.check
        assert c.key.n == _paired_runs(runs, a, b)
        assert c.key.margin == margin and f"±{margin:g} m" in c.rule
        assert c.key.null == 0.0  # the margin is an equivalence margin, not the null
    assert (claims["UAV-1"].key.n, claims["UAV-2"].key.n, claims["UAV-3"].key.n) == (9, 8, 6)


def unused_macros(module: ModuleType) -> set[str]:
    """The macros of a claims module's template (its ``WORDS``) that nothing uses: neither the
    module (the macro's name as a string constant), nor a claim spec of the module (the texts
    ``<prefix>_<field>``), nor another macro."""
    words = module.WORDS
    source = resources.files(words.package).joinpath(words.template).read_text(encoding="utf-8")
    tree = jinja2.Environment().parse(CONTINUATION.sub(" ", source))
    defined = {m.name for m in tree.find_all(nodes.Macro)}
    called = {c.node.name for c in tree.find_all(nodes.Call) if isinstance(c.node, nodes.Name)}
    code = {
        n.value
        for n in ast.walk(ast.parse(inspect.getsource(module)))
        if isinstance(n, ast.Constant) and isinstance(n.value, str)
    }
    specs = [
        s
        for v in vars(module).values()
        for s in (v.values() if isinstance(v, dict) else [v])
        if isinstance(s, ClaimSpec)
    ]
    texts = {f"{s.prefix}_{f}" for s in specs for f in TEXT_FIELDS}
    assert specs and defined
    return defined - called - code - texts


def test_every_macro_of_the_claims_template_is_used():
    assert unused_macros(uav_claims) == set()
