"""One colour per method, shared by every figure and every rerun recording.

Methods are named as in the results tables. The schemes of the LQG and estimator studies have
fixed colours here: ``nbo``, ``mc`` (independent, non-overlapping trajectories), ``tree``
(shared draws per level), ``tree_pernode`` (fresh draws per node), ``pruned`` (pruned tree),
``antithetic``, ``sobol``, ``cubature``, ``gauss_hermite``; ``exact`` is the exact cost or
optimum. A UAV planning method (``rsmhp_nt<N_T>``, ``tree_n<N>_m<M>``, any registered
family) takes the colour its family module declares (:mod:`rsmhp.uav.methods`; RS-MHP N_T
in shades of the ``mc`` blue, darker for larger N_T). This module does not import the UAV
registry (so that the LQG and estimator figures do not depend on the UAV model's code): the
registry adds itself with :func:`register_resolver` when it is imported, and a UAV name met
before that raises a ``ValueError`` saying so. Colours come from
seaborn's colour-blind palette (as RGB hex strings, so this module needs no plotting library);
derived or closed-form curves use the method's colour with a dashed line, likeliness-weighted
variants a dotted one (:data:`LINESTYLES`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = [
    "LINESTYLES",
    "METHOD_COLOURS",
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
}

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
    of any registered family (its :meth:`rsmhp.uav.methods.Method.shade`, the same in every
    figure). Unknown names raise ``ValueError``."""
    name = str(method).lower()
    if name in METHOD_COLOURS:
        return METHOD_COLOURS[name]
    return _uav_method(method).shade()


#: lookups of method names beyond the fixed schemes (name -> object with ``shade()`` and
#: ``label()``, ``ValueError`` if the name is not theirs), in registration order
_RESOLVERS: list[Callable[[str], Any]] = []


def register_resolver(resolve: Callable[[str], Any]) -> None:
    """Let ``resolve(name)`` (an object with ``shade()`` and ``label()``, or ``ValueError``)
    colour and label the method names it knows; registering the same callable twice is a
    no-op. The UAV method registry registers :func:`rsmhp.uav.methods.from_name`."""
    if resolve not in _RESOLVERS:
        _RESOLVERS.append(resolve)


def _uav_method(method: str):
    """The registered method called ``method`` (``ValueError`` if no resolver knows it)."""
    for resolve in _RESOLVERS:
        try:
            return resolve(str(method).lower())
        except ValueError:
            continue
    hint = "" if _RESOLVERS else " (the UAV registry is not imported: import rsmhp.uav.methods)"
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
