r"""Compiled planner kernel: cost of C control sequences and its exact gradient in one pass.

For normalised controls :math:`x \in [-1, 1]^{2H}` (rows of ``x`` (C, 2H)), the UAV state
:math:`s_0` (4,) and ``T`` target hypotheses ``target_xy`` (T, H, 2) this computes

.. math::
    J(x) = \frac1T \sum_{i=1}^{T} \sum_{j=1}^{H} \mathrm{tr}\, P_j^{i}(x)

exactly as :func:`rsmhp.models.uav.kinematics.rollout` followed by
:func:`rsmhp.models.uav.kernel.objective`
(the numpy kernel, kept as this module's test oracle), and optionally :math:`\nabla_x J`
(C, 2H), in a single compiled loop without temporaries.

Forward pass. Controls :math:`u_j = (a_{\max} x_{2j}, \phi_{\max} x_{2j+1})` drive the
kinematics of :mod:`rsmhp.models.uav.kinematics`; the UAV positions :math:`q_j` (j = 1..H) set
:math:`R_j = R(q_j, t^i_j)` (:mod:`rsmhp.models.uav.sensor`) in the covariance recursion of
:mod:`rsmhp.models.uav.kernel` (same block formulas, same operation order).

Reverse pass (adjoint of the covariance recursion). With gain :math:`K = P^- H^T S^{-1}` and
:math:`E = I - KH`, the first-order change of one update is
:math:`dP^+ = E\, dP^-\, E^T + K\, dR\, K^T` (the optimal-gain identity), and the prediction
:math:`P^- = F P F^T + Q` gives :math:`dP^- = F\, dP\, F^T`. So with :math:`G_j = \partial J /
\partial P_j` (symmetric 4x4, starting from :math:`G_H = I`):

.. math::
    \bar R_j = K_j^T G_j K_j, \qquad G^-_j = E_j^T G_j E_j, \qquad
    G_{j-1} = F^T G^-_j F + I .

In 2x2 blocks, :math:`K = [M^T; N^T]` with :math:`M = S^{-1}A^-`, :math:`N = S^{-1}B^-` (the
quantities the forward pass already forms), so nothing but 8 numbers per step is stored.

Sensor geometry. With :math:`v = t - q` (target minus UAV, horizontal), :math:`\rho^2 = |v|^2`,
:math:`d^2 = \rho^2 + h^2` and :math:`D = f_r^2 - f_c^2`,
:math:`R = f_c^2 d^2 I + D\,(1 + h^2/\rho^2)\, v v^T`, hence for
:math:`L = \langle \bar R, R\rangle`, :math:`\bar q = v^T \bar R v`:

.. math::
    \frac{\partial L}{\partial v} = 2 f_c^2\, \mathrm{tr}(\bar R)\, v
    + 2D\Big(1 + \frac{h^2}{\rho^2}\Big) \bar R v - \frac{2 D h^2 \bar q}{\rho^4}\, v,
    \qquad \frac{\partial L}{\partial q} = -\frac{\partial L}{\partial v}.

Directly overhead (:math:`\rho = 0`) the bearing is undefined: the value uses
:math:`\beta = 0` (as the numpy kernel does) and R is discontinuous there, so no derivative
exists; we return the derivative with the bearing frozen, which is :math:`0` (the
:math:`v`-terms vanish at :math:`v = 0`). Near (not at) overhead the derivative is exact but
grows like :math:`h^2 \|\bar R\| / \rho`.

Kinematics adjoint (state :math:`(p_x, p_y, s, \psi)`, step :math:`s' =
\mathrm{clip}(s + a\Delta t)`, :math:`\psi' = \psi + g \tan\phi/s\,\Delta t`, :math:`p' = p +
s'\Delta t (\cos\psi', \sin\psi')`): back-substitution of these three lines. At a clip the
speed derivative is taken as 0 when :math:`s + a\Delta t` lies on or outside the speed
bounds (a one-sided derivative; the clip has a kink there).

Layout: the recursion runs over the hypotheses in structure-of-arrays form (hypotheses
innermost, one loop per step and stage), which LLVM vectorises; below
:data:`SOA_MIN_HYPOTHESES` hypotheses one hypothesis at a time is faster. Both layouts do the
same IEEE operations per hypothesis and sum over hypotheses in the same order (no fastmath),
so they give the same bits. :func:`minimise` runs a whole planning step
(:func:`rsmhp.core.boxqn.minimise` on this cost) in one compiled call.

Compilation: numba ``njit`` with ``cache=True``; the first call on a machine compiles (about
half a minute for the planner's kernels, :func:`warm_up`; ``python -m rsmhp.pipeline.warm``
compiles every kernel of the project in parallel processes) and writes the cache beside this
file, or in numba's user-wide cache directory when the install is read-only (or in
``NUMBA_CACHE_DIR`` when set); later processes load it. Single-threaded: parallelism is across
closed-loop runs (joblib), never inside the kernel.
"""

from __future__ import annotations

import functools

import llvmlite.binding as llvm
import numpy as np
from numba import njit, objmode

from rsmhp.core import boxqn, clock, guards, numba_cache
from rsmhp.models.uav import kernel, target
from rsmhp.models.uav.kinematics import UAVParams
from rsmhp.models.uav.sensor import SensorModel

__all__ = [
    "Frozen",
    "check_frozen",
    "check_uav_state",
    "check_weights",
    "cost",
    "cost_and_grad",
    "covariance_traces",
    "evaluate",
    "minimise",
    "path",
    "warm_up",
    "weight_args",
]


# LLVM's loop vectoriser gives up on a loop whose arrays it cannot prove disjoint with at most
# 8 run-time pointer comparisons (its default); the per-step hypothesis loops below touch
# about 30 array rows. Raising the limits lets it vectorise them (over the hypotheses, no
# floating-point reassociation: results are bit-identical to the scalar loop). Set before the
# first compilation in the process, as numba does for its own LLVM options; it only widens
# what LLVM may vectorise in any later compilation.
llvm.set_option("rsmhp", "-runtime-memory-check-threshold=512")
llvm.set_option("rsmhp", "-vectorize-memory-check-threshold=512")

#: below this many hypotheses the planner kernel runs one hypothesis at a time
#: (:func:`_value_grad_scalar`); from it on, vectorised over hypotheses (crossover measured by
#: ``benchmarks/speed.py kernel``)
SOA_MIN_HYPOTHESES = 24

# --------------------------------------------------------------------------------------------
# compiled building blocks (tuples of scalars, no heap allocation)
#
# Inlining: the blocks the vectorised loops need inline in their loop body
# (``_meas_cov``, ``_kalman_step``, ``_adjoint_step``, ``_meas_cov_grad``) are inlined by numba
# (``inline="always"``, before typing), because LLVM's cost model leaves them as calls and a
# loop with a call does not vectorise (measured: 15x slower at 256 hypotheses). The small ones
# (``_mm``, ``_mmt``, ``_sub``) and those outside the hypothesis loops (``_detection``, in its
# own scalar loop; the kinematics and their adjoint) are ordinary compiled functions, which
# LLVM inlines where it pays: numba types an inlined function again at every call site, and
# these sites were a quarter of the kernel's compile time (39 s -> 28 s CPU, same speed).


@njit(cache=True, inline="always")
def _meas_cov(ux, uy, tx, ty, sens):  # pragma: no cover - compiled
    """(R_xx, R_xy, R_yy): same operation order as rsmhp.models.uav.sensor.measurement_cov_entries.
    ``sens`` = (f_r^2, f_c^2, h^2, quadratic growth 0/1, d_0^2, footprint 0/1, rho_0, w)."""
    fr2, fc2, h2 = sens[0], sens[1], sens[2]
    dx = tx - ux
    dy = ty - uy
    rho2 = dx * dx + dy * dy
    if rho2 == 0.0:
        c, s = 1.0, 0.0
    else:
        rho = np.sqrt(rho2)
        c, s = dx / rho, dy / rho
    d2 = rho2 + h2
    if sens[3] != 0.0:
        d2 = d2 * d2 / sens[4]
    rxx = d2 * (fr2 * c * c + fc2 * s * s)
    rxy = d2 * (fr2 - fc2) * c * s
    ryy = d2 * (fr2 * s * s + fc2 * c * c)
    return rxx, rxy, ryy


@njit(cache=True, inline="always")
def _kalman_step(p, rxx, rxy, ryy, dt, q, pd, limited):  # pragma: no cover - compiled
    """One predict + update of the 10 distinct entries ``p`` of P (order a11, a12, a22, b11,
    b12, b21, b22, c11, c12, c22; ``q`` likewise for Q). Returns (P+, M, N, X) with M = S^-1
    A^-, N = S^-1 B^- as 4-tuples (row-major) and X = K S K^T (10 entries). Without a
    footprint (``limited`` False) P+ = P^- - X, evaluated as A+ = R M, B+ = R N, C+ = C^- -
    X_C (the same arithmetic as rsmhp.models.uav.kernel); with one, the expected update P+ = P^- -
    p_d X = (1 - p_d) P^- + p_d (P^- - X)."""
    a11, a12, a22, b11, b12, b21, b22, c11, c12, c22 = p
    dt2 = dt * dt
    pa11 = a11 + 2 * dt * b11 + dt2 * c11 + q[0]
    pa12 = a12 + dt * (b12 + b21) + dt2 * c12 + q[1]
    pa22 = a22 + 2 * dt * b22 + dt2 * c22 + q[2]
    pb11 = b11 + dt * c11 + q[3]
    pb12 = b12 + dt * c12 + q[4]
    pb21 = b21 + dt * c12 + q[5]
    pb22 = b22 + dt * c22 + q[6]
    pc11, pc12, pc22 = c11 + q[7], c12 + q[8], c22 + q[9]
    s11 = pa11 + rxx
    s12 = pa12 + rxy
    s22 = pa22 + ryy
    inv_det = 1.0 / (s11 * s22 - s12 * s12)
    i11, i12, i22 = s22 * inv_det, -s12 * inv_det, s11 * inv_det
    m11 = i11 * pa11 + i12 * pa12
    m12 = i11 * pa12 + i12 * pa22
    m21 = i12 * pa11 + i22 * pa12
    m22 = i12 * pa12 + i22 * pa22
    n11 = i11 * pb11 + i12 * pb21
    n12 = i11 * pb12 + i12 * pb22
    n21 = i12 * pb11 + i22 * pb21
    n22 = i12 * pb12 + i22 * pb22
    x = (
        pa11 * m11 + pa12 * m21,
        pa11 * m12 + pa12 * m22,
        pa12 * m12 + pa22 * m22,
        pa11 * n11 + pa12 * n21,
        pa11 * n12 + pa12 * n22,
        pa12 * n11 + pa22 * n21,
        pa12 * n12 + pa22 * n22,
        pb11 * n11 + pb21 * n21,
        pb11 * n12 + pb21 * n22,
        pb12 * n12 + pb22 * n22,
    )
    # Position and cross blocks in the cancellation-free form A+ = A- - A- S^-1 A- = R S^-1 A-
    # = R M and B+ = R N (S - A- = R); the subtraction A- - A- M loses every digit when R is
    # tiny next to A- (tests/core/test_properties.py). The velocity block keeps C- - B-^T N.
    ra11 = rxx * m11 + rxy * m21
    ra12 = rxx * m12 + rxy * m22
    ra22 = rxy * m12 + ryy * m22
    rb11 = rxx * n11 + rxy * n21
    rb12 = rxx * n12 + rxy * n22
    rb21 = rxy * n11 + ryy * n21
    rb22 = rxy * n12 + ryy * n22
    if limited:  # expected update (1 - p_d) P- + p_d P+
        qd = 1.0 - pd
        out = (
            qd * pa11 + pd * ra11,
            qd * pa12 + pd * ra12,
            qd * pa22 + pd * ra22,
            qd * pb11 + pd * rb11,
            qd * pb12 + pd * rb12,
            qd * pb21 + pd * rb21,
            qd * pb22 + pd * rb22,
            pc11 - pd * x[7],
            pc12 - pd * x[8],
            pc22 - pd * x[9],
        )
    else:
        out = (
            ra11,
            ra12,
            ra22,
            rb11,
            rb12,
            rb21,
            rb22,
            pc11 - x[7],
            pc12 - x[8],
            pc22 - x[9],
        )
    return out, (m11, m12, m21, m22), (n11, n12, n21, n22), x


@njit(cache=True)
def _detection(ux, uy, tx, ty, sens):  # pragma: no cover - compiled
    """(p_d, dp_d/d uav_x, dp_d/d uav_y) of the logistic footprint (see rsmhp.models.uav.sensor);
    the derivative is taken as 0 directly overhead (rho = 0)."""
    dx = tx - ux
    dy = ty - uy
    rho = np.sqrt(dx * dx + dy * dy)
    pd = 1.0 / (1.0 + np.exp((rho - sens[6]) / sens[7]))
    if rho == 0.0:
        return pd, 0.0, 0.0
    k = pd * (1.0 - pd) / sens[7] / rho  # dp/drho = -pd(1-pd)/w, drho/du = -(t-u)/rho
    return pd, k * dx, k * dy


@njit(cache=True)
def _mm(a, b):  # pragma: no cover - compiled
    """2x2 product of row-major 4-tuples."""
    return (
        a[0] * b[0] + a[1] * b[2],
        a[0] * b[1] + a[1] * b[3],
        a[2] * b[0] + a[3] * b[2],
        a[2] * b[1] + a[3] * b[3],
    )


@njit(cache=True)
def _mmt(a, b):  # pragma: no cover - compiled
    """a @ b.T for row-major 2x2 4-tuples."""
    return (
        a[0] * b[0] + a[1] * b[1],
        a[0] * b[2] + a[1] * b[3],
        a[2] * b[0] + a[3] * b[1],
        a[2] * b[2] + a[3] * b[3],
    )


@njit(cache=True)
def _sub(a, b):  # pragma: no cover - compiled
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2], a[3] - b[3])


@njit(cache=True, inline="always")
def _adjoint_step(ga, gb, gc, m, n, dt, pd, limited):  # pragma: no cover - compiled
    r"""Given G = [[Ga, Gb], [Gb^T, Gc]] = dJ/dP^+ (2x2 blocks as row-major 4-tuples), return
    (Rbar = K^T G K, and the blocks of F^T (E^T G E) F), with K = [M^T; N^T], E = I - K H.
    With a footprint (expected update P+ = P^- - p_d K S K^T, so dP+ = (1 - p_d) dP^- +
    p_d (E dP^- E^T + K dR K^T) - dp_d K S K^T): Rbar = p_d K^T G K and G^- = (1 - p_d) G +
    p_d E^T G E."""
    mga = _mm(m, ga)
    mgb = _mm(m, gb)
    ngc = _mm(n, gc)
    # Rbar = M Ga M^T + M Gb N^T + N Gb^T M^T + N Gc N^T
    t1 = _mmt(mga, m)
    t2 = _mmt(mgb, n)
    t4 = _mmt(ngc, n)
    rbar = (
        t1[0] + 2.0 * t2[0] + t4[0],
        t1[1] + t2[1] + t2[2] + t4[1],
        t1[2] + t2[2] + t2[1] + t4[2],
        t1[3] + 2.0 * t2[3] + t4[3],
    )
    # E^T G E with W = I - M: TL = W X - N Y, X = Ga W^T - Gb N^T, Y = Gb^T W^T - Gc N^T,
    # TR = W Gb - N Gc, BR = Gc
    w = (1.0 - m[0], -m[1], -m[2], 1.0 - m[3])
    gbt = (gb[0], gb[2], gb[1], gb[3])
    x = _sub(_mmt(ga, w), _mmt(gb, n))
    y = _sub(_mmt(gbt, w), _mmt(gc, n))
    tl = _sub(_mm(w, x), _mm(n, y))
    tr = _sub(_mm(w, gb), ngc)
    # symmetrise TL (it is symmetric in exact arithmetic)
    tl_s = 0.5 * (tl[1] + tl[2])
    tl = (tl[0], tl_s, tl_s, tl[3])
    if limited:
        rbar = (pd * rbar[0], pd * rbar[1], pd * rbar[2], pd * rbar[3])
        qd = 1.0 - pd
        tl = (
            qd * ga[0] + pd * tl[0],
            qd * ga[1] + pd * tl[1],
            qd * ga[2] + pd * tl[2],
            qd * ga[3] + pd * tl[3],
        )
        tr = (
            qd * gb[0] + pd * tr[0],
            qd * gb[1] + pd * tr[1],
            qd * gb[2] + pd * tr[2],
            qd * gb[3] + pd * tr[3],
        )
    # F^T G^- F: Ga' = Ga, Gb' = dt Ga + Gb, Gc' = dt^2 Ga + dt (Gb + Gb^T) + Gc
    ga2 = tl
    gb2 = (dt * tl[0] + tr[0], dt * tl[1] + tr[1], dt * tl[2] + tr[2], dt * tl[3] + tr[3])
    dt2 = dt * dt
    gc2 = (
        dt2 * tl[0] + dt * 2.0 * tr[0] + gc[0],
        dt2 * tl[1] + dt * (tr[1] + tr[2]) + gc[1],
        dt2 * tl[2] + dt * (tr[2] + tr[1]) + gc[2],
        dt2 * tl[3] + dt * 2.0 * tr[3] + gc[3],
    )
    return rbar, ga2, gb2, gc2


@njit(cache=True, inline="always")
def _meas_cov_grad(ux, uy, tx, ty, rbar, sens):  # pragma: no cover - compiled
    """d<Rbar, R>/d(uav x, uav y) (see module docstring); 0 directly overhead."""
    fr2, fc2, h2 = sens[0], sens[1], sens[2]
    dx = tx - ux
    dy = ty - uy
    rho2 = dx * dx + dy * dy
    if rho2 == 0.0:
        return 0.0, 0.0
    dd = fr2 - fc2
    if sens[3] != 0.0:
        # R = s(d^2) [f_c^2 I + D v v^T / rho^2], s = d^4 / d0^2, s' = 2 d^2 / d0^2
        d2 = rho2 + h2
        sc = d2 * d2 / sens[4]
        sp = 2.0 * d2 / sens[4]
        rv0 = rbar[0] * dx + rbar[1] * dy
        rv1 = rbar[2] * dx + rbar[3] * dy
        qb = dx * rv0 + dy * rv1
        tr = rbar[0] + rbar[3]
        k1 = 2.0 * sp * (fc2 * tr + dd * qb / rho2) - 2.0 * sc * dd * qb / (rho2 * rho2)
        k2 = 2.0 * sc * dd / rho2
        return -(k1 * dx + k2 * rv0), -(k1 * dy + k2 * rv1)
    rv0 = rbar[0] * dx + rbar[1] * dy
    rv1 = rbar[2] * dx + rbar[3] * dy
    qb = dx * rv0 + dy * rv1
    tr = rbar[0] + rbar[3]
    k1 = 2.0 * fc2 * tr - 2.0 * dd * h2 * qb / (rho2 * rho2)
    k2 = 2.0 * dd * (1.0 + h2 / rho2)
    gvx = k1 * dx + k2 * rv0
    gvy = k1 * dy + k2 * rv1
    return -gvx, -gvy


@njit(cache=True)
def _kinematics(
    xc, state0, amax, phimax, dt, g, smin, smax, uxy, spd, hdg, inside
):  # pragma: no cover
    """Rollout of one normalised control sequence ``xc`` (2H,): positions ``uxy`` (H, 2),
    speeds and headings ``spd``, ``hdg`` (H+1,) (entry 0 = start), and whether each speed
    update stayed strictly inside the bounds. rsmhp.models.uav.kinematics.step, same operation
    order.
    """
    px, py = state0[0], state0[1]
    spd[0], hdg[0] = state0[2], state0[3]
    for j in range(uxy.shape[0]):
        a = min(max(xc[2 * j] * amax, -amax), amax)
        phi = min(max(xc[2 * j + 1] * phimax, -phimax), phimax)
        v = spd[j] + a * dt
        inside[j] = smin < v < smax
        s_new = min(max(v, smin), smax)
        h_new = hdg[j] + g * np.tan(phi) / spd[j] * dt
        px = px + s_new * dt * np.cos(h_new)
        py = py + s_new * dt * np.sin(h_new)
        spd[j + 1], hdg[j + 1] = s_new, h_new
        uxy[j, 0], uxy[j, 1] = px, py


@njit(cache=True, nogil=True)
def _path_kernel(xc, state0, cfg, out):  # pragma: no cover - compiled
    horizon = xc.shape[0] // 2
    uxy = np.empty((horizon, 2))
    spd = np.empty(horizon + 1)
    hdg = np.empty(horizon + 1)
    inside = np.empty(horizon, dtype=np.bool_)
    _kinematics(xc, state0, cfg[0], cfg[1], cfg[2], cfg[3], cfg[4], cfg[5], uxy, spd, hdg, inside)
    for j in range(horizon):
        out[j, 0], out[j, 1], out[j, 2], out[j, 3] = uxy[j, 0], uxy[j, 1], spd[j + 1], hdg[j + 1]
    return out


@njit(cache=True)
def _kinematics_adjoint(xc, cfg, spd, hdg, inside, gxy, grad):  # pragma: no cover - compiled
    """dJ/dx (2H,) into ``grad`` from ``gxy`` (H, 2) = dJ/d(UAV position after step j) times
    the weight divisor (back-substitution of the kinematics; module docstring)."""
    amax, phimax, udt, g, norm = cfg[0], cfg[1], cfg[2], cfg[3], cfg[6]
    horizon = gxy.shape[0]
    # ---- kinematics adjoint: (bpx, bpy, bs, bpsi) = dJ/d(state after step j)
    bpx = bpy = bs = bpsi = 0.0
    for j in range(horizon - 1, -1, -1):
        bpx += gxy[j, 0] / norm
        bpy += gxy[j, 1] / norm
        s_new, h_new = spd[j + 1], hdg[j + 1]
        ch, sh = np.cos(h_new), np.sin(h_new)
        bs_new = bs + udt * (bpx * ch + bpy * sh)
        bpsi_new = bpsi + s_new * udt * (bpy * ch - bpx * sh)
        phi = min(max(xc[2 * j + 1] * phimax, -phimax), phimax)
        cphi = np.cos(phi)
        bphi = bpsi_new * g * udt / (spd[j] * cphi * cphi)
        bs = -bpsi_new * g * np.tan(phi) * udt / (spd[j] * spd[j])
        bpsi = bpsi_new
        ba = 0.0
        if inside[j]:
            bs += bs_new
            ba = bs_new * udt
        grad[2 * j] = ba * amax
        grad[2 * j + 1] = bphi * phimax


@njit(cache=True, nogil=True, error_model="numpy")
def _value_grad_scalar(
    xc, st, cfg, p0, q, sens, tx, ty, wts, uxy, spd, hdg, inside, gxy, mn, det, want_grad, grad
):  # pragma: no cover - compiled
    """:func:`_value_grad` one hypothesis at a time (each hypothesis' recursion in registers,
    no loop over hypotheses per step): faster below :data:`SOA_MIN_HYPOTHESES` hypotheses,
    where entering the vectorised loops costs more than they save. Same arithmetic and the
    same order of every sum as the vectorised layout, hence the same bits."""
    q = (q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7], q[8], q[9])
    sens = (sens[0], sens[1], sens[2], sens[3], sens[4], sens[5], sens[6], sens[7])
    amax, phimax, udt, g, smin, smax, norm, tdt = (
        cfg[0], cfg[1], cfg[2], cfg[3], cfg[4], cfg[5], cfg[6], cfg[7]
    )  # fmt: skip
    horizon, n_t = tx.shape[0], tx.shape[1]
    limited = sens[5] != 0.0
    _kinematics(xc, st, amax, phimax, udt, g, smin, smax, uxy, spd, hdg, inside)
    total = 0.0
    for j in range(horizon):
        gxy[j, 0] = 0.0
        gxy[j, 1] = 0.0
    for i in range(n_t):
        wi = wts[i]
        p = (p0[0], p0[1], p0[2], p0[3], p0[4], p0[5], p0[6], p0[7], p0[8], p0[9])
        acc = 0.0
        for j in range(horizon):
            ux, uy, txi, tyi = uxy[j, 0], uxy[j, 1], tx[j, i], ty[j, i]
            rxx, rxy, ryy = _meas_cov(ux, uy, txi, tyi, sens)
            pd, dpx, dpy = _detection(ux, uy, txi, tyi, sens) if limited else (1.0, 0.0, 0.0)
            p, m, n, xk = _kalman_step(p, rxx, rxy, ryy, tdt, q, pd, limited)
            acc += p[0] + p[2] + p[7] + p[9]
            if want_grad:
                mn[j, 0], mn[j, 1], mn[j, 2], mn[j, 3] = m
                mn[j, 4], mn[j, 5], mn[j, 6], mn[j, 7] = n
                if limited:
                    det[j, 0], det[j, 1], det[j, 2] = pd, dpx, dpy
                    for e in range(10):
                        det[j, 3 + e] = xk[e]
        total += wi * acc
        if not want_grad:
            continue
        ga = (1.0, 0.0, 0.0, 1.0)
        gb = (0.0, 0.0, 0.0, 0.0)
        gc = (1.0, 0.0, 0.0, 1.0)
        for j in range(horizon - 1, -1, -1):
            m = (mn[j, 0], mn[j, 1], mn[j, 2], mn[j, 3])
            n = (mn[j, 4], mn[j, 5], mn[j, 6], mn[j, 7])
            pd = 1.0
            if limited:
                pd = det[j, 0]
                pbar = -(
                    ga[0] * det[j, 3]
                    + (ga[1] + ga[2]) * det[j, 4]
                    + ga[3] * det[j, 5]
                    + 2.0
                    * (
                        gb[0] * det[j, 6]
                        + gb[1] * det[j, 7]
                        + gb[2] * det[j, 8]
                        + gb[3] * det[j, 9]
                    )
                    + gc[0] * det[j, 10]
                    + (gc[1] + gc[2]) * det[j, 11]
                    + gc[3] * det[j, 12]
                )
                gxy[j, 0] += wi * (pbar * det[j, 1])
                gxy[j, 1] += wi * (pbar * det[j, 2])
            rbar, ga, gb, gc = _adjoint_step(ga, gb, gc, m, n, tdt, pd, limited)
            ga = (ga[0] + 1.0, ga[1], ga[2], ga[3] + 1.0)
            gc = (gc[0] + 1.0, gc[1], gc[2], gc[3] + 1.0)
            gx, gy = _meas_cov_grad(uxy[j, 0], uxy[j, 1], tx[j, i], ty[j, i], rbar, sens)
            gxy[j, 0] += wi * gx
            gxy[j, 1] += wi * gy
    if want_grad:
        _kinematics_adjoint(xc, cfg, spd, hdg, inside, gxy, grad)
    return total / norm


@njit(cache=True, inline="always", error_model="numpy")
def _forward_hypothesis(
    i, j, ux, uy, tx, ty, tdt, q, sens, P, MN, DET, acc, limited, want_grad
):  # pragma: no cover
    """Step j of hypothesis i: predict + update of its P (columns of ``P``), its cost, and
    what the adjoint needs (M, N; with a footprint K S K^T). ``limited`` and ``want_grad``
    are literal at every call, so each of the four loops below is branch-free."""
    rxx, rxy, ryy = _meas_cov(ux, uy, tx[j, i], ty[j, i], sens)
    pd = DET[0][j, i] if limited else 1.0
    p = (P[0][i], P[1][i], P[2][i], P[3][i], P[4][i], P[5][i], P[6][i], P[7][i], P[8][i], P[9][i])
    p, m, n, xk = _kalman_step(p, rxx, rxy, ryy, tdt, q, pd, limited)
    P[0][i], P[1][i], P[2][i], P[3][i], P[4][i] = p[0], p[1], p[2], p[3], p[4]
    P[5][i], P[6][i], P[7][i], P[8][i], P[9][i] = p[5], p[6], p[7], p[8], p[9]
    acc[i] += p[0] + p[2] + p[7] + p[9]
    if want_grad:
        MN[0][j, i], MN[1][j, i], MN[2][j, i], MN[3][j, i] = m[0], m[1], m[2], m[3]
        MN[4][j, i], MN[5][j, i], MN[6][j, i], MN[7][j, i] = n[0], n[1], n[2], n[3]
        if limited:
            DET[3][j, i], DET[4][j, i], DET[5][j, i], DET[6][j, i] = xk[0], xk[1], xk[2], xk[3]
            DET[7][j, i], DET[8][j, i], DET[9][j, i] = xk[4], xk[5], xk[6]
            DET[10][j, i], DET[11][j, i], DET[12][j, i] = xk[7], xk[8], xk[9]


@njit(cache=True, inline="always", error_model="numpy")
def _reverse_hypothesis(
    i, j, ux, uy, tx, ty, tdt, sens, G, MN, DET, tmp, limited
):  # pragma: no cover
    """Adjoint of step j of hypothesis i: G (columns of ``G``: rows 0-3 Ga, 4-7 Gb, 8-11 Gc)
    from dJ/dP+ of step j to dJ/dP+ of step j-1, and this step's terms of dJ/d(UAV x, y) in
    ``tmp`` (rows 0-1: through p_d, rows 2-3: through R)."""
    ga = (G[0][i], G[1][i], G[2][i], G[3][i])
    gb = (G[4][i], G[5][i], G[6][i], G[7][i])
    gc = (G[8][i], G[9][i], G[10][i], G[11][i])
    m = (MN[0][j, i], MN[1][j, i], MN[2][j, i], MN[3][j, i])
    n = (MN[4][j, i], MN[5][j, i], MN[6][j, i], MN[7][j, i])
    pd = 1.0
    if limited:
        pd = DET[0][j, i]
        # dJ/dp_d = -<G, K S K^T> (G = dJ/dP+ of this step, symmetric)
        pbar = -(
            ga[0] * DET[3][j, i]
            + (ga[1] + ga[2]) * DET[4][j, i]
            + ga[3] * DET[5][j, i]
            + 2.0
            * (
                gb[0] * DET[6][j, i]
                + gb[1] * DET[7][j, i]
                + gb[2] * DET[8][j, i]
                + gb[3] * DET[9][j, i]
            )
            + gc[0] * DET[10][j, i]
            + (gc[1] + gc[2]) * DET[11][j, i]
            + gc[3] * DET[12][j, i]
        )
        tmp[0][i] = pbar * DET[1][j, i]
        tmp[1][i] = pbar * DET[2][j, i]
    rbar, ga, gb, gc = _adjoint_step(ga, gb, gc, m, n, tdt, pd, limited)
    G[0][i], G[1][i], G[2][i], G[3][i] = ga[0] + 1.0, ga[1], ga[2], ga[3] + 1.0
    G[4][i], G[5][i], G[6][i], G[7][i] = gb[0], gb[1], gb[2], gb[3]
    G[8][i], G[9][i], G[10][i], G[11][i] = gc[0] + 1.0, gc[1], gc[2], gc[3] + 1.0
    gx, gy = _meas_cov_grad(ux, uy, tx[j, i], ty[j, i], rbar, sens)
    tmp[2][i] = gx
    tmp[3][i] = gy


@njit(cache=True, inline="always", error_model="numpy")
def _value_grad(xc, st, cfg, p0, q, sens, tx, ty, wts, ws, want_grad, grad):  # pragma: no cover
    """Cost of ``xc`` (2H,) and, if ``want_grad``, its gradient into ``grad``: the vectorised
    layout from :data:`SOA_MIN_HYPOTHESES` hypotheses on, the scalar one below."""
    if tx.shape[1] < SOA_MIN_HYPOTHESES:
        # only the arrays it uses: fewer references to count per call
        return _value_grad_scalar(
            xc, st, cfg, p0, q, sens, tx, ty, wts,
            ws[6], ws[7], ws[8], ws[9], ws[10], ws[11], ws[12], want_grad, grad,
        )  # fmt: skip
    return _value_grad_soa(xc, st, cfg, p0, q, sens, tx, ty, wts, ws, want_grad, grad)


@njit(cache=True, nogil=True, error_model="numpy")
def _value_grad_soa(xc, st, cfg, p0, q, sens, tx, ty, wts, ws, want_grad, grad):  # pragma: no cover
    """Cost of one normalised control sequence ``xc`` (2H,) and, if ``want_grad``, its
    gradient written to ``grad`` (2H,). Hypotheses in structure-of-arrays layout: ``tx``,
    ``ty`` (H, T), hypotheses innermost, so that every per-step loop over the T hypotheses
    is one vectorised loop (branch-free: the flags are literal in each loop, the overhead
    case is a select; the footprint's exp runs in a separate scalar loop). ``ws`` is the
    workspace (:func:`_workspace`). The arithmetic of every hypothesis,
    and the order of the sums over hypotheses, are those of the per-hypothesis recursion of
    :mod:`rsmhp.models.uav.kernel` and its adjoint (module docstring)."""
    # constants as tuples of scalars: loads from the argument arrays inside the loops would
    # be further pointers for LLVM's overlap checks (and stop the vectoriser)
    q = (q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7], q[8], q[9])
    sens = (sens[0], sens[1], sens[2], sens[3], sens[4], sens[5], sens[6], sens[7])
    P, G, acc, MN, DET, tmp, uxy, spd, hdg, inside, gxy = ws[:11]
    amax, phimax, udt, g, smin, smax, norm, tdt = (
        cfg[0], cfg[1], cfg[2], cfg[3], cfg[4], cfg[5], cfg[6], cfg[7]
    )  # fmt: skip
    horizon, n_t = tx.shape[0], tx.shape[1]
    limited = sens[5] != 0.0
    _kinematics(xc, st, amax, phimax, udt, g, smin, smax, uxy, spd, hdg, inside)
    for i in range(n_t):
        P[0][i], P[1][i], P[2][i], P[3][i], P[4][i] = p0[0], p0[1], p0[2], p0[3], p0[4]
        P[5][i], P[6][i], P[7][i], P[8][i], P[9][i] = p0[5], p0[6], p0[7], p0[8], p0[9]
        acc[i] = 0.0
    # ---- forward: covariance recursion of every hypothesis, one step at a time
    for j in range(horizon):
        ux, uy = uxy[j, 0], uxy[j, 1]
        if limited:
            for i in range(n_t):  # scalar: exp does not vectorise without a vector math library
                pd, dpx, dpy = _detection(ux, uy, tx[j, i], ty[j, i], sens)
                DET[0][j, i], DET[1][j, i], DET[2][j, i] = pd, dpx, dpy
            if want_grad:
                for i in range(n_t):
                    _forward_hypothesis(
                        i, j, ux, uy, tx, ty, tdt, q, sens, P, MN, DET, acc, True, True
                    )
            else:
                for i in range(n_t):
                    _forward_hypothesis(
                        i, j, ux, uy, tx, ty, tdt, q, sens, P, MN, DET, acc, True, False
                    )
        elif want_grad:
            for i in range(n_t):
                _forward_hypothesis(
                    i, j, ux, uy, tx, ty, tdt, q, sens, P, MN, DET, acc, False, True
                )
        else:
            for i in range(n_t):
                _forward_hypothesis(
                    i, j, ux, uy, tx, ty, tdt, q, sens, P, MN, DET, acc, False, False
                )
    total = 0.0
    for i in range(n_t):
        total += wts[i] * acc[i]
    if not want_grad:
        return total / norm
    # ---- reverse: G = dJ/dP+ per hypothesis, from G_H = I
    for i in range(n_t):
        G[0][i], G[1][i], G[2][i], G[3][i] = 1.0, 0.0, 0.0, 1.0
        G[4][i], G[5][i], G[6][i], G[7][i] = 0.0, 0.0, 0.0, 0.0
        G[8][i], G[9][i], G[10][i], G[11][i] = 1.0, 0.0, 0.0, 1.0
    for j in range(horizon - 1, -1, -1):
        ux, uy = uxy[j, 0], uxy[j, 1]
        sx = 0.0
        sy = 0.0
        # the weighted sums over hypotheses follow the per-hypothesis kernel's order
        if limited:
            for i in range(n_t):
                _reverse_hypothesis(i, j, ux, uy, tx, ty, tdt, sens, G, MN, DET, tmp, True)
            for i in range(n_t):
                wi = wts[i]
                sx += wi * tmp[0][i]
                sy += wi * tmp[1][i]
                sx += wi * tmp[2][i]
                sy += wi * tmp[3][i]
        else:
            for i in range(n_t):
                _reverse_hypothesis(i, j, ux, uy, tx, ty, tdt, sens, G, MN, DET, tmp, False)
            for i in range(n_t):
                wi = wts[i]
                sx += wi * tmp[2][i]
                sy += wi * tmp[3][i]
        gxy[j, 0] = sx
        gxy[j, 1] = sy
    _kinematics_adjoint(xc, cfg, spd, hdg, inside, gxy, grad)
    return total / norm


@njit(cache=True, nogil=True)
def _workspace(horizon, n_t, limited):  # pragma: no cover - compiled
    """Scratch arrays of :func:`_value_grad` for H steps and T hypotheses, allocated once per
    kernel call: P (10 rows of T), G (12 rows), per-hypothesis cost (T,), M and N per step
    (8 arrays (H, T)), footprint quantities per step (13 arrays (H, T); (H, 0) without a
    footprint), per-hypothesis gradient terms (4 rows), UAV positions (H, 2), speeds and
    headings (H+1,), speed-clip flags (H,), the position gradient (H, 2), and the scalar
    layout's M, N (H, 8) and footprint quantities (H, 13) of one hypothesis. Rows are
    separate arrays so that LLVM checks them for overlap at run time and vectorises."""
    p = np.empty((10, n_t))
    g = np.empty((12, n_t))
    mn = np.empty((8, horizon, n_t))
    det = np.empty((13, horizon, n_t if limited else 0))
    tmp = np.empty((4, n_t))
    return (
        (p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9]),
        (g[0], g[1], g[2], g[3], g[4], g[5], g[6], g[7], g[8], g[9], g[10], g[11]),
        np.empty(n_t),
        (mn[0], mn[1], mn[2], mn[3], mn[4], mn[5], mn[6], mn[7]),
        (
            det[0],
            det[1],
            det[2],
            det[3],
            det[4],
            det[5],
            det[6],
            det[7],
            det[8],
            det[9],
            det[10],
            det[11],
            det[12],
        ),
        (tmp[0], tmp[1], tmp[2], tmp[3]),
        np.empty((horizon, 2)),
        np.empty(horizon + 1),
        np.empty(horizon + 1),
        np.empty(horizon, dtype=np.bool_),
        np.empty((horizon, 2)),
        np.empty((horizon, 8)),
        np.empty((horizon, 13)),
    )


#: modes of :func:`_planner_kernel`
_EVALUATE, _MINIMISE, _CLOSED_LOOP = 0, 1, 2

#: how the compiled closed loop gets a step's hypotheses (``loop[0][0]``):
#: :data:`NOMINAL`, NBO's noise-free prediction computed in compiled code
#: (:func:`rsmhp.models.uav.target.nominal`'s kernel); :data:`DRAWN`, the method's own
#: Python generator, called once per step from compiled code (:func:`_drawn`)
NOMINAL, DRAWN = 0, 1

#: the Python side of the compiled closed loops now running, by handle: an object with
#: ``draw(k) -> (states, weights)`` and ``advance(k, u0, u1) -> (detected, error, trace)``
#: working on the same state arrays as the compiled loop
#: (:class:`rsmhp.models.uav.loop._Context`, registered for the length of its compiled call)
CONTEXTS: dict[int, object] = {}


def _step_hypotheses(handle, k):
    """The hypotheses of step ``k`` (object mode) as C-contiguous ``states`` (T, H, 4) and
    ``weights`` (T,)."""
    states, weights = CONTEXTS[int(handle)].draw(int(k))
    return np.ascontiguousarray(states, dtype=float), np.ascontiguousarray(weights, dtype=float)


def _step_advance(handle, k, u0, u1):
    """Step ``k`` after the plan with the control ``(u0, u1)`` (object mode): the state
    arrays, shared with the compiled loop, updated in place."""
    seen, err, tr = CONTEXTS[int(handle)].advance(int(k), u0, u1)
    return bool(seen), float(err), float(tr)


@njit(cache=True)
def _drawn(handle, k):  # pragma: no cover - compiled
    """:func:`_step_hypotheses` called from compiled code (object mode: the GIL is taken;
    scalars in, the arrays out; a few µs per call)."""
    with objmode(states="float64[:, :, ::1]", weights="float64[::1]"):
        states, weights = _step_hypotheses(handle, k)
    return states, weights


@njit(cache=True)
def _advanced(handle, k, u0, u1):  # pragma: no cover - compiled
    """:func:`_step_advance` called from compiled code. The closed-loop step
    (:func:`rsmhp.models.uav.stepper._advance`) is called, not linked: linking would compile
    it (about 7 s) into the planner kernel at set-up, on top of the kernel's own compile,
    while a call costs a few µs per step."""
    with objmode(seen="boolean", err="float64", tr="float64"):
        seen, err, tr = _step_advance(handle, k, u0, u1)
    return seen, err, tr


@njit(cache=True, nogil=True, error_model="numpy")
def _loop_plan_data(k, loop, cfg, p0, H):  # pragma: no cover - compiled
    """Step ``k`` of the compiled closed loop, before the optimisation: the hypotheses
    (:data:`NOMINAL` or :data:`DRAWN`), their coordinates ``(tx, ty)`` (H, T), the weights and
    the divisor (``cfg[6]``) as :func:`weight_args` gives them, and the covariance's entries
    into ``p0``: the arguments :class:`Frozen` builds in the Python loop."""
    flags, F, _c, _uav, _xt, x_est, P, _sc, _st, _v, _i = loop
    if flags[0] == NOMINAL:
        x0 = np.empty((1, 4))
        for a in range(4):
            x0[0, a] = x_est[a]
        states = target._propagate_kernel(x0, np.zeros((1, H, 4)), F, np.empty((1, H, 4)))
        weights = np.ones(1)
    else:
        states, weights = _drawn(flags[1], k)
    n_t = states.shape[0]
    tx = np.empty((H, n_t))
    ty = np.empty((H, n_t))
    for i in range(n_t):
        for j in range(H):
            tx[j, i] = states[i, j, 0]
            ty[j, i] = states[i, j, 1]
    equal = True
    for i in range(1, n_t):
        if weights[i] != weights[0]:
            equal = False
    if equal:  # equal weights (or one hypothesis): ones and the plain average
        wts = np.ones(n_t)
        cfg[6] = float(n_t)
    else:
        wts = weights.copy()
        cfg[6] = 1.0
    for e in range(10):
        r, c = _ROWS[e], _COLS[e]
        p0[e] = 0.5 * (P[r, c] + P[c, r])
    return tx, ty, wts


@njit(cache=True, nogil=True, error_model="numpy")
def _loop_step(k, loop, x_best, warm, plan):  # pragma: no cover - compiled
    """Step ``k`` of the compiled closed loop, after the optimisation: the controls of the
    winning plan ``x_best``, the next warm start (``shift_plan``), the first control applied by
    :func:`rsmhp.models.uav.stepper._advance` and the step's row (``plan``: cost, warm cost,
    status, winning start, iterations, kernel calls, work)."""
    flags, _F, _c, uav, x_true, x_est, _P, scale, _st, vals, ints = loop
    n = scale.shape[0]
    controls = np.empty(n)
    for i in range(n):
        controls[i] = x_best[i] * scale[i]
    for i in range(n - 2):
        warm[i] = controls[i + 2]
    warm[n - 2] = controls[n - 2]
    warm[n - 1] = controls[n - 1]
    seen, err, tr = _advanced(flags[1], k, controls[0], controls[1])
    f_best, f_warm, status, winner, nit, calls, work = plan
    row = vals[k - 1]
    row[0], row[1] = err, tr
    for a in range(4):
        row[2 + a] = uav[a]
    row[6], row[7], row[8], row[9] = x_true[0], x_true[1], x_est[0], x_est[1]
    row[10], row[11] = controls[0], controls[1]
    row[12], row[13], row[14], row[15] = f_best, f_warm, float(status), float(winner)
    ints[k - 1, 0] = nit
    ints[k - 1, 1] = calls
    ints[k - 1, 2] = work
    ints[k - 1, 3] = 1 if seen else 0


@njit(cache=True, inline="always", error_model="numpy")
def _objective(x, grad, data):  # pragma: no cover - compiled
    """The planning cost and its gradient in :mod:`rsmhp.core.boxqn`'s calling convention."""
    st, cfg, p0, q, sens, tx, ty, wts, ws, want_grad = data
    return _value_grad(x, st, cfg, p0, q, sens, tx, ty, wts, ws, want_grad, grad)


@njit(cache=True, nogil=True)
def _planner_kernel(
    mode, x, st, cfg, p0, q, sens, tx, ty, wts, want_grad, maxiter, maxfun, cost, grad, x_out, loop
):  # pragma: no cover - compiled
    """Both compiled entry points in one function, so that the two layouts are linked into
    one kernel only. ``mode`` :data:`_EVALUATE`: :func:`_value_grad` for every row of ``x``
    (C, 2H) into ``cost`` (C,) and, if ``want_grad``, ``grad`` (C, 2H); returns zeros.
    :data:`_MINIMISE`: :func:`rsmhp.core.boxqn.minimise` of the cost from ``x[0]`` (2H,) with
    ``want_grad`` true, the final point into ``x_out`` (2H,); returns ``(f, f0, nit, nfev,
    status)``. :data:`_CLOSED_LOOP`: a whole closed-loop run of K steps
    (:mod:`rsmhp.models.uav.loop`: its arguments in ``loop``; ``q``, ``sens``, ``maxiter``,
    ``maxfun`` and ``want_grad``, true, as in the other modes; the other arguments unused):
    at each step the hypotheses and cost arguments (:func:`_loop_plan_data`), the
    optimisation from the shifted warm start and from each restart start (the lowest cost
    wins, ties keep the earlier: ``planner._restart``), then the control applied and the row
    (:func:`_loop_step`); returns ``(planning cycles, all cycles, 0, 0, 0)`` (zeros without the
    cycle counter).

    Why one function: numba links the layouts' compiled code into every kernel that calls them
    and optimises the linked module again; for the vectorised layout that second pass took
    12-14 s per calling kernel (measured: numba 0.68, LLVM host znver4), so two calling kernels
    paid it twice. ``want_grad`` is a run-time ``bool`` in both modes (a literal ``True`` would
    make numba compile both layouts a second time, for the literal's type)."""
    limited = sens[5] != 0.0
    ws = _workspace(tx.shape[0], tx.shape[1], limited)
    if mode == _EVALUATE:
        for c in range(x.shape[0]):
            g_row = grad[c] if want_grad else grad[0]
            cost[c] = _value_grad(x[c], st, cfg, p0, q, sens, tx, ty, wts, ws, want_grad, g_row)
        return 0.0, 0.0, 0, 0, 0
    # _MINIMISE: one optimisation from x[0]; _CLOSED_LOOP: K steps of (restarts + 1) each.
    # One call site of the (inlined) optimiser serves both: a second one would be typed and
    # optimised again at compile time.
    closed = mode == _CLOSED_LOOP
    flags, scale, starts, vals = loop[0], loop[7], loop[8], loop[9]
    timed = closed and flags[2] != 0
    n = scale.shape[0] if closed else x.shape[1]
    n_steps = vals.shape[0] if closed else 1
    n_starts = starts.shape[0] + 1 if closed else 1
    cfg_k = loop[2].copy() if closed else cfg
    p0_k = np.empty(10) if closed else p0
    warm = np.zeros(n)  # the closed loop's warm start, controls (H, 2) flattened
    x_start = np.empty(n)
    x_try = x_out if not closed else np.empty(n)
    x_best = np.empty(n)
    data = (st, cfg, p0, q, sens, tx, ty, wts, ws, want_grad)
    plan_cycles = 0
    t_begin = clock.cycles() if timed else 0
    for k in range(1, n_steps + 1):
        t0 = clock.cycles() if timed else 0
        if closed:
            tx_k, ty_k, wts_k = _loop_plan_data(k, loop, cfg_k, p0_k, n // 2)
            ws_k = _workspace(n // 2, tx_k.shape[1], limited)
            data = (loop[3], cfg_k, p0_k, q, sens, tx_k, ty_k, wts_k, ws_k, want_grad)
        n_t = data[5].shape[1]
        f_best, f_warm, status_best, winner = 0.0, 0.0, 0, 0
        nit_total, calls, calls_best, work = 0, 0, 0, 0
        for r in range(n_starts):
            for i in range(n):
                if not closed:
                    x_start[i] = x[0, i]
                elif r == 0:  # the warm start as BoxQN.minimise clips it
                    x_start[i] = min(max(warm[i] / scale[i], -1.0), 1.0)
                else:
                    x_start[i] = starts[r - 1, i]
            f, f0, nit, nfev, status = boxqn.minimise(
                _objective, data, x_start, maxiter, maxfun, boxqn.MEMORY, boxqn.PGTOL,
                boxqn.FTOL, x_try,
            )  # fmt: skip
            if not closed:
                return f, f0, nit, nfev, status
            # planner._restart: the lowest own cost wins, ties keep the earlier
            calls += nfev
            work += 2 * nfev * n_t * (n // 2)
            nit_total += nit
            if r == 0 or f < f_best:
                f_best, status_best, winner, calls_best = f, status, r, calls
                for i in range(n):
                    x_best[i] = x_try[i]
            if r == 0:
                f_warm = f0
        if timed:
            plan_cycles += clock.cycles() - t0
        plan = (f_best, f_warm, status_best, winner, nit_total, calls_best, work)
        _loop_step(k, loop, x_best, warm, plan)
    t_end = clock.cycles() if timed else 0
    return float(plan_cycles), float(t_end - t_begin), 0, 0, 0


@njit(cache=True, nogil=True)
def _traces_kernel(p0, uxy, txy, tdt, q, sens, out):  # pragma: no cover - compiled
    limited = sens[5] != 0.0
    for c in range(uxy.shape[0]):
        for i in range(txy.shape[0]):
            p = (p0[0], p0[1], p0[2], p0[3], p0[4], p0[5], p0[6], p0[7], p0[8], p0[9])
            for j in range(uxy.shape[1]):
                ux, uy, tx, ty = uxy[c, j, 0], uxy[c, j, 1], txy[i, j, 0], txy[i, j, 1]
                rxx, rxy, ryy = _meas_cov(ux, uy, tx, ty, sens)
                pd = _detection(ux, uy, tx, ty, sens)[0] if limited else 1.0
                p, _m, _n, _x = _kalman_step(p, rxx, rxy, ryy, tdt, q, pd, limited)
                out[c, i, j] = p[0] + p[2] + p[7] + p[9]
    return out


# --------------------------------------------------------------------------------------------
# Python entry points


_ROWS = np.array([0, 0, 1, 0, 0, 1, 1, 2, 2, 3])
_COLS = np.array([0, 1, 1, 2, 3, 2, 3, 2, 3, 3])


def _entries(P: np.ndarray) -> np.ndarray:
    """The 10 distinct entries (10,) of a symmetric 4x4 matrix, in the kernel's order."""
    P = np.asarray(P, dtype=float)
    return 0.5 * (P[_ROWS, _COLS] + P[_COLS, _ROWS])


def _constant_entries(matrix: bytes) -> np.ndarray:
    """:func:`_entries` of a 4x4 matrix given by its bytes (the target's Q: the same at every
    planning step; a fresh writable array, so that the kernels see one array type)."""
    return np.array(_entries_of_bytes(matrix))


@functools.lru_cache(maxsize=64)
def _entries_of_bytes(matrix: bytes) -> tuple[float, ...]:
    return tuple(_entries(np.frombuffer(matrix, dtype=float).reshape(4, 4)).tolist())


@functools.cache
def _uav_args(uav: UAVParams) -> tuple[float, ...]:
    """(a_max, phi_max, dt, g, s_min, s_max) of an aircraft (computed once per aircraft)."""
    return (uav.accel_max, uav.bank_max, uav.dt, uav.g, uav.speed_min, uav.speed_max)


def _sensor_args(sensor: SensorModel) -> np.ndarray:
    """(f_r^2, f_c^2, h^2, quadratic growth 0/1, d_0^2, footprint 0/1, rho_0, w) (8,)."""
    return np.array(_sensor_tuple(sensor))


@functools.cache
def _sensor_tuple(sensor: SensorModel) -> tuple[float, ...]:
    limited = sensor.limited
    return (
        sensor.sigma_r_per_m**2,
        sensor.sigma_c_per_m**2,
        sensor.altitude**2,
        1.0 if sensor.noise_growth == "quadratic" else 0.0,
        sensor.reference_distance**2,
        1.0 if limited else 0.0,
        float(sensor.footprint_radius) if limited else 0.0,
        float(sensor.footprint_width),
    )


def covariance_traces(
    P0: np.ndarray,
    uav_xy: np.ndarray,
    target_xy: np.ndarray,
    dt: float,
    Q: np.ndarray,
    sensor: SensorModel,
) -> np.ndarray:
    """Compiled twin of :func:`rsmhp.models.uav.kernel.covariance_traces`: ``tr P_j`` (C, T, H) for
    UAV positions ``uav_xy`` (C, H, 2) and hypotheses ``target_xy`` (T, H, 2); arguments
    checked by :func:`rsmhp.models.uav.kernel.check_arguments`."""
    kernel.check_arguments(P0, uav_xy, target_xy, dt, Q, sensor)
    uav_xy = np.ascontiguousarray(uav_xy, dtype=float)
    target_xy = np.ascontiguousarray(target_xy, dtype=float)
    out = np.empty((uav_xy.shape[0], target_xy.shape[0], uav_xy.shape[1]))
    P0 = np.asarray(P0, dtype=float)
    Q = np.asarray(Q, dtype=float)
    return _traces_kernel(
        _entries(P0), uav_xy, target_xy, float(dt), _entries(Q), _sensor_args(sensor), out
    )


def check_frozen(
    uav_state: np.ndarray,
    uav: UAVParams,
    P0: np.ndarray,
    target_xy: np.ndarray,
    target_dt: float,
    Q: np.ndarray,
    sensor: SensorModel,
) -> None:
    """The checks of :class:`Frozen`: ``uav_state`` finite (4,) with speed ``uav_state[2]``
    > 0 (the turn rate divides by it); ``uav`` a :class:`UAVParams`; ``P0``, ``Q`` finite
    symmetric positive semidefinite (4, 4); ``target_xy`` finite (T, H, 2), T, H >= 1;
    ``target_dt`` > 0; ``sensor`` a :class:`SensorModel`."""
    check_uav_state(uav_state)
    guards.instance_of("uav", uav, UAVParams)
    guards.spd_matrix("P0", P0, semi=True, size=4)
    guards.finite_array("target_xy", target_xy, shape=("T", "H", 2), nonempty=True)
    guards.real("target_dt", target_dt, lo=0.0, lo_open=True)
    guards.spd_matrix("Q", Q, semi=True, size=4)
    guards.instance_of("sensor", sensor, SensorModel)


def check_weights(weights: np.ndarray, n: int) -> np.ndarray:
    """Hypothesis weights: finite (n,), every entry >= 0, summing to 1 within 1e-9."""
    w = guards.finite_array("weights", weights, shape=(n,))
    if (w < 0).any():
        raise ValueError(f"weights must be >= 0, got min {w.min()}")
    if abs(w.sum() - 1.0) > 1e-9:
        raise ValueError(f"weights must sum to 1 (within 1e-9), got sum {w.sum()!r}")
    return w


def weight_args(weights: np.ndarray | None, n: int) -> tuple[np.ndarray, float]:
    """The kernel's (per-hypothesis factors (n,), divisor): equal weights (``None``, or all
    entries equal) give (ones, n), the arithmetic of the plain average; others (w, 1)."""
    if weights is None or n == 1:
        return np.ones(n), float(n)
    w = np.ascontiguousarray(weights, dtype=float)
    if w.size and (w == w[0]).all():
        return np.ones(n), float(n)
    return w, 1.0


def check_uav_state(uav_state: np.ndarray) -> None:
    """A UAV state ``(p_x, p_y, s, psi)``: finite (4,), speed ``s`` > 0 (the turn rate
    divides by it)."""
    state = guards.finite_array("uav_state", uav_state, shape=(4,))
    if not state[2] > 0:
        raise ValueError(
            f"uav_state[2] (speed) must be > 0 (the turn rate divides by it), got {state[2]}"
        )


class Frozen:
    """The arguments that stay fixed during one planning step (UAV state, aircraft, posterior,
    hypotheses and their weights, target model, sensor), converted once for :func:`evaluate`
    (hypotheses transposed to (H, T) coordinate arrays).

    Checked by :func:`check_frozen` unless ``check=False`` (for callers that checked them,
    e.g. :class:`rsmhp.models.uav.planner.PlanningProblem`; :func:`evaluate`, called for every
    objective evaluation, checks only the shape of ``x``)."""

    __slots__ = ("args", "horizon")

    def __init__(
        self,
        uav_state,
        uav,
        P0,
        target_xy,
        target_dt,
        Q,
        sensor,
        *,
        weights: np.ndarray | None = None,
        check: bool = True,
    ) -> None:
        if check:
            check_frozen(uav_state, uav, P0, target_xy, target_dt, Q, sensor)
            if weights is not None:
                weights = check_weights(weights, np.shape(target_xy)[0])
        txy = np.asarray(target_xy, dtype=float)
        n_t, horizon = txy.shape[0], txy.shape[1]
        wts, norm = weight_args(weights, n_t)
        cfg = np.array((*_uav_args(uav), norm, target_dt), dtype=float)
        self.horizon = horizon
        self.args = (
            np.ascontiguousarray(uav_state, dtype=float),
            cfg,
            _entries(P0),
            _constant_entries(np.asarray(Q, dtype=float).tobytes()),
            _sensor_args(sensor),
            np.ascontiguousarray(txy[:, :, 0].T),
            np.ascontiguousarray(txy[:, :, 1].T),
            np.ascontiguousarray(wts, dtype=float),
        )


# the arguments :func:`_planner_kernel` does not use in a mode (the types of the used ones)
_NO_POINT = np.empty(0)
_NO_COST = np.empty(1)
_NO_LOOP = (
    np.zeros(3, dtype=np.int64),
    np.empty((4, 4)),
    np.empty(0),
    np.empty(4),
    np.empty(4),
    np.empty(4),
    np.empty((4, 4)),
    np.empty(0),
    np.empty((0, 0)),
    np.empty((0, 16)),
    np.empty((0, 4), dtype=np.int64),
)


def evaluate(x: np.ndarray, frozen: Frozen, want_grad: bool) -> tuple[np.ndarray, np.ndarray]:
    """Costs (C,) and, if ``want_grad``, gradients (C, 2H) of ``x`` (C, 2H) (else (0, 0))."""
    x = np.ascontiguousarray(x, dtype=float)
    if x.ndim != 2:
        raise ValueError(f"x must have shape (C, 2H), got {x.shape}")
    if x.shape[1] != 2 * frozen.horizon:
        raise ValueError(f"target_xy has {frozen.horizon} steps, x has {x.shape[1] // 2}")
    n_c = x.shape[0]
    cost_out = np.empty(n_c)
    grad_out = np.empty((n_c, x.shape[1]) if want_grad else (1, x.shape[1]))
    _planner_kernel(
        _EVALUATE, x, *frozen.args, bool(want_grad), 0, 0, cost_out, grad_out, _NO_POINT, _NO_LOOP
    )
    return cost_out, (grad_out if want_grad else np.empty((0, 0)))


def minimise(
    x0: np.ndarray, frozen: Frozen, maxiter: int, maxfun: int
) -> tuple[np.ndarray, float, float, int, int, int]:
    """Minimise the frozen planning cost over the normalised box [-1, 1]^2H from ``x0`` (2H,)
    with :func:`rsmhp.core.boxqn.minimise` (scipy's L-BFGS-B budgets and tolerances), in one
    compiled call: ``(x, J(x), J(x0), iterations, evaluations, status)``."""
    x0 = np.ascontiguousarray(x0, dtype=float).ravel()
    if x0.size != 2 * frozen.horizon:
        raise ValueError(f"x0 must have 2H = {2 * frozen.horizon} entries, got {x0.size}")
    x_out = np.empty_like(x0)
    f, f0, nit, nfev, status = _planner_kernel(
        _MINIMISE, x0[None, :], *frozen.args, True, int(maxiter), int(maxfun),
        _NO_COST, np.empty((1, x0.size)), x_out, _NO_LOOP,
    )  # fmt: skip
    return x_out, float(f), float(f0), int(nit), int(nfev), int(status)


def path(x: np.ndarray, frozen: Frozen) -> np.ndarray:
    """UAV states (H, 4) after each control of the normalised sequence ``x`` (2H,): the
    compiled twin of :func:`rsmhp.models.uav.kinematics.rollout` (same operation order)."""
    guards.instance_of("frozen", frozen, Frozen)
    x = np.ascontiguousarray(x, dtype=float).ravel()
    if x.size != 2 * frozen.horizon:
        raise ValueError(f"x must have 2H = {2 * frozen.horizon} entries, got shape {np.shape(x)}")
    st, cfg = frozen.args[0], frozen.args[1]
    return _path_kernel(x, st, cfg, np.empty((x.size // 2, 4)))


def cost_and_grad(
    x: np.ndarray,
    uav_state: np.ndarray,
    uav: UAVParams,
    P0: np.ndarray,
    target_xy: np.ndarray,
    target_dt: float,
    Q: np.ndarray,
    sensor: SensorModel,
    weights: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    r"""Planner cost :math:`J` (C,) and exact gradient :math:`\nabla_x J` (C, 2H) of normalised
    control sequences ``x`` (C, 2H) from UAV state ``uav_state`` (4,), posterior ``P0`` (4, 4)
    and hypotheses ``target_xy`` (T, H, 2) with ``weights`` (T,) (``None``: equal) (m², per
    unit of normalised control)."""
    frozen = Frozen(uav_state, uav, P0, target_xy, target_dt, Q, sensor, weights=weights)
    return evaluate(_controls(x, frozen), frozen, True)


def cost(
    x: np.ndarray,
    uav_state: np.ndarray,
    uav: UAVParams,
    P0: np.ndarray,
    target_xy: np.ndarray,
    target_dt: float,
    Q: np.ndarray,
    sensor: SensorModel,
    weights: np.ndarray | None = None,
) -> np.ndarray:
    """Planner cost only (C,) (see :func:`cost_and_grad`)."""
    frozen = Frozen(uav_state, uav, P0, target_xy, target_dt, Q, sensor, weights=weights)
    return evaluate(_controls(x, frozen), frozen, False)[0]


def _controls(x: np.ndarray, frozen: Frozen) -> np.ndarray:
    """Normalised controls ``x`` (2H,) or (C, 2H), finite, as (C, 2H)."""
    n = 2 * frozen.horizon
    x = np.atleast_2d(guards.finite_array("x", x, ndim=(1, 2)))
    if x.shape[1] != n or x.shape[0] == 0:
        raise ValueError(f"x must have shape (C, 2H) = (C, {n}) with C >= 1, got {x.shape}")
    return x


def warm_up_extras() -> float:
    """Compile (or load from the cache) the module's small kernels, :func:`covariance_traces`
    and :func:`path` (:mod:`rsmhp.pipeline.warm` compiles them in another process than the
    planner kernel); returns the seconds it took."""
    import time

    t0 = time.perf_counter()
    uav = UAVParams(1.0, 9.81, 3.0, 0.7, 10.0, 35.0, 100.0)
    sensor = SensorModel(0.05, 0.1, 100.0)
    txy, eye, state = np.zeros((1, 2, 2)), np.eye(4), np.array([1.0, 0.0, 20.0, 0.0])
    covariance_traces(eye, np.zeros((1, 2, 2)), txy, 1.0, eye, sensor)
    path(np.zeros(4), Frozen(state, uav, eye, txy, 1.0, eye, sensor))
    return time.perf_counter() - t0


def warm_up() -> float:
    """Compile (or load from the cache) the planner kernel: :func:`evaluate`, :func:`minimise`
    and the compiled closed loop (one compiled function, both layouts, with the small kernels
    it calls); returns the seconds it took. :func:`covariance_traces` and :func:`path` have
    :func:`warm_up_extras`, the hypotheses and the closed-loop step their own
    (``rsmhp.models.uav.target.warm_up``, ``rsmhp.models.uav.stepper.warm_up``);
    :mod:`rsmhp.pipeline.warm` runs them all in parallel processes."""
    import time

    t0 = time.perf_counter()
    uav = UAVParams(1.0, 9.81, 3.0, 0.7, 10.0, 35.0, 100.0)
    sensor = SensorModel(0.05, 0.1, 100.0)
    txy, eye, state = np.zeros((1, 2, 2)), np.eye(4), np.array([1.0, 0.0, 20.0, 0.0])
    frozen = Frozen(state, uav, eye, txy, 1.0, eye, sensor)
    evaluate(np.zeros((1, 4)), frozen, want_grad=True)
    minimise(np.zeros(4), frozen, 1, 2)
    # the other layout, the value alone and the sensor variants run the same compiled code
    # (hypothesis count, want_grad and the variants' flags are run-time values)
    return time.perf_counter() - t0


# the compiled planning step inlines rsmhp.core.boxqn: numba's cache does not see edits there,
# and, for the closed loop, the nominal hypothesis (target) and the cycle counter (clock)
numba_cache.invalidate_if_changed(_planner_kernel, [boxqn, clock, target])
