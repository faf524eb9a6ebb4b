"""
χ² goodness-of-fit test of a BRDF sampler against its pdf
=========================================================

Checks that ``model.sample(wo, u)`` draws directions with exactly the density
``model.pdf(wi, wo)`` claims, in the spirit of Mitsuba 3's
``mitsuba.python.chi2`` (itself after Jakob's original Mitsuba 0.5 test):

1. Draw ``n_samples`` directions wi for a fixed wo from seeded uniform numbers.
2. Histogram them over the sphere (samplers may produce directions below the
   horizon, with positive density). By default the upper hemisphere is binned
   finely and every other sample — below the horizon or discarded by the
   sampler (pdf 0) — falls in ONE extra cell whose expected count is
   n·(1 − ∫_{z>0} pdf), so every sample is accounted for. (Binning the lower
   hemisphere too, ``lower="bins"``, is exact in principle, but a microfacet
   sampler's pdf has an integrable 1/ε singularity at wi = −wo, where all
   half vectors with wo·h → 0 land; at grazing wo it lies next to the lobe
   and no fixed quadrature rule resolves it. The BRDF is 0 there anyway.)
   The sphere is parametrised around a lobe axis (the mirror direction of wo
   for mirror/half-vector lobes, the normal otherwise) by the polar angle θ'
   from the axis and the azimuth φ' about it. The θ' bins are uniform in the
   warped variable ``log(1 + θ'/w) / log(1 + π/w)`` with ``w`` half the
   sharpest lobe's width in wi (:meth:`BRDF.sharpest_lobe`,
   :func:`lobe_axis_and_width`), so bins are a small fraction of the lobe
   width near the axis and coarse far from it: the resolution follows lobe
   sharpness.
3. Integrate the pdf over every bin (tensor-product Gauss–Legendre rule in
   (θ', φ') with Jacobian sin θ', refined adaptively where a bin's 1-cell and
   4-cell estimates disagree) and multiply by ``n_samples``: the expected
   counts.
4. Pool cells with expected count < 5 (smallest first), compute Pearson's
   statistic and its p-value, and reject at the significance level
   ``1 − (1 − alpha)^(1/n_tests)`` (Šidák correction for ``n_tests`` tests
   in one run).

It also checks the pdf's integral over the binned region (must be ≤ 1), and fails
when samples land in a cell whose expected count is 0, when the pdf returned
by ``sample`` disagrees with ``pdf``, when a sample with pdf 0 carries a
positive BRDF value, or when the pdf is 0 somewhere the BRDF is not
(:func:`check_support`).

Public objects
--------------
- :func:`chi2_test` — run the test for one model and one wo.
- :class:`Chi2Result` — its outcome (``passed``, ``p_value``, ``status``/``success``/
  ``message`` of ``brdfkit.status.STATUS["chi2"]``: passed, rejected, limit — passed with
  unresolved quadrature cells —, nonfinite).
- :func:`check_support` — pdf > 0 wherever f > 0 (called by :func:`chi2_test`).
- :func:`sidak_alpha` — the per-test significance level.
- :class:`SphereBinning` — the lobe-adapted binning (also usable alone).
- :func:`lobe_axis_and_width` — the axis and width it adapts to.

References
----------
- W. Jakob et al., Mitsuba 3, ``src/python/python/chi2.py`` (the
  ChiSquareTest class and its pooling rule).
- K. Pearson, 1900; Z. Šidák, *Rectangular confidence regions for the means of
  multivariate normal distributions*, JASA 62, 1967.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from brdfkit.errors import BrdfkitError
from brdfkit.geometry import frame_around, reflect
from brdfkit.status import STATUS

__all__ = ["chi2_test", "Chi2Result", "check_support", "sidak_alpha", "SphereBinning",
           "lobe_axis_and_width"]

MIN_EXPECTED = 5.0
_CODES = STATUS["chi2"]


def sidak_alpha(alpha: float, n_tests: int) -> float:
    """Per-test significance so that *n_tests* independent tests have overall level *alpha*."""
    if not 0.0 < alpha < 1.0:
        raise BrdfkitError(f"alpha must lie in (0, 1); got {alpha!r}")
    if int(n_tests) < 1:
        raise BrdfkitError(f"n_tests must be >= 1; got {n_tests!r}")
    return 1.0 - (1.0 - alpha) ** (1.0 / int(n_tests))


def lobe_axis_and_width(model, wo: np.ndarray) -> tuple[np.ndarray, float]:
    """Axis and angular width (rad) in ω_i of the sharpest lobe of *model* for viewer *wo*.

    Reads :meth:`BRDF.sharpest_lobe` (the one reading of :meth:`BRDF.lobes`
    every engine uses): a ``mirror`` or ``half`` lobe concentrates ω_i about
    the mirror direction of ω_o, and a half-vector lobe of width w is about
    2w wide in ω_i (ω_i turns twice as fast as h); ``normal`` and ``diffuse``
    lobes lie about the normal. The width is kept in [1e-5, π/2].
    """
    lobe = model.sharpest_lobe()
    directional = lobe.kind in ("mirror", "half")
    axis = reflect(wo) if directional else np.array([0.0, 0.0, 1.0])
    width = 2.0 * lobe.width if lobe.kind == "half" else lobe.width
    return np.asarray(axis, dtype=np.float64), float(min(max(width, 1e-5), math.pi / 2))


@dataclass
class SphereBinning:
    """Bins over the full sphere in (θ', φ') about *axis*, θ' warped for a lobe of *width*.

    Parameters
    ----------
    axis : array_like, shape (3,)
        Unit vector; θ' is measured from it.
    width : float
        Lobe width in radians; bins near the axis are ~width/10.
    n_theta, n_phi : int
        Number of bins in θ' and φ'.
    """

    axis: np.ndarray
    width: float
    n_theta: int = 40
    n_phi: int = 32
    _w: float = field(init=False, repr=False)
    _log: float = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.axis = np.asarray(self.axis, dtype=np.float64)
        self.axis = self.axis / np.linalg.norm(self.axis)
        self._w = max(0.5 * float(self.width), 1e-6)
        self._log = math.log1p(math.pi / self._w)
        t, b, a = frame_around(self.axis)
        self._frame = np.stack([t, b, a])  # rows: local x, y, z axes

    @property
    def n_bins(self) -> int:
        return self.n_theta * self.n_phi

    def theta_edges(self) -> np.ndarray:
        """Bin edges in θ' (radians), from 0 to π."""
        s = np.linspace(0.0, 1.0, self.n_theta + 1)
        edges = self._w * np.expm1(s * self._log)
        edges[-1] = math.pi
        return edges

    def phi_edges(self) -> np.ndarray:
        return np.linspace(0.0, 2.0 * math.pi, self.n_phi + 1)

    def to_local_angles(self, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(θ', φ') of directions *w* (..., 3)."""
        t, b, a = self._frame
        loc = np.stack([w[..., 0] * t[0] + w[..., 1] * t[1] + w[..., 2] * t[2],
                        w[..., 0] * b[0] + w[..., 1] * b[1] + w[..., 2] * b[2],
                        w[..., 0] * a[0] + w[..., 1] * a[1] + w[..., 2] * a[2]], axis=-1)
        theta = np.arctan2(np.hypot(loc[..., 0], loc[..., 1]), loc[..., 2])
        phi = np.mod(np.arctan2(loc[..., 1], loc[..., 0]), 2.0 * math.pi)
        return theta, phi

    def from_local_angles(self, theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
        """Directions at (θ', φ') about the axis."""
        st = np.sin(theta)
        x, y, z = st * np.cos(phi), st * np.sin(phi), np.cos(theta)
        t, b, a = self._frame
        return np.stack([x * t[0] + y * b[0] + z * a[0], x * t[1] + y * b[1] + z * a[1],
                         x * t[2] + y * b[2] + z * a[2]], axis=-1)

    def bin_index(self, w: np.ndarray) -> np.ndarray:
        """Flat bin index (θ-major) of each direction."""
        theta, phi = self.to_local_angles(w)
        s = np.log1p(theta / self._w) / self._log
        i = np.clip((s * self.n_theta).astype(np.int64), 0, self.n_theta - 1)
        j = np.clip((phi * (self.n_phi / (2.0 * math.pi))).astype(np.int64), 0, self.n_phi - 1)
        return i * self.n_phi + j

    def histogram(self, w: np.ndarray) -> np.ndarray:
        """Counts per bin of the directions *w* (N, 3)."""
        return np.bincount(self.bin_index(w), minlength=self.n_bins).astype(np.float64)

    def _cells(self, bins: np.ndarray, sub: int) -> tuple[np.ndarray, np.ndarray]:
        """Cells (θ0, θ1, φ0, φ1) covering *bins*, each split into sub × sub; and their owners."""
        te, pe = self.theta_edges(), self.phi_edges()
        i, j = np.divmod(np.asarray(bins, dtype=np.int64), self.n_phi)
        f = (np.arange(sub + 1) / sub)[None, :]
        tg = te[i][:, None] + (te[i + 1] - te[i])[:, None] * f  # (B, sub+1)
        pg = pe[j][:, None] + (pe[j + 1] - pe[j])[:, None] * f
        a, b = np.meshgrid(np.arange(sub), np.arange(sub), indexing="ij")
        a, b = a.ravel(), b.ravel()
        cells = np.stack([tg[:, a], tg[:, a + 1], pg[:, b], pg[:, b + 1]], axis=-1)
        owner = np.repeat(np.asarray(bins, dtype=np.int64), sub * sub)
        return cells.reshape(-1, 4), owner

    def _rule(self, density, cells: np.ndarray, order: int) -> np.ndarray:
        x, wq = np.polynomial.legendre.leggauss(order)
        x = 0.5 * (x + 1.0)
        wq = 0.5 * wq
        t0, t1, p0, p1 = (cells[:, k:k + 1, None] for k in range(4))
        th = t0 + (t1 - t0) * x[None, :, None]
        ph = p0 + (p1 - p0) * x[None, None, :]
        th, ph = np.broadcast_arrays(th, ph)
        dens = np.asarray(density(self.from_local_angles(th, ph)), dtype=np.float64)
        dens = np.where(np.isfinite(dens), dens, np.inf)  # NaN/inf: flagged by the caller
        wts = wq[None, :, None] * wq[None, None, :] * np.sin(th)
        return np.sum(dens * wts, axis=(1, 2)) * (t1 - t0)[:, 0, 0] * (p1 - p0)[:, 0, 0]

    @staticmethod
    def _split(c: np.ndarray) -> np.ndarray:
        tm = 0.5 * (c[:, 0] + c[:, 1])
        pm = 0.5 * (c[:, 2] + c[:, 3])
        return np.concatenate([
            np.stack([c[:, 0], tm, c[:, 2], pm], -1), np.stack([tm, c[:, 1], c[:, 2], pm], -1),
            np.stack([c[:, 0], tm, pm, c[:, 3]], -1), np.stack([tm, c[:, 1], pm, c[:, 3]], -1),
        ])

    def straddles_horizon(self, cells: np.ndarray) -> np.ndarray:
        """Cells that the horizon z = 0 crosses (tested on a 5 × 5 grid of points)."""
        f = np.linspace(0.0, 1.0, 5)
        th = cells[:, 0, None, None] + (cells[:, 1] - cells[:, 0])[:, None, None] * f[:, None]
        ph = cells[:, 2, None, None] + (cells[:, 3] - cells[:, 2])[:, None, None] * f[None, :]
        z = self.from_local_angles(*np.broadcast_arrays(th, ph))[..., 2]
        # 1e-12: a bin edge lying on the horizon (cos(π/2) ≈ 6e-17) is not a crossing
        return np.any(z > 1e-12, axis=(1, 2)) & np.any(z < -1e-12, axis=(1, 2))

    def integrate(self, density, *, bins=None, sub: int = 1, order: int = 4, max_depth: int = 6,
                  tol: float = 1e-7, max_cells: int = 400_000, must_refine=None,
                  force_depth: int = 4) -> tuple[np.ndarray, int]:
        """∫ density over every bin (solid angle), adaptive tensor-product Gauss–Legendre.

        Each cell is integrated with an ``order``×``order`` rule and as four
        sub-cells; where the two differ by more than ``tol`` (absolute, in
        probability) plus 1e-4 of the value, or where ``must_refine(cells)``
        is True (e.g. :meth:`straddles_horizon` for a density cut at the
        horizon; only for the first ``force_depth`` levels), the sub-cells are
        refined again, down to ``max_depth`` levels.

        Parameters
        ----------
        density : callable
            Directions (..., 3) → density (...) per steradian.
        bins : array of int, optional
            Only these bins (default: all); the result still has ``n_bins`` entries.
        sub : int
            Start from sub × sub cells per bin.

        Returns
        -------
        integrals : ndarray (n_bins,)
        unresolved : int
            Cells still above tolerance at ``max_depth`` (or beyond ``max_cells``).
        """
        bins = np.arange(self.n_bins) if bins is None else np.asarray(bins, dtype=np.int64)
        cells, owner = self._cells(bins, int(sub))
        result = np.zeros(self.n_bins)
        coarse = self._rule(density, cells, order)
        unresolved = 0
        for depth in range(max_depth + 1):
            children = self._split(cells)
            fine_parts = self._rule(density, children, order)
            m = len(cells)
            fine = fine_parts.reshape(4, m).sum(axis=0)
            converged = np.abs(fine - coarse) <= tol + 1e-4 * np.abs(fine)
            done = converged
            if must_refine is not None and depth < force_depth:
                done = converged & ~must_refine(cells)
            if depth == max_depth or 4 * np.count_nonzero(~done) > max_cells:
                np.add.at(result, owner, fine)
                unresolved = int(np.count_nonzero(~converged))
                break
            np.add.at(result, owner[done], fine[done])
            keep = np.tile(~done, 4)
            cells = children[keep]
            coarse = fine_parts[keep]
            owner = np.tile(owner, 4)[keep]
            if len(cells) == 0:
                break
        return result, unresolved


@dataclass
class Chi2Result:
    """Outcome of :func:`chi2_test`.

    Attributes
    ----------
    passed : bool
    p_value : float
        Probability of a statistic at least this large if the sampler follows the pdf.
    statistic : float
        Pearson's χ² after pooling.
    dof : int
        Degrees of freedom (pooled cells − 1).
    alpha : float
        Per-test significance level used (after the Šidák correction).
    pdf_integral : float
        ∫ pdf over the binned region (the upper hemisphere unless ``lower="bins"``).
    pdf_integral_sphere : float
        ∫ pdf over the whole sphere (a quadrature estimate; must be ≤ 1).
    n_samples, n_valid : int
        Samples drawn; samples with pdf > 0 (histogrammed).
    message : str
        The status's message, then why it failed, with the numbers.
    unresolved_cells : int
        Quadrature cells that did not reach tolerance (should be 0).
    status : int
        ``STATUS["chi2"]``: converged (0, passed), rejected (1), limit (2: passed, but
        ``unresolved_cells`` > 0), nonfinite (3: the pdf is NaN or infinite somewhere).
    success : bool
        The status's success: the same as ``passed``.
    """

    passed: bool
    p_value: float
    statistic: float
    dof: int
    alpha: float
    pdf_integral: float
    pdf_integral_sphere: float
    n_samples: int
    n_valid: int
    message: str = ""
    unresolved_cells: int = 0
    observed: np.ndarray | None = field(default=None, repr=False)
    expected: np.ndarray | None = field(default=None, repr=False)
    status: int = 0

    @property
    def success(self) -> bool:
        return _CODES.success(self.status)

    def __bool__(self) -> bool:
        return self.passed


def _status(fail: list[str], nonfinite: bool, unresolved: int) -> tuple[int, str]:
    """(status, message) of a χ² run from its failure texts."""
    if nonfinite:
        code = _CODES.NONFINITE
    elif fail:
        code = _CODES.REJECTED
    elif unresolved:
        code = _CODES.LIMIT
        fail = [f"{unresolved} cells unresolved"]
    else:
        code = _CODES.CONVERGED
    return code, _CODES.describe(code, *fail)


def _pool(observed: np.ndarray, expected: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pool cells with expected < 5, smallest first (Mitsuba's rule)."""
    order = np.argsort(expected, kind="stable")
    obs, exp = observed[order], expected[order]
    big = exp >= MIN_EXPECTED
    out_o, out_e = list(obs[big]), list(exp[big])
    acc_o = acc_e = 0.0
    for o, e in zip(obs[~big], exp[~big], strict=True):
        acc_o += o
        acc_e += e
        if acc_e >= MIN_EXPECTED:
            out_o.append(acc_o)
            out_e.append(acc_e)
            acc_o = acc_e = 0.0
    if acc_e > 0.0 or acc_o > 0.0:
        if out_e:  # leftover below 5: merge into the smallest remaining cell
            k = int(np.argmin(out_e))
            out_o[k] += acc_o
            out_e[k] += acc_e
        else:
            out_o.append(acc_o)
            out_e.append(acc_e)
    return np.asarray(out_o), np.asarray(out_e)


def check_support(model, wo, *, n: int = 50_000, seed=0, f_min: float = 1e-10) -> str:
    """'' if ``pdf(wi, wo) > 0`` wherever ``f(wi, wo) > f_min`` for wi above the horizon.

    The χ² test cannot see regions the sampler never visits and the pdf calls
    0; there an importance-sampled estimate silently loses energy. *n*
    directions uniform on the upper hemisphere plus the mirror direction of wo
    are checked. Returns a failure message, or '' when the support is covered.
    """
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    wo = np.asarray(wo, dtype=np.float64)
    z = 1.0 - rng.random(n)  # uniform on the upper hemisphere, z in (0, 1]
    phi = 2.0 * np.pi * rng.random(n)
    r = np.sqrt(np.maximum(0.0, 1.0 - z * z))  # clamp: rounding at the pole
    wi = np.concatenate([np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1),
                         reflect(wo)[None, :]])
    wi = wi[wi[:, 2] > 0.0]
    f = np.asarray(model.eval(wi, wo))
    f = f.reshape(len(wi), -1).max(axis=1)
    p = np.asarray(model.pdf(wi, np.broadcast_to(wo, wi.shape)))
    bad = (f > f_min) & ~(p > 0.0)
    if not np.any(bad):
        return ""
    k = int(np.argmax(np.where(bad, f, -1.0)))
    return (f"pdf is 0 where f > 0 for {np.count_nonzero(bad)} of {len(wi)} directions "
            f"(f={f[k]:.3g} at wi={wi[k]})")


def chi2_test(model, wo, *, n_samples: int = 200_000, seed=0, alpha: float = 0.01,
              n_tests: int = 1, n_theta: int | None = None, n_phi: int | None = None,
              binning: SphereBinning | None = None, lower: str = "pool") -> Chi2Result:
    """χ² test that ``model.sample(wo, u)`` follows ``model.pdf(wi, wo)``.

    Parameters
    ----------
    model : BRDF
        A model: its ``sample``, ``pdf``, ``eval`` and ``sharpest_lobe`` are used.
    wo : array_like, shape (3,)
        Unit direction toward the viewer.
    n_samples : int
        Number of samples (≥ 1000).
    seed : int or numpy.random.Generator
        Source of the uniform numbers.
    alpha : float
        Overall significance level of the run.
    n_tests : int
        Number of tests in the run, for the Šidák correction.
    n_theta, n_phi : int, optional
        Resolution (default 40 × 32 for a sharp lobe, 24 × 24 for diffuse ones).
    binning : SphereBinning, optional
        Use this binning instead of the lobe-adapted one.
    lower : {"pool", "bins"}
        ``"pool"``: samples at or below the horizon share one cell with the
        discarded ones (see the module docstring); ``"bins"``: bin the whole
        sphere (for samplers whose pdf is smooth below the horizon).

    Returns
    -------
    Chi2Result
        ``passed`` False with a ``message`` on any failure.
    """
    if lower not in ("pool", "bins"):
        raise BrdfkitError(f"lower must be 'pool' or 'bins'; got {lower!r}")
    if int(n_samples) < 1000:
        raise BrdfkitError(f"n_samples must be >= 1000; got {n_samples!r}")
    n_samples = int(n_samples)
    level = sidak_alpha(alpha, n_tests)
    wo = np.asarray(wo, dtype=np.float64)
    if wo.shape != (3,) or not np.all(np.isfinite(wo)):
        raise BrdfkitError(f"wo must be one finite direction of shape (3,); got {wo!r}")
    wo = wo / np.linalg.norm(wo)
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)

    if binning is None:
        axis, width = lobe_axis_and_width(model, wo)
        sharp = width < 0.5
        binning = SphereBinning(axis, width, n_theta or (40 if sharp else 24),
                                n_phi or (32 if sharp else 24))

    u = rng.random((n_samples, 2))
    wi, pdf_s = model.sample(wo, u)
    wi = np.asarray(wi, dtype=np.float64).reshape(n_samples, 3)
    pdf_s = np.asarray(pdf_s, dtype=np.float64).reshape(n_samples)
    fail = []
    nonfinite = False

    finite = np.all(np.isfinite(wi), axis=-1) & np.isfinite(pdf_s)
    valid = finite & (pdf_s > 0.0)
    if np.any(valid):
        norms = np.linalg.norm(wi[valid], axis=-1)
        if np.max(np.abs(norms - 1.0)) > 1e-6:
            fail.append(f"sampled directions are not unit vectors (|wi| up to "
                        f"{np.max(np.abs(norms - 1.0)):.3g} off)")
    if np.any(np.isfinite(pdf_s) & (pdf_s < 0.0)):
        fail.append("sample returned a negative pdf")

    # the pdf returned by sample must be the pdf function's value
    wi_v = wi[valid]
    pdf_f = np.asarray(model.pdf(wi_v, wo), dtype=np.float64)
    mismatch = ~np.isclose(pdf_f, pdf_s[valid], rtol=1e-6, atol=0.0)
    if np.any(mismatch):
        k = np.argmax(mismatch)
        fail.append(f"{np.count_nonzero(mismatch)} samples: pdf from sample() "
                    f"{pdf_s[valid][k]:.6g} != pdf() {pdf_f[k]:.6g} at wi={wi_v[k]}")

    # samples the sampler discards (pdf 0) must carry no BRDF value
    zero = finite & (pdf_s == 0.0)
    if np.any(zero):
        f0 = np.asarray(model.eval(wi[zero], wo))
        f0 = f0.reshape(f0.shape[0], -1).max(axis=1)
        if np.any(f0 > 0.0):
            k = int(np.argmax(f0))
            fail.append(f"{np.count_nonzero(f0 > 0)} samples have pdf 0 but f > 0 "
                        f"(f={f0[k]:.3g} at wi={wi[zero][k]})")

    if lower == "pool":
        binned = wi_v[wi_v[:, 2] > 0.0]

        def density(w):
            return np.where(w[..., 2] > 0.0, model.pdf(w, np.broadcast_to(wo, w.shape)), 0.0)
    else:
        binned = wi_v

        def density(w):
            return model.pdf(w, np.broadcast_to(wo, w.shape))

    # support: wherever f > 0 above the horizon the pdf must be > 0 (else the estimator is biased)
    missing = check_support(model, wo, n=50_000, seed=rng)
    if missing:
        fail.append(missing)

    observed = binning.histogram(binned)
    refine = binning.straddles_horizon if lower == "pool" else None
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        probs, unresolved = binning.integrate(density, must_refine=refine)
        # Samples in a bin whose integral is 0: first re-integrate those bins on a much
        # finer grid (a thin sliver of the lobe above the horizon can slip between nodes).
        suspicious = np.flatnonzero((probs <= 1e-12) & (observed > 0))
        if len(suspicious):
            again, _ = binning.integrate(density, bins=suspicious, sub=32, max_depth=2,
                                         must_refine=refine)
            probs[suspicious] = again[suspicious]
    total = float(np.sum(probs))
    region = "the upper hemisphere" if lower == "pool" else "the sphere"
    if not np.isfinite(total):
        fail.append(f"pdf is not finite somewhere on {region}")
        nonfinite = True
        total = math.inf
    elif total > 1.0 + 1e-3:
        fail.append(f"pdf integrates to {total:.6f} > 1 over {region}")

    # the whole sphere too (coarser tolerance: a microfacet pdf's 1/ε point at wi = −wo makes
    # this quadrature less accurate; it is a sanity bound, the χ² cells above are exact)
    if lower == "pool":
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            full, _ = binning.integrate(lambda w: model.pdf(w, np.broadcast_to(wo, w.shape)),
                                        max_depth=4)
        sphere_total = float(np.sum(full))
        if not np.isfinite(sphere_total):
            fail.append("pdf is not finite somewhere on the sphere")
            nonfinite = True
        elif sphere_total > 1.0 + 1e-2:
            fail.append(f"pdf integrates to {sphere_total:.4f} > 1 over the sphere")
    else:
        sphere_total = total

    expected = probs * n_samples
    # one more cell: samples not binned (discarded, or below the horizon with lower="pool")
    # against the mass of the pdf outside the binned region
    observed = np.append(observed, n_samples - len(binned))
    expected = np.append(expected, max(n_samples * (1.0 - total), 0.0))

    # a cell the pdf does not reach at all (integral exactly 0) must not receive samples
    empty = (expected <= 0.0) & (observed > 0)
    if np.any(empty):
        fail.append(f"{int(observed[empty].sum())} samples fell in {np.count_nonzero(empty)} "
                    "cells where the pdf is 0")
    keep = ~empty & np.isfinite(expected) & ((expected > 0.0) | (observed > 0))
    o, e = _pool(observed[keep], expected[keep])
    dof = max(len(e) - 1, 1)
    stat = float(np.sum((o - e) ** 2 / e)) if len(e) else 0.0
    p_value = float(stats.chi2.sf(stat, dof))
    if p_value < level:
        fail.append(f"chi2 = {stat:.1f} with {dof} dof: p = {p_value:.3g} < {level:.3g}")

    status, message = _status(fail, nonfinite, unresolved)
    return Chi2Result(
        passed=not fail, p_value=p_value, statistic=stat, dof=dof, alpha=level,
        pdf_integral=total, pdf_integral_sphere=sphere_total, n_samples=n_samples,
        n_valid=int(np.count_nonzero(valid)),
        message=message, unresolved_cells=unresolved, observed=observed,
        expected=expected, status=status,
    )
