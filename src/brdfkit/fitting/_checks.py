"""Validation of :func:`brdfkit.fitting.fit`'s arguments at the public boundary.

Each check names the argument, the allowed values and the value received, so that a
wrong argument is a :class:`~brdfkit.errors.ParameterError` (one line on the command
line), never a NumPy or Python error from deep inside the fit.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from brdfkit.errors import ParameterError
from brdfkit.fitting.samples import merl_samples

__all__ = ["check_fit_args", "check_channels", "check_samples"]


def _is_int(value) -> bool:
    return isinstance(value, int | np.integer) and not isinstance(value, bool | np.bool_)


def check_fit_args(*, fixed, theta_max, seed, strides, max_evals, progress) -> tuple:
    """The checked ``(fixed, theta_max, strides)``; raise naming the first bad argument."""
    if not (_is_int(seed) and seed >= 0):
        raise ParameterError(f"fit: seed must be an integer >= 0 (it seeds NumPy's random "
                             f"starts); got {seed!r}")
    if not (_is_int(max_evals) and max_evals >= 1):
        raise ParameterError(f"fit: max_evals must be an integer >= 1 (Nelder-Mead "
                             f"evaluations per run of a stage); got {max_evals!r}")
    if progress is not None and not callable(progress):
        raise ParameterError(f"fit: progress must be None or a callable progress(stage, "
                             f"evaluations, loss); got {type(progress).__name__} {progress!r}")
    if fixed is None:
        fixed = {}
    if not isinstance(fixed, Mapping) or not all(isinstance(k, str) for k in fixed):
        raise ParameterError(f"fit: fixed must be a dict of parameter name -> value (e.g. "
                             f"{{'n': 20.0}}); got {type(fixed).__name__} {fixed!r}")
    try:
        pair = tuple(strides)
    except TypeError:
        pair = ()
    if len(pair) != 2 or not all(_is_int(s) and s >= 1 for s in pair):
        raise ParameterError(f"fit: strides must be two integers >= 1 that divide (90, 180) "
                             f"(the MERL grid's theta_d and phi_d bins), e.g. (9, 15); got "
                             f"{strides!r}")
    if theta_max is not None:
        try:
            t = float(theta_max)
        except (TypeError, ValueError):
            t = math.nan
        if not 0.0 < t <= 0.5 * math.pi:  # also refuses NaN
            raise ParameterError(f"fit: theta_max must be None or an angle in (0, pi/2] "
                                 f"radians; got {theta_max!r}")
        theta_max = t
    return dict(fixed), theta_max, tuple(int(s) for s in pair)


def check_samples(*, strides, theta_max) -> None:
    """*theta_max* must leave at least one sample pair of the MERL grid at *strides* and at
    the shape search's coarser strides (``SEARCH_STRIDES``); the error names the smallest
    theta_max that does."""
    from brdfkit.fitting._run import SEARCH_STRIDES

    if theta_max is None:
        return
    grids = {tuple(strides), tuple(max(int(a), b) for a, b in
                                   zip(strides, SEARCH_STRIDES, strict=True))}
    if all(len(merl_samples(strides=g, theta_max=theta_max)) for g in grids):
        return
    least = 0.0
    for g in grids:
        s = merl_samples(strides=g)
        cos = float(np.clip(np.minimum(s.wi[:, 2], s.wo[:, 2]).max(), -1.0, 1.0))
        least = max(least, math.degrees(math.acos(cos)))
    least = math.ceil(least * 1e4) / 1e4  # rounded up, so that the value printed keeps a pair
    raise ParameterError(
        f"fit: theta_max = {theta_max:.6g} rad ({math.degrees(theta_max):.4g} deg) leaves no "
        f"sample pair (theta_i, theta_o <= theta_max) on the MERL grid at strides {strides}; "
        f"it must be at least {least:g} deg ({math.radians(least):.6g} rad); use a larger "
        "theta_max or smaller strides")


def check_channels(model, target) -> None:
    """A coloured *model* must have one channel or as many as *target*."""
    c_model, c_target = model.n_channels, int(target.n_channels or 1)
    if c_model is None or c_model in (1, c_target):
        return
    raise ParameterError(
        f"fit: {model.name} has {c_model} colour channels (a per-channel parameter with "
        f"{c_model} values) but the target has {c_target}; give 1 or {c_target} values per "
        "channel, or none (the fit then finds one per channel)")
