"""How the planner kernel is compiled (``rsmhp.models.uav.fused``): the layouts are vectorised
once, inside the kernel that links them, and not in their own compilation (the listener
``fused._LayoutLimits``); a guard against a numba or LLVM change that would silently drop the
vectorised loops (4x slower at 256 hypotheses) or bring back the slow second pass."""

from __future__ import annotations

import json
import os
import subprocess
import sys

CHILD = r"""
import json, re
from rsmhp.models.uav import fused
fused.warm_up()
packed = re.compile(r"\bv\w+pd\s+[^\n]*%[yz]mm")
def count(d):
    return len(packed.findall(d.inspect_asm(d.signatures[0])))
print(json.dumps({"kernel": count(fused._planner_kernel), "soa": count(fused._value_grad_soa)}))
"""


def test_the_kernel_holds_the_vectorised_loops(tmp_path):
    # a cache of its own, empty: the child compiles (inspection needs freshly compiled code)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run(
        [sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, check=True
    ).stdout
    n = json.loads(out.strip().splitlines()[-1])
    # the layout's own compilation runs without the loop vectoriser's wide limits (only
    # straight-line packing); the kernel's copy of the same code is loop-vectorised: packed
    # double operations on 256/512-bit registers at least twice as many
    assert n["soa"] > 0
    assert n["kernel"] >= 2 * n["soa"], n
