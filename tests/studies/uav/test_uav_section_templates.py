"""The UAV section's prose templates (``src/rsmhp/studies/uav/*.md``): every name a template
uses is a value the section module passes, a missing value is an error, nothing is left
unfilled; and the section assembled from them on small synthetic runs."""

from __future__ import annotations

import re
from importlib import resources
from typing import Any

import jinja2
import numpy as np
import pandas as pd
import pytest
from jinja2 import meta

from rsmhp.report.templates import render
from rsmhp.studies.uav import claims as uav_claims
from rsmhp.studies.uav import section as narrative
from rsmhp.studies.uav import summarise as analysis

PACKAGE = "rsmhp.studies.uav"
LEFT_OVER = re.compile(r"\{\{|\}\}|\{%|%\}|\{#|#\}")


#: small values for every template, every optional part present (so every name is used)
VALUES: dict[str, dict[str, Any]] = {
    "section.md": {
        "n_runs": "8",
        "steps": "12",
        "dt": "1",
        "horizon": "4",
        "has_rsmhp": True,
        "nt_set": "{5, 20}",
        "trees": [narrative.Tree(N="3", M="20")],
        "other_methods": ["other member"],
        "variant_note": " **Model variant, not the paper's model:** a variant.",
        "n_boot": "200",
        "mean_min": "12.03",
        "mean_max": "12.11",
        "sd": "2.7",
        "key_numbers": [narrative.KeyNumberText("UAV-1", "-0.017", "[-0.15, +0.12]", "equivalent")],
        "margin": "0.25",
        "margin_pct": "2.1",
        "margin_sd": "0.092",
        "n_claims": 3,
        "n_equivalent": 1,
        "n_inconclusive": 1,
        "half_width": "0.15",
        "half_width_pct": "1.3",
        "decided": [narrative.KeyNumberText("UAV-3", "-0.50", "[-0.9, -0.1]", "supported")],
        "unresolved": [narrative.PaperFigure(figure="Fig. 4", id="UAV-1")],
        "nts": "5, 20",
        "largest_rsmhp": "RS-MHP N_T=20",
        "notes": {stem: f"note on {stem}" for stem in narrative.FIGURES},
    },
    "section_appendix.md": {
        "dt": "1",
        "aircraft": {
            "altitude": "100",
            "accel_max": "3",
            "bank_max_deg": "45",
            "speed_min": "10",
            "speed_max": "35",
        },
        "target": {"q": "1"},
        "sensor": {"sigma_r_per_m": "0.05", "sigma_c_per_m": "0.1"},
        "tracker": {"p0_pos_sd": "50", "p0_vel_sd": "5"},
        "scenario": {
            "target_speed_min": "5",
            "target_speed_max": "12",
            "uav_distance_min": "300",
            "uav_distance_max": "600",
            "uav_speed": "20",
        },
        "horizon": "4",
        "optimiser": "scipy",
        "maxiter": "5",
        "maxfun": "10",
        "variant_note": "",
        "methods_table": "| method |\n|:--|\n| NBO |",
        "paired_table": "| comparison |\n|:--|\n| a − b |",
    },
    "section_variant.md": {
        "footprint": narrative.Footprint(radius="150", detection="logistic", width="12.5"),
        "reference": "80",
    },
    "section_paired_table.md": {"table": "| a |\n|--:|\n| 1 |", "undefined_p": True},
}


def _source(template: str) -> str:
    return (resources.files(PACKAGE) / template).read_text(encoding="utf-8")


def _filled(text: str) -> None:
    assert text.strip(), "empty"
    assert not LEFT_OVER.search(text), LEFT_OVER.search(text)
    assert "None" not in text and "\n\n\n" not in text


def test_every_template_is_tested():
    """Every template beside the modules is a section template tested here, or the words of
    the claims (``claims.md``, :data:`rsmhp.studies.uav.claims.WORDS`, tested with them)."""
    found = {p.name for p in resources.files(PACKAGE).iterdir() if p.name.endswith(".md")}
    assert uav_claims.WORDS.package == PACKAGE
    assert found == set(VALUES) | {uav_claims.WORDS.template}


@pytest.mark.parametrize("template", sorted(VALUES))
def test_template_names_exactly_its_values(template):
    used = meta.find_undeclared_variables(jinja2.Environment().parse(_source(template)))
    assert used == set(VALUES[template])


@pytest.mark.parametrize("template", sorted(VALUES))
def test_template_renders_completely(template):
    _filled(render(PACKAGE, template, **VALUES[template]))


@pytest.mark.parametrize(
    ("template", "name"), [(t, n) for t, values in sorted(VALUES.items()) for n in values]
)
def test_a_missing_value_is_an_error(template, name):
    values = {k: v for k, v in VALUES[template].items() if k != name}
    with pytest.raises(jinja2.UndefinedError, match=name):
        render(PACKAGE, template, **values)


def test_variant_note_is_empty_for_the_reconstruction():
    assert narrative._variant_note({"sigma_r_per_m": 0.05}) == ""
    note = narrative._variant_note(
        {"footprint_radius": 150.0, "noise_growth": "quadratic", "reference_distance": 80.0}
    )
    assert note == (
        " **Model variant, not the paper's model:** a sensor footprint of radius 150 m "
        "(truth detections hard, planner width 10 m); noise growing quadratically with "
        "distance (reference 80 m)."
    )


# ------------------------------------------------------------ the section on synthetic runs

METHODS = {  # method: (family, N_T, N, M)
    "nbo": ("nbo", 1, 0, 0),
    "rsmhp_nt5": ("rsmhp", 5, 0, 0),
    "rsmhp_nt20": ("rsmhp", 20, 0, 0),
    "tree_n3_m20": ("tree", 20, 3, 20),
}
SETTING = {
    "dt": 1.0,
    "g": 9.81,
    "aircraft": {
        "accel_max": 3.0,
        "bank_max_deg": 45.0,
        "speed_min": 10.0,
        "speed_max": 35.0,
        "altitude": 100.0,
    },
    "target": {"q": 1.0},
    "sensor": {
        "sigma_r_per_m": 0.05,
        "sigma_c_per_m": 0.1,
        "footprint_radius": 150.0,
        "footprint_width": 10.0,
        "detection": "hard",
        "noise_growth": "linear",
        "reference_distance": 100.0,
    },
    "tracker": {"p0_pos_sd": 50.0, "p0_vel_sd": 5.0},
    "scenario": {
        "steps": 12,
        "target_box": 200.0,
        "target_speed_min": 5.0,
        "target_speed_max": 12.0,
        "uav_distance_min": 300.0,
        "uav_distance_max": 600.0,
        "uav_speed": 20.0,
    },
    "planner": {"horizon": 4, "maxiter": 5, "maxfun": 10, "optimiser": "boxqn"},
}


def _runs(n_runs: int = 8) -> pd.DataFrame:
    rng = np.random.default_rng(3)
    base = rng.normal(12.0, 2.0, n_runs)
    rows = [
        {
            "method": m,
            "family": fam,
            "N_T": nt,
            "N": n,
            "M": mm,
            "run": r,
            "seed": 7,
            "mean_error": base[r] + rng.normal(0.0, 0.1),
            "rmse": base[r] + 2.0,
            "final_error": base[r] - 1.0,
            "mean_trace": 240.0 + r,
            "mean_nit": 4.0,
            "plan_seconds": 0.01,
        }
        for m, (fam, nt, n, mm) in METHODS.items()
        for r in range(n_runs)
    ]
    return pd.DataFrame(rows)


def test_section_is_assembled_from_the_templates(monkeypatch):
    runs = _runs()
    summary = analysis.summarize_methods(runs, 7, 200)
    paired = analysis.paired_differences(runs, 7, 200)
    tables = narrative.uav_tables(summary, paired)
    calls: list[tuple[str, set[str]]] = []

    def spy(package: str, template: str, /, **values: Any) -> str:
        calls.append((template, set(values)))
        return render(package, template, **values)

    monkeypatch.setattr(narrative, "render", spy)
    section = narrative.uav_section(summary, paired, tables, SETTING, 200, runs, 0.25)
    for template, names in calls:  # the module passes just the values each template uses
        used = meta.find_undeclared_variables(jinja2.Environment().parse(_source(template)))
        assert names == used, template
    assert {t for t, _ in calls} == {"section.md", "section_appendix.md", "section_variant.md"}
    for text in (section.body, section.appendix):
        _filled(text)
        assert not text.endswith("\n")
        assert (
            "**Model variant, not the paper's model:** a sensor footprint of radius 150 m" in text
        )
    assert "RS-MHP with N_T ∈ {5, 20} independently sampled" in section.body
    assert "a pruned tree (3 draws per level, the 20 most likely kept)" in section.body
    assert section.body.count("](figures/") == len(narrative.FIGURES)
    assert tables["uav_methods"] in section.appendix and tables["uav_paired"] in section.appendix
    assert "a projected L-BFGS (`rsmhp.core.boxqn`" in section.appendix
