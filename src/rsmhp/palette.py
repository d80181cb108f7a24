"""One colour per method, shared by every figure and every rerun recording.

Methods are named as in the results tables: ``nbo``, ``mc`` (independent, non-overlapping
trajectories), ``rsmhp_nt<N_T>`` (RS-MHP with N_T trajectories: shades of the ``mc`` blue,
darker for larger N_T), ``tree`` (shared draws per level), ``tree_pernode`` (fresh draws per
node), ``pruned`` / ``tree_n<N>_m<M>`` (pruned tree), ``antithetic``, ``sobol``,
``cubature``, ``gauss_hermite``; ``exact`` is the exact cost or optimum. Colours come from
seaborn's colour-blind palette (as RGB hex strings, so this module needs no plotting library);
derived or closed-form curves use the method's colour with a dashed line, likeliness-weighted
variants a dotted one (:data:`LINESTYLES`).
"""

from __future__ import annotations

import re

__all__ = [
    "LINESTYLES",
    "METHOD_COLOURS",
    "method_colour",
    "method_label",
    "method_rgb",
]

#: seaborn "colorblind" palette, in its order (C0..C9)
_CB = (
    "#0173b2",  # blue
    "#de8f05",  # orange
    "#029e73",  # green
    "#d55e00",  # vermilion
    "#cc78bc",  # purple
    "#ca9161",  # brown
    "#fbafe4",  # pink
    "#949494",  # grey
    "#ece133",  # yellow
    "#56b4e9",  # light blue
)

#: the fixed colour of every method family
METHOD_COLOURS: dict[str, str] = {
    "nbo": _CB[3],
    "mc": _CB[0],
    "rsmhp": _CB[0],
    "tree": _CB[2],
    "tree_pernode": _CB[9],
    "pruned": _CB[1],
    "antithetic": _CB[4],
    "sobol": _CB[5],
    "cubature": _CB[6],
    "gauss_hermite": _CB[7],
    "exact": "#000000",
}

#: line style by role: a measured curve, a derived (closed-form) curve, a weighted variant
LINESTYLES = {"measured": "-", "derived": "--", "weighted": ":"}

#: RS-MHP shades (light to dark) for increasing N_T; blends of the ``mc`` blue with white/black
_RSMHP_SHADES = ("#67a9d9", "#3a8cc6", "#0173b2", "#01548a", "#013a5e")

_RSMHP = re.compile(r"^rsmhp_nt(\d+)$")
_PRUNED = re.compile(r"^tree_n(\d+)_m(\d+)$")


def method_colour(method: str) -> str:
    """Hex colour of ``method``. RS-MHP variants get a fixed shade of the ``mc`` blue by N_T
    (<= 10, <= 50, <= 100, <= 250, larger: light to dark), the same in every figure; a pruned
    tree ``tree_n<N>_m<M>`` gets the ``pruned`` colour. Unknown names raise ``ValueError``."""
    name = str(method).lower()
    if name in METHOD_COLOURS:
        return METHOD_COLOURS[name]
    m = _RSMHP.match(name)
    if m:
        nt = int(m.group(1))
        return _RSMHP_SHADES[sum(nt > edge for edge in (10, 50, 100, 250))]
    if _PRUNED.match(name):
        return METHOD_COLOURS["pruned"]
    raise ValueError(
        f"method {method!r} has no colour (allowed: {sorted(METHOD_COLOURS)}, rsmhp_nt<N_T>, "
        "tree_n<N>_m<M>)"
    )


def method_rgb(method: str) -> tuple[int, int, int]:
    """``method_colour`` as an (r, g, b) tuple of 0..255 integers (for rerun-sdk)."""
    h = method_colour(method).lstrip("#")
    return int(h[0:2], 16), int(h[2:4], 16), int(h[4:6], 16)


def method_label(method: str) -> str:
    """Human-readable name: ``rsmhp_nt250`` -> ``RS-MHP N_T=250``, ``tree_n8_m100`` ->
    ``pruned tree N=8 M=100``, ``nbo`` -> ``NBO``, ``mc`` -> ``MC (independent)``."""
    name = str(method).lower()
    m = _RSMHP.match(name)
    if m:
        return f"RS-MHP N_T={m.group(1)}"
    m = _PRUNED.match(name)
    if m:
        return f"pruned tree N={m.group(1)} M={m.group(2)}"
    labels = {
        "nbo": "NBO",
        "mc": "MC (independent)",
        "rsmhp": "RS-MHP",
        "tree": "tree (shared draws)",
        "tree_pernode": "tree (draws per node)",
        "pruned": "pruned tree",
        "antithetic": "antithetic",
        "sobol": "Sobol' (scrambled)",
        "cubature": "cubature",
        "gauss_hermite": "Gauss-Hermite",
        "exact": "exact",
    }
    if name in labels:
        return labels[name]
    raise ValueError(f"method {method!r} has no label")
