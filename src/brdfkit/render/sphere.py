"""
Lewis's sphere test configuration, computed exactly
===================================================

An S×S image of the unit sphere seen orthographically from +z (Lewis 1993,
Fig. 2): V = +z at every pixel; pixel (row r, column c) has its centre at

    x = (c + ½)/S·2 − 1,    y = 1 − (r + ½)/S·2,

and, inside the disc x² + y² < 1, the normal N = (x, y, √(1 − x² − y²)).
One directional light shines toward the sphere from L = (sin Φ_L, 0, cos Φ_L)
(Φ_L the angle between the light and the viewer, Lewis's Fig. 2) with
irradiance E on a surface facing it, and a uniform ambient radiance L_a fills
the hemisphere of every N. The radiance toward the viewer is (Lewis eq. 7)

    L_r = E·f_r(L, V)·max(N·L, 0) + L_a·ρ(V),
    ρ(V) = ∫ f_r(L′, V) cos θ_L′ dω_L′           (:mod:`brdfkit.render.ambient`),

and 0 outside the disc (a black background). f_r is evaluated in each pixel's
local frame (N = +z local): tangent T = the world x axis projected onto the
tangent plane, T = (x̂ − N_x N)/√(1 − N_x²), and B = N × T. For an isotropic
model any tangent gives the same value; for an anisotropic one this is the
stated choice of tangent (the projected x axis). No sampling: the direct term
is the model's kernel at the pixel centre, the ambient term the tabulated albedo
integral with its stated error — except where the rim or the terminator crosses a
pixel: it holds the mean of n × n sub-pixel samples (:mod:`brdfkit.render.silhouette`:
smooth edges). The sphere does not shadow itself (it is convex) and there is no
interreflection.

A delta (perfectly specular) term (``has_delta``) reflects the directional
light into exactly one direction, which no pixel centre receives: it adds
nothing to the direct term, and its specular albedo to ρ(V).

Public objects
--------------
- :func:`render_sphere` → :class:`SphereRender` (with its error and a ``status`` of
  ``brdfkit.status.STATUS["render"]``: the direct engine states the ambient term's error,
  the Monte-Carlo engine the per-pixel standard error of K independent passes).
- :func:`sphere_geometry` — pixel centres, disc mask, normals.

References
----------
- [Lewis1993] Fig. 2 (test configuration), eq. (7), Figs. 3, 4, 6, 10.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from brdfkit._cache import bounded_cache, memo
from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.models import BRDF
from brdfkit.models._drivers import add_loop, loop_driver
from brdfkit.render.ambient import RHO_TOL, ambient_table
from brdfkit.render.silhouette import (
    DEFAULT_ANTIALIAS,
    MAX_ANTIALIAS,
    edge_pixels,
    local_frame_pairs,
    silhouette_pixels,
    silhouette_samples,
)
from brdfkit.status import STATUS

__all__ = ["SphereRender", "render_sphere", "sphere_geometry", "exposure_phi0", "MAX_SIZE",
           "ENGINES", "MAX_RENDER_VALUES", "BYTES_PER_VALUE"]

#: Largest image side: 8192² pixels of 3 channels are 1.6 GB of float64 radiance.
MAX_SIZE = 8192
#: Largest θ_V the ambient table is built to for the rim's sub-samples (89.9°: the last
#: 0.1° of the rim is under 2e-6 of the radius wide, far below a pixel at any size).
RIM_THETA_MAX = math.radians(89.9)
#: Peak memory of a direct render and its output file per pixel and channel, measured
#: (maximum resident size of ``brdfkit render sphere`` at 2048², RGB, less that at 16²):
#: 48 bytes with a PNG (the float64 image, its exposed copy, the 8-bit rows), 34 with
#: an EXR and the ambient term, 11 for a plain .npy.
BYTES_PER_VALUE = 48
#: Most pixels x channels of a direct render: a memory budget of 12 GiB (half of the
#: 24 GiB machine this was measured on) at :data:`BYTES_PER_VALUE`, so ~268 M values; an
#: RGB image of :data:`MAX_SIZE`² (201 M values, ~9.7 GB) fits. 20000 channels at 256²
#: (1.3 G values) asked for > 4 GB before the bound and are refused.
MAX_RENDER_VALUES = (12 * 2**30) // BYTES_PER_VALUE
#: Engines of :func:`render_sphere`; ``mitsuba`` (Monte Carlo) is planned (issue 11 §3).
ENGINES = ("direct", "mitsuba")
#: Default samples per pixel of the Monte-Carlo engine.
DEFAULT_SPP = 64
_CODES = STATUS["render"]


@dataclass(frozen=True)
class SphereRender:
    """A render of the sphere test configuration and what it was made from.

    Attributes
    ----------
    radiance : ndarray (S, S, C)
        Linear radiance in the units of L_a (f_r is in 1/sr: E in W/m² and L_a
        in W/(m²·sr) give W/(m²·sr)); C = the model's channel count (1 for a
        scalar model). 0 outside the disc.
    mask : ndarray of bool (S, S)
        The disc: pixels whose centre lies on the sphere. With ``antialias`` > 1 the rim
        pixels just outside it hold the sphere's share of their area (not 0).
    model : dict
        ``model.to_dict()``.
    phi_l : float
        Φ_L, radians.
    ambient, irradiance : float
        L_a and E.
    engine : str
        ``"direct"`` (deterministic; no samples, no variance) or ``"mitsuba"``
        (Monte Carlo: pixel-area averages, noise ∝ 1/√spp).
    spp, seed : int or None
        The Monte-Carlo engine's samples per pixel and seed (None for direct).
    ambient_error : float
        Absolute error estimate of the ambient term L_a·ρ(V) at any pixel
        (0 when L_a = 0); the direct term is exact to rounding.
    ambient_message : str
        The ρ table's accuracy statement (empty when L_a = 0).
    status : int
        ``STATUS["render"]``: converged (0: every term within its stated error), limit
        (1: the ρ table missed its goal; its error estimate is stated), undetermined (2:
        one Monte-Carlo pass, no standard error), nonfinite (3: NaN or inf radiance).
    mc_error : ndarray (S, S, C) or None
        The Monte-Carlo engine's per-pixel standard error of the radiance (1σ, from
        ``passes`` independent passes; :mod:`brdfkit.render.mitsuba_sphere`); None for
        the direct engine (no sampling) and for one pass.
    passes : int or None
        The Monte-Carlo engine's passes (None for direct).
    success, message
        The status's success; its message with what was reached.
    """

    radiance: np.ndarray
    mask: np.ndarray
    model: dict
    phi_l: float
    ambient: float
    irradiance: float
    engine: str = "direct"
    ambient_error: float = 0.0
    ambient_message: str = ""
    status: int = 0
    spp: int | None = None
    seed: int | None = None
    mc_error: np.ndarray | None = None
    passes: int | None = None
    antialias: int = 1

    @property
    def success(self) -> bool:
        return _CODES.success(self.status)

    @property
    def message(self) -> str:
        """The status's message, then the ambient term's statement and, for Monte Carlo,
        the largest standard error."""
        mc = ("" if self.mc_error is None else
              f"standard error up to {self.mc_error_max:.3g} per pixel ({self.passes} passes)")
        return _CODES.describe(self.status, self.ambient_message, mc)

    @property
    def mc_error_max(self) -> float | None:
        """Largest per-pixel standard error over the disc (None without one)."""
        if self.mc_error is None:
            return None
        return float(np.max(self.mc_error[self.mask])) if np.any(self.mask) else 0.0

    @property
    def size(self) -> int:
        return int(self.radiance.shape[0])

    @property
    def peak(self) -> float:
        """Largest radiance over pixels and channels."""
        return float(np.max(self.radiance)) if self.radiance.size else 0.0

    def metadata(self) -> dict:
        """JSON-ready description (angles in degrees)."""
        return {"model": self.model, "phi_l_deg": math.degrees(self.phi_l),
                "ambient": self.ambient, "irradiance": self.irradiance, "size": self.size,
                "channels": int(self.radiance.shape[2]), "engine": self.engine,
                "ambient_error": self.ambient_error, "ambient_message": self.ambient_message,
                "success": self.success, "peak": self.peak, "spp": self.spp,
                "seed": self.seed, "status": int(self.status), "message": self.message,
                "antialias": self.antialias,
                **({} if self.engine == "direct" else
                   {"passes": self.passes, "mc_error_max": self.mc_error_max})}


@numba.njit(cache=True, inline="always")
def _pixel(size, r, c, lx, ly, lz):
    """(x, y, z = N_z, N·L) of pixel (r, c); z < 0 outside the disc."""
    y = 1.0 - (r + 0.5) / size * 2.0
    x = (c + 0.5) / size * 2.0 - 1.0
    r2 = x * x + y * y
    if r2 >= 1.0:
        return x, y, -1.0, 0.0  # outside the disc (strictly inside: N_z > 0)
    z = math.sqrt(1.0 - r2)
    return x, y, z, lx * x + ly * y + lz * z


# Serial, on purpose: measured on the shared 2-core machine (benchmarks/bench_render.py),
# a prange version of these loops was 2-6x slower than this one whenever the other core was
# busy (the row loop waits for the descheduled thread); serial it is ~4 ms for 512².
@numba.njit(cache=True)
def _lit_pixels(size, lx, ly, lz, wi, wo, index, cos_l):  # pragma: no cover - compiled
    """The disc pixels with N·L > 0, in row order: local wi, wo, flat index, N·L; returns
    their count.

    Frame of pixel (x, y, z = N_z): T = (x̂ − x N)/s with s = √(1 − x²) > 0 inside the
    disc, B = N × T = (0, z/s, −y/s) (worked out from T and N), so in local coordinates
    wi = (L·T, L·B, L·N) and wo = V = ẑ = (T_z, B_z, N_z) = (−x z/s, −y/s, z).
    """
    k = 0
    for r in range(size):
        for c in range(size):
            x, y, z, n_dot_l = _pixel(size, r, c, lx, ly, lz)
            if not (z > 0.0 and n_dot_l > 0.0):
                continue  # outside the disc, or max(N·L, 0) = 0: not evaluated
            s = math.sqrt(1.0 - x * x)
            wi[k, 0] = (lx * (1.0 - x * x) - ly * x * y - lz * x * z) / s
            wi[k, 1] = (ly * z - lz * y) / s
            wi[k, 2] = n_dot_l
            wo[k, 0] = -x * z / s
            wo[k, 1] = -y / s
            wo[k, 2] = z
            index[k] = r * size + c
            cos_l[k] = n_dot_l
            k += 1
    return k


# The loop template of the "sphere" loop (models._drivers.add_loop, below): generated per
# kernel and cached on disk, as the models' own loops (compiled in every process, it cost
# 0.35-0.6 s of every first sphere: the explorer's first views, `render sphere`). Serial for
# the reason above; it writes the image directly, with no arrays of directions in between.
def _direct(kernel, size, lx, ly, lz, P, E, out):  # pragma: no cover - compiled
    """out[r·S + c, ch] += E·kernel(wi, wo, P[ch])·(N·L) at the lit disc pixels (frames as
    in :func:`_lit_pixels`); other rows of *out* are left as they are."""
    for r in range(size):
        for c in range(size):
            x, y, z, n_dot_l = _pixel(size, r, c, lx, ly, lz)
            if not (z > 0.0 and n_dot_l > 0.0):
                continue  # outside the disc, or max(N·L, 0) = 0: nothing to add
            s = math.sqrt(1.0 - x * x)
            ix = (lx * (1.0 - x * x) - ly * x * y - lz * x * z) / s
            iy = (ly * z - lz * y) / s
            ox = -x * z / s
            oy = -y / s
            w = E * n_dot_l
            for ch in range(P.shape[0]):
                out[r * size + c, ch] += w * kernel(ix, iy, n_dot_l, ox, oy, z, P[ch])


add_loop("sphere", (("_pixel", _pixel, 'inline="always"'), ("driver", _direct, "")))


@numba.njit(cache=True)
def _scatter(out, index, weight, f):  # pragma: no cover - compiled
    """out[index[k], c] += weight[k]·f[k, c] (serial: see _lit_pixels)."""
    for k in range(index.shape[0]):
        for ch in range(f.shape[1]):
            out[index[k], ch] += weight[k] * f[k, ch]


@memo(maxsize=16)  # one float per image size
def _max_r2(size: int) -> float:
    """Largest x² + y² of a pixel centre inside the disc (the outermost pixel)."""
    c, mask = _disc(size)
    r2 = c[None, :] ** 2 + c[:, None] ** 2
    return float(np.max(r2[mask]))


#: The last few ρ(θ_V) images, keyed by (id(table), S): the ambient image does not depend
#: on Φ_L or E, so a series of renders of one model reuses it (each entry keeps its table
#: alive, so an id is never reused while its entry exists). 4 entries: ≤ 25 MB at 512², RGB.
_RHO_IMAGES = bounded_cache("brdfkit.render.sphere._RHO_IMAGES", maxsize=4)


def _rho_image(table, S: int, C: int) -> np.ndarray:
    """ρ(θ_V) at every pixel, (S·S, C), 0 outside the disc (read-only, cached)."""
    key = (id(table), S)
    hit = _RHO_IMAGES.get(key)
    if hit is not None and hit[0] is table:
        return hit[1]
    # ρ(θ_V) is the same at (±x, ±y): evaluate one quadrant (the first h rows and columns,
    # h = ⌈S/2⌉) and mirror it; N_z = √(1 − x² − y²) = cos θ_V
    c, _ = _disc(S)
    h = (S + 1) // 2
    q = c[:h] ** 2
    r2 = q[:, None] + q[None, :]
    inside = r2 < 1.0
    theta_v = np.arccos(np.sqrt(1.0 - r2[inside]))  # θ_V = angle between N and V = ẑ
    quadrant = np.zeros((h, h, C))
    quadrant[inside] = table(theta_v)
    # mirror: columns (and then rows) 0 … h−1 followed by S − h of them reversed
    top = np.concatenate([quadrant, quadrant[:, : S - h][:, ::-1]], axis=1)
    image = np.concatenate([top, top[: S - h][::-1]], axis=0).reshape(S * S, C)
    image.flags.writeable = False
    _RHO_IMAGES[key] = (table, image)
    return image


def _disc(size: int):
    c = (np.arange(size) + 0.5) / size * 2.0 - 1.0  # x of column c (pixel centre)
    x = c[None, :]
    y = -c[:, None]  # y = 1 − (r + ½)/S·2 = −(x of column r)
    mask = x * x + y * y < 1.0  # strictly inside: N_z > 0
    return c, mask


def sphere_geometry(size: int) -> dict:
    """Pixel centres, disc mask and normals of an S×S sphere image.

    Returns
    -------
    dict
        ``x`` (S,) and ``y`` (S,): centre coordinates of columns and rows;
        ``mask`` (S, S) bool; ``normal`` (S, S, 3) with 0 outside the disc.
    """
    size = _check_size(size)
    c, mask = _disc(size)
    x, y = np.meshgrid(c, -c)
    nz = np.sqrt(np.maximum(1.0 - x * x - y * y, 0.0))  # the clamp only touches masked pixels
    normal = np.where(mask[..., None], np.stack([x, y, nz], axis=-1), 0.0)
    return {"x": c, "y": -c, "mask": mask, "normal": normal}


def _check_size(size) -> int:
    if isinstance(size, bool) or not isinstance(size, int | np.integer) \
            or not 1 <= size <= MAX_SIZE:
        raise ParameterError(f"size must be an integer from 1 to {MAX_SIZE} pixels; got "
                             f"{size!r}")
    return int(size)


def _check_number(value, name: str, *, lower: float = 0.0) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if not (math.isfinite(v) and v >= lower):
        raise ParameterError(f"{name} must be a finite number >= {lower:g}; got {value!r}")
    return v


def render_sphere(model: BRDF, *, phi_l: float, light_azimuth: float = 0.0,
                  ambient: float = 0.0, irradiance: float = 1.0,
                  size: int = 256, engine: str = "direct", spp: int | None = None,
                  seed: int = 0, variant: str = "llvm_ad_rgb",
                  rho_tol: float = RHO_TOL, passes: int | None = None,
                  antialias: int = DEFAULT_ANTIALIAS) -> SphereRender:
    """Render Lewis's sphere test configuration exactly.

    Parameters
    ----------
    model : BRDF
        Any brdfkit model (registered, pumped, measured, …).
    phi_l : float, keyword-only
        Φ_L, the angle between the light and the view direction, radians in
        [0, π]: the light direction is L = (sin Φ_L, 0, cos Φ_L).
    light_azimuth : float, keyword-only
        ψ, the light's azimuth in the image plane, radians, counter-clockwise from +x
        (image right); default 0 (Lewis's configuration). Generally
        L = (sin Φ_L cos ψ, sin Φ_L sin ψ, cos Φ_L): ψ = π/4 lights from the upper right
        (north-east), 5π/4 from the lower left (south-west; Nielsen et al. 2015, Fig. 1).
    ambient : float, keyword-only
        Uniform ambient radiance L_a ≥ 0 (default 0).
    irradiance : float, keyword-only
        E ≥ 0, the light's irradiance on a surface facing it (default 1).
    size : int, keyword-only
        Image side S in pixels, 1 … :data:`MAX_SIZE` (default 256).
    engine : {"direct", "mitsuba"}, keyword-only
        ``direct``: deterministic, exact at pixel centres. ``mitsuba``: Monte
        Carlo through Mitsuba 3 with brdfkit's own sampler
        (:func:`brdfkit.render.mitsuba_sphere.render_sphere_mitsuba`): pixel-area
        averages that agree with ``direct`` within noise away from the rim.
    spp, seed, variant, passes : keyword-only
        Samples per pixel (default :data:`DEFAULT_SPP`), seed, Mitsuba variant and
        independent passes (default
        :data:`~brdfkit.render.mitsuba_sphere.DEFAULT_PASSES`; they give the per-pixel
        standard error ``mc_error``) of the ``mitsuba`` engine; ``direct`` takes no
        samples (``spp`` and ``passes`` must be None).
    rho_tol : float, keyword-only
        Accuracy goal of ρ(V) when L_a > 0 (see
        :func:`brdfkit.render.ambient.ambient_table`; cached per model).
    antialias : int, keyword-only
        ``direct`` only: sub-samples per axis of each pixel the rim of the disc may cross
        (1 … :data:`~brdfkit.render.silhouette.MAX_ANTIALIAS`, default
        :data:`~brdfkit.render.silhouette.DEFAULT_ANTIALIAS`): such a pixel holds the
        mean over its n × n cell midpoints of the radiance there (0 off the sphere), so
        the silhouette is smooth — and so does a pixel the terminator N·L = 0 crosses
        (where a 1/(N·L) shader jumps); 1 evaluates every pixel at its centre only (a
        staircase rim). Other pixels are always exact at their centre.

    Returns
    -------
    SphereRender
        ``radiance`` (S, S, C), ``mask``, the inputs, the ambient term's
        error estimate (direct) or the per-pixel standard error (mitsuba), and the
        status.

    Examples
    --------
    >>> import brdfkit, math
    >>> from brdfkit.render import render_sphere
    >>> r = render_sphere(brdfkit.model("lambert", rho_d=0.5), phi_l=0.0, size=2)
    >>> r.radiance.shape
    (2, 2, 1)
    """
    if not isinstance(model, BRDF):
        hint = (f" (build it first: brdfkit.model({model!r}))" if isinstance(model, str)
                else "")
        raise BrdfkitError(f"render_sphere: model must be a brdfkit model (BRDF); got "
                           f"{type(model).__name__}{hint}")
    if engine not in ENGINES:
        raise ParameterError(f"engine must be one of {', '.join(ENGINES)}; got {engine!r}")
    phi = _check_number(phi_l, "phi_l")
    if phi > math.pi:
        raise ParameterError(f"phi_l must lie in [0, pi] radians = [0, 180] degrees; got "
                             f"{phi_l!r} rad")
    L_a = _check_number(ambient, "ambient")
    E = _check_number(irradiance, "irradiance")
    S = _check_size(size)
    C = model.n_channels or 1
    if engine == "direct" and S * S * C > MAX_RENDER_VALUES:
        raise ParameterError(
            f"size {S} with {C} channels is {S * S * C:.3g} pixel values; a render holds at "
            f"most MAX_RENDER_VALUES = {MAX_RENDER_VALUES:.3g} (~{BYTES_PER_VALUE} bytes each "
            f"at peak, a 12 GiB budget): use a size of at most "
            f"{math.isqrt(MAX_RENDER_VALUES // C)} or fewer channels")
    if engine == "mitsuba":
        from brdfkit.render.mitsuba_sphere import render_sphere_mitsuba_passes

        if light_azimuth != 0.0:
            raise ParameterError("light_azimuth is not supported by the mitsuba engine; "
                                 "use engine='direct'")
        n = DEFAULT_SPP if spp is None else spp
        rad, se, k = render_sphere_mitsuba_passes(model, phi_l=phi, ambient=L_a,
                                                  irradiance=E, size=S, spp=n, seed=seed,
                                                  passes=passes, variant=variant)
        _, mask = _disc(S)
        msg = "Monte Carlo: pixel-area averages, noise ~ 1/sqrt(spp)"
        status = (_CODES.NONFINITE if not np.all(np.isfinite(rad))
                  else _CODES.UNDETERMINED if se is None else _CODES.CONVERGED)
        return SphereRender(radiance=np.asarray(rad, dtype=np.float64), mask=mask,
                            model=model.to_dict(), phi_l=phi, ambient=L_a, irradiance=E,
                            engine="mitsuba", spp=int(n), seed=int(seed),
                            ambient_message=msg, status=status, mc_error=se, passes=k)
    if spp is not None or passes is not None:
        name, value = ("spp", spp) if spp is not None else ("passes", passes)
        raise ParameterError(f"{name}={value!r}: the direct engine is exact and takes no "
                             f"samples; drop {name} or use engine='mitsuba'")
    if isinstance(antialias, bool) or not isinstance(antialias, int | np.integer) \
            or not 1 <= antialias <= MAX_ANTIALIAS:
        raise ParameterError(f"antialias must be an integer from 1 to {MAX_ANTIALIAS} "
                             f"(sub-samples per axis of a rim pixel); got {antialias!r}")
    psi = float(light_azimuth)
    if not math.isfinite(psi):
        raise ParameterError(f"light_azimuth must be a finite angle in radians; got "
                             f"{light_azimuth!r}")
    L = (math.sin(phi) * math.cos(psi), math.sin(phi) * math.sin(psi), math.cos(phi))
    # the pixels the rim crosses and, lit by the light (E > 0), the terminator (module
    # silhouette); none without anti-aliasing
    if antialias == 1:
        rim = np.empty(0, dtype=np.int64)
    elif E > 0.0:
        rim = edge_pixels(S, L)
    else:
        rim = silhouette_pixels(S)
    sx, sy = silhouette_samples(S, rim, int(antialias))
    err, msg, ok = 0.0, "", True
    table, theta_max = None, 0.0  # the ambient table, when L_a > 0
    if L_a > 0.0:  # the ambient image first; the direct term is added to it
        # at least 1e-3 rad: the one pixel of a 1×1 image has θ_V = 0; the table needs a range
        # the rim's sub-samples reach closer to the horizon than any centre: the table
        # covers them up to RIM_THETA_MAX (beyond, a sliver of < 1e-3 of a pixel's width,
        # they read the table's last value)
        r2_sub = sx * sx + sy * sy
        r2 = max(_max_r2(S), float(np.max(r2_sub[r2_sub < 1.0], initial=0.0)))
        theta_max = min(max(math.acos(math.sqrt(max(1.0 - r2, 0.0))), 1e-3), RIM_THETA_MAX)
        table = ambient_table(model, theta_max=theta_max, tol=rho_tol)
        out = L_a * _rho_image(table, S, C)
        err, msg, ok = L_a * table.error, table.detail, table.success
    else:
        out = np.zeros((S * S, C))
    if E > 0.0 and model.kernel is not None:
        P = np.ascontiguousarray(np.asarray(model.packed, dtype=np.float64))
        loop_driver(model.kernel, loop="sphere")(S, L[0], L[1], L[2], P, E, out)
    elif E > 0.0:  # a model evaluated in NumPy (kernel None): directions, then model.eval
        M = S * S
        wi, wo = np.empty((M, 3)), np.empty((M, 3))
        index, cos_l = np.empty(M, dtype=np.int64), np.empty(M)
        k = _lit_pixels(S, L[0], L[1], L[2], wi, wo, index, cos_l)
        if k:
            f = np.asarray(model.eval(wi[:k], wo[:k]), dtype=np.float64).reshape(k, C)
            _scatter(out, index[:k], E * cos_l[:k], np.ascontiguousarray(f))
    if rim.size:  # out is this render's own array (L_a·ρ image or zeros): written in place
        out[rim] = _rim_means(model, sx, sy, L, E, L_a, table, theta_max, C)
    _, mask = _disc(S)
    status = (_CODES.NONFINITE if not np.all(np.isfinite(out))
              else _CODES.CONVERGED if ok else _CODES.LIMIT)
    return SphereRender(radiance=out.reshape(S, S, C), mask=mask, model=model.to_dict(),
                        phi_l=phi, ambient=L_a, irradiance=E, engine="direct",
                        ambient_error=err, ambient_message=msg, status=status,
                        antialias=int(antialias))


def _rim_means(model, sx, sy, L, E, L_a, table, theta_max, C) -> np.ndarray:
    """(P, C): each rim pixel's mean over its sub-samples of E·f·max(N·L, 0) + L_a·ρ(θ_V),
    0 at samples off the sphere (module silhouette)."""
    inside, wi, wo, n_dot_l = local_frame_pairs(sx, sy, L)
    vals = np.zeros((*sx.shape, C))
    if wi.shape[0]:
        v = np.zeros((wi.shape[0], C))
        if E > 0.0:
            f = np.asarray(model.eval(wi, wo), dtype=np.float64).reshape(-1, C)
            v += E * np.maximum(n_dot_l, 0.0)[:, None] * f
        if table is not None:
            v += L_a * np.asarray(table(np.minimum(np.arccos(wo[:, 2]), theta_max)),
                                  dtype=np.float64).reshape(-1, C)
        vals[inside] = v
    return vals.mean(axis=1)


def exposure_phi0(model: BRDF, *, ambient: float = 0.0, irradiance: float = 1.0,
                  size: int = 256, rho_tol: float = RHO_TOL) -> float:
    """Lewis's exposure rule: 1/peak of the same scene lit at Φ_L = 0.

    "Incident light for each shader is scaled to produce a peak unsaturated
    radiance at normal incidence (Φ_L = 0) and then held constant as Φ_L and
    β are varied" (Lewis 1993, §3.3, Fig. 4). The returned k maps the
    brightest pixel of the Φ_L = 0 render to display value 1; every render
    of a series shown with it is comparable.

    Raises
    ------
    BrdfkitError
        The Φ_L = 0 render is black (peak 0): no exposure follows from it.
    """
    peak = render_sphere(model, phi_l=0.0, ambient=ambient, irradiance=irradiance, size=size,
                         rho_tol=rho_tol).peak
    if not peak > 0.0:
        raise BrdfkitError("the sphere lit at phi_l = 0 is black (peak radiance 0), so no "
                           "exposure follows from it; give an explicit exposure")
    return 1.0 / peak
