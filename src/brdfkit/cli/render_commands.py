"""
Render commands: ``brdfkit render sphere``
==========================================

- ``brdfkit render sphere MODEL [-p …] [--pump …] --phi-l DEG [--ambient L_a]
  [--irradiance E] [--size S] [--engine direct] [--spp N] [--exposure K|phi0|peak]
  --out FILE`` — Lewis's sphere test configuration computed exactly
  (:func:`brdfkit.render.render_sphere`), written as ``.npy``/``.exr`` (linear
  radiance) or ``.png`` (sRGB with the stated exposure). Prints the path, or
  the render's metadata with ``--json``.

Angles are in degrees on the command line. ``--engine mitsuba --spp N`` renders the
same configuration by Monte Carlo through Mitsuba 3 (brdfkit's model as the BSDF).
"""

from __future__ import annotations

import math

import click
import numpy as np

import brdfkit.cli._progress as _progress
from brdfkit import _io
from brdfkit.cli._common import build_model, build_model_words, emit_json, model_options
from brdfkit.errors import BrdfkitError
from brdfkit.render import MAX_SIZE, SUFFIXES, exposure_phi0, render_sphere, save_render
from brdfkit.render.image import save_panels
from brdfkit.render.mitsuba_bridge import (
    MAX_SAMPLES,
    MITSUBA_MAX_SIZE,
    SEED_LIMIT,
    VARIANTS,
    check_samples,
)
from brdfkit.render.silhouette import DEFAULT_ANTIALIAS, MAX_ANTIALIAS
from brdfkit.render.sphere import BYTES_PER_VALUE, DEFAULT_SPP

__all__ = ["render_group", "sphere_cmd", "parse_exposure", "MAX_COMPARE"]

#: Most --compare models of one render (four panels side by side).
MAX_COMPARE = 3
#: A render is "black but for its highlight" when fewer than this share of the disc's
#: pixels reach DARK_LEVEL of its peak (a metal with α = 0.05 under one light: ~1 %).
DARK_SHARE = 0.05
#: The level, relative to the peak, below which a pixel reads as black on a display (8-bit
#: sRGB: 1 % is code 25 of 255).
DARK_LEVEL = 0.01


def _mostly_dark(result) -> bool:
    """Whether fewer than DARK_SHARE of the disc's pixels reach DARK_LEVEL of the peak."""
    disc = result.radiance[result.mask].max(axis=-1)
    peak = float(disc.max()) if disc.size else 0.0
    return peak > 0.0 and float(np.mean(disc >= DARK_LEVEL * peak)) < DARK_SHARE


def parse_exposure(text: str) -> float | str:
    """``phi0`` | ``peak`` | a number > 0 → the exposure rule or factor."""
    s = str(text).strip().lower()
    if s in ("phi0", "peak"):
        return s
    try:
        k = float(s)
    except ValueError:
        k = math.nan
    if not (k > 0.0 and math.isfinite(k)):
        raise BrdfkitError(f"--exposure must be 'phi0', 'peak' or a number > 0 (display value "
                           f"= min(1, K x radiance) before sRGB encoding); got {text!r}")
    return k


@click.group("render")
def render_group() -> None:
    """Render images of a model (exact sphere test configuration)."""


@render_group.command("sphere")
@model_options
@click.option("--phi-l", "phi_l", type=float, required=True, metavar="DEG",
              help="Angle between the light and the view direction, DEGREES in [0, 180]; the "
                   "light shines from L = (sin phi_L, 0, cos phi_L), the viewer is at +z.")
@click.option("--ambient", type=float, default=0.0, show_default=True, metavar="L_A",
              help="Uniform ambient radiance L_a >= 0 over every normal's hemisphere; it adds "
                   "L_a x rho(V), rho computed by the albedo engine.")
@click.option("--irradiance", type=float, default=1.0, show_default=True, metavar="E",
              help="Irradiance E >= 0 of the directional light on a surface facing it.")
@click.option("--size", type=int, default=256, show_default=True, metavar="S",
              help=f"Image side in pixels: 1 to {MAX_SIZE} (direct; ~{BYTES_PER_VALUE} bytes "
                   f"per pixel and channel at peak, 9.7 GB for RGB at {MAX_SIZE}), 1 to "
                   f"{MITSUBA_MAX_SIZE} (mitsuba).")
@click.option("--engine", type=click.Choice(["direct", "mitsuba"]), default="direct",
              show_default=True,
              help="direct: exact, deterministic. mitsuba: Monte Carlo through Mitsuba 3 "
                   "with brdfkit's sampler (pixel-area averages; noise ~ 1/sqrt(spp)).")
@click.option("--spp", type=int, default=None, metavar="N",
              help=f"Samples per pixel of --engine mitsuba (default {DEFAULT_SPP}, at most "
                   f"65536 and S² x N <= {MAX_SAMPLES:.3g} = 2^30); the direct engine takes "
                   "none. Cost "
                   "(2 cores): ~0.26 M samples/s for most models, ~3 M/s for microfacet; "
                   "memory stays under ~3 GB (renders are split into calls of 2^20 "
                   "paths).")
@click.option("--seed", type=click.IntRange(0, SEED_LIMIT - 1), default=0, show_default=True,
              help=f"Sampler seed of --engine mitsuba, 0 to {SEED_LIMIT - 1} (Mitsuba's seeds "
                   "are 32-bit; the render is deterministic given it).")
@click.option("--variant", default=None, metavar="NAME",
              help=f"Mitsuba variant of --engine mitsuba: {', '.join(VARIANTS)} (default "
                   "llvm_ad_rgb; mono renders luminance); the direct engine takes none.")
@click.option("--antialias", type=int, default=None, metavar="N",
              help=f"Direct engine: sub-samples per axis of each pixel the sphere's rim "
                   f"crosses, averaged (1 to {MAX_ANTIALIAS}; default {DEFAULT_ANTIALIAS}: "
                   "a smooth silhouette); 1 evaluates every pixel at its centre only.")
@click.option("--exposure", default="phi0", show_default=True, metavar="K|phi0|peak",
              help="PNG only: display value = sRGB(min(1, K x radiance)). phi0: K = 1/peak "
                   "of the same sphere lit at phi_L = 0 (Lewis's rule: held constant across "
                   "a series); peak: K = 1/peak of this image.")
@click.option("--out", required=True, metavar="FILE",
              help="Output file: .png (sRGB), .exr (linear, 32-bit float) or .npy (linear, "
                   "float64). Written atomically.")
@click.option("--compare", multiple=True, metavar="'SPEC [-p NAME=VALUE]...'",
              help=f"Render this model too, beside MODEL in one image at one exposure "
                   f"(repeatable, up to {MAX_COMPARE}): a spec with its own -p, --compensate, "
                   "--pump, --times words, quoted, e.g. --compare 'nielsen -p k_s=5'. Panels "
                   "left to right, S/32 black pixels apart; phi0/peak expose the brightest "
                   "of them.")
@click.option("--json", "as_json", is_flag=True, help="Print the render's metadata as JSON.")
def sphere_cmd(model, param, compensate, pump, times, phi_l, ambient, irradiance, size, engine,
               spp, seed, variant, antialias, compare, exposure, out, as_json):
    """Render MODEL on Lewis's sphere test configuration (Lewis 1993, Fig. 2).

    An S x S orthographic image of the unit sphere seen from +z, one
    directional light at phi_L from the viewer and an optional uniform
    ambient radiance; radiance E f_r(L, V) max(N.L, 0) + L_a rho(V) at each
    pixel centre (the rim's pixels: the mean of --antialias^2 sub-samples), 0 outside
    the disc (docs/rendering.md).
    """
    if engine == "mitsuba" and antialias is not None:
        raise BrdfkitError(f"--antialias {antialias}: the mitsuba engine averages every "
                           "pixel's area itself; drop --antialias (it is for --engine direct)")
    if antialias is not None and not 1 <= antialias <= MAX_ANTIALIAS:
        raise BrdfkitError(f"--antialias must be an integer from 1 to {MAX_ANTIALIAS}; got "
                           f"{antialias}")
    if engine == "direct" and variant is not None:
        raise BrdfkitError(f"--variant {variant}: the direct engine is exact and runs no "
                           "Mitsuba; drop --variant (it is for --engine mitsuba)")
    if variant is not None and variant not in VARIANTS:
        raise BrdfkitError(f"--variant must be one of {', '.join(VARIANTS)}; got {variant!r}")
    aa = ({"variant": variant} if variant else {}) if engine == "mitsuba" else \
        {"antialias": antialias or DEFAULT_ANTIALIAS}
    if engine == "direct" and spp is not None:
        raise BrdfkitError(f"--spp {spp}: the direct engine is exact and takes no samples; "
                           "drop --spp (it is for --engine mitsuba)")
    if spp is not None and not 1 <= spp <= 65536:
        raise BrdfkitError(f"--spp must be an integer from 1 to 65536; got {spp}")
    if engine == "mitsuba" and phi_l > 90.0:
        raise BrdfkitError(f"--phi-l {phi_l}: the mitsuba engine lights from the front "
                           "hemisphere, 0 to 90 degrees; use --engine direct beyond")
    if not 0.0 <= phi_l <= 180.0:  # also refuses NaN
        raise BrdfkitError(f"--phi-l must lie in [0, 180] degrees; got {phi_l}")
    for name, v in (("--ambient", ambient), ("--irradiance", irradiance)):
        if not (v >= 0.0 and math.isfinite(v)):
            raise BrdfkitError(f"{name} must be a finite number >= 0; got {v}")
    if not 1 <= size <= MAX_SIZE:
        raise BrdfkitError(f"--size must be an integer from 1 to {MAX_SIZE} pixels; got {size}")
    if engine == "mitsuba":
        if size > MITSUBA_MAX_SIZE:
            raise BrdfkitError(f"--size {size}: the mitsuba engine renders at most "
                               f"{MITSUBA_MAX_SIZE} pixels a side (one sample per pixel of "
                               f"{MITSUBA_MAX_SIZE}² is ~2.5 GB of paths); use a smaller "
                               "--size or --engine direct")
        check_samples(size * size, DEFAULT_SPP if spp is None else spp, size_name="--size")
    rule = parse_exposure(exposure)
    _io.check_output_path(out, option="--out", suffixes=SUFFIXES)  # before any work
    if len(compare) > MAX_COMPARE:
        raise BrdfkitError(f"--compare takes at most {MAX_COMPARE} models (one image of "
                           f"{MAX_COMPARE + 1} panels); got {len(compare)}")
    with _progress.working(f"rendering {model}" + (f" and {len(compare)} more" if compare
                                                   else ""), as_json=as_json):
        models = [build_model(model, param, pump, times, compensate),
                  *(build_model_words(c, option="--compare") for c in compare)]
        results = [render_sphere(m, phi_l=math.radians(phi_l), ambient=ambient,
                                 irradiance=irradiance, size=size, engine=engine, spp=spp,
                                 seed=seed, **aa) for m in models]
    if not all(np.all(np.isfinite(r.radiance)) for r in results):
        raise BrdfkitError(f"the radiance is not finite (it overflows at --irradiance "
                           f"{irradiance:g}, --ambient {ambient:g}); lower them ({out} is not "
                           "written)")
    if ambient == 0.0 and any(_mostly_dark(r) for r in results):
        click.echo("brdfkit: note: the sphere is black but for its highlight (a glossy or "
                   "metallic model under one light); --ambient 0.5 adds uniform light that "
                   "shows its whole response", err=True)
    k, how = None, ""
    if out.lower().endswith(".png"):
        several = " (the brightest of the panels)" if len(results) > 1 else ""
        if rule == "phi0":
            k = min(exposure_phi0(m, ambient=ambient, irradiance=irradiance, size=size)
                    for m in models)
            how = "1/peak of the same sphere at phi_L = 0 (Lewis 1993 Sec. 3.3)" + several
        elif rule == "peak":
            peak = max(r.peak for r in results)
            if not peak > 0.0:
                raise BrdfkitError("--exposure peak: the image is black (peak radiance 0); "
                                   "give --exposure K")
            k, how = 1.0 / peak, "1/peak of this image" + several
        else:
            k, how = rule, "given (--exposure)"
    if len(results) == 1:
        save_render(results[0], out, exposure=k, exposure_rule=how, option="--out")
        meta = dict(results[0].metadata(), out=out, exposure=k, exposure_rule=how)
    else:
        meta = {"panels": [r.metadata() for r in results], "out": out, "exposure": k,
                "exposure_rule": how}
        save_panels([r.radiance for r in results], out, exposure=k, metadata=meta,
                    exposure_rule=how, option="--out")
    if as_json:
        emit_json(meta)
    else:
        click.echo(out)

