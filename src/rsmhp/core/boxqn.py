r"""Compiled projected quasi-Newton method (L-BFGS with an active set) for :math:`[-1, 1]^n`.

Minimises a smooth :math:`f` over the box :math:`B = [-1, 1]^n` with the budgets and stopping
rules of scipy's L-BFGS-B (``maxiter`` iterations, ``maxfun`` evaluations, ``pgtol`` on the
projected gradient, ``ftol`` on the relative decrease; memory ``m`` pairs), entirely in
compiled code: the objective is a numba function ``fg(x, grad, data) -> f`` that writes
:math:`\nabla f(x)` into ``grad``, and one call of :func:`minimise` runs the whole
optimisation without returning to Python (scipy's L-BFGS-B returns to Python for every
evaluation, which is most of a small problem's cost).

Iteration k at :math:`x_k` with gradient :math:`g_k` (:math:`P` = projection onto B):

1. **Stop** if :math:`\|P(x_k - g_k) - x_k\|_\infty \le` ``pgtol`` (a KKT point of the box
   problem), or when ``maxiter`` iterations or ``maxfun`` evaluations are used.
2. **Active set** :math:`A = \{i : x_i = -1, g_i > 0\} \cup \{i : x_i = 1, g_i < 0\}`; the
   other coordinates are free. **Direction**: the first iteration (and after a reset) takes
   the projected steepest-descent step with unit metric, :math:`d = P(x - g) - x` (L-BFGS-B's
   first step on a fully boxed problem); later ones the L-BFGS direction on the free
   coordinates, :math:`d_F = -H_k g_F`, :math:`d_A = 0` (two-loop recursion over the last m
   pairs, :math:`H_0 = \gamma I`, :math:`\gamma = s^T y / y^T y` of the newest pair). Since
   :math:`H_k` is positive definite, :math:`g^T d = -g_F^T H_k g_F < 0`.
3. **Line search** along the projected path :math:`x(\alpha) = P(x + \alpha d)` from
   :math:`\alpha = 1`: accept the first :math:`\alpha` with
   :math:`f(x(\alpha)) \le f(x) + c_1 g^T (x(\alpha) - x)`, :math:`c_1 = 10^{-4}` (Armijo);
   otherwise :math:`\alpha` moves to the minimiser of the quadratic through
   :math:`f(x), g^T d, f(x(\alpha))`, safeguarded to :math:`[0.1\alpha, 0.5\alpha]`. After 20
   rejections the memory is reset and the iteration restarts from steepest descent; a second
   failure in a row stops (scipy: "abnormal termination in line search"). When the first
   trial is accepted but the slope there is still steep (:math:`g(x(\alpha))^T d > 0.9\,
   g^T d` fails: the curvature condition of a Wolfe line search), longer steps
   :math:`4\alpha`, up to the largest step inside the box, are tried while they keep
   decreasing f (scipy's line search extrapolates likewise; without it a flat region, where
   the unit-metric steepest-descent step is tiny, would be crossed in tiny steps).
4. **Update** with :math:`s = x_{k+1} - x_k`, :math:`y = g_{k+1} - g_k` when
   :math:`s^T y > \epsilon\, y^T y` (curvature; otherwise the pair is skipped), and stop if
   :math:`(f_k - f_{k+1}) \le \mathrm{ftol} \cdot \max(|f_k|, |f_{k+1}|, 1)`.

Every accepted step decreases :math:`f`, so the result is never worse than the start. This is
not L-BFGS-B's algorithm (no generalised Cauchy point or subspace minimisation over the
compact quasi-Newton matrix): the two find the same minimiser on convex problems (tested),
and on the planner's non-convex costs their final costs are compared on belief states of
both sensor models by ``benchmarks/optimiser_quality.py``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["FTOL", "MEMORY", "PGTOL", "STATUS", "minimise"]

#: scipy's L-BFGS-B defaults: ``factr`` 1e7 times machine epsilon, ``pgtol`` 1e-5, m = 10
FTOL = 1e7 * np.finfo(float).eps
PGTOL = 1e-5
MEMORY = 10
C1 = 1e-4
CURVATURE = 0.9
MAX_BACKTRACK = 20

#: the ``status`` returned by :func:`minimise`
STATUS = {
    0: "projected gradient below pgtol",
    1: "relative decrease below ftol",
    2: "iteration limit",
    3: "evaluation limit",
    4: "line search failed twice",
}


@njit(cache=True, nogil=True, error_model="numpy")
def _proj_grad_norm(x, g):  # pragma: no cover - compiled
    out = 0.0
    for i in range(x.size):
        v = min(max(x[i] - g[i], -1.0), 1.0) - x[i]
        out = max(out, abs(v))
    return out


@njit(cache=True, nogil=True, error_model="numpy")
def _trial(x, d, a, g, out):  # pragma: no cover - compiled
    """The projected trial point P(x + a d) into ``out``; returns g^T (out - x), the
    first-order decrease of the Armijo test."""
    decrease = 0.0
    for i in range(x.size):
        out[i] = min(max(x[i] + a * d[i], -1.0), 1.0)
        decrease += g[i] * (out[i] - x[i])
    return decrease


@njit(cache=True, nogil=True, error_model="numpy")
def _max_step(x, d):  # pragma: no cover - compiled
    """The largest alpha with x + alpha d in the box (inf if d = 0)."""
    out = np.inf
    for i in range(x.size):
        if d[i] > 0.0:
            out = min(out, (1.0 - x[i]) / d[i])
        elif d[i] < 0.0:
            out = min(out, (-1.0 - x[i]) / d[i])
    return out


@njit(cache=True, nogil=True, error_model="numpy")
def _direction(x, g, S, Y, rho, n_mem, newest, steepest, d, q, alpha):  # pragma: no cover
    """Search direction into ``d`` (see the module docstring, step 2); returns g^T d."""
    n = x.size
    m = S.shape[0]
    if steepest:
        gd = 0.0
        for i in range(n):
            d[i] = min(max(x[i] - g[i], -1.0), 1.0) - x[i]
            gd += g[i] * d[i]
        return gd
    free = np.empty(n)
    for i in range(n):
        active = (x[i] <= -1.0 and g[i] > 0.0) or (x[i] >= 1.0 and g[i] < 0.0)
        free[i] = 0.0 if active else 1.0
        q[i] = free[i] * g[i]
    # two-loop recursion on the free coordinates (pairs restricted to them; a pair without
    # positive curvature there is skipped), newest pair first
    gamma = 0.0
    for t in range(n_mem):
        k = (newest - t) % m
        sy = 0.0
        yy = 0.0
        a = 0.0
        for i in range(n):
            sy += free[i] * S[k, i] * Y[k, i]
            yy += free[i] * Y[k, i] * Y[k, i]
            a += S[k, i] * q[i]
        if not sy > np.finfo(np.float64).eps * yy:
            rho[k] = 0.0
            alpha[k] = 0.0
            continue
        rho[k] = 1.0 / sy
        if gamma == 0.0:
            gamma = sy / yy
        a *= rho[k]
        alpha[k] = a
        for i in range(n):
            q[i] -= a * free[i] * Y[k, i]
    if gamma == 0.0:
        gamma = 1.0
    for i in range(n):
        q[i] *= gamma
    for t in range(n_mem - 1, -1, -1):
        k = (newest - t) % m
        if rho[k] == 0.0:
            continue
        b = 0.0
        for i in range(n):
            b += free[i] * Y[k, i] * q[i]
        b *= rho[k]
        for i in range(n):
            q[i] += free[i] * S[k, i] * (alpha[k] - b)
    gd = 0.0
    for i in range(n):
        active = (x[i] <= -1.0 and g[i] > 0.0) or (x[i] >= 1.0 and g[i] < 0.0)
        d[i] = 0.0 if active else -q[i]
        gd += g[i] * d[i]
    return gd


@njit(inline="always", error_model="numpy")
def minimise(fg, data, x0, maxiter, maxfun, m, pgtol, ftol, x_out):  # pragma: no cover
    """Minimise ``fg`` over [-1, 1]^n from ``x0`` (n,) (clipped into the box).

    ``fg(x, grad, data) -> f`` is a numba function writing the gradient into ``grad``;
    ``data`` is passed through. Writes the final point to ``x_out`` (n,) and returns
    ``(f_final, f_start, nit, nfev, status)`` (status: :data:`STATUS`). ``f_final <=
    f_start`` always; ``nfev`` counts every evaluation, the start's included."""
    n = x0.size
    x = np.empty(n)
    for i in range(n):
        x[i] = min(max(x0[i], -1.0), 1.0)
    g = np.empty(n)
    xt = np.empty(n)
    gt = np.empty(n)
    x2 = np.empty(n)
    g2 = np.empty(n)
    d = np.empty(n)
    q = np.empty(n)
    S = np.zeros((m, n))
    Y = np.zeros((m, n))
    rho = np.zeros(m)
    alpha = np.zeros(m)
    f = fg(x, g, data)
    f_start = f
    nfev = 1
    nit = 0
    n_mem = 0
    newest = m - 1
    steepest = True
    failed_once = False
    status = 2
    while True:
        if _proj_grad_norm(x, g) <= pgtol:
            status = 0
            break
        if nit >= maxiter:
            status = 2
            break
        if nfev >= maxfun:
            status = 3
            break
        gd = _direction(x, g, S, Y, rho, n_mem, newest, steepest, d, q, alpha)
        if not gd < 0.0:  # no descent (rounding): restart from steepest descent or stop
            if steepest:
                status = 0
                break
            steepest = True
            n_mem = 0
            continue
        # ---- Armijo backtracking along the projected path
        a = 1.0
        accepted = False
        ft = f
        for _ in range(MAX_BACKTRACK):
            decrease = _trial(x, d, a, g, xt)
            ft = fg(xt, gt, data)
            nfev += 1
            if ft <= f + C1 * decrease:
                accepted = True
                break
            if nfev >= maxfun:
                break
            denom = 2.0 * (ft - f - a * gd)
            a_q = -gd * a * a / denom if denom > 0.0 else 0.5 * a
            a = min(max(a_q, 0.1 * a), 0.5 * a)
        # ---- extrapolation: the first trial was accepted but the slope along d is still
        # steep (curvature condition g(x_t)^T d <= 0.9 g^T d fails) and the box allows a
        # longer step: try 4x longer steps up to the box, while they keep decreasing f
        if accepted and a == 1.0:
            a_max = _max_step(x, d)
            while nfev < maxfun and a < a_max:
                slope = 0.0
                for i in range(n):
                    slope += gt[i] * d[i]
                if slope >= CURVATURE * gd:
                    break
                a2 = min(4.0 * a, a_max)
                decrease = _trial(x, d, a2, g, x2)
                f2 = fg(x2, g2, data)
                nfev += 1
                if not (f2 < ft and f2 <= f + C1 * decrease):
                    break
                a = a2
                ft = f2
                for i in range(n):
                    xt[i] = x2[i]
                    gt[i] = g2[i]
        if not accepted:
            if nfev >= maxfun:
                status = 3
                break
            if failed_once or steepest:
                status = 4
                break
            failed_once = True
            steepest = True
            n_mem = 0
            continue
        failed_once = False
        # ---- curvature pair and the ftol test
        sy = 0.0
        yy = 0.0
        for i in range(n):
            si = xt[i] - x[i]
            yi = gt[i] - g[i]
            sy += si * yi
            yy += yi * yi
        if sy > np.finfo(np.float64).eps * yy:
            newest = (newest + 1) % m
            for i in range(n):
                S[newest, i] = xt[i] - x[i]
                Y[newest, i] = gt[i] - g[i]
            n_mem = min(n_mem + 1, m)
        f_old = f
        f = ft
        for i in range(n):
            x[i] = xt[i]
            g[i] = gt[i]
        nit += 1
        steepest = n_mem == 0
        if f_old - f <= ftol * max(abs(f_old), abs(f), 1.0):
            status = 1
            break
    for i in range(n):
        x_out[i] = x[i]
    return f, f_start, nit, nfev, status
