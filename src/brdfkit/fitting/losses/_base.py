"""
What a loss is: the base class every loss of :mod:`brdfkit.fitting.losses` derives from
========================================================================================

A loss (one small class, one module) carries everything the fitting procedure needs to
know about it, so that no stage tests a loss by name:

- :meth:`Loss.value` — its value for model values *m* against target values *y*;
- :meth:`Loss.sample_mask` — the samples it is defined over (None: all of them);
- :meth:`Loss.solve` — its linear solve: the per-channel linear parameters minimising
  the L1 norm (:attr:`Loss.irls`: iteratively reweighted least squares) or the L2 norm,
  and, where the solve's residual sum gives it (:meth:`Loss.from_residual`), the loss
  at the solution;
- :attr:`Loss.exact_projection` — whether that solve minimises the loss itself, so that
  variable projection is exact (min over (shape, linear) = min over the shape of the loss
  with the linear part solved);
- :attr:`Loss.needs_albedo` — whether its value needs the model's directional albedo
  (then :meth:`Loss.albedo_nodes` says where).
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

__all__ = ["Loss"]


class Loss:
    """One fitting loss (module docstring). Subclasses set the class attributes and
    override :meth:`value` (and, where they differ, the other methods)."""

    #: Registry name (``fit(loss=...)``, ``--loss``).
    name: ClassVar[str] = ""
    #: Where the loss comes from.
    reference: ClassVar[str] = ""
    #: The linear solve minimises the weighted L1 norm (IRLS), else the L2 norm.
    irls: ClassVar[bool] = False
    #: The linear solve minimises this loss (variable projection is exact).
    exact_projection: ClassVar[bool] = False
    #: The value needs the model's and the target's albedos (``albedo_m``, ``albedo_t``).
    needs_albedo: ClassVar[bool] = False

    def value(self, m, y, w, *, mask=None, albedo_m=None, albedo_t=None) -> float:
        """The loss of cosine-weighted model values *m* (N, C) against target values *y*
        (N, C) with sample measures *w* (N,); *mask* is :meth:`sample_mask`'s, the
        albedos (T, C) are given when :attr:`needs_albedo`."""
        raise NotImplementedError

    def sample_mask(self, samples) -> np.ndarray | None:
        """Boolean (N,) of the samples the loss is defined over, or None for all."""
        return None

    def albedo_nodes(self):
        """The quadrature of the albedos the value needs
        (:func:`brdfkit.fitting.samples.albedo_nodes` output), or None."""
        return None

    def from_residual(self, total: float, w_sum: float, n_channels: int) -> float | None:
        """The loss at the linear solution from the solve's residual sum *total*
        (Σ_c Σ_j w_j |r| or r²) over samples of measure *w_sum*, or None when the value
        needs the prediction."""
        return None

    def solve(self, B, R, w, lo, hi, *, iterations: int, start, w_sum: float):
        """Per-channel linear parameters P (K, C) minimising the weighted L1
        (:attr:`irls`, at most *iterations* IRLS steps from *start*) or L2 norm of
        B·P − R, within [lo, hi], with weights *w* (0 outside :meth:`sample_mask`), and
        :meth:`from_residual` at P (:func:`brdfkit.fitting._linear.solve_channels`)."""
        from brdfkit.fitting._linear import solve_channels  # Numba: only when fitting

        P, total = solve_channels(B, R, w, lo, hi, self.irls, iterations, start)
        return P, self.from_residual(total, w_sum, R.shape[1])

    def __repr__(self) -> str:
        return f"<loss {self.name!r}>"
