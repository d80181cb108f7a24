"""One colour per method (rsmhp.report.palette), shared by figures and recordings."""

import ast
import sys
from pathlib import Path

import pytest

import rsmhp.models.uav.methods  # registers the UAV method names with the palette
from rsmhp.models.lqg import recording
from rsmhp.report import palette
from rsmhp.report.palette import METHOD_COLOURS, method_colour, method_label, method_rgb

#: every method name that appears in a results table of the pipeline
PIPELINE_METHODS = [
    "nbo", "mc", "tree", "tree_pernode", "pruned", "antithetic", "sobol", "cubature",
    "gauss_hermite", "rsmhp_nt10", "rsmhp_nt50", "rsmhp_nt100", "rsmhp_nt250", "tree_n8_m100",
]  # fmt: skip


def _luminance(hex_colour: str) -> float:
    r, g, b = (int(hex_colour[i : i + 2], 16) / 255 for i in (1, 3, 5))
    return 0.2126 * r + 0.7152 * g + 0.0722 * b


def test_every_pipeline_method_has_a_colour_and_a_label():
    for m in PIPELINE_METHODS:
        assert method_colour(m).startswith("#") and len(method_colour(m)) == 7
        assert method_label(m)
    # method families are told apart: distinct colours
    families = [c for k, c in METHOD_COLOURS.items() if k != "rsmhp"]
    assert len(set(families)) == len(families)
    assert method_colour("tree_n8_m100") == method_colour("pruned")
    assert method_colour("rsmhp_nt100") == method_colour("mc")
    assert method_label("rsmhp_nt250") == "RS-MHP N_T=250"
    assert method_label("tree_n8_m100") == "pruned tree N=8 M=100"


def test_rsmhp_shades_get_darker_with_n_t_and_do_not_depend_on_the_figure():
    lum = [_luminance(method_colour(f"rsmhp_nt{n}")) for n in (10, 50, 100, 250, 1000)]
    assert lum == sorted(lum, reverse=True) and len(set(lum)) == len(lum)
    assert method_colour("RSMHP_NT50") == method_colour("rsmhp_nt50")


def test_unknown_methods_are_refused_by_name():
    with pytest.raises(ValueError, match="'magic'"):
        method_colour("magic")
    with pytest.raises(ValueError, match="'magic'"):
        method_label("magic")


def test_uav_names_are_resolved_by_the_registry_the_palette_does_not_import(monkeypatch):
    """The palette never imports the UAV registry (so the LQG figures do not depend on the UAV
    code) and the registry never imports the palette (so a colour edit reruns no simulation):
    UAV names resolve through the registry once something imported it, or a registered
    resolver; without either, a UAV name is refused with the reason."""
    tree = ast.parse(Path(palette.__file__).read_text())
    imported = [n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
    imported += [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
    assert imported and not any(str(m).startswith("rsmhp") for m in imported), imported
    registry = Path(rsmhp.models.uav.methods.__file__).read_text()
    assert "palette" not in registry, "the method registry must not import the palette"
    assert method_colour("rsmhp_nt250").startswith("#")  # the registry is imported: resolved
    monkeypatch.setattr(palette, "_RESOLVERS", [])
    monkeypatch.delitem(sys.modules, "rsmhp.models.uav.methods")
    with pytest.raises(ValueError, match=r"import rsmhp\.models\.uav\.methods"):
        method_colour("rsmhp_nt250")
    assert method_colour("nbo") == METHOD_COLOURS["nbo"]  # fixed schemes need no resolver
    palette.register_resolver(rsmhp.models.uav.methods.from_name)
    palette.register_resolver(rsmhp.models.uav.methods.from_name)  # twice: no-op
    assert palette._RESOLVERS == [rsmhp.models.uav.methods.from_name]
    assert method_label("rsmhp_nt250") == "RS-MHP N_T=250"


def test_recordings_use_the_figure_colours():
    h = method_colour("nbo").lstrip("#")
    assert method_rgb("nbo") == tuple(int(h[i : i + 2], 16) for i in (0, 2, 4))
    assert recording.KEPT == method_rgb("pruned")
    assert recording.SERIES["nbo"] == method_rgb("nbo")
    assert recording.SERIES["uniform"] == method_rgb("pruned")
