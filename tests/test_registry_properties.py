"""Registry-wide physical and interface properties of every model.

Parametrised at import time over every class in :data:`brdfkit.MODELS` and
every parameter set in its ``examples`` (so new models are tested as soon as
they are registered). The references are identities, not numbers:

- f_r ≥ 0 and finite everywhere, exactly 0 at and below the horizon
  (the package conventions);
- Helmholtz reciprocity f(wi, wo) = f(wo, wi) for models whose class claims
  ``reciprocal = True``, and a demonstrated violation for those claiming False
  (Lewis 1993 §2 shows Phong and Blinn are not reciprocal; Neumann et al. 1999
  §1.2 likewise for the original Phong);
- broadcasting agrees with evaluating pair by pair, and a per-channel model's
  channel c is the scalar model built from channel c's values;
- every declared bound is enforced with a ParameterError naming the parameter
  and the bounds.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import brdfkit
from brdfkit.errors import ParameterError
from brdfkit.geometry import reflect

CASES = [
    pytest.param(cls, i, ex, id=f"{name}-ex{i}")
    for name, cls in brdfkit.MODELS.items()
    for i, ex in enumerate(cls.examples)
]
CLASSES = [pytest.param(cls, id=name) for name, cls in brdfkit.MODELS.items()]
NONRECIPROCAL_BY_PAPER = ("phong", "blinn", "phong-energy-conserving")


def uniform_sphere(rng, n):
    # Uniform on the full sphere (z ~ U(-1, 1), Archimedes): half the pairs are below the horizon.
    z = rng.uniform(-1.0, 1.0, n)
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    r = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)


def upper(rng, n):
    v = uniform_sphere(rng, n)
    v[:, 2] = np.abs(v[:, 2])
    return v


def lobe_width(m) -> float:
    widths = [lb.width for lb in m.lobes() if lb.kind != "diffuse"]
    return min(widths) if widths else math.pi / 2


def near_peak_pairs(m, rng, n):
    """Pairs concentrated where the non-diffuse lobes live (mirror / half / normal)."""
    w = max(lobe_width(m), 1e-4)
    wi = upper(rng, n)
    target = reflect(wi)
    wo = target + rng.normal(scale=2.0 * w, size=(n, 3))
    wo /= np.linalg.norm(wo, axis=-1, keepdims=True)
    wo[:, 2] = np.abs(wo[:, 2])
    return wi, wo


def structured_directions():
    """Polar angles 0…180° incl. exactly 90° (z = 0 exactly), below and just above the horizon."""
    dirs = []
    for deg in (0.0, 1e-6, 15.0, 45.0, 60.0, 80.0, 85.0, 89.0, 89.9, 89.9999, 90.0, 90.0001,
                95.0, 135.0, 180.0):
        for phi in (0.0, 0.7, math.pi / 2, math.pi):
            t = math.radians(deg)
            z = 0.0 if deg == 90.0 else math.cos(t)
            s = 1.0 if deg == 90.0 else math.sin(t)
            dirs.append((s * math.cos(phi), s * math.sin(phi), z))
    return np.array(dirs)


def rel_close(a, b, rtol):
    scale = np.maximum(np.maximum(np.abs(a), np.abs(b)), 1e-300)
    return np.abs(a - b) <= rtol * scale + 1e-12 * max(float(np.max(np.abs(a))), 1.0)


# --------------------------------------------------------------------------- positivity
@pytest.mark.parametrize("cls,i,ex", CASES)
def test_nonnegative_finite_random_pairs(cls, i, ex, rng):
    m = cls(**ex)
    wi, wo = uniform_sphere(rng, 20000), uniform_sphere(rng, 20000)
    f = m.eval(wi, wo)
    assert np.all(np.isfinite(f)), f"{cls.name} {ex}: non-finite values"
    assert np.all(f >= 0.0), f"{cls.name} {ex}: negative value {f.min()}"
    below = (wi[:, 2] <= 0.0) | (wo[:, 2] <= 0.0)
    assert np.all(f[below] == 0.0), f"{cls.name} {ex}: nonzero below the horizon"
    wi2, wo2 = near_peak_pairs(m, rng, 20000)
    f2 = m.eval(wi2, wo2)
    assert np.all(np.isfinite(f2)) and np.all(f2 >= 0.0), f"{cls.name} {ex}: near the peak"


@pytest.mark.parametrize("cls,i,ex", CASES)
def test_nonnegative_finite_structured_grid(cls, i, ex):
    m = cls(**ex)
    d = structured_directions()
    wi = np.repeat(d, len(d), axis=0)
    wo = np.tile(d, (len(d), 1))
    # add the exact mirror and retro-reflection pairs, including grazing ones
    wi = np.concatenate([wi, d, d])
    wo = np.concatenate([wo, reflect(d), d])
    f = m.eval(wi, wo)
    bad = ~np.isfinite(f)
    if np.any(bad):
        j = np.argwhere(bad)[0][0]
        pytest.fail(f"{cls.name} {ex}: non-finite at wi={wi[j]}, wo={wo[j]}")
    assert np.all(f >= 0.0), f"{cls.name} {ex}: negative value"
    horizon = (wi[:, 2] <= 0.0) | (wo[:, 2] <= 0.0)
    if f.ndim == 2:
        horizon = horizon[:, None] & np.ones(f.shape, bool)
    assert np.all(f[horizon] == 0.0), f"{cls.name} {ex}: nonzero at/below the horizon"


# --------------------------------------------------------------------------- symmetry
def _turned(w, angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.stack([c * w[:, 0] - s * w[:, 1], s * w[:, 0] + c * w[:, 1], w[:, 2]], -1)


@pytest.mark.parametrize("cls,i,ex", CASES)
def test_isotropy_and_mirror_symmetry_when_claimed(cls, i, ex, rng):
    """``isotropic``: f unchanged when both directions turn about the normal (identity:
    rotation invariance); ``mirror_symmetric``: unchanged when both are mirrored in y → −y
    (the albedo engine integrates half the azimuths only on this claim). A model claiming
    neither is not tested here (anisotropic models: their own tests)."""
    m = cls(**ex)
    if not m.isotropic:
        pytest.skip(f"{cls.name} {ex} is anisotropic (isotropic False)")
    wi, wo = upper(rng, 20000), upper(rng, 20000)
    wi2, wo2 = near_peak_pairs(m, rng, 20000)
    wi, wo = np.concatenate([wi, wi2]), np.concatenate([wo, wo2])
    f = m.eval(wi, wo)
    checks = [("turned by 1.1 rad", m.eval(_turned(wi, 1.1), _turned(wo, 1.1)))]
    if m.mirror_symmetric:
        mirror = np.array([1.0, -1.0, 1.0])
        checks.append(("mirrored y -> -y", m.eval(wi * mirror, wo * mirror)))
    for what, g in checks:
        ok = rel_close(f, g, 1e-7)
        if not np.all(ok):
            j = np.argwhere(~ok)[0][0]
            pytest.fail(f"{cls.name} {ex}: f = {f[j]} but {g[j]} with both directions {what} "
                        f"at wi={wi[j]}, wo={wo[j]}")


# --------------------------------------------------------------------------- reciprocity
@pytest.mark.parametrize("cls,i,ex", [c for c in CASES if c.values[0].reciprocal])
def test_reciprocity_when_claimed(cls, i, ex, rng):
    m = cls(**ex)
    wi, wo = upper(rng, 20000), upper(rng, 20000)
    wi2, wo2 = near_peak_pairs(m, rng, 20000)
    wi, wo = np.concatenate([wi, wi2]), np.concatenate([wo, wo2])
    a, b = m.eval(wi, wo), m.eval(wo, wi)
    ok = rel_close(a, b, 1e-7)
    if not np.all(ok):
        j = np.argwhere(~ok)[0][0]
        pytest.fail(f"{cls.name} {ex} claims reciprocity but f(wi,wo)={a[j]} != "
                    f"f(wo,wi)={b[j]} at wi={wi[j]}, wo={wo[j]}")


@pytest.mark.parametrize("cls", [c for c in CLASSES if not c.values[0].reciprocal])
def test_nonreciprocity_demonstrated_when_not_claimed(cls, rng):
    # The class says its formula is not symmetric: at least one example must show it.
    worst = 0.0
    for ex in cls.examples:
        m = cls(**ex)
        wi, wo = near_peak_pairs(m, rng, 20000)
        wi = np.concatenate([wi, upper(rng, 20000)])
        wo = np.concatenate([wo, upper(rng, 20000)])
        a, b = m.eval(wi, wo), m.eval(wo, wi)
        scale = max(float(np.max(a)), 1e-300)
        worst = max(worst, float(np.max(np.abs(a - b))) / scale)
    assert worst > 1e-3, f"{cls.name} claims reciprocal=False but no example shows asymmetry"


@pytest.mark.parametrize("name", NONRECIPROCAL_BY_PAPER)
def test_papers_nonreciprocal_models_claim_false(name):
    # Lewis 1993 §2/§3.1: Phong (R·V)ⁿ and Blinn (N·H)ⁿ/(N·L) shaders violate reciprocity;
    # the "energy-conserving" Phong of Lewis §5 keeps the asymmetric normalisation.
    if name not in brdfkit.MODELS:
        pytest.skip(f"{name} not registered yet")
    assert brdfkit.MODELS[name].reciprocal is False


# --------------------------------------------------------------------------- broadcasting
@pytest.mark.parametrize("cls,i,ex", CASES)
def test_broadcasting_shapes(cls, i, ex, rng):
    m = cls(**ex)
    C = () if m.n_channels is None else (m.n_channels,)
    wi, wo = near_peak_pairs(m, rng, 24)
    ref = m.eval(wi, wo)
    assert ref.shape == (24, *C)
    # pair by pair
    one = np.array([m.eval(wi[j], wo[j]) for j in range(24)])
    np.testing.assert_array_equal(one.reshape(ref.shape), ref)
    # (N,3) against (3,) and (3,) against (N,3)
    np.testing.assert_array_equal(m.eval(wi, wo[0]), m.eval(wi, np.tile(wo[0], (24, 1))))
    np.testing.assert_array_equal(m.eval(wi[0], wo), m.eval(np.tile(wi[0], (24, 1)), wo))
    # (A,1,3) × (1,B,3) → (A,B)
    A, B = wi[:4, None, :], wo[None, :6, :]
    grid = m.eval(A, B)
    assert grid.shape == (4, 6, *C)
    for a in range(4):
        for b in range(6):
            np.testing.assert_array_equal(grid[a, b], m.eval(wi[a], wo[b]))
    # (A,B,3) with non-contiguous input, and inputs are not mutated
    wi3 = np.asfortranarray(np.broadcast_to(A, (4, 6, 3)))
    wo3 = np.broadcast_to(B, (4, 6, 3)).copy()
    before = (wi3.copy(), wo3.copy())
    np.testing.assert_array_equal(m.eval(wi3, wo3), grid)
    np.testing.assert_array_equal(wi3, before[0])
    np.testing.assert_array_equal(wo3, before[1])


@pytest.mark.parametrize("cls,i,ex", [
    c for c in CASES
    if any(p.kind == "colour" and np.ndim(c.values[2].get(p.name)) == 1 for p in c.values[0].params)
])
def test_colour_channel_equals_scalar_model(cls, i, ex, rng):
    m = cls(**ex)
    assert m.n_channels is not None
    wi, wo = near_peak_pairs(m, rng, 2000)
    f = m.eval(wi, wo)
    assert f.shape == (2000, m.n_channels)
    colour = {p.name for p in cls.params if p.kind == "colour"}
    for c in range(m.n_channels):
        scalar_ex = {k: (v[c] if k in colour and np.ndim(v) == 1 else v) for k, v in ex.items()}
        ms = cls(**scalar_ex)
        assert ms.n_channels is None
        np.testing.assert_allclose(f[:, c], ms.eval(wi, wo), rtol=1e-13, atol=0,
                                   err_msg=f"{cls.name} channel {c}")


# --------------------------------------------------------------------------- validation
def out_of_range_values(p):
    """Values just outside the declared bounds (and non-finite ones)."""
    vals = []
    if p.kind == "choice":
        return ["no-such-choice"]
    if math.isfinite(p.lower):
        vals.append(p.lower if p.lower_open else p.lower - max(1.0, abs(p.lower)))
    if math.isfinite(p.upper):
        vals.append(p.upper if p.upper_open else p.upper + max(1.0, abs(p.upper)))
    return [*vals, math.nan, math.inf]


PARAM_CASES = [
    pytest.param(cls, p, v, id=f"{name}-{p.name}-{v}")
    for name, cls in brdfkit.MODELS.items()
    for p in cls.params
    for v in out_of_range_values(p)
]


@pytest.mark.parametrize("cls,p,value", PARAM_CASES)
def test_bounds_enforced_with_named_error(cls, p, value):
    with pytest.raises(ParameterError) as info:
        cls(**{p.name: value})
    msg = str(info.value)
    assert repr(p.name) in msg, msg
    assert p.bounds_text() in msg, msg
    if p.kind != "choice" and math.isfinite(value):
        assert f"{value:g}" in msg, msg
    if p.kind in ("colour", "lobes"):
        # a per-channel/per-lobe list with one bad entry is rejected too
        ok = valid_value(p)
        with pytest.raises(ParameterError, match=repr(p.name)):
            cls(**{p.name: [ok, value, ok]})


def valid_value(p) -> float:
    """A value inside the declared bounds: the default, else a point between the bounds."""
    if isinstance(p.default, int | float) and p._inside(float(p.default)):
        return float(p.default)
    lo = p.lower if math.isfinite(p.lower) else min(p.upper, 0.0) - 1.0
    hi = p.upper if math.isfinite(p.upper) else max(lo, 0.0) + 1.0
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("cls", CLASSES)
def test_defaults_are_inside_bounds_and_examples_build(cls):
    for p in cls.params:
        if p.kind == "choice":
            assert p.default in p.choices, (cls.name, p.name)
        elif p.default is not None:  # a colour's default may be per channel (disney's RGB)
            for x in np.atleast_1d(np.asarray(p.default, dtype=np.float64)):
                assert p._inside(float(x)), (cls.name, p.name, p.default)
    for ex in cls.examples:
        cls(**ex)
    assert len(cls.examples) >= 1, cls.name


@pytest.mark.parametrize("cls", [c for c in CLASSES if c.values[0].width_param])
def test_beta_out_of_range_is_rejected(cls):
    for beta in (0.0, -0.1, math.pi / 2, 2.0):
        with pytest.raises(ParameterError, match="beta"):
            cls(beta=beta)


@pytest.mark.parametrize("cls", CLASSES)
def test_unknown_parameter_lists_valid_ones(cls):
    with pytest.raises(ParameterError) as info:
        cls(no_such_parameter=1.0)
    for p in cls.params:
        assert p.name in str(info.value)


@pytest.mark.parametrize("cls", CLASSES)
def test_describe_is_complete(cls):
    d = cls.describe()
    assert d["name"] == cls.name and d["citation"], cls.name
    assert isinstance(d["reciprocal"], bool) and isinstance(d["has_sampler"], bool)
    assert brdfkit.model(cls.name).name == cls.name
    for alias in cls.aliases:
        assert brdfkit.model(alias).name == cls.name


# --------------------------------------------------------------------------- grazing angles
# Cosines that are tiny but positive: subnormal (5e-324 is the smallest float64), where the
# squares of the components of wi + wo underflow (< 1.5e-154), and ordinary small ones.
TINY_COS = (5e-324, 1e-320, 1e-310, 1e-300, 1e-200, 1e-162, 1e-150, 1e-100, 1e-20)


def _grazing(z, phi=0.0):
    """The unit vector at cos θ = z and azimuth phi; exact components at multiples of π/2
    (cos π rounds to −1 but sin π to 1.2e-16, which would move the pair off the mirror)."""
    s = math.sqrt(1.0 - z * z)
    exact = {0.0: (1.0, 0.0), math.pi: (-1.0, 0.0), math.pi / 2: (0.0, 1.0),
             -math.pi / 2: (0.0, -1.0)}
    c, sn = exact.get(phi, (math.cos(phi), math.sin(phi)))
    return (s * c, s * sn, z)


def grazing_pairs():
    """(wi, wo) pairs at extreme grazing angles, and pairs at/below the horizon.

    Both grazing: forward (wo the mirror image, h = n), retro-reflection (wi = wo),
    perpendicular azimuths, wi = −wo + a tiny azimuthal offset, and every combination of two
    different tiny cosines; one grazing, the other at 0°, 60° or 89.94° on either side;
    and z = 0, −0, −5e-324, −1e-300 (the BRDF must be exactly 0 there).
    """
    pairs = []
    for e in TINY_COS:
        g = _grazing(e)
        pairs += [(g, _grazing(e, math.pi)), (g, g), (g, _grazing(e, math.pi / 2)),
                  (g, _grazing(e, -math.pi / 2))]
        pairs += [(_grazing(e, d), _grazing(e, math.pi)) for d in (1e-8, 1e-100, 1e-300)]
        for c in (1.0, 0.5, 1e-3):
            for phi in (0.0, math.pi):
                pairs += [(g, _grazing(c, phi)), (_grazing(c, phi), g)]
        for e2 in TINY_COS:
            pairs += [(g, _grazing(e2, math.pi)), (g, _grazing(e2))]
    for z in (0.0, -0.0, -5e-324, -1e-300):
        pairs += [((1.0, 0.0, z), (-1.0, 0.0, z)), ((1.0, 0.0, z), (0.0, 0.0, 1.0)),
                  ((0.0, 0.0, 1.0), (1.0, 0.0, z)), ((1.0, 0.0, z), (1.0, 0.0, z))]
    wi = np.array([p[0] for p in pairs])
    wo = np.array([p[1] for p in pairs])
    return wi, wo


def assert_finite_nonnegative_zero_below(m, label):
    # Reference: the package conventions (issue 2): f is finite and ≥ 0 for θ ≤ 90°, and
    # exactly 0 when either cosine is ≤ 0.
    wi, wo = grazing_pairs()
    assert np.min(wi[wi[:, 2] > 0.0, 2]) == 5e-324  # the smallest subnormal is covered
    f = np.asarray(m.eval(wi, wo)).reshape(len(wi), -1)
    bad = ~np.all(np.isfinite(f) & (f >= 0.0), axis=1)
    below = (wi[:, 2] <= 0.0) | (wo[:, 2] <= 0.0)
    bad |= below & np.any(f != 0.0, axis=1)
    if np.any(bad):
        j = np.argwhere(bad)[0][0]
        pytest.fail(f"{label}: f = {f[j]} at wi = {wi[j].tolist()}, wo = {wo[j].tolist()} "
                    f"({int(bad.sum())} bad pairs)")


@pytest.mark.parametrize("cls,i,ex", CASES)
def test_finite_at_extreme_grazing_angles(cls, i, ex):
    assert_finite_nonnegative_zero_below(cls(**ex), f"{cls.name} {ex}")


def extreme_parameter_sets(cls):
    """Every choice, and each parameter at each finite closed bound (others at default)."""
    out = []
    for p in cls.params:
        if p.kind == "choice":
            out += [{p.name: c} for c in p.choices]
            continue
        for bound, is_open in ((p.lower, p.lower_open), (p.upper, p.upper_open)):
            if math.isfinite(bound) and not is_open:
                out.append({p.name: [bound] if p.kind == "lobes" else bound})
    choices = [p for p in cls.params if p.kind == "choice"]
    if choices:  # the bounds again under every choice of the first choice parameter
        c0 = choices[0]
        out += [{**v, c0.name: c} for v in list(out) if c0.name not in v for c in c0.choices]
    return out


@pytest.mark.parametrize("cls", CLASSES)
def test_finite_at_extreme_grazing_angles_and_parameter_bounds(cls):
    # e.g. phong with k_s = 1e6 (f ∝ k_s/N·L) or neumann-phong with c_n = 1e7
    tried = 0
    for values in extreme_parameter_sets(cls):
        try:
            m = cls(**values)
        except ParameterError:
            continue  # a combination another parameter's bounds exclude (e.g. c with D3)
        assert_finite_nonnegative_zero_below(m, f"{cls.name} {values}")
        tried += 1
    assert tried > 0 or not any(p.kind != "choice" for p in cls.params)


# Limits as both cosines → 0 with wo the mirror image of wi (so h = n, L·V → −1, R·V → 1,
# ω_i·h = |wi + wo|/2 → 0 and F(0) = 1), from the formulas, at cosines where the components
# of wi + wo underflow when squared (the case the kernels once returned 0, NaN or inf for):
#   microfacet beckmann: D(h=n) = 1/(πα²), G₁/cos θ → 2√π/(α h(0)) with h(0) = 1 (Walter
#       eq. 27 as a → 0): f → (1/(πα²))(4π/α²)/4 = 1/α⁴;
#   microfacet ggx: D = 1/(πα²), G₁/cos θ → 2/α (eq. 34): f → 1/(πα⁴);
#   nielsen (eq. 3): base (1−α)R·V + α(N·H)⁴ → 1, f → ρ_d/π + k_s;
#   phong-blinn-reciprocal (Lewis eq. 24): (N·H)ⁿ = 1, f = k_d + k_s;
#   modified-blinn-phong (Nielsen eq. 2): f = ρ_d/π + ρ_s (n+8)/(8π);
#   cook-torrance (Neumann eq. 9): D = 1/(4πm²), G = 1, (N·L)(N·V) floored at DENOM_FLOOR
#       = 1e-280 (documented in brdfkit.models.microfacet): f = ρ_s/(4πm²)·1e280.
GRAZING_LIMITS = [
    ("microfacet", {"alpha": 0.1}, 1.0 / 0.1**4),
    ("microfacet", {"alpha": 0.5, "eta": 1.5, "k": 2.0}, 1.0 / 0.5**4),
    ("microfacet", {"distribution": "ggx", "alpha": 0.5}, 1.0 / (math.pi * 0.5**4)),
    ("nielsen", {"rho_d": 0.2, "k_s": 2.0, "alpha": 0.5, "s": 20.0}, 0.2 / math.pi + 2.0),
    ("nielsen", {"rho_d": 0.0, "k_s": 3.0, "alpha": 0.7, "s": 8.0, "eta": 1.5}, 3.0),
    ("phong-blinn-reciprocal", {"k_d": 0.1, "k_s": 1.0, "n": 20.0}, 1.1),
    ("modified-blinn-phong", {"rho_d": 0.2, "rho_s": 0.5, "n": 20.0},
     0.2 / math.pi + 0.5 * 28.0 / (8.0 * math.pi)),
    ("cook-torrance", {"m": 0.3}, 1e280 / (4.0 * math.pi * 0.09)),
]


@pytest.mark.parametrize("name,values,limit", GRAZING_LIMITS)
@pytest.mark.parametrize("e", [1e-150, 1e-162, 1e-200, 1e-300, 1e-320, 5e-324])
def test_grazing_mirror_limit(name, values, limit, e):
    m = brdfkit.model(name, **values)
    f = float(m.eval(np.array(_grazing(e)), np.array(_grazing(e, math.pi))))
    assert f == pytest.approx(limit, rel=1e-12), f"{name} {values} at cos = {e}"
