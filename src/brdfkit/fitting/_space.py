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
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Coord", "LOG_FLOOR", "BOUND_TOL", "Z_MAX"]

#: Stands for a lower bound of 0 in the log reparametrisation.
LOG_FLOOR = 1e-6
#: A coordinate is "at a bound" when σ(z) is within this of 0 or 1 (log: of L₀/L₁).
BOUND_TOL = 1e-6
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


def as_vector(values: dict, coords) -> np.ndarray:
    """z of each coordinate for parameter *values*."""
    out = np.empty(len(coords))
    for k, c in enumerate(coords):
        v = values[c.name]
        out[k] = c.to_z(float(v if c.index is None else np.asarray(v)[c.index]))
    return out


def from_vector(z, coords, base: dict) -> dict:
    """Parameter values: *base* with the coordinates set from *z* (arrays copied)."""
    out = {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in base.items()}
    for zk, c in zip(z, coords, strict=True):
        x = c.to_x(float(zk))
        if c.index is None:
            out[c.name] = x
        else:
            out[c.name][c.index] = x
    return out
