"""
Compiled linear solves of a fit: box-constrained least squares and L1 by IRLS
=============================================================================

For one channel, with A (N, K) the cosine-weighted bases of the linear
parameters, r (N) the target minus the offset and w (N) the sample measures:

- :func:`box_lstsq` — argmin_p pᵀGp − 2bᵀp subject to lo ≤ p ≤ hi for small
  K, exactly: every assignment of each p_k to {free, lower, upper} (3^K
  active sets) is solved from the reduced normal equations and the feasible
  one with the least objective kept (the convex problem's minimiser satisfies
  KKT, so it is one of them);
- :func:`solve_channel` — the L2 solution (G = Aᵀ diag(w) A, b = Aᵀ diag(w) r),
  then for L1 (from ``p_start`` instead when given: the previous
  solution of a nearby shape) iteratively reweighted least squares: weights
  w_j / max(|A p − r|_j, ε), ε = 10⁻⁹ × mean |r| (bounds the weight of an
  exactly fitted sample), each step a box solve, until p changes by less than
  10⁻⁶ relative or ``iterations`` steps.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["box_lstsq", "solve_channel"]


@numba.njit(cache=True)
def _small_solve(M, v):  # pragma: no cover - compiled
    """M x = v for n ≤ 3 by Cramer's rule (LAPACK's call overhead dominates at this size);
    NaN when M is singular; np.linalg.solve above 3."""
    n = v.size
    x = np.full(n, np.nan)
    if n == 1:
        if M[0, 0] > 0.0:
            x[0] = v[0] / M[0, 0]
        return x
    if n == 2:
        det = M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0]
        if det != 0.0:
            x[0] = (v[0] * M[1, 1] - M[0, 1] * v[1]) / det
            x[1] = (M[0, 0] * v[1] - M[1, 0] * v[0]) / det
        return x
    if n == 3:
        det = (M[0, 0] * (M[1, 1] * M[2, 2] - M[1, 2] * M[2, 1])
               - M[0, 1] * (M[1, 0] * M[2, 2] - M[1, 2] * M[2, 0])
               + M[0, 2] * (M[1, 0] * M[2, 1] - M[1, 1] * M[2, 0]))
        if det != 0.0:
            for c in range(3):
                T = M.copy()
                T[:, c] = v
                x[c] = (T[0, 0] * (T[1, 1] * T[2, 2] - T[1, 2] * T[2, 1])
                        - T[0, 1] * (T[1, 0] * T[2, 2] - T[1, 2] * T[2, 0])
                        + T[0, 2] * (T[1, 0] * T[2, 1] - T[1, 1] * T[2, 0])) / det
        return x
    if abs(np.linalg.det(M)) > 0.0:
        x = np.linalg.solve(M, v)
    return x


@numba.njit(cache=True)
def box_lstsq(G, b, lo, hi):  # pragma: no cover - compiled
    K = b.size
    best = np.empty(K)
    best_val = np.inf
    found = False
    n_sets = 3 ** K
    p = np.empty(K)
    for code in range(n_sets):
        state = np.empty(K, np.int64)
        c = code
        n_free = 0
        ok = True
        for k in range(K):
            state[k] = c % 3
            c //= 3
            if state[k] == 0:
                n_free += 1
            elif state[k] == 1:
                p[k] = lo[k]
                ok &= np.isfinite(lo[k])
            else:
                p[k] = hi[k]
                ok &= np.isfinite(hi[k])
        if not ok:
            continue
        if n_free > 0:
            free = np.empty(n_free, np.int64)
            j = 0
            for k in range(K):
                if state[k] == 0:
                    free[j] = k
                    j += 1
            Af = np.empty((n_free, n_free))
            rhs = np.empty(n_free)
            for a in range(n_free):
                rhs[a] = b[free[a]]
                for k in range(K):
                    if state[k] != 0:
                        rhs[a] -= G[free[a], k] * p[k]
                for e in range(n_free):
                    Af[a, e] = G[free[a], free[e]]
            # a singular reduced system (a basis of zeros) has no unique free solution:
            # that active set is skipped (a bound assignment of the same parameter covers it)
            x = _small_solve(Af, rhs)
            if not np.all(np.isfinite(x)):
                continue
            inside = True
            for a in range(n_free):
                k = free[a]
                if x[a] < lo[k] or x[a] > hi[k]:
                    inside = False
                p[k] = x[a]
            if not inside:
                continue
        val = 0.0
        for k in range(K):
            val -= 2.0 * b[k] * p[k]
            for e in range(K):
                val += p[k] * G[k, e] * p[e]
        if val < best_val:
            best_val = val
            best[:] = p
            found = True
    if not found:  # every basis zero: nothing to fit, the lower bounds
        best[:] = lo
    return best


@numba.njit(cache=True)
def _normal(A, r, u):  # pragma: no cover - compiled
    N, K = A.shape
    G = np.zeros((K, K))
    b = np.zeros(K)
    for j in range(N):
        for k in range(K):
            a = A[j, k] * u[j]
            b[k] += a * r[j]
            for e in range(K):
                G[k, e] += a * A[j, e]
    return G, b


@numba.njit(cache=True)
def solve_channel(A, r, w, lo, hi, l1, iterations, p_start):  # pragma: no cover - compiled
    N, K = A.shape
    if l1 and p_start.size == K:  # warm start (IRLS from the previous solution of a nearby
        p = p_start.copy()        # shape): the L2 start is not needed
    else:
        G, b = _normal(A, r, w)
        p = box_lstsq(G, b, lo, hi)
        if not l1:
            return p
    mean_r = 0.0
    for j in range(N):
        mean_r += abs(r[j])
    eps = 1e-9 * max(mean_r / N, 1e-300)
    for _ in range(iterations):
        # one pass: the IRLS weight of each sample and its term of the normal equations
        G = np.zeros((K, K))
        b = np.zeros(K)
        for j in range(N):
            res = -r[j]
            for k in range(K):
                res += A[j, k] * p[k]
            u = w[j] / max(abs(res), eps)
            for k in range(K):
                a = A[j, k] * u
                b[k] += a * r[j]
                for e in range(K):
                    G[k, e] += a * A[j, e]
        q = box_lstsq(G, b, lo, hi)
        change = 0.0
        size = 0.0
        for k in range(K):
            change = max(change, abs(q[k] - p[k]))
            size = max(size, abs(q[k]))
        p = q
        if change <= 1e-6 * size:
            break
    return p
