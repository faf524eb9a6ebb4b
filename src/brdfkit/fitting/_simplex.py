"""
The Nelder–Mead simplex search of the fitting procedure
=======================================================

:func:`nelder_mead` minimises a function of a few variables from a given
initial simplex: reflection, expansion, outside and inside contraction and
shrink (Nelder & Mead 1965), with the dimension-dependent coefficients of Gao
& Han (2012) when ``adaptive`` (ρ = 1, χ = 1 + 2/n, ψ = 3/4 − 1/(2n),
σ = 1 − 1/n; else 1, 2, 1/2, 1/2). It stops when the values at the vertices
agree to ``fatol`` or after ``maxfev`` evaluations.

The steps, their order and their arithmetic are those of SciPy's
``minimize(method="Nelder-Mead")`` with ``xatol=inf`` (which the procedure used
before): the same evaluations in the same order, so the same result —
``tests/test_fitting.py`` checks it against SciPy on Rosenbrock's function. It
is here, 60 lines, because importing :mod:`scipy.optimize` costs ~0.5 s, a
quarter of a one-line ``brdfkit fit``.

:func:`search_simplex` is the procedure's use of it: a run from a point with given
steps, stopped also when it stalls, its stop checked by one restart.

References
----------
- J. A. Nelder, R. Mead, *A simplex method for function minimization*, The
  Computer Journal 7(4), 1965.
- F. Gao, L. Han, *Implementing the Nelder-Mead simplex algorithm with adaptive
  parameters*, Computational Optimization and Applications 51(1), 2012.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["nelder_mead", "search_simplex", "NM_RESTARTS", "STALL_EVALS"]

#: Restarts of a Nelder–Mead run from its best point (see search_simplex).
NM_RESTARTS = 1
#: A Nelder–Mead run stops after this many evaluations per coordinate without a
#: significant improvement (see search_simplex).
STALL_EVALS = 10


class _Budget(Exception):
    """The evaluation budget is spent (raised by the counting wrapper)."""


def nelder_mead(fun, simplex, *, maxfev: int, fatol: float, adaptive: bool = False):
    """Minimise *fun* from *simplex* (n + 1, n). Returns (best vertex, its value,
    evaluations). *fun* receives a copy of each point; evaluations past *maxfev* are
    not made."""
    sim = np.array(simplex, dtype=np.float64)
    n = sim.shape[1]
    if adaptive:
        rho, chi, psi, sigma = 1.0, 1.0 + 2.0 / n, 0.75 - 1.0 / (2.0 * n), 1.0 - 1.0 / n
    else:
        rho, chi, psi, sigma = 1.0, 2.0, 0.5, 0.5
    calls = [0]

    def f(x):
        if calls[0] >= maxfev:
            raise _Budget
        calls[0] += 1
        return float(fun(np.copy(x)))

    fsim = np.full(n + 1, np.inf)
    try:
        for k in range(n + 1):
            fsim[k] = f(sim[k])
    except _Budget:
        pass
    order = np.argsort(fsim)
    sim, fsim = np.take(sim, order, 0), np.take(fsim, order, 0)
    while calls[0] < maxfev:
        try:
            # a vertex value of inf (a refused point) gives inf − inf = NaN: not a stop
            if np.max(np.abs(fsim[0] - fsim[1:])) <= fatol:
                break
            xbar = np.add.reduce(sim[:-1], 0) / n
            xr = (1 + rho) * xbar - rho * sim[-1]
            fxr = f(xr)
            if fxr < fsim[0]:  # expand
                xe = (1 + rho * chi) * xbar - rho * chi * sim[-1]
                fxe = f(xe)
                sim[-1], fsim[-1] = (xe, fxe) if fxe < fxr else (xr, fxr)
            elif fxr < fsim[-2]:  # accept the reflection
                sim[-1], fsim[-1] = xr, fxr
            else:
                shrink = False
                if fxr < fsim[-1]:  # outside contraction
                    xc = (1 + psi * rho) * xbar - psi * rho * sim[-1]
                    fxc = f(xc)
                    if fxc <= fxr:
                        sim[-1], fsim[-1] = xc, fxc
                    else:
                        shrink = True
                else:  # inside contraction
                    xcc = (1 - psi) * xbar + psi * sim[-1]
                    fxcc = f(xcc)
                    if fxcc < fsim[-1]:
                        sim[-1], fsim[-1] = xcc, fxcc
                    else:
                        shrink = True
                if shrink:
                    for j in range(1, n + 1):
                        sim[j] = sim[0] + sigma * (sim[j] - sim[0])
                        fsim[j] = f(sim[j])
        except _Budget:
            pass
        order = np.argsort(fsim)
        sim, fsim = np.take(sim, order, 0), np.take(fsim, order, 0)
    return sim[0], float(np.min(fsim)), calls[0]


class _Stalled(Exception):
    """Raised inside a Nelder–Mead run to stop it (see search_simplex)."""


def search_simplex(fun, z0, steps, maxfev, scale, fatol):
    """Nelder–Mead from z0 with an initial simplex of the given steps; the loss is
    divided by *scale* (a loss near the optimum: a change below *fatol* of it is
    negligible, also where the loss tends to 0 on exact data).

    A run stops when the losses at the simplex's vertices agree to *fatol*, or when
    :data:`STALL_EVALS` × n evaluations in a row have not lowered the best loss by more
    than *fatol* (stalled: crawling along a flat valley, e.g. Lafortune's common scale of
    C_xy, C_z against ρ_s, or towards a bound approached only asymptotically in z; the
    bound is then reported by _flat_to_bound). The stop is checked by restarting once from
    the best point with a fresh simplex of half the steps (the standard remedy for a
    collapsed simplex: along a curved valley, e.g. Nielsen's s against α, the simplex can
    flatten and stop short). *maxfev* evaluations in all. Returns (z, value,
    n_evaluations, hit_limit)."""
    z = np.asarray(z0, dtype=np.float64)
    n = z.size
    st = {"n": 0, "best": math.inf, "z": z, "ref": math.inf, "since": 0}

    def f(x):
        v = fun(x) / scale
        st["n"] += 1
        if v < st["best"]:
            st["best"], st["z"] = v, np.array(x, dtype=np.float64)
        if v < st["ref"] - fatol:  # a significant improvement
            st["ref"], st["since"] = v, 0
        else:
            st["since"] += 1
            if st["since"] >= STALL_EVALS * n:
                raise _Stalled
        return v

    for run in range(1 + NM_RESTARTS):
        before = st["best"]
        st["ref"], st["since"] = st["best"], 0
        h = np.asarray(steps, dtype=np.float64) * (0.5 if run else 1.0)
        zs = st["z"]
        simplex = np.vstack([zs] + [zs + np.eye(n)[k] * h[k] for k in range(n)])
        try:
            with np.errstate(invalid="ignore"):  # inf − inf at refused vertices: not a stop
                nelder_mead(f, simplex, maxfev=maxfev - st["n"], fatol=fatol, adaptive=n > 2)
        except _Stalled:
            pass
        if before - st["best"] <= fatol or st["n"] >= maxfev:
            break
    return st["z"], st["best"] * scale, st["n"], st["n"] >= maxfev
