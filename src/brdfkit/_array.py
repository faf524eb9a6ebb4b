"""Tiny helpers that fix the array-shape convention once.

Directions are float64 arrays of shape ``(..., 3)``; the helpers here validate
them at the public boundary and give names to the components so that the
formulas elsewhere read like the papers.
"""

from __future__ import annotations

import numpy as np

from brdfkit.errors import BrdfkitError


def _as_float64(v, name: str, shape_text: str) -> np.ndarray:
    """*v* as float64, or a :class:`BrdfkitError` naming *name* (never a raw NumPy error).

    Rejected: strings and bytes (also inside lists: NumPy would parse ``"1"``
    as 1.0), complex numbers (the imaginary part would be dropped), ragged
    nested lists, and anything else NumPy cannot convert to float64.
    """
    if type(v) is np.ndarray and v.dtype == np.float64:
        return v  # the hot path (every eval): no conversion, no copy
    if isinstance(v, str | bytes):
        raise BrdfkitError(f"{name} must be numbers of shape {shape_text}; got the string {v!r}")
    try:
        a = np.asarray(v)
    except (ValueError, TypeError):  # ragged nested lists: NumPy >= 1.24 refuses them
        raise BrdfkitError(
            f"{name} must be a rectangular array of shape {shape_text}; got a ragged "
            f"{type(v).__name__} (rows of different lengths)"
        ) from None
    kind = a.dtype.kind
    if kind in "biuf":  # bool, signed/unsigned integer, float: exact or widening to float64
        return a.astype(np.float64, copy=False)
    if kind in "USa":
        raise BrdfkitError(f"{name} must be numbers of shape {shape_text}; got strings "
                           f"(e.g. {str(a.flat[0])!r}); convert them with float() first")
    if kind == "c":
        raise BrdfkitError(f"{name} must be real numbers of shape {shape_text}; got complex "
                           f"values (dtype {a.dtype})")
    try:  # object arrays: Decimal, Fraction, None, mixed ... convert element by element
        return a.astype(np.float64)
    except (ValueError, TypeError):
        raise BrdfkitError(f"{name} must be numbers of shape {shape_text}; got a non-numeric "
                           f"{type(v).__name__}: {v!r:.60}") from None


def as_directions(v, name: str, *, check_finite: bool = True) -> np.ndarray:
    """Return *v* as a float64 array of shape ``(..., 3)``; never mutates *v*.

    ``check_finite=False`` skips the finiteness test, for callers that do it
    themselves in the same pass as their computation (:meth:`BRDF.eval`).

    Raises
    ------
    BrdfkitError
        If *v* is not numeric (strings, complex, ragged lists, other objects),
        the last axis is not of length 3, or a component is not finite. The
        message names the argument *name*.
    """
    a = _as_float64(v, name, "(..., 3)")
    if a.ndim == 0 or a.shape[-1] != 3:
        raise BrdfkitError(
            f"{name} must be an array of unit vectors of shape (..., 3); got shape {a.shape}"
        )
    if check_finite and not np.all(np.isfinite(a)):
        raise BrdfkitError(f"{name} contains NaN or infinite components")
    return a


def as_uniform(u, name: str = "u", dim: int = 2) -> np.ndarray:
    """Return *u* as float64 of shape ``(..., dim)`` with entries in [0, 1]."""
    a = _as_float64(u, name, f"(..., {dim})")
    if a.ndim == 0 or a.shape[-1] != dim:
        raise BrdfkitError(f"{name} must have shape (..., {dim}); got shape {a.shape}")
    if np.any(~(a >= 0.0) | ~(a <= 1.0)):
        bad = a[~((a >= 0.0) & (a <= 1.0))].flat[0]
        raise BrdfkitError(f"{name} must lie in [0, 1]; got {bad!r}")
    return a


def xyz(v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The three components of direction array *v* (views, not copies)."""
    return v[..., 0], v[..., 1], v[..., 2]


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Dot product over the last axis, broadcasting the leading axes."""
    return np.einsum("...k,...k->...", a, b) if a.shape == b.shape else np.sum(a * b, axis=-1)


def stack(x, y, z) -> np.ndarray:
    """Stack three broadcastable component arrays into ``(..., 3)``."""
    x, y, z = np.broadcast_arrays(x, y, z)
    return np.stack([x, y, z], axis=-1)
