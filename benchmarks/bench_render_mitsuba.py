"""Render time: brdfkit ``microfacet`` through the Mitsuba bridge vs Mitsuba's ``roughconductor``.

Scene: the sphere test configuration (``brdfkit.render.mitsuba_sphere.sphere_scene``):
orthographic camera from +z, unit sphere, directional light at Φ_L = 45° (E = 1) and a
constant environment L_a = 0.2, ``path`` integrator with max_depth 2, S×S pixels,
``--spp`` samples per pixel. The sphere's BSDF is, in ``llvm_ad_rgb``:

- ``roughconductor``: Mitsuba's own GGX conductor (α = 0.2, eta/k of the RGB set below,
  visible-normal sampling, its default), rendered in Dr.Jit's default symbolic mode
  (one fused kernel: how Mitsuba is normally run) — the baseline of the ratios;
- ``roughconductor (wavefront)``: the same with the symbolic modes off (the mode the
  wavefront route needs), to separate the cost of the mode from the cost of the bridge;
- ``bridge microfacet GGX (traced)``: ``brdfkit.model("microfacet", distribution="ggx",
  alpha=0.2, eta=…, k=…)`` through ``mitsuba_bsdf`` — its formulas (``brdfkit._dual``,
  the code Numba compiles for ``model.eval``/``sample``/``pdf``) traced by Dr.Jit into
  Mitsuba's kernel, symbolic mode: the bridge's route for this model;
- ``bridge microfacet GGX (wavefront route)``: the same model with ``route="wavefront"``
  (NumPy/Numba on every wavefront), for comparison;
- ``bridge lambert`` (traced: its formulas, as microfacet's; and with
  ``route="wavefront"``) and Mitsuba's ``diffuse`` (ρ = 0.5): the cheapest pair;

in ``llvm_ad_rgb`` again, measured materials (issue 23): ``merl:nickel`` (the NBRDF net),
``@npf``, ``@abc``, ``@sgd`` and a MERL table (``@abc`` tabulated on the MERL grid, linear
lookup, one Dr.Jit array gathered in the kernel) on the traced route (their formulas,
the proxy sampler), ``merl:nickel`` and the table on the wavefront route too, against
Mitsuba's ``roughconductor`` of nickel's proxy α (the GGX α fitted to the material's
lobe, :func:`brdfkit.user.proxy_sampler.proxy_args`) — the closest native BSDF; the
images of a material are compared between its two routes (different samplers of one
f_r: within Monte-Carlo noise);

in ``llvm_ad_rgb`` again, the last four model kinds ported to the traced route (issue 23,
``--sections ported``): ``lafortune`` (one lobe, and the two-lobe example) and
``nh-power-series`` (three terms) against Mitsuba's ``roughplastic`` (GGX of the lobe's
proxy α, the same diffuse ρ) — a diffuse + glossy pair, the closest native BSDF — and
against the traced ``modified-phong`` (a cosⁿ lobe, their Dr.Jit twin of one lobe);
``he-torrance`` (σ₀ = 0.1: 16 terms of D's series; σ₀ = 0.3: 54) against
``roughconductor`` (Beckmann, α = its sampler's m); the GGX conductor compensated by
Kulla–Conty against ``roughconductor`` of the same α, η, k (the ratio is the cost of the
compensation); and the wavefront route of lafortune, he-torrance and the compensated
conductor for comparison. The extra column ``vs twin`` is the row's median over the
named twin's;

with ``--sections registry``, every registered model at its defaults (``brdfkit.models.
MODELS``) and a pumped model (``modified-phong`` pumped ``controlled`` twice) on the traced
route, each against the closest native Mitsuba BSDF chosen from its lobes
(:func:`closest_native`): ``diffuse`` for a model whose lobes are all diffuse or about the
normal, ``roughplastic`` (GGX of the proxy sampler's α, ``brdfkit.models.proxy_sampler.
proxy_args``) for a diffuse + glossy model, ``roughconductor`` (the same α; its own α_x,
α_y for ``microfacet-anisotropic``) for a glossy-only one — the ``vs twin`` column is the
target's ratio (≤ 1.5, issue 23);

and in ``llvm_ad_spectral`` a gold-like metal with n(λ), k(λ) on a 16-point grid over
360-830 nm: Mitsuba's ``roughconductor`` with the grid as ``irregular`` spectra against
the bridge's traced ``spectral_model("microfacet", …)`` (parameters interpolated at each
path's wavelengths).

Each row: the median over ``--repeats`` renders (after one warm-up render that compiles
the kernels), all rows in one process, side by side; the symbolic rows' renders
interleaved (a change of load falls on all of them alike), ``--traced-only`` leaves out
the (slow) wavefront rows. The ratio column is the row's
median over the native ``roughconductor`` (symbolic) median of its variant; the target
of issue 11 is ≤ 2 for the bridge's microfacet. The script also checks that the bridge
and the native images agree: the sum over the image of the differences of the two mean
images within 3 standard errors (per-pixel variances from the repeats, pixels
independent), and that the two routes of the bridge, which draw the same directions from
the same random numbers, give the same image up to float32 rounding.

The machine is shared: the load average is printed before and after.

Usage::

    .venv/bin/python benchmarks/bench_render_mitsuba.py            # 256², 16 spp, 5 repeats
    .venv/bin/python benchmarks/bench_render_mitsuba.py --size 128 --spp 8 --repeats 3
    .venv/bin/python benchmarks/bench_render_mitsuba.py --sections ported --size 128
"""

from __future__ import annotations

import argparse
import gc
import math
import os
import statistics
import time

import numpy as np

import brdfkit
from brdfkit.render.mitsuba_bridge import mitsuba_bsdf, spectral_model, use_variant, wavefront
from brdfkit.render.mitsuba_sphere import sphere_scene

ALPHA = 0.2
ETA = [0.2, 0.9, 1.1]
K = [3.9, 2.4, 2.2]
PHI_L = math.radians(45.0)
GRID = np.linspace(360.0, 830.0, 16)  # nm, the spectral rows' grid


def n_gold_like(lam):
    """A gold-like n(λ), k(λ), linear in λ (F₀ ≈ 0.37 at 360 nm, 0.97 at 830 nm)."""
    return 1.5 - 1.35 * (lam - 360.0) / 470.0


def k_gold_like(lam):
    return 1.8 + 2.7 * (lam - 360.0) / 470.0


def _irregular(values) -> dict:
    return {"type": "irregular", "wavelengths": ", ".join(f"{x:g}" for x in GRID),
            "values": ", ".join(f"{x:.6g}" for x in values)}


def time_rows(mi, rows, variant, args) -> dict:
    """{name: (median seconds, images (R, S, S, C))} of each (name, make, wavefront) row.

    The symbolic rows' renders are interleaved (repeat r of every row, then repeat r + 1),
    so that a change of the shared machine's load falls on every row alike; the wavefront
    rows follow one by one (while a wavefront BSDF object is alive, Dr.Jit's symbolic
    calls trace it too and fail)."""
    results = {}
    if args.traced_only:
        rows = [r for r in rows if not r[2]]

    def render(scene, seed, wave):
        if wave:
            with wavefront():
                return np.array(mi.render(scene, spp=args.spp, seed=seed))
        return np.array(mi.render(scene, spp=args.spp, seed=seed))

    def scene_of(make):
        return mi.load_dict(sphere_scene(make(), phi_l=PHI_L, ambient=0.2, size=args.size,
                                         variant=variant))

    symbolic = [(name, scene_of(make)) for name, make, wave in rows if not wave]
    for _, scene in symbolic:
        render(scene, 1000, False)  # warm-up: kernel compilation
    times = {name: [] for name, _ in symbolic}
    images = {name: [] for name, _ in symbolic}
    for r in range(args.repeats):
        for name, scene in symbolic:
            t0 = time.perf_counter()
            images[name].append(render(scene, r, False))
            times[name].append(time.perf_counter() - t0)
    for name, _ in symbolic:
        results[name] = (statistics.median(times[name]), np.stack(images[name]))
    del symbolic
    gc.collect()
    for name, make, wave in rows:
        if not wave:
            continue
        scene = scene_of(make)
        render(scene, 1000, True)
        t, im = [], []
        for r in range(args.repeats):
            t0 = time.perf_counter()
            im.append(render(scene, r, True))
            t.append(time.perf_counter() - t0)
        results[name] = (statistics.median(t), np.stack(im))
        del scene  # dropped after its row (the symbolic calls above)
        gc.collect()
    return results


def report(results, rows, variant, args, pairs, same, twins=None) -> None:
    """The table (ratio: over the first row; ``vs twin``: over the row *twins* names)."""
    base = results[rows[0][0]][0]
    twins = twins or {}
    print(f"\n{variant}: {args.size}² pixels, {args.spp} spp, {args.repeats} repeats")
    print(f"{'renderer':44s} {'median s':>9s} {'ratio':>7s}"
          + (f" {'vs twin':>8s}  twin" if twins else ""))
    for name, _, _ in rows:
        if name not in results:
            continue  # --traced-only
        t = results[name][0]
        twin = twins.get(name)
        extra = f" {t / results[twin][0]:8.2f}  {twin}" if twin else ""
        print(f"{name:44s} {t:9.3f} {t / base:7.2f}{extra}")
    for a, b in pairs:  # agreement: the image sums within 3 standard errors
        if a not in results or b not in results:
            continue  # --traced-only
        ia, ib = results[a][1], results[b][1]
        d = ia.mean(axis=0) - ib.mean(axis=0)
        var = (ia.var(axis=0, ddof=1) + ib.var(axis=0, ddof=1)) / args.repeats
        z = d.sum() / math.sqrt(var.sum())
        print(f"agreement {b} vs {a}: mean difference {d.mean():+.2e}, z = {z:+.2f}"
              f"{'' if abs(z) < 3 else '  <-- DISAGREE'}")
    for a, b in same:  # the same directions from the same numbers: equal images
        if a not in results or b not in results:
            continue  # --traced-only
        diff = np.abs(results[a][1] - results[b][1]).max()
        print(f"largest pixel difference, {a} vs {b} (same seeds): {diff:.2e}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--sections", default="rgb,measured,ported,registry,spectral",
                    help="comma-separated subset of rgb, measured, ported, registry, spectral")
    ap.add_argument("--traced-only", action="store_true",
                    help="leave out the wavefront-route rows (slow; the images' agreement "
                         "between the routes is then not checked)")
    args = ap.parse_args()
    sections = set(args.sections.split(","))

    import mitsuba as mi

    print(f"load average before: {os.getloadavg()[0]:.2f}")
    if "rgb" in sections:
        rgb_rows(mi, args)
    if "measured" in sections:
        measured_rows(mi, args)
    if "ported" in sections:
        ported_rows(mi, args)
    if "registry" in sections:
        registry_rows(mi, args)
    if "spectral" in sections:
        spectral_rows(mi, args)
    print(f"\nload average after: {os.getloadavg()[0]:.2f}")


def rgb_rows(mi, args) -> None:
    variant = use_variant("llvm_ad_rgb")
    model = brdfkit.model("microfacet", distribution="ggx", alpha=ALPHA, eta=ETA, k=K)
    native = {"type": "roughconductor", "distribution": "ggx", "alpha": ALPHA,
              "eta": {"type": "rgb", "value": ETA}, "k": {"type": "rgb", "value": K}}
    rows = [
        ("roughconductor (Mitsuba, symbolic)", lambda: native, False),
        ("roughconductor (Mitsuba, wavefront)", lambda: native, True),
        ("bridge microfacet GGX (traced)", lambda: mitsuba_bsdf(model), False),
        ("bridge microfacet GGX (wavefront route)",
         lambda: mitsuba_bsdf(model, route="wavefront"), True),
        ("diffuse (Mitsuba, symbolic)", lambda: {"type": "diffuse", "reflectance": 0.5}, False),
        ("bridge lambert (traced)",
         lambda: mitsuba_bsdf(brdfkit.model("lambert", rho_d=0.5)), False),
        ("bridge lambert (wavefront route)",
         lambda: mitsuba_bsdf(brdfkit.model("lambert", rho_d=0.5), route="wavefront"), True),
    ]
    results = time_rows(mi, rows, variant, args)
    report(results, rows, variant, args,
           pairs=[(rows[0][0], rows[2][0]), (rows[0][0], rows[3][0]), (rows[4][0], rows[5][0]),
                  (rows[4][0], rows[6][0])],
           same=[(rows[2][0], rows[3][0]), (rows[5][0], rows[6][0])])


def measured_rows(mi, args) -> None:
    from brdfkit.data.measured import MeasuredBRDF
    from brdfkit.data.merl import table_from_function
    from brdfkit.user.proxy_sampler import proxy_args

    variant = use_variant("llvm_ad_rgb")
    nickel = brdfkit.model("merl:nickel")
    table = MeasuredBRDF(table_from_function(brdfkit.model("merl:nickel@abc").eval,
                                             source="nickel@abc"), lookup="linear")
    alpha = proxy_args(nickel)[0]
    # nickel's n, k at ~650, 550, 450 nm (Johnson & Christy 1974 / refractiveindex.info)
    native = {"type": "roughconductor", "distribution": "ggx", "alpha": alpha,
              "eta": {"type": "rgb", "value": [2.0, 1.8, 1.6]},
              "k": {"type": "rgb", "value": [3.9, 3.4, 2.8]}}
    rows = [
        (f"roughconductor α={alpha:.3f} (Mitsuba, symbolic)", lambda: native, False),
        ("merl:nickel NBRDF (traced)", lambda: mitsuba_bsdf(nickel), False),
        ("merl:nickel NBRDF (wavefront route)",
         lambda: mitsuba_bsdf(nickel, route="wavefront"), True),
        ("merl:nickel@npf (traced)", lambda: mitsuba_bsdf(brdfkit.model("merl:nickel@npf")),
         False),
        ("merl:nickel@abc (traced)", lambda: mitsuba_bsdf(brdfkit.model("merl:nickel@abc")),
         False),
        ("merl:nickel@sgd (traced)", lambda: mitsuba_bsdf(brdfkit.model("merl:nickel@sgd")),
         False),
        ("MERL table, nearest (traced)",
         lambda: mitsuba_bsdf(table.with_params(lookup="nearest")), False),
        ("MERL table, linear (traced)", lambda: mitsuba_bsdf(table), False),
        ("MERL table, linear (wavefront route)",
         lambda: mitsuba_bsdf(table, route="wavefront"), True),
    ]
    results = time_rows(mi, rows, variant, args)
    report(results, rows, variant, args,
           pairs=[(rows[1][0], rows[2][0]), (rows[7][0], rows[8][0])], same=[])


def ported_rows(mi, args) -> None:
    import warnings

    from brdfkit.user.proxy_sampler import proxy_args

    variant = use_variant("llvm_ad_rgb")
    laf = brdfkit.model("lafortune", rho_d=0.2, rho_s=1.0, n=20.0)
    laf2 = brdfkit.model("lafortune", C_xy=[-1.0, -0.9], C_z=[1.0, 0.7], n=[20.0, 5.0])
    nhs = brdfkit.model("nh-power-series", k_s=[0.06, 0.5, 5.0], n=[0.0, 10.0, 200.0])
    phong = brdfkit.model("modified-phong", rho_d=0.2, rho_s=0.5, n=20.0)
    ht = brdfkit.model("he-torrance", sigma0=0.1, tau=1.7, rho_d=0.1)
    ht3 = brdfkit.model("he-torrance", sigma0=0.3, tau=3.0, rho_d=0.1)
    kc = brdfkit.compensate(brdfkit.model("microfacet", distribution="ggx", alpha=0.5,
                                          eta=ETA, k=K), "kulla-conty")
    a_laf = proxy_args(laf)[0]
    plastic = {"type": "roughplastic", "distribution": "ggx", "alpha": a_laf,
               "diffuse_reflectance": {"type": "rgb", "value": [0.2, 0.2, 0.2]}}
    conductor = {"type": "roughconductor", "distribution": "ggx", "alpha": 0.5,
                 "eta": {"type": "rgb", "value": ETA}, "k": {"type": "rgb", "value": K}}

    def beckmann(m):
        return {"type": "roughconductor", "distribution": "beckmann", "alpha": m}

    def bsdf(model, **kw):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # he-torrance: its delta is not rendered
            return mitsuba_bsdf(model, **kw)

    rows = [
        (f"roughplastic α={a_laf:.3f} (Mitsuba, symbolic)", lambda: plastic, False),
        ("bridge modified-phong n=20 (traced)", lambda: bsdf(phong), False),
        ("bridge lafortune 1 lobe (traced)", lambda: bsdf(laf), False),
        ("bridge lafortune 2 lobes (traced)", lambda: bsdf(laf2), False),
        ("bridge lafortune 1 lobe (wavefront route)",
         lambda: bsdf(laf, route="wavefront"), True),
        ("bridge nh-power-series 3 terms (traced)", lambda: bsdf(nhs), False),
        (f"roughconductor beckmann α={ht._sampling_m():.3f} (Mitsuba)",
         lambda: beckmann(ht._sampling_m()), False),
        ("bridge he-torrance σ0=0.1, 16 terms (traced)", lambda: bsdf(ht), False),
        ("bridge he-torrance σ0=0.1 (wavefront route)",
         lambda: bsdf(ht, route="wavefront"), True),
        (f"roughconductor beckmann α={ht3._sampling_m():.3f} (Mitsuba)",
         lambda: beckmann(ht3._sampling_m()), False),
        ("bridge he-torrance σ0=0.3, 54 terms (traced)", lambda: bsdf(ht3), False),
        ("roughconductor GGX α=0.5 (Mitsuba, symbolic)", lambda: conductor, False),
        ("bridge microfacet+kulla-conty (traced)", lambda: bsdf(kc), False),
        ("bridge microfacet+kulla-conty (wavefront)", lambda: bsdf(kc, route="wavefront"),
         True),
    ]
    n = [r[0] for r in rows]
    twins = {n[1]: n[0], n[2]: n[0], n[3]: n[0], n[4]: n[0], n[5]: n[0], n[7]: n[6],
             n[8]: n[6], n[10]: n[9], n[12]: n[11], n[13]: n[11]}
    results = time_rows(mi, rows, variant, args)
    report(results, rows, variant, args,
           pairs=[(n[2], n[4]), (n[7], n[8]), (n[12], n[13])], same=[], twins=twins)
    for a in (n[2], n[3], n[5]):
        print(f"{a} vs {n[1]}: {results[a][0] / results[n[1]][0]:.2f}")


def closest_native(model) -> tuple[str, dict]:
    """(label, Mitsuba BSDF dict) of the native BSDF closest to *model* (module docstring)."""
    from brdfkit.models.proxy_sampler import proxy_args

    lobes = model.lobes()
    glossy = [lb for lb in lobes if lb.kind in ("mirror", "half")]
    if not glossy:
        return "diffuse", {"type": "diffuse", "reflectance": 0.5}
    if model.name == "microfacet-anisotropic":
        ax, ay = (float(model.values[k]) for k in ("alpha_x", "alpha_y"))
        return (f"roughconductor GGX αu={ax:g} αv={ay:g}",
                {"type": "roughconductor", "distribution": "ggx", "alpha_u": ax,
                 "alpha_v": ay})
    alpha = proxy_args(model)[0]
    if len(glossy) < len(lobes):  # a diffuse lobe beside the glossy one
        return (f"roughplastic GGX α={alpha:.3f}",
                {"type": "roughplastic", "distribution": "ggx", "alpha": alpha,
                 "diffuse_reflectance": {"type": "rgb", "value": [0.2, 0.2, 0.2]}})
    return (f"roughconductor GGX α={alpha:.3f}",
            {"type": "roughconductor", "distribution": "ggx", "alpha": alpha})


def registry_rows(mi, args) -> None:
    import warnings

    from brdfkit.models import MODELS
    from brdfkit.pumping import pump

    variant = use_variant("llvm_ad_rgb")
    models = [(name, brdfkit.model(name)) for name in MODELS]
    models.append(("pumped modified-phong (controlled, 2 times)",
                   pump(brdfkit.model("modified-phong"), "controlled", times=2)))
    natives, twins, rows = {}, {}, []
    for label, model in models:
        native, bsdf_dict = closest_native(model)
        if native not in natives:
            natives[native] = bsdf_dict
            rows.append((f"{native} (Mitsuba)", lambda d=bsdf_dict: d, False))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # he-torrance: its delta is not rendered
            route = "traced" if mitsuba_bsdf(model).traced else "wavefront route"
        name = f"bridge {label} ({route})"
        twins[name] = f"{native} (Mitsuba)"

        def make(m=model):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                return mitsuba_bsdf(m)

        rows.append((name, make, False))
    results = time_rows(mi, rows, variant, args)
    report(results, rows, variant, args, pairs=[], same=[], twins=twins)
    worst = max(twins, key=lambda n: results[n][0] / results[twins[n]][0])
    print(f"largest ratio to the closest native BSDF: "
          f"{results[worst][0] / results[twins[worst]][0]:.2f} ({worst}); target <= 1.5")


def spectral_rows(mi, args) -> None:
    variant = use_variant("llvm_ad_spectral")
    metal, grid = spectral_model("microfacet", GRID, distribution="ggx", alpha=ALPHA,
                                 eta=n_gold_like, k=k_gold_like)
    native_s = {"type": "roughconductor", "distribution": "ggx", "alpha": ALPHA,
                "eta": _irregular(n_gold_like(GRID)), "k": _irregular(k_gold_like(GRID))}
    rows = [
        ("roughconductor (Mitsuba, symbolic)", lambda: native_s, False),
        ("bridge microfacet GGX (traced)", lambda: mitsuba_bsdf(metal, wavelengths=grid),
         False),
        ("bridge microfacet GGX (wavefront route)",
         lambda: mitsuba_bsdf(metal, wavelengths=grid, route="wavefront"), True),
    ]
    results = time_rows(mi, rows, variant, args)
    report(results, rows, variant, args,
           pairs=[(rows[0][0], rows[1][0]), (rows[0][0], rows[2][0])], same=[])


if __name__ == "__main__":
    main()
