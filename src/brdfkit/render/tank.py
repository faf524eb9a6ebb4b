"""
Neumann et al. Fig. 8: a golden tank with metal pyramids, by Monte Carlo at 8 wavelengths
=========================================================================================

The scene of Neumann et al. (1999, §4, Fig. 8), built in code ("a golden tank
with aluminum, silver, copper and golden pyramids", "illuminated by both point
lightsources and sky-light"; the paper gives no dimensions, these are chosen):

- the tank: an open box of gold, a square floor slab 2·:data:`TANK_HALF` wide
  and four walls :data:`WALL_HEIGHT` high and :data:`WALL_THICKNESS` thick,
  every part a closed box (so every visible face faces outward: brdfkit's
  models are one-sided);
- four square pyramids standing on the floor (:data:`PYRAMIDS`: aluminium back
  left, silver back right, copper front left, gold front right);
- two point lights (:data:`POINT_LIGHTS`) and a constant environment of radiance
  :data:`SKY_RADIANCE` (flat spectrum), hidden from the camera (black background);
- a perspective camera from the front, above the rim (:data:`CAMERA`).

Every surface is :func:`brdfkit.render.metals.metal_phong` of its metal: the grey
reciprocal Phong (plain or pumped) times the conductor Fresnel factor with the
metal's n, k.

Exactly 8 wavelengths
---------------------
Mitsuba's spectral variants sample continuous wavelengths per path (4 per path,
drawn from the visible range), so they cannot compute "at 8 discrete
wavelengths". The 8 wavelengths (:data:`brdfkit.render.metals.WAVELENGTHS`) are
rendered instead in Mitsuba's ``llvm_ad_rgb`` variant, three at a time as the
R, G, B channels of one render (3 + 3 + 2 renders): an RGB variant does no
colour arithmetic on its channels — emitters given as a plain float are
(v, v, v), the bridge returns the model's 3 channels as they are, the path
tracer multiplies per channel and the ``hdrfilm`` stores them unconverted. So
each channel is exactly the monochromatic render at its wavelength, and the
light is a flat spectrum by construction (a plain float in a *spectral* variant
would become D65; that question does not arise here). The three renders share
the seed, and Russian roulette is off (``rr_depth`` > ``max_depth``), and the
sampler of the metal Phong does not depend on the channel: every render traces
the same paths, so the 8 wavelengths carry correlated noise and the image has no
colour noise. Colour then follows :func:`brdfkit.render.metals.spectral_to_linear_srgb`
(explicit CIE 1931 integration over 8 bands, XYZ → linear sRGB).

Public objects
--------------
- :func:`render_tank` — the spectral image (H, W, 8) of the scene for one Phong.
- :func:`tank_scene` — the scene dict for given Mitsuba BSDFs.
- :func:`check_render_options` — the checks of size, spp, seed, max_depth.
- :data:`TANK_HALF`, :data:`WALL_HEIGHT`, :data:`WALL_THICKNESS`, :data:`PYRAMIDS`,
  :data:`POINT_LIGHTS`, :data:`SKY_RADIANCE`, :data:`CAMERA`, :data:`MAX_DEPTH`.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable

import numpy as np

from brdfkit.errors import ParameterError
from brdfkit.models import BRDF
from brdfkit.render.metals import METALS, WAVELENGTHS, metal_nk, metal_phong
from brdfkit.render.mitsuba_bridge import (
    _mitsuba,
    check_samples,
    check_seed,
    mitsuba_bsdf,
    render_bounded,
    use_variant,
    wavefront,
)

__all__ = ["render_tank", "tank_scene", "check_render_options", "TANK_HALF", "WALL_HEIGHT",
           "WALL_THICKNESS", "PYRAMIDS", "POINT_LIGHTS", "SKY_RADIANCE", "CAMERA", "MAX_DEPTH",
           "ASPECT"]

#: Half the tank's outer width (scene units); the floor's top is z = 0.
TANK_HALF = 2.0
WALL_HEIGHT = 0.45
WALL_THICKNESS = 0.12
#: Thickness of the floor slab below z = 0.
FLOOR_THICKNESS = 0.12
#: metal → (centre x, centre y, half base width, height) of its square pyramid.
PYRAMIDS = {
    "Al": (-0.95, 0.95, 0.5, 1.05),
    "Ag": (0.95, 0.95, 0.5, 1.05),
    "Cu": (-0.95, -0.75, 0.5, 1.05),
    "Au": (0.95, -0.75, 0.5, 1.05),
}
#: (position, intensity W/sr) of the point lights: one high front left, one lower right.
POINT_LIGHTS = (((-3.0, -4.0, 6.0), 60.0), ((4.5, -1.5, 3.5), 30.0))
#: Radiance of the sky (a constant environment, flat spectrum).
SKY_RADIANCE = 1.0
#: Camera: origin, target, field of view (degrees, horizontal).
CAMERA = ((0.0, -6.4, 5.2), (0.0, 0.2, 0.15), 38.0)
#: Image height / width.
ASPECT = 0.75
#: Path length cap (Mitsuba's max_depth): camera ray + up to 5 reflections before the light.
#: Mirror-like chains (n = 5000: pyramid → floor → pyramid → wall …) cut at 4 left black
#: wedges at the pyramids' feet; 6 and 8 look the same (measured at 256 px, 8 spp: 11 s at
#: 4, 16 s at 6 and 8).
MAX_DEPTH = 6
#: Wavelengths rendered per Mitsuba render (the R, G, B channels of llvm_ad_rgb).
PACK = 3


def _box(lo, hi) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (8, 3) and faces (12, 3) of an axis-aligned box, normals outward."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = np.array([[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
                  [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]])
    # counter-clockwise seen from outside (Mitsuba's face normal is (v1 − v0) × (v2 − v0))
    f = np.array([[0, 2, 1], [0, 3, 2],   # bottom (−z)
                  [4, 5, 6], [4, 6, 7],   # top (+z)
                  [0, 1, 5], [0, 5, 4],   # front (−y)
                  [2, 3, 7], [2, 7, 6],   # back (+y)
                  [3, 0, 4], [3, 4, 7],   # left (−x)
                  [1, 2, 6], [1, 6, 5]])  # right (+x)
    return v, f


def _pyramid(cx, cy, half, height) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (5, 3) and faces (6, 3) of a square pyramid on z = 0, normals outward."""
    v = np.array([[cx - half, cy - half, 0.0], [cx + half, cy - half, 0.0],
                  [cx + half, cy + half, 0.0], [cx - half, cy + half, 0.0],
                  [cx, cy, height]])
    f = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [0, 2, 1], [0, 3, 2]])
    return v, f


def _tank_parts() -> list[tuple[np.ndarray, np.ndarray]]:
    a, t, h = TANK_HALF, WALL_THICKNESS, WALL_HEIGHT
    return [_box((-a, -a, -FLOOR_THICKNESS), (a, a, 0.0)),
            _box((-a, a - t, 0.0), (a, a, h)), _box((-a, -a, 0.0), (a, -a + t, h)),
            _box((-a, -a, 0.0), (-a + t, a, h)), _box((a - t, -a, 0.0), (a, a, h))]


def _merge(parts) -> tuple[np.ndarray, np.ndarray]:
    verts, faces, offset = [], [], 0
    for v, f in parts:
        verts.append(v)
        faces.append(f + offset)
        offset += len(v)
    return np.concatenate(verts), np.concatenate(faces)


def _mesh(mi, dr, name: str, vertices: np.ndarray, faces: np.ndarray, bsdf):
    """A Mitsuba triangle mesh (flat shading: face normals) with *bsdf*."""
    props = mi.Properties()
    props["bsdf"] = bsdf
    mesh = mi.Mesh(name, len(vertices), len(faces), props=props, has_vertex_normals=False)
    params = mi.traverse(mesh)
    params["vertex_positions"] = dr.ravel(mi.Point3f(
        np.ascontiguousarray(vertices.T, dtype=np.float32)))
    params["faces"] = dr.ravel(mi.Vector3u(np.ascontiguousarray(faces.T, dtype=np.uint32)))
    params.update()
    return mesh


def tank_scene(bsdfs: dict, *, width: int, height: int, max_depth: int = MAX_DEPTH) -> dict:
    """The scene dict with *bsdfs* (metal → Mitsuba BSDF; the tank is ``"Au"``)."""
    mi, dr = _mitsuba()
    origin, target, fov = CAMERA
    scene = {
        "type": "scene",
        # rr_depth beyond max_depth: no Russian roulette, so renders of different
        # wavelengths trace the same paths (module docstring)
        "integrator": {"type": "path", "max_depth": int(max_depth),
                       "rr_depth": int(max_depth) + 1, "hide_emitters": True},
        "sensor": {
            "type": "perspective", "fov": float(fov), "fov_axis": "x",
            "to_world": mi.ScalarTransform4f().look_at(origin=list(origin),
                                                       target=list(target), up=[0, 0, 1]),
            "film": {"type": "hdrfilm", "width": int(width), "height": int(height),
                     "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent"},
        },
        "sky": {"type": "constant", "radiance": float(SKY_RADIANCE)},
    }
    for i, (pos, intensity) in enumerate(POINT_LIGHTS):
        scene[f"light{i}"] = {"type": "point", "position": list(pos),
                              "intensity": float(intensity)}
    v, f = _merge(_tank_parts())
    scene["tank"] = _mesh(mi, dr, "tank", v, f, bsdfs["Au"])
    for metal, geom in PYRAMIDS.items():
        v, f = _pyramid(*geom)
        scene[f"pyramid_{metal}"] = _mesh(mi, dr, f"pyramid_{metal}", v, f, bsdfs[metal])
    return scene


def check_render_options(*, size, spp, seed, max_depth=MAX_DEPTH) -> None:
    """Raise :class:`ParameterError` naming the first of *size* (16 … 2048), *spp*
    (1 … 4096), *seed* (0 … 2^32 − 1, Mitsuba's), *max_depth* (2 … 64) that is not an
    allowed integer, or when size × height × spp exceeds
    :data:`~brdfkit.render.mitsuba_bridge.MAX_SAMPLES` (2^30 samples per render)."""
    for name, value, lo, hi in (("size", size, 16, 2048), ("spp", spp, 1, 4096),
                                ("max_depth", max_depth, 2, 64)):
        if not (isinstance(value, (int, np.integer)) and lo <= value <= hi):
            raise ParameterError(f"{name} must be an integer in [{lo}, {hi}]; got {value!r}")
    check_seed(seed)
    check_samples(int(size) * max(1, round(ASPECT * int(size))), spp)


def render_tank(phong: BRDF, *, size: int = 320, spp: int = 16, seed: int = 0,
                wavelengths=WAVELENGTHS, max_depth: int = MAX_DEPTH,
                progress: Callable[[], None] | None = None) -> np.ndarray:
    """Spectral radiance of the tank scene with every metal as *phong* times its Fresnel.

    Parameters
    ----------
    phong : BRDF
        A grey model (plain or pumped reciprocal Phong); each metal's surface is
        :func:`~brdfkit.render.metals.metal_phong` (*phong*, n, k of the metal).
    size : int, keyword-only
        Image width in pixels, 16 … 2048; the height is round(ASPECT · size).
    spp : int, keyword-only
        Samples per pixel, 1 … 4096 (noise falls as 1/√spp).
    seed : int, keyword-only
        Mitsuba's sampler seed (the same for every wavelength).
    wavelengths : array_like, keyword-only
        nm (default the 8 of :data:`~brdfkit.render.metals.WAVELENGTHS`).
    max_depth : int, keyword-only
        Mitsuba's path length cap (2: direct light only).
    progress : callable, optional
        Called with no argument after each render (one per 3 wavelengths).

    Returns
    -------
    ndarray (H, W, K), float64
        Linear radiance per pixel and wavelength (pixel-area average), the
        sky's radiance being :data:`SKY_RADIANCE`.
    """
    if not isinstance(phong, BRDF):
        raise ParameterError(f"phong must be a brdfkit model (BRDF); got {type(phong)!r}")
    check_render_options(size=size, spp=spp, seed=seed, max_depth=max_depth)
    lam = np.asarray(wavelengths, dtype=np.float64)
    nk = {m: metal_nk(m, lam) for m in METALS}
    mi, _ = _mitsuba()
    use_variant("llvm_ad_rgb")
    width, height = int(size), max(1, round(ASPECT * int(size)))
    out = np.empty((height, width, lam.size))
    for start in range(0, lam.size, PACK):
        # 3 wavelengths per render; the last pack repeats its last wavelength to fill RGB
        idx = np.minimum(np.arange(start, start + PACK), lam.size - 1)
        bsdfs = {m: mitsuba_bsdf(metal_phong(phong, n[idx], k[idx])) for m, (n, k) in nk.items()}
        scene = mi.load_dict(tank_scene(bsdfs, width=width, height=height,
                                        max_depth=max_depth))
        # traced BSDFs render in Dr.Jit's default symbolic mode; wavefront ones need it off
        traced = all(b.traced for b in bsdfs.values())
        with contextlib.nullcontext() if traced else wavefront():
            image = render_bounded(scene, spp=spp, seed=seed, pixels=width * height)
        keep = idx[: min(PACK, lam.size - start)]
        out[:, :, keep] = image[:, :, : keep.size]
        del scene, bsdfs
        if progress is not None:
            progress()
    return out
