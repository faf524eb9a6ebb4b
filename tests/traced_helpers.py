"""Helpers of the tests that compare brdfkit's formulas with their Mitsuba traced versions.

Shared by tests/test_mitsuba_derived.py, test_formulas_measured.py, test_formulas_families.py,
test_render_mitsuba.py, test_rough_diffuse_mitsuba.py and test_user_traced.py (each had its
own copy): the Mitsuba variant with its fallback warning silenced, and direction sets
rounded to float32 (what a traced BSDF sees), so that both sides evaluate the same
directions. Nothing here imports Mitsuba before a test asks for a variant.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest


def variant(name: str, *, llvm: bool = False) -> str:
    """``use_variant(name)`` (its scalar fallback's RuntimeWarning silenced: the library's
    own warning, tested in test_render_mitsuba.py); *llvm*: skip unless an llvm variant
    was set (the traced route needs one)."""
    from brdfkit.render.mitsuba_bridge import use_variant

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        got = use_variant(name)
    if llvm and not got.startswith("llvm"):
        pytest.skip(f"the traced route needs an llvm variant ({name} fell back to {got})")
    return got


def _hemisphere64(rng, n: int, lo: float) -> np.ndarray:
    z = rng.uniform(lo, 1.0, n)
    ph = rng.uniform(0.0, 2.0 * math.pi, n)
    s = np.sqrt(1.0 - z * z)
    return np.stack([s * np.cos(ph), s * np.sin(ph), z], -1)


def float32_hemisphere(rng, n: int, lo: float = 0.05) -> np.ndarray:
    """*n* directions uniform in cos θ ∈ [lo, 1) and φ, rounded to float32 first (the
    traced BSDF sees float32 directions), as float64."""
    return _hemisphere64(rng, n, lo).astype(np.float32).astype(float)


def mirror_pairs(rng, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(view, light): float32-exact unit vectors above the horizon, half of the lights
    near the view's mirror direction (the specular peaks)."""
    view, light = _hemisphere64(rng, n, 0.05), _hemisphere64(rng, n, 0.05)
    light[: n // 2] = view[: n // 2] * [-1.0, -1.0, 1.0] + rng.normal(scale=0.1, size=(n // 2, 3))
    light[:, 2] = np.abs(light[:, 2]) + 0.02
    light /= np.linalg.norm(light, axis=-1, keepdims=True)
    return view.astype(np.float32).astype(float), light.astype(np.float32).astype(float)


def mitsuba_chi2(props: dict, wi) -> None:
    """Mitsuba's own χ² goodness-of-fit test (``mitsuba.chi2``, Šidák-corrected) of the
    ``brdfkit`` plugin built from *props*: its sample() against its pdf() at incidence
    *wi*, on a 51 × 102 sphere grid with 200,000 samples; asserts it passes. A variant
    must be set first (:func:`variant`)."""
    import gc

    from mitsuba.chi2 import BSDFAdapter, ChiSquareTest, SphericalDomain

    sample_func, pdf_func = BSDFAdapter("brdfkit", {"type": "brdfkit", **props}, wi=wi)
    chi2 = ChiSquareTest(domain=SphericalDomain(), sample_func=sample_func,
                         pdf_func=pdf_func, sample_dim=3, res=51, ires=4,
                         sample_count=200_000)
    assert chi2.run(), chi2.messages
    gc.collect()
