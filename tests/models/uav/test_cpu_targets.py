"""The AVX2 path gives the native path's bits: the planner's compiled kernels built for an AVX2
CPU without AVX-512 (LLVM ``znver3`` with its own features, OpenBLAS ``Haswell`` kernels,
numpy's AVX-512 dispatch off: :func:`rsmhp.report.portability.emulation.cpu_target_env`)
compute exactly what the host's build computes.

The kernels do the same IEEE operations in the same order whatever the vector width (no
fastmath, no reassociation: :mod:`rsmhp.models.uav.fused`), so the comparison is exact
(float bits), never a tolerance. One subprocess in the emulated environment computes
:func:`compute` (cost and gradient in both layouts, with and without a sensor footprint and
with unequal weights; a planning step of the compiled optimiser; short closed-loop runs) and
writes it with ``float.hex``; this process computes the same natively.

Cost: the subprocess compiles the kernels it uses for ``znver3`` once (about a minute), into
numba's cache beside the host's build (the index keys entries on CPU name and features);
later runs load them. Only what the closed loop needs is compiled (no
``covariance_traces``, no tree search). Run on its own with
``.venv/bin/python -m pytest tests/models/uav/test_cpu_targets.py``; the subprocess alone:
``.venv/bin/python tests/models/uav/test_cpu_targets.py OUT.json`` (in the environment given).
"""

from __future__ import annotations

import copy
import json
import math
import os
import platform
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import rsmhp
from rsmhp.models.uav import fused
from rsmhp.models.uav import methods as uav_methods
from rsmhp.models.uav.kinematics import UAVParams
from rsmhp.models.uav.sensor import SensorModel
from rsmhp.models.uav.simulation import UAVSetup, simulate_run
from rsmhp.models.uav.target import TargetModel

ROOT = Path(__file__).resolve().parents[3]
DEFAULT_UAV = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["uav"]
H = 6
#: hypotheses below and above fused.SOA_MIN_HYPOTHESES (one at a time / vectorised, with a
#: remainder after the vector loop)
LAYOUTS = {"scalar": 7, "soa": 37}

pytestmark = [
    pytest.mark.compile,  # the subprocess compiles for the emulated CPU (cold: about a minute)
    pytest.mark.skipif(
        platform.machine().lower() not in ("x86_64", "amd64"),
        reason="emulates an x86-64 CPU (LLVM znver3)",
    ),
]


def _sensors() -> dict[str, SensorModel]:
    paper = SensorModel.from_config(DEFAULT_UAV)
    return {
        "paper": paper,
        "footprint150": SensorModel(
            paper.sigma_r_per_m, paper.sigma_c_per_m, paper.altitude, footprint_radius=150.0
        ),
    }


def _closed_loop() -> dict[str, Any]:
    """Short closed-loop runs (8 steps, the default planner budget): NBO (one hypothesis) and
    RS-MHP with N_T = 32 (vectorised layout) on the paper's model, RS-MHP with a footprint of
    400 m (half of the steps of run 1 measure, half only predict)."""
    out = {}
    for model in ("paper", "footprint400"):
        cfg = copy.deepcopy(DEFAULT_UAV)
        cfg["scenario"]["steps"] = 8
        if model == "footprint400":
            cfg["sensor"]["footprint_radius"] = 400.0
        setup = UAVSetup.from_config(cfg)
        specs = uav_methods.from_config({"nbo": model == "paper", "rsmhp_nt": [32]})
        for name, spec in specs.items():
            summary, rows = simulate_run(setup, spec, 20210512, 1)
            summary = {k: v for k, v in summary.items() if k != "plan_seconds"}  # wall time
            out[f"{model}/{name}"] = {"summary": summary, "rows": rows}
    return out


def compute() -> dict[str, Any]:
    """Every compared quantity, from fixed seeded inputs."""
    rng = np.random.default_rng(20240611)
    uav = UAVParams.from_config(DEFAULT_UAV)
    model = TargetModel.from_config(DEFAULT_UAV)
    state = np.array([10.0, -5.0, 22.0, 0.3])
    P0 = np.diag([900.0, 900.0, 25.0, 25.0])
    P0[0, 2] = P0[2, 0] = 30.0
    P0[1, 3] = P0[3, 1] = -20.0
    x = rng.uniform(-1.0, 1.0, (16, 2 * H))
    x[0], x[1] = 1.0, -1.0  # the box's corners: the speed clip
    x0 = rng.uniform(-0.5, 0.5, 2 * H)
    out: dict[str, Any] = {"evaluate": {}, "minimise": {}}
    for layout, n_t in LAYOUTS.items():
        txy = rng.uniform(-300.0, 300.0, (n_t, H, 2))
        w = rng.uniform(0.5, 1.5, n_t)
        for sensor_name, sensor in _sensors().items():
            for weighted in (False, True):
                frozen = fused.Frozen(
                    state, uav, P0, txy, model.dt, model.Q, sensor,
                    weights=w / w.sum() if weighted else None,
                )  # fmt: skip
                key = f"{layout}/{sensor_name}" + ("/weighted" if weighted else "")
                value, _ = fused.evaluate(x, frozen, want_grad=False)
                cost, grad = fused.evaluate(x, frozen, want_grad=True)
                out["evaluate"][key] = {"value": value, "cost": cost, "gradient": grad}
                xo, f, f0, nit, nfev, status = fused.minimise(x0, frozen, 30, 60)
                out["minimise"][key] = {
                    "x": xo, "f": f, "f0": f0, "nit": nit, "nfev": nfev, "status": status,
                }  # fmt: skip
    out["closed_loop"] = _closed_loop()
    return out


def facts() -> dict[str, Any]:
    """What this process compiled for and ran on: numba's CPU name and features (configured,
    and of every rsmhp kernel it ran), OpenBLAS core types, numpy's active SIMD targets."""
    from numba.core import config
    from numba.core.dispatcher import Dispatcher
    from numba.core.registry import cpu_target
    from threadpoolctl import threadpool_info

    try:
        from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    except ImportError:  # numpy < 2
        from numpy.core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    targets = set()
    kernels = []
    for name, mod in list(sys.modules.items()):
        if not name.startswith("rsmhp") or mod is None:
            continue
        for attr, obj in list(vars(mod).items()):
            if isinstance(obj, Dispatcher) and obj.overloads:
                kernels.append(f"{name}.{attr}")
                for res in obj.overloads.values():
                    targets.add(tuple(map(str, res.library.codegen.magic_tuple()[1:])))
    return {
        "rsmhp": rsmhp.__file__,
        "CPU_NAME": config.CPU_NAME,
        "CPU_FEATURES": config.CPU_FEATURES,
        "codegen": list(map(str, cpu_target.target_context.codegen().magic_tuple()[1:])),
        "kernel_targets": sorted(map(list, targets)),
        "kernels": sorted(kernels),
        "openblas": sorted(
            {str(i.get("architecture")) for i in threadpool_info() if i.get("user_api") == "blas"}
        ),
        "numpy_simd": [f for f in __cpu_dispatch__ if __cpu_features__.get(f)],
    }


def pack(v: Any) -> Any:
    """``v`` as JSON with exact floats: float -> ``float.hex``, float array -> its shape and
    hex entries; int, bool, str, None as they are; dicts and sequences entry by entry."""
    if isinstance(v, dict):
        return {str(k): pack(x) for k, x in v.items()}
    if isinstance(v, np.ndarray):
        if v.dtype.kind == "f":
            return {"shape": list(v.shape), "hex": [float(e).hex() for e in v.ravel()]}
        return {"shape": list(v.shape), "values": v.ravel().tolist()}
    if isinstance(v, (list, tuple)):
        return [pack(x) for x in v]
    if isinstance(v, (float, np.floating)):
        return float(v).hex()
    if isinstance(v, np.integer | np.bool_):
        return v.item()
    return v


def _ordinal(x: float) -> int:
    """Monotone integer of a float64: consecutive floats differ by 1."""
    i = int(np.array(x).view(np.int64))
    return i if i >= 0 else -(2**63) - i


def _ulps(a: str, b: str) -> str:
    fa, fb = float.fromhex(a), float.fromhex(b)
    if math.isnan(fa) or math.isnan(fb):
        return f"{fa!r} vs {fb!r}"
    return f"{fa!r} vs {fb!r}: {abs(_ordinal(fa) - _ordinal(fb))} ulps"


def differences(native: Any, avx2: Any, path: str = "") -> Iterator[str]:
    """Every leaf of two :func:`pack` results that differs, with the distance in ulps."""
    if isinstance(native, dict) and isinstance(avx2, dict):
        if set(native) != set(avx2):
            yield f"{path}: keys {sorted(native)} vs {sorted(avx2)}"
        if "hex" in native and "hex" in avx2:
            if native["shape"] != avx2["shape"]:
                yield f"{path}: shape {native['shape']} vs {avx2['shape']}"
                return
            shape = tuple(native["shape"])
            pairs = enumerate(zip(native["hex"], avx2["hex"], strict=True))
            diff = [(i, a, b) for i, (a, b) in pairs if a != b]
            for i, a, b in diff[:5]:
                where = [int(j) for j in np.unravel_index(i, shape)] if shape else ""
                yield f"{path}{where}: {_ulps(a, b)}"
            if len(diff) > 5:
                yield f"{path}: ... {len(diff)} of {len(native['hex'])} entries differ"
            return
        for k in sorted(set(native) & set(avx2)):
            yield from differences(native[k], avx2[k], f"{path}/{k}")
    elif isinstance(native, list) and isinstance(avx2, list) and len(native) == len(avx2):
        for i, (a, b) in enumerate(zip(native, avx2, strict=True)):
            yield from differences(a, b, f"{path}[{i}]")
    elif native != avx2:
        try:
            yield f"{path}: {_ulps(native, avx2)}"
        except (TypeError, ValueError):
            yield f"{path}: {native!r} vs {avx2!r}"


def _avx2_env() -> dict[str, str]:
    from rsmhp.report.portability.emulation import (
        AVX2_CORETYPE,
        AVX2_CPU,
        cpu_target_env,
        numpy_avx512_targets,
    )

    base = dict(os.environ)
    src = str(Path(rsmhp.__file__).resolve().parents[1])  # the rsmhp this process imported
    base["PYTHONPATH"] = os.pathsep.join(filter(None, [src, base.get("PYTHONPATH")]))
    return cpu_target_env(base, AVX2_CPU, AVX2_CORETYPE, numpy_avx512_targets())


@pytest.fixture(scope="module")
def avx2(tmp_path_factory) -> dict[str, Any]:
    """What the subprocess in the AVX2 environment computed, and its facts."""
    out = tmp_path_factory.mktemp("avx2") / "avx2.json"
    res = subprocess.run(
        [sys.executable, __file__, str(out)],
        env=_avx2_env(),
        capture_output=True,
        text=True,
        timeout=1800,
    )
    assert res.returncode == 0, res.stderr[-3000:]
    return json.loads(out.read_text())


@pytest.fixture(scope="module")
def native() -> dict[str, Any]:
    return {"results": pack(compute()), "facts": facts()}


def test_the_subprocess_compiled_for_the_emulated_cpu(avx2, native):
    child, host = avx2["facts"], native["facts"]
    assert child["rsmhp"] == host["rsmhp"]
    assert child["CPU_NAME"] == "znver3" and child["CPU_FEATURES"] == ""
    assert child["codegen"] == ["znver3", ""]
    # every kernel the subprocess ran was built (or loaded from the cache) for znver3
    assert child["kernel_targets"] == [["znver3", ""]]
    modules = {k.rsplit(".", 1)[0] for k in child["kernels"]}  # the planner's and the loop's
    assert {"rsmhp.models.uav.fused", "rsmhp.models.uav.stepper"} <= modules
    assert child["openblas"] == ["Haswell"]
    assert not [f for f in child["numpy_simd"] if f == "X86_V4" or f.startswith("AVX512")]
    # and this process did not: the comparison is between two builds
    assert host["kernel_targets"] and ["znver3", ""] not in host["kernel_targets"]


@pytest.mark.parametrize("part", ["evaluate", "minimise", "closed_loop"])
def test_avx2_gives_the_native_bits(avx2, native, part):
    a, n = avx2["results"][part], native["results"][part]
    assert n, part  # something was compared
    diff = list(differences(n, a, part))
    assert not diff, "native vs avx2 (znver3):\n" + "\n".join(diff)


if __name__ == "__main__":  # the subprocess: compute in this environment, write to argv[1]
    results = pack(compute())
    Path(sys.argv[1]).write_text(json.dumps({"results": results, "facts": facts()}))
