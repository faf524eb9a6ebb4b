"""
The proxy sampler on NumPy arrays
=================================

The proxy mixture of :mod:`brdfkit.models.proxy_sampler` (w_c · cos⁺θ_i/π +
(1 − w_c) · GGX half-vector sampling, its α from the model's sharpest lobe; the formulas
and the measurement behind w_c are there) as a :class:`~brdfkit.models.sampling.Strategy`,
run through the generated sampler loops of :mod:`brdfkit.user._loops` (for
``StrategySampled`` models and the χ² tests of :mod:`brdfkit.analysis.chi2`). The
formulas are re-exported here, where the user's models first took them from.

Public objects
--------------
- :class:`ProxyStrategy` — the proxy on NumPy arrays.
- :func:`proxy_formulas`, :func:`proxy_args`, :func:`proxy_sample`, :func:`proxy_pdf`,
  :data:`COSINE_WEIGHT`, :data:`ALPHA_MIN` — of :mod:`brdfkit.models.proxy_sampler`.
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit.errors import ParameterError
from brdfkit.models.proxy_sampler import (
    ALPHA_MIN,
    COSINE_WEIGHT,
    proxy_args,
    proxy_formulas,
    proxy_pdf,
    proxy_sample,
)
from brdfkit.models.sampling import Strategy
from brdfkit.user._loops import sampler_loops
from brdfkit.user.model import SamplerFormulas

__all__ = ["proxy_formulas", "proxy_args", "proxy_sample", "proxy_pdf", "ProxyStrategy",
           "COSINE_WEIGHT", "ALPHA_MIN"]


# --------------------------------------------------------------------------- NumPy access
#: The proxy as a sampler of the generated loops that run a user's own sampler
#: (:func:`brdfkit.user._loops.sampler_loops`); its arguments are a strategy's (α, w_c),
#: not read from a model's values.
_PROXY = SamplerFormulas(sample=proxy_sample, pdf=proxy_pdf, args=lambda values: ())


def _rows(a: np.ndarray, shape: tuple, k: int) -> np.ndarray:
    return np.ascontiguousarray(np.broadcast_to(a, shape + (k,)).reshape(-1, k),
                                dtype=np.float64)


class ProxyStrategy(Strategy):
    """:func:`proxy_sample`/:func:`proxy_pdf` on NumPy arrays (a
    :class:`~brdfkit.models.sampling.Strategy`: validated, broadcastable inputs).

    Parameters
    ----------
    alpha : float
        GGX α of the half-vector component, > 0.
    w_c : float
        Weight of the cosine component, in (0, 1].
    """

    def __init__(self, alpha: float, w_c: float = COSINE_WEIGHT):
        if not (math.isfinite(float(alpha)) and float(alpha) > 0.0):
            raise ParameterError(f"ProxyStrategy: alpha must be a finite number > 0; got "
                                 f"{alpha!r}")
        if not 0.0 < float(w_c) <= 1.0:
            raise ParameterError(f"ProxyStrategy: w_c must lie in (0, 1]; got {w_c!r}")
        self.alpha, self.w_c = float(alpha), float(w_c)

    @classmethod
    def of(cls, model) -> ProxyStrategy:
        """The proxy of *model* (:func:`proxy_args`)."""
        return cls(*proxy_args(model))

    def sample(self, wo, u):
        shape = np.broadcast_shapes(wo.shape[:-1], u.shape[:-1])
        w, uu = _rows(wo, shape, 3), _rows(u, shape, 2)
        wi, density = np.empty_like(w), np.empty(w.shape[0])
        draw, _ = sampler_loops(_PROXY, 2)
        draw(w, uu, np.array([self.alpha, self.w_c]), wi, density)
        return wi.reshape(shape + (3,))

    def pdf(self, wi, wo):
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        out = np.empty(int(np.prod(shape)))
        _, density = sampler_loops(_PROXY, 2)
        density(_rows(wi, shape, 3), _rows(wo, shape, 3), np.array([self.alpha, self.w_c]), out)
        return out.reshape(shape)

    def __repr__(self) -> str:
        return f"ProxyStrategy(alpha={self.alpha:g}, w_c={self.w_c:g})"
