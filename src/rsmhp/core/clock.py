"""A cycle counter readable from compiled code (the closed loop's planner timing).

numba's nopython mode has no clock; :func:`cycles` reads the processor's time-stamp counter
(LLVM's ``llvm.readcyclecounter``, the ``rdtsc`` instruction on x86-64), which costs a few
nanoseconds and needs no call back into Python. The counter's rate is not assumed: a caller
converts cycles to seconds by measuring, around the same compiled call, both the wall time
(:func:`time.perf_counter`) and the cycles, so that ``seconds = cycles x wall / total
cycles`` (the rate of a CPU with an invariant TSC, every x86-64 CPU of the last decade, is
constant). On other architectures the instruction may trap in user space, so
:data:`AVAILABLE` is false there and callers must not call :func:`cycles`.
"""

from __future__ import annotations

import platform

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

__all__ = ["AVAILABLE", "cycles"]

#: whether :func:`cycles` may be called on this machine (x86-64 only)
AVAILABLE = platform.machine().lower() in ("x86_64", "amd64")


@intrinsic
def cycles(typingctx):  # pragma: no cover - compiled
    """The time-stamp counter (int64 cycles since an arbitrary origin); compiled code only."""
    sig = types.int64()

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.IntType(64), [])
        fn = cgutils.get_or_insert_function(builder.module, fnty, "llvm.readcyclecounter")
        return builder.call(fn, [])

    return sig, codegen
