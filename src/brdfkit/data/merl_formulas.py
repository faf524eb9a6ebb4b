"""
The MERL table lookups as formulas (traced by Mitsuba, compiled by Numba)
=========================================================================

:class:`~brdfkit.data.measured.MeasuredBRDF` looks its table up with compiled
loops (:mod:`brdfkit.data._merl_index`: a fast nearest index without acos/atan2,
blocks of pairs located first and read after). For the Mitsuba bridge's traced
route the same lookups are written here as *formulas* (:mod:`brdfkit._dual`):
the half/difference angles as the reference reader computes them
(:func:`merl_angles`: the operations of ``_merl_index._half_diff``, its branches
selects), the bins of :mod:`brdfkit.data.merl`'s docstring (θ_h with MERL's
square-root mapping), and the table read at the bin by
:func:`~brdfkit.tables.row_at` — in the trace a ``dr.gather`` from the table as
one Dr.Jit array (:mod:`brdfkit.traced_tables`):

- :func:`merl_nearest` — the reference reader's bin (``lookup="nearest"``);
- :func:`merl_linear` — trilinear between bin centres (``lookup="linear"``): the
  eight corners in ``_linear_sum``'s order, unmeasured (NaN) corners left out and
  the other weights renormalised, NaN when all eight are unmeasured.

Both give 0 at and below the horizon. The packed row is MeasuredBRDF's ``[lookup
mode, table (1,458,000 bins)]``; :func:`measured_formulas` returns
``Formulas(tables=1)``: the bins are the row's tables. In float32 (Mitsuba's
single-precision variants) a pair within rounding of a bin boundary can fall in
the neighbouring bin: ``nearest`` then reads the neighbour's value (the lookup
is discontinuous there), ``linear`` differs by rounding only.

Sampler: the cosine + GGX proxy of the table's lobe
(:mod:`brdfkit.models.proxy_sampler`), as for the surrogates
(:mod:`brdfkit.data.surrogate_formulas`).

Public objects
--------------
- :func:`measured_formulas` — a MeasuredBRDF's formulas.
- :func:`merl_angles`, :func:`merl_nearest`, :func:`merl_linear` — the formulas.

References
----------
- [Matusik2003] W. Matusik, H. Pfister, M. Brand, L. McMillan, *A Data-Driven
  Reflectance Model*, ACM TOG 22(3), 2003 (``BRDFRead.cpp``).
"""

from __future__ import annotations

import math

from brdfkit._dual import Formulas, acos, atan2, floor, formula, maximum, minimum, select, sqrt
from brdfkit.models.proxy_sampler import proxy_args, proxy_pdf, proxy_sample
from brdfkit.tables import row_at

__all__ = ["measured_formulas", "merl_angles", "merl_nearest", "merl_linear"]

HALF_PI = 0.5 * math.pi
PI = math.pi
NAN = math.nan
#: Offset of the table in MeasuredBRDF's packed row ([lookup mode, table …]).
TABLE = 1
N_BINS = 90 * 90 * 180


@formula
def merl_angles(ix, iy, iz, ox, oy, oz):
    """(θ_h, θ_d, φ_d) as ``_merl_index._half_diff`` computes them (φ_d ∈ (−π, π])."""
    hx, hy, hz = ix + ox, iy + oy, iz + oz
    n = sqrt(hx * hx + hy * hy + hz * hz)
    inv = 1.0 / select(n > 0.0, n, 1.0)  # n = 0: ω_i = −ω_o, below the horizon only
    hx, hy, hz = hx * inv, hy * inv, hz * inv
    rho = sqrt(hx * hx + hy * hy)
    pos = rho > 0.0
    inv = 1.0 / select(pos, rho, 1.0)
    cp = select(pos, hx * inv, 1.0)  # h = n: φ_h = atan2(0, 0) = 0
    sp = select(pos, hy * inv, 0.0)
    tx = ix * cp + iy * sp  # rot_z(−φ_h)
    ty = iy * cp - ix * sp
    dx = tx * hz - iz * rho  # rot_y(−θ_h): cos θ_h = h_z, sin θ_h = ρ
    dz = iz * hz + tx * rho
    # cosines of (nearly) unit vectors, clamped to [−1, 1] against rounding before acos
    theta_h = acos(minimum(1.0, maximum(-1.0, hz)))
    theta_d = acos(minimum(1.0, maximum(-1.0, dz)))
    return theta_h, theta_d, atan2(ty, dx)


@formula
def merl_nearest(ix, iy, iz, ox, oy, oz, p):
    """The reference reader's bin's value (``_merl_index._nearest_index``)."""
    live = (iz > 0.0) & (oz > 0.0)
    theta_h, theta_d, phi_d = merl_angles(ix, iy, iz, ox, oy, oz)
    # each index ⌊·⌋ of its coordinate, clamped to its range (the reference's int() and clamp)
    ih = minimum(maximum(floor(sqrt(theta_h / HALF_PI * 90.0 * 90.0)), 0.0), 89.0)
    ih = select(theta_h <= 0.0, 0.0, ih)
    i_d = minimum(maximum(floor(theta_d / HALF_PI * 90.0), 0.0), 89.0)
    phi = select(phi_d < 0.0, phi_d + PI, phi_d)
    ip = minimum(maximum(floor(phi / PI * 180.0), 0.0), 179.0)
    return select(live, row_at(p, TABLE + (ip + 180.0 * i_d + 16200.0 * ih)), 0.0)


@formula
def _corner(p, k, w, acc, wsum):
    """One corner of the trilinear sum: (acc, wsum) with bin k's value of weight w added
    unless unmeasured (NaN) or w = 0 (``_merl_index._linear_sum``)."""
    v = row_at(p, TABLE + k)
    ok = (v == v) & (w > 0.0)
    return acc + select(ok, w * v, 0.0), wsum + select(ok, w, 0.0)


@formula
def merl_linear(ix, iy, iz, ox, oy, oz, p):
    """Trilinear interpolation between bin centres (``_merl_index._linear``)."""
    live = (iz > 0.0) & (oz > 0.0)
    theta_h, theta_d, phi_d = merl_angles(ix, iy, iz, ox, oy, oz)
    uh = sqrt(maximum(theta_h, 0.0) / HALF_PI) * 90.0 - 0.5
    ud = theta_d / HALF_PI * 90.0 - 0.5
    up = select(phi_d < 0.0, phi_d + PI, phi_d) / PI * 180.0 - 0.5
    # θ_h, θ_d: clamped to the centres of the end bins; φ_d periodic (180 bins)
    uh = minimum(maximum(uh, 0.0), 89.0)
    ud = minimum(maximum(ud, 0.0), 89.0)
    h0 = minimum(floor(uh), 88.0)
    d0 = minimum(floor(ud), 88.0)
    fp = floor(up)  # in [−1, 179]: φ ∈ [0, π]
    p0 = select(fp < 0.0, fp + 180.0, fp)
    step = select(p0 < 179.0, 1.0, -179.0)
    k0 = p0 + 180.0 * d0 + 16200.0 * h0
    th, td, tp = uh - h0, ud - d0, up - fp
    acc, wsum = 0.0, 0.0
    acc, wsum = _corner(p, k0, (1.0 - th) * (1.0 - td) * (1.0 - tp), acc, wsum)
    acc, wsum = _corner(p, k0 + step, (1.0 - th) * (1.0 - td) * tp, acc, wsum)
    acc, wsum = _corner(p, k0 + 180.0, (1.0 - th) * td * (1.0 - tp), acc, wsum)
    acc, wsum = _corner(p, k0 + step + 180.0, (1.0 - th) * td * tp, acc, wsum)
    acc, wsum = _corner(p, k0 + 16200.0, th * (1.0 - td) * (1.0 - tp), acc, wsum)
    acc, wsum = _corner(p, k0 + step + 16200.0, th * (1.0 - td) * tp, acc, wsum)
    acc, wsum = _corner(p, k0 + 16380.0, th * td * (1.0 - tp), acc, wsum)
    acc, wsum = _corner(p, k0 + step + 16380.0, th * td * tp, acc, wsum)
    value = select(wsum > 0.0, acc / select(wsum > 0.0, wsum, 1.0), NAN)  # NaN: none measured
    return select(live, value, 0.0)


def measured_formulas(model) -> Formulas:
    """*model*'s (a MeasuredBRDF's) formulas: its lookup (module docstring), the cosine +
    GGX proxy of its lobe as sampler and pdf; the table from column TABLE on."""
    f = merl_linear if model.values["lookup"] == "linear" else merl_nearest
    return Formulas(eval=f, sample=proxy_sample, pdf=proxy_pdf, args=proxy_args(model),
                    tables=TABLE)
