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

References
----------
- J. A. Nelder, R. Mead, *A simplex method for function minimization*, The
  Computer Journal 7(4), 1965.
- F. Gao, L. Han, *Implementing the Nelder-Mead simplex algorithm with adaptive
  parameters*, Computational Optimization and Applications 51(1), 2012.
"""

from __future__ import annotations

import numpy as np

__all__ = ["nelder_mead"]


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
