"""One colour per method, shared by every figure and every rerun recording.

Methods are named as in the results tables. The schemes of the LQG and estimator studies have
fixed colours here: ``nbo``, ``mc`` (independent, non-overlapping trajectories), ``tree``
(shared draws per level), ``tree_pernode`` (fresh draws per node), ``pruned`` (pruned tree),
``antithetic``, ``sobol``, ``cubature``, ``gauss_hermite``; ``exact`` is the exact cost or
optimum. A UAV planning method (``rsmhp_nt<N_T>``, ``tree_n<N>_m<M>``, any registered
family) takes the colour of the palette key its family declares (``colour_key``, e.g.
``rsmhp``), shaded by the member's size where the family gives one (``shade_size``: RS-MHP N_T
in fixed shades of the ``mc`` blue, darker for larger N_T; RQMC and antithetic members by
:func:`size_shade`). Colours are presentation: the UAV method modules do not import this
module, so a colour edit reruns figures, tables and the report but no simulation
(:mod:`rsmhp.pipeline.code_digest`). Nor does this module import the UAV registry (so that
the LQG and estimator figures do not depend on the UAV model's code): UAV names are resolved by
the registry once something has imported it (every script that handles UAV method names
does), or by a resolver added with :func:`register_resolver`; a UAV name met before either
raises a ``ValueError`` saying so. Colours come from
seaborn's colour-blind palette (as RGB hex strings, so this module needs no plotting library);
derived or closed-form curves use the method's colour with a dashed line, likeliness-weighted
variants a dotted one (:data:`LINESTYLES`).
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

__all__ = [
    "LINESTYLES",
    "METHOD_COLOURS",
    "RSMHP_SHADES",
    "member_colour",
    "method_colour",
    "method_label",
    "method_rgb",
    "register_resolver",
    "size_shade",
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
    "dpw": _CB[8],
    "exact": "#000000",
    "rsmhp_per_step": "#67a9d9",  # RS-MHP with N_T growing with H: the lightest RS-MHP shade
}
#: shades of the RS-MHP blue (light to dark) for N_T <= 10, <= 50, <= 100, <= 250, more
RSMHP_SHADES = ("#67a9d9", "#3a8cc6", "#0173b2", "#01548a", "#013a5e")

#: line style by role: a measured curve, a derived (closed-form) curve, a weighted variant
LINESTYLES = {"measured": "-", "derived": "--", "weighted": ":"}


#: mixing weights of :func:`size_shade` (towards white > 0, towards black < 0), small to large
_SIZE_MIX = (0.45, 0.25, 0.0, -0.25, -0.45)


def size_shade(colour: str, n: int, edges: tuple[int, ...] = (16, 32, 64, 128)) -> str:
    """A shade of the hex ``colour`` for a member of size ``n`` (hypotheses): lighter below
    the middle edge, darker above it, five levels split at ``edges`` (4 increasing values)."""
    if len(edges) != len(_SIZE_MIX) - 1:
        raise ValueError(f"edges must hold {len(_SIZE_MIX) - 1} values, got {edges!r}")
    mix = _SIZE_MIX[sum(n > e for e in edges)]
    h = colour.lstrip("#")
    rgb = [int(h[i : i + 2], 16) for i in (0, 2, 4)]
    target = 255 if mix > 0 else 0
    out = [round(c + abs(mix) * (target - c)) for c in rgb]
    return "#" + "".join(f"{c:02x}" for c in out)


def method_colour(method: str) -> str:
    """Hex colour of ``method``: a scheme of :data:`METHOD_COLOURS`, or a UAV planning method
    of any registered family (its :meth:`rsmhp.models.uav.methods.Method.shade`, the same in every
    figure). Unknown names raise ``ValueError``."""
    name = str(method).lower()
    if name in METHOD_COLOURS:
        return METHOD_COLOURS[name]
    return member_colour(_uav_method(method))


def member_colour(member: Any) -> str:
    """Hex colour of a UAV method ``member`` (an object with ``colour_key``, a key of
    :data:`METHOD_COLOURS` or, for a family this palette does not know such as a plugin's, a hex
    colour itself, and ``shade_size()``): its family's colour, shaded by size where it has one
    (RS-MHP members in
    :data:`RSMHP_SHADES` by N_T, split at 10, 50, 100, 250; other sized families by
    :func:`size_shade`)."""
    key = member.colour_key
    base = key if str(key).startswith("#") else METHOD_COLOURS[key]
    size = member.shade_size()
    if size is None:
        return base
    if member.colour_key == "rsmhp":
        return RSMHP_SHADES[sum(size > edge for edge in (10, 50, 100, 250))]
    return size_shade(base, size)


#: lookups of method names beyond the fixed schemes (name -> object with ``shade()`` and
#: ``label()``, ``ValueError`` if the name is not theirs), in registration order
_RESOLVERS: list[Callable[[str], Any]] = []


def register_resolver(resolve: Callable[[str], Any]) -> None:
    """Let ``resolve(name)`` (an object with ``shade()`` and ``label()``, or ``ValueError``)
    colour and label the method names it knows; registering the same callable twice is a
    no-op. The UAV method registry registers :func:`rsmhp.models.uav.methods.from_name`."""
    if resolve not in _RESOLVERS:
        _RESOLVERS.append(resolve)


def _resolvers() -> list[Callable[[str], Any]]:
    """The registered resolvers, and the UAV registry's ``from_name`` if something imported
    the registry (looked up in ``sys.modules``: this module never imports it)."""
    registry = sys.modules.get("rsmhp.models.uav.methods")
    found = getattr(registry, "from_name", None)
    return [*_RESOLVERS, *([found] if found is not None and found not in _RESOLVERS else [])]


def _uav_method(method: str):
    """The registered method called ``method`` (``ValueError`` if no resolver knows it)."""
    resolvers = _resolvers()
    for resolve in resolvers:
        try:
            return resolve(str(method).lower())
        except ValueError:
            continue
    hint = (
        "" if resolvers else " (the UAV registry is not imported: import rsmhp.models.uav.methods)"
    )
    raise ValueError(
        f"method {method!r} has no colour (allowed: {sorted(METHOD_COLOURS)}, or a "
        f"registered UAV method: rsmhp_nt<N_T>, tree_n<N>_m<M>, ...){hint}"
    )


def method_rgb(method: str) -> tuple[int, int, int]:
    """``method_colour`` as an (r, g, b) tuple of 0..255 integers (for rerun-sdk)."""
    h = method_colour(method).lstrip("#")
    return int(h[0:2], 16), int(h[2:4], 16), int(h[4:6], 16)


def method_label(method: str) -> str:
    """Human-readable name: ``nbo`` -> ``NBO``, ``mc`` -> ``MC (independent)``; a UAV method
    as its family module says (``rsmhp_nt250`` -> ``RS-MHP N_T=250``, ``tree_n8_m100`` ->
    ``pruned tree N=8 M=100``)."""
    name = str(method).lower()
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
        "dpw": "tree search",
        "exact": "exact",
    }
    if name in labels:
        return labels[name]
    try:
        return _uav_method(method).label()
    except ValueError:
        raise ValueError(f"method {method!r} has no label") from None
