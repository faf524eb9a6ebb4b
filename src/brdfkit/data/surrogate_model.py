"""
The built-in measured material as a brdfkit model: SurrogateBRDF and its provenance
===================================================================================

A compact surrogate of a measured material (:mod:`brdfkit.data.surrogates`:
the representations' kernels and builders) wrapped as a
:class:`~brdfkit.models.DerivedBRDF` with no free parameters: its name
(``merl:NAME[@npf|abc|sgd]``, ``rgl:NAME``, ``nielsen:NAME``), citation and
licence per data source and representation, lobes estimated from its own
values, kinks declared from its fitted numbers, and a sampler tabulated from its
values (:mod:`brdfkit.data.sampler`).

Public objects
--------------
- :class:`SurrogateBRDF` — a built-in material as a brdfkit model.
- :data:`REPRESENTATIONS` — the representations of a MERL material, default first.
- :data:`CITATIONS`, :data:`SOURCES`, :data:`LICENCES` — per representation / data source.
"""

from __future__ import annotations

import math

import numpy as np

from brdfkit.data.sampler import TabulatedSampler
from brdfkit.data.surrogate_formulas import surrogate_formulas
from brdfkit.errors import ParameterError
from brdfkit.models._base import DerivedBRDF, Lobe

__all__ = ["CITATIONS", "LICENCES", "REPRESENTATIONS", "SOURCES", "SurrogateBRDF"]

HALF_PI = 0.5 * math.pi

#: The representations of a MERL material, default first.
REPRESENTATIONS = ("nbrdf", "npf", "abc", "sgd")

_MERL = ("MERL BRDF database: W. Matusik, H. Pfister, M. Brand, L. McMillan, A Data-Driven "
         "Reflectance Model, ACM TOG 22(3), 2003 (CC-BY-SA-4.0)")
#: Citation of each representation (the surrogate's paper and where the numbers came from).
CITATIONS = {
    "nbrdf": "A. Sztrajman, G. Rainer, T. Ritschel, T. Weyrich, Neural BRDF Representation "
             "and Importance Sampling, CGF 40(6), 2021 (weights: github.com/asztr/Neural-BRDF)",
    "npf": "M. M. Bagher, J. Snyder, D. Nowrouzezahrai, A Non-Parametric Factor Microfacet "
           "Model for Isotropic BRDFs, ACM TOG 35(5), 2016 (data: jdupuy/opengl-framework "
           "demo-merl/npf.bin)",
    "abc": "J. Löw, J. Kronander, A. Ynnerman, J. Unger, BRDF Models for Accurate and "
           "Efficient Rendering of Glossy Surfaces, ACM TOG 31(1), 2012 (parameters by "
           "J. Kronander, via J. Dupuy's dj_brdf.h)",
    "sgd": "M. M. Bagher, C. Soler, N. Holzschuch, Accurate Fitting of Measured Reflectances "
           "Using a Shifted Gamma Micro-facet Distribution, CGF 31(4), 2012 (parameters via "
           "J. Dupuy's dj_brdf.h)",
}
#: Data source → (measurement citation, licence of the measured data).
SOURCES = {
    "merl": (_MERL, "CC-BY-SA-4.0"),
    "rgl": ("RGL-EPFL isotropic materials: J. Dupuy, W. Jakob, An Adaptive Parameterization "
            "for Efficient Material Acquisition and Rendering, ACM TOG 37(6), 2018",
            "CC0-1.0 (as described by a third-party download script; not verified)"),
    "nielsen": ("J. B. Nielsen, H. W. Jensen, R. Ramamoorthi, On Optimal, Minimal BRDF "
                "Sampling for Reflectance Acquisition, ACM TOG 34(6), 2015",
                "not stated by the authors"),
}
#: Licence of the fitted numbers of each representation.
LICENCES = {
    "nbrdf": "MIT (c) 2022 asztr",
    "npf": "public domain (jdupuy/opengl-framework README)",
    "abc": "public domain (dj_brdf.h)",
    "sgd": "public domain (dj_brdf.h)",
}


def _half_width(model) -> float:
    """θ_h half-width (rad) of the specular part: along θ_h ∈ [0, 60°] at θ_d = 5°,
    φ_d = 90° (both directions stay above the horizon), the channel mean minus its
    minimum (the diffuse floor) falls to half its value at θ_h = 0. π/2 when there is
    no peak at θ_h = 0 (diffuse materials)."""
    from brdfkit.data.merl import half_diff_to_directions

    # quadratic spacing (as MERL's θ_h bins): 0.002° steps near the peak, 60° at the end
    u = np.linspace(0.0, 1.0, 513)
    theta_h = u * u * math.radians(60.0)
    wi, wo = half_diff_to_directions(theta_h, math.radians(5.0), HALF_PI)
    prof = np.mean(model.eval(wi, wo), axis=-1)
    floor = float(np.min(prof))
    peak = float(prof[0]) - floor
    if not (peak > 0.0 and np.all(np.isfinite(prof))):
        return HALF_PI
    below = np.nonzero(prof - floor < 0.5 * peak)[0]
    if below.size == 0:
        return HALF_PI
    # linear interpolation of the crossing; at least the first grid step
    i = int(below[0])
    y0, y1 = prof[i - 1] - floor - 0.5 * peak, prof[i] - floor - 0.5 * peak
    w = theta_h[i - 1] + (theta_h[i] - theta_h[i - 1]) * y0 / (y0 - y1)
    return float(min(max(w, theta_h[1]), HALF_PI))


class SurrogateBRDF(TabulatedSampler, DerivedBRDF):
    """A built-in measured material, evaluated from a compact surrogate.

    ===================  ==================================================
    what                 value
    ===================  ==================================================
    name                 ``merl:NAME`` (NBRDF), ``merl:NAME@npf|abc|sgd``,
                         ``rgl:NAME``, ``nielsen:NAME``
    parameters           none (``params == ()``; ``to_dict()`` gives
                         ``{"model": name, "params": {}}``)
    channels             3 (RGB, MERL's colour scales included), 1/sr
    reciprocal           NPF, ABC, SGD: yes (functions of θ_h, θ_d and the
                         two polar angles); NBRDF: no — the net sees ω_i's
                         difference vector d, and swapping ω_i, ω_o maps d to
                         (−d_x, −d_y, d_z), which the net does not enforce
    isotropic            yes (no φ_h dependence: rotation invariant)
    mirror_symmetric     NPF, ABC, SGD: yes (functions of θ_h, θ_d and the
                         polar angles); NBRDF: no — the net sees d_y, the
                         sign of sin φ_d, and its evenness in φ_d is learnt,
                         not enforced (white-diffuse-bball at θ_i = 80°:
                         f(φ_o) against f(−φ_o) differs by 1.8 % median,
                         77 % at most), so the albedo engine integrates
                         the full azimuth
    lobes                diffuse + ``half`` (θ_h half-width estimated from
                         the surrogate, :func:`_half_width`)
    sampling             from the surrogate's own values
                         (:mod:`brdfkit.data.sampler`: per-θ_o bilinear
                         half-vector tables mixed with the cosine), built
                         on the first ``sample``/``pdf`` (~50 ms)
    ===================  ==================================================

    Plausibility verdicts (:func:`brdfkit.analysis.check`) are verdicts on the
    surrogate, not on the measurement: NPF, ABC and SGD are reciprocal by their
    form (functions of θ_h, θ_d and symmetric in θ_i, θ_o) — but NPF reads D and F
    at the *nearest* bin, and θ_d computed from ω_i or from ω_o can round to
    neighbouring bins when it lies on a bin edge: ``check`` finds up to ~2 %
    asymmetry at such pairs of its set (violet-rubber@npf: θ_i = 15°,
    θ_o = 89°, Δφ = 180°) and 3e-16 a 1e-4° step away — its "not reciprocal"
    is this rounding on bin edges, not the fit's form. NBRDF is declared
    and found non-reciprocal — the net learns f from ω_i's difference vector and
    nothing ties f(ω_i, ω_o) to f(ω_o, ω_i), so its asymmetry (1–30 % median by
    material) is a fitting artefact, not a property of the material. Energy:
    the albedo is computed from the surrogate, so *exceeds* or *diverges* says
    the fit (e.g. a G₁/cos θ factor at grazing angles) gains energy, which MERL
    itself, measured only up to θ ≈ 90° in finite bins, cannot confirm.

    Attributes: ``source`` ("merl", "rgl", "nielsen"), ``material`` (the
    source's name), ``representation`` (:data:`REPRESENTATIONS`), ``licence``
    (of the measured data and of the fitted numbers), ``rho_d`` (the fit's
    diffuse albedo per channel, or None for NBRDF).
    """

    def __init__(self, *, source: str, material: str, representation: str, kernel, packed,
                 reciprocal: bool, rho_d=None, driver=None, albedo_kinks=frozenset(),
                 kink_theta0=None):
        if source not in SOURCES:
            raise ParameterError(f"SurrogateBRDF: source must be one of {', '.join(SOURCES)}; "
                                 f"got {source!r}")
        if representation not in REPRESENTATIONS:
            raise ParameterError(f"SurrogateBRDF: representation must be one of "
                                 f"{', '.join(REPRESENTATIONS)}; got {representation!r}")
        self.source = source
        self.material = material
        self.representation = representation
        self.rho_d = None if rho_d is None else np.asarray(rho_d, dtype=np.float64)
        measured, data_licence = SOURCES[source]
        self.licence = (f"measured data: {data_licence}; {representation.upper()} numbers: "
                        f"{LICENCES[representation]}")
        name = f"{source}:{material}" + ("" if representation == "nbrdf" else f"@{representation}")
        self._width: float | None = None
        self._kink_theta0 = kink_theta0
        super().__init__(
            name=name, params=(), values={},
            citation=f"{measured}; surrogate: {CITATIONS[representation]}",
            summary=f"{material} ({source.upper()}), {representation.upper()} surrogate",
            reciprocal=reciprocal, has_sampler=True, isotropic=True,
            mirror_symmetric=representation != "nbrdf", kernel=kernel, packed=packed)
        self.n_channels = 3
        self._driver = driver
        self.albedo_kinks = frozenset(albedo_kinks)
        if kink_theta0 is not None:  # a(θ_i) ∝ G₁(θ_i) has the same kink in θ_i
            t0 = np.asarray(kink_theta0, dtype=np.float64)
            self.albedo_kink_mus = tuple(float(c) for c in np.unique(
                np.cos(t0[(t0 > 0.0) & (t0 < HALF_PI)])))

    def lobes(self) -> list[Lobe]:
        if self._width is None:
            self._width = _half_width(self)
        if self._width >= HALF_PI:
            return [Lobe("diffuse", HALF_PI)]
        return [Lobe("diffuse", HALF_PI), Lobe("half", self._width)]

    def formulas(self):
        """f_r as a formula of its representation, the cosine + GGX proxy of its lobe as
        sampler (:func:`brdfkit.data.surrogate_formulas.surrogate_formulas`): the Mitsuba
        bridge's traced route."""
        return surrogate_formulas(self)

    def provenance(self) -> str:
        """Verdicts on this model are verdicts on the surrogate (class docstring)."""
        what = (f"the {self.representation.upper()} surrogate of {self.material} "
                f"({self.source.upper()}), a fit of the measurement, not the measurement")
        if self.representation == "nbrdf":
            others = (f" (merl:{self.material}@npf, @abc and @sgd are reciprocal by their "
                      "form)" if self.source == "merl" else "")
            return (f"{what}: the net enforces neither reciprocity nor mirror symmetry, so "
                    f"an asymmetry it shows is the fit's, not the material's{others}")
        return f"{what}: reciprocal by its form; its albedo is the fit's"

    def albedo_kinks_nv(self, theta) -> np.ndarray | None:
        """SGD: G₁(θ_o) has a kink at θ_o = θ₀ per channel (the max(0, θ − θ₀)): levels
        N·V = cos θ₀ for θ₀ ∈ (0, π/2), the same for every θ_i."""
        if self._kink_theta0 is None:
            return None
        t0 = np.asarray(self._kink_theta0, dtype=np.float64)
        levels = np.unique(np.cos(t0[(t0 > 0.0) & (t0 < HALF_PI)]))
        if levels.size == 0:
            return None
        theta = np.atleast_1d(np.asarray(theta, dtype=np.float64))
        return np.broadcast_to(levels, (theta.size, levels.size)).copy()

    def with_params(self, **changes) -> SurrogateBRDF:
        if changes:
            raise ParameterError(f"{self.name}: a built-in material has no parameters; got "
                                 f"{sorted(changes)[0]!r}")
        return self

    def to_dict(self) -> dict:
        return {"model": self.name, "params": {}}

    def __repr__(self) -> str:
        return f"brdfkit.data.material({self.name!r})"

