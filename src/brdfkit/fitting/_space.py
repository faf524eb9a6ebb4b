"""
The parameter space of a fit: free coordinates and their bounded reparametrisation
===================================================================================

Each free scalar (a scalar parameter, one channel of a colour parameter, one
lobe of a per-lobe parameter) is optimised as an unbounded coordinate z:

- ``log`` (exponents, roughnesses, unbounded scales: lower ≥ 0 and an upper
  bound at least 10³ × the lower one, or none): ln x = L₀ + (L₁ − L₀)·σ(z)
  with L₀ = ln max(lower, x_floor), L₁ = ln upper (x = exp(z) when upper is
  infinite); x_floor = :data:`LOG_FLOOR` stands for a lower bound of 0 (a log
  cannot reach it; 10⁻⁶ of an exponent or a scale is 0 for every purpose);
- ``logit`` (mixes and other finite ranges): x = lower + (upper − lower)·σ(z);
- ``identity`` (no finite bounds): x = z.

σ is the logistic function. So every z gives a valid parameter and the bounds
are approached, never crossed: a coordinate at a bound shows as |z| large,
reported by :meth:`Coord.at_bound`.

A fit's parameters live in one form, a dict of parameter values (per-channel and
per-lobe values as arrays); :class:`ParameterSpace` is the one object that reads a
coordinate from it (:meth:`ParameterSpace.x`), maps coordinates to z and back
(:meth:`ParameterSpace.z`, :meth:`ParameterSpace.point`) and knows which coordinates are
free: every declared parameter but choices, bools, optional ones that are None and fixed ones
(:meth:`ParameterSpace.of_model`), less those a fit holds (gauges of
``BRDF.fit_gauge``, inert ones, a scale a pumped model does not see:
:meth:`ParameterSpace.hold`).

Public objects
--------------
- :class:`Coord` — one free scalar and its transform.
- :class:`ParameterSpace` — the free coordinates of a fit.
- :data:`LOG_FLOOR`, :data:`BOUND_TOL`, :data:`Z_MAX`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Coord", "ParameterSpace", "LOG_FLOOR", "BOUND_TOL", "BOUND_LOSS_RTOL", "Z_MAX"]

#: Stands for a lower bound of 0 in the log reparametrisation.
LOG_FLOOR = 1e-6
#: A coordinate is "at a bound" when σ(z) is within this of 0 or 1 (log: of L₀/L₁).
BOUND_TOL = 1e-6
#: A coordinate whose move to its bound changes the final loss by less than this relative
#: amount is reported at that bound (the data cannot tell it from the bound); one the loss
#: cannot tell from either bound is reported inert (FitRun.flat_to_bound).
BOUND_LOSS_RTOL = 1e-4
#: σ(±30) = 1 − 9e-14: z is clipped there (the bound to double precision).
Z_MAX = 30.0
_Z_MAX = Z_MAX


def _sigmoid(z):
    z = min(max(z, -_Z_MAX), _Z_MAX)  # clip: beyond ±30 σ is 0 or 1 to double precision
    return 1.0 / (1.0 + math.exp(-z))


def _logit(s):
    s = min(max(s, 1e-12), 1.0 - 1e-12)  # keep the start strictly inside the bounds
    return math.log(s / (1.0 - s))


@dataclass(frozen=True)
class Coord:
    """One free scalar of a fit.

    Attributes
    ----------
    name : str
        The parameter.
    index : int or None
        Channel (colour) or lobe (lobes) index; None for a scalar.
    lower, upper : float
        The declared bounds.
    transform : {"log", "logit", "identity"}
    """

    name: str
    index: int | None
    lower: float
    upper: float
    transform: str

    @classmethod
    def for_param(cls, p, index=None) -> Coord:
        lo, hi = float(p.lower), float(p.upper)
        if lo >= 0.0 and (math.isinf(hi) or (hi > 1.0 and hi / max(lo, LOG_FLOOR) >= 1e3)):
            t = "log"
        elif math.isfinite(lo) and math.isfinite(hi):
            t = "logit"
        else:
            t = "identity"
        return cls(p.name, index, lo, hi, t)

    @property
    def label(self) -> str:
        return self.name if self.index is None else f"{self.name}[{self.index}]"

    def _log_range(self):
        return math.log(max(self.lower, LOG_FLOOR)), math.log(self.upper)

    def to_x(self, z: float) -> float:
        if self.transform == "log":
            if math.isinf(self.upper):
                return max(self.lower, math.exp(min(z, 700.0)))  # 700: exp overflows at 709
            l0, l1 = self._log_range()
            return math.exp(l0 + (l1 - l0) * _sigmoid(z))
        if self.transform == "logit":
            return self.lower + (self.upper - self.lower) * _sigmoid(z)
        return z

    def to_z(self, x: float) -> float:
        if self.transform == "log":
            lx = math.log(max(x, self.lower, LOG_FLOOR))
            if math.isinf(self.upper):
                return lx
            l0, l1 = self._log_range()
            return _logit((lx - l0) / (l1 - l0))
        if self.transform == "logit":
            return _logit((x - self.lower) / (self.upper - self.lower))
        return float(x)

    def at_bound(self, x: float) -> str | None:
        """"lower"/"upper" when *x* sits at a bound (within :data:`BOUND_TOL`), else None."""
        if self.transform == "log":
            l0 = math.log(max(self.lower, LOG_FLOOR))
            if math.log(max(x, LOG_FLOOR)) - l0 <= BOUND_TOL * max(1.0, abs(l0)):
                return "lower"
            if math.isfinite(self.upper) and math.log(self.upper) - math.log(x) <= BOUND_TOL:
                return "upper"
            return None
        if self.transform == "logit":
            s = (x - self.lower) / (self.upper - self.lower)
            return "lower" if s <= BOUND_TOL else "upper" if s >= 1.0 - BOUND_TOL else None
        return None

    def step(self, x: float) -> float:
        """Initial simplex step in z: ~20 % of x for log, ~5 % of the range (or of |x|)
        for logit."""
        if self.transform == "log":
            l0, l1 = (self._log_range() if math.isfinite(self.upper) else (0.0, 1.0))
            if math.isinf(self.upper):
                return 0.2
            s = (math.log(max(x, LOG_FLOOR)) - l0) / (l1 - l0)
            s = min(max(s, 0.01), 0.99)  # keep the derivative of σ away from 0
            return 0.2 / ((l1 - l0) * s * (1.0 - s))
        if self.transform == "logit":
            span = self.upper - self.lower
            s = min(max((x - self.lower) / span, 0.01), 0.99)  # as above
            dx = 0.05 * span if span <= 10.0 else 0.2 * max(abs(x), 0.1)
            return dx / (span * s * (1.0 - s))
        return 0.2 * max(abs(x), 0.1)


class ParameterSpace:
    """The free coordinates of a fit (module docstring).

    Attributes
    ----------
    coords : list of Coord
        The coordinates free now (the methods' *coords* default to them).
    """

    def __init__(self, coords):
        self.coords = list(coords)

    @classmethod
    def of_model(cls, model, fixed: dict, n_channels: int) -> tuple[ParameterSpace, dict]:
        """The space of every free scalar of *model* and the values to start from: its
        own, colour parameters broadcast to *n_channels*, lobe ones to its lobes, *fixed*
        set."""
        C = n_channels
        values = model.values
        coords = []
        for p in model.params:
            v = values[p.name]
            if p.kind in ("choice", "bool") or p.name in fixed or (p.optional and v is None):
                continue
            if p.kind == "colour":
                arr = np.broadcast_to(np.atleast_1d(np.asarray(v, dtype=np.float64)),
                                      (C,)).copy()
                values[p.name] = arr if C > 1 else float(arr[0])
                coords += [Coord.for_param(p, c if C > 1 else None) for c in range(C)]
            elif p.kind == "lobes":
                arr = np.broadcast_to(np.atleast_1d(np.asarray(v, dtype=np.float64)),
                                      (model.n_lobes(),)).copy()
                values[p.name] = arr
                coords += [Coord.for_param(p, k) for k in range(arr.size)]
            else:
                coords.append(Coord.for_param(p))
        values.update(fixed)
        return cls(coords), values

    # ------------------------------------------------------------------ reading
    @staticmethod
    def x(values: dict, c: Coord) -> float:
        """The value of coordinate *c* in parameter *values*."""
        v = values[c.name]
        return float(v if c.index is None else np.asarray(v)[c.index])

    def z(self, values: dict, coords=None) -> np.ndarray:
        """z of each coordinate for parameter *values*."""
        coords = self.coords if coords is None else coords
        out = np.empty(len(coords))
        for k, c in enumerate(coords):
            out[k] = c.to_z(self.x(values, c))
        return out

    @staticmethod
    def point(z, coords, base: dict) -> dict:
        """Parameter values: *base* with the coordinates *coords* set from *z* (arrays
        copied)."""
        out = {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in base.items()}
        for zk, c in zip(z, coords, strict=True):
            x = c.to_x(float(zk))
            if c.index is None:
                out[c.name] = x
            else:
                out[c.name][c.index] = x
        return out

    def steps(self, values: dict, coords=None) -> np.ndarray:
        """The initial simplex steps in z (:meth:`Coord.step`) at *values*."""
        coords = self.coords if coords is None else coords
        return np.array([c.step(self.x(values, c)) for c in coords])

    def labels(self, coords=None) -> list[str]:
        return [c.label for c in (self.coords if coords is None else coords)]

    def names(self, coords=None) -> list[str]:
        """The parameter names of the coordinates, each once, in order."""
        return list(dict.fromkeys(c.name for c in (self.coords if coords is None
                                                   else coords)))

    def at_bounds(self, values: dict) -> list[str]:
        """Labels of the free coordinates at a bound (:meth:`Coord.at_bound`)."""
        return [c.label for c in self.coords if c.at_bound(self.x(values, c))]

    def jsonable(self, values: dict) -> dict:
        """The free parameters of *values*, JSON-ready (lists for arrays)."""
        names = {c.name for c in self.coords}
        return {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                for k, v in values.items() if k in names}

    # ------------------------------------------------------------------ holding
    def hold(self, held) -> None:
        """Hold the coordinates *held* (an iterable of Coord): no longer free."""
        held = list(held)
        self.coords = [c for c in self.coords if c not in held]

    def gauges(self, model, values: dict) -> list[Coord]:
        """The free coordinates that are a gauge freedom of *model* (``BRDF.fit_gauge``)
        and not 0 at *values* (at 0 the other coordinates no longer absorb it)."""
        return [c for c in self.coords
                if c.label in model.fit_gauge and self.x(values, c) != 0.0]
