"""
Physical plausibility verdicts
==============================

:func:`check` decides, by computation, whether a model is reciprocal and
whether it conserves energy (Lewis §4–5, Neumann §2):

- **Reciprocity** — the largest relative asymmetry
  |f(L,V) − f(V,L)| / max(f(L,V), f(V,L)) over a structured set of pairs
  (θ ∈ {0, 15, 30, 45, 60, 75, 85, 89, 89.9}°, both directions, five relative
  azimuths including the mirror configuration, L at azimuth 0). An anisotropic
  model (``isotropic`` False) depends on the absolute azimuths too: L is placed at
  seven absolute azimuths (0, 20, 45, 90, 135, 200, 290°, not symmetric about any
  axis) and V at eight relative ones (every 45°, both sides of the plane of
  incidence). Reciprocal when ≤ 1e-6. The set does not depend on the ``phi`` of
  :func:`check`.
  Pairs where f is NaN in either order (unmeasured bins of a measured table)
  are left out and counted in the notes; *undetermined* when none is left.
- **Energy** — the albedo a(θ_i) at the incidence azimuth ``phi`` (default 0; an
  isotropic model's albedo does not depend on it) on 0…87° in 3° steps plus
  89°, 89.5°, 89.9°, 89.99°, 89.999°, refined about its maximum.
  *diverges*: a grows without bound as θ_i → 90°; the rate p of
  a ∝ (cos θ_i)^−p is the log–log slope between 89.99° and 89.999°, and the
  verdict needs a positive slope (> 0.05) over the last two decades and an
  increasing sequence a(89°) < a(89.9°) < a(89.99°) < a(89.999°) — the
  asymptotics, not one value. Otherwise *conserves* if max a ≤ 1 (+1e-6
  numerical slack) or *exceeds*, with ``max_scale`` = 1/max a, the largest
  factor on the model's reflectance that makes it conserve (Lewis §4.2's b_j).
  *undetermined*: the albedo could not be computed (NaN), or did not converge
  to the tolerance and its maximum is within its error estimate of 1 — no
  verdict is claimed that the accuracy cannot support; the notes say why.
- **Other objections** detected numerically: radiance that always peaks at
  the normal (Lewis §3.3–3.4 against Neumann–Neumann and Minnaert; in the plane of
  incidence at ``phi``), albedo
  that collapses at grazing incidence (Neumann §1.2, the "dark Phong mirror").

Every verdict has a ``status`` (``brdfkit.status.STATUS["verdict"]``): *converged*
when every part is decided, *undetermined* when reciprocity or energy is undetermined
(the verdict says so rather than claim an answer), *nonfinite* when the albedo is NaN
or infinite; ``success`` and ``message`` as for every result.

Public objects
--------------
- :class:`Verdict` — the result (``to_dict`` gives the JSON of
  ``brdfkit check --json``).
- :func:`check` — compute the verdict of a model.
- :func:`divergence_rate` — slopes of log a against log cos θ_i near 90°.

References
----------
- [Lewis1993] eqs. (15), (19), (23), §4.2 (b_j bound), Table 2.
- [Neumann1999] §1.2, §2.1 eqs. (8)–(15).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from brdfkit.analysis.albedo_engine import check_phi, evaluate_pairs
from brdfkit.analysis.stored import stored_albedo
from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.models._base import BRDF
from brdfkit.status import STATUS

__all__ = ["Verdict", "check", "divergence_rate", "reciprocity", "ENERGY_GRID_DEG", "GRAZING_DEG",
           "RECIPROCITY_TOL"]

RECIPROCITY_TOL = 1e-6
CONSERVE_SLACK = 1e-6
GRAZING_DEG = (89.0, 89.9, 89.99, 89.999)
#: The incidence angles (degrees) of the energy verdict's albedo scan: 0…87° in 3° steps,
#: 89°, 89.5° and the grazing angles (the energy tables of issue 22 scan the same grid).
ENERGY_GRID_DEG = (*(3.0 * k for k in range(30)), 89.0, 89.5, *GRAZING_DEG[1:])
_PAIR_THETA_DEG = (0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0, 89.0, 89.9)
_PAIR_DPHI_DEG = (0.0, 45.0, 90.0, 135.0, 180.0)
# anisotropic models: L at absolute azimuths with no symmetry between them (a model
# symmetric about an axis cannot hide an asymmetry at all of them), V on both sides
_ANISO_PHI_DEG = (0.0, 20.0, 45.0, 90.0, 135.0, 200.0, 290.0)
_ANISO_DPHI_DEG = (0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0)
_CODES = STATUS["verdict"]


@dataclass
class Verdict:
    """Plausibility verdict of one model (see the module docstring for the rules).

    ``reciprocity`` ("reciprocal", "not reciprocal" or "undetermined": no pair with both
    values) is the one record of the reciprocity verdict; ``reciprocal`` is derived from
    it (True only for "reciprocal"). ``status`` is a code of ``STATUS["verdict"]``;
    ``success`` and ``message`` follow from it (``detail`` adds what was undetermined).
    """

    model: str
    params: dict
    reciprocity: str
    max_asymmetry: float
    energy: str
    max_albedo: float
    theta_max_deg: float
    divergence_exponent: float | None
    max_scale: float | None
    notes: list[str] = field(default_factory=list)
    grazing: dict = field(default_factory=dict)
    slopes: list = field(default_factory=list)
    peaks_at_normal: bool = False
    albedo_error: float = 0.0
    min_albedo: float = 0.0
    theta_min_deg: float = 0.0
    #: The pumping stages of a pumped model (``PumpedBRDF.to_dict()["pump"]``), else None.
    pump: dict | list | None = None
    #: The compensation of a compensated model (``to_dict()["compensate"]``), else None.
    compensate: dict | None = None
    status: int = 0
    detail: str = ""
    #: The incidence azimuth of the energy part (radians), and whether the model is
    #: anisotropic (then ``to_dict`` records ``phi_deg``; also when phi is not 0).
    phi: float = 0.0
    anisotropic: bool = False

    @property
    def reciprocal(self) -> bool:
        """True when the reciprocity verdict is "reciprocal" (derived from ``reciprocity``)."""
        return self.reciprocity == "reciprocal"

    @property
    def success(self) -> bool:
        return _CODES.success(self.status)

    @property
    def message(self) -> str:
        return _CODES.describe(self.status, self.detail)

    def to_dict(self) -> dict:
        """JSON-ready dict with the keys of ``brdfkit check --json``."""
        return {
            "model": self.model,
            "params": self.params,
            "reciprocal": bool(self.reciprocal),
            "reciprocity": self.reciprocity,
            "max_asymmetry": float(self.max_asymmetry),
            "energy": self.energy,
            "max_albedo": float(self.max_albedo),
            "theta_max_deg": float(self.theta_max_deg),
            "divergence_exponent": (None if self.divergence_exponent is None
                                    else float(self.divergence_exponent)),
            "max_scale": None if self.max_scale is None else float(self.max_scale),
            "notes": list(self.notes),
            "grazing_albedo": {f"{k:g}": v for k, v in self.grazing.items()},
            "grazing_slopes": [float(s) for s in self.slopes],
            "peaks_at_normal": bool(self.peaks_at_normal),
            "albedo_error": float(self.albedo_error),
            "min_albedo": float(self.min_albedo),
            "theta_min_deg": float(self.theta_min_deg),
            **({"phi_deg": math.degrees(self.phi)}
               if self.anisotropic or self.phi != 0.0 else {}),
            **({"compensate": self.compensate} if self.compensate is not None else {}),
            **({"pump": self.pump} if self.pump is not None else {}),
            "status": int(self.status),
            "success": self.success,
            "message": self.message,
        }


def _dirs(theta_deg, phi_deg) -> np.ndarray:
    t = np.radians(theta_deg)
    p = np.radians(phi_deg)
    return np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1)


def _reciprocity(model) -> tuple[float, int, int]:
    """(asymmetry over the pairs where both values exist, pairs without both, all pairs).
    A plain callable claims nothing: it gets the anisotropic pair set."""
    if isinstance(model, BRDF) and model.isotropic:
        # rotation invariant: L at azimuth 0 stands for every azimuth; one side of the plane
        # of incidence stands for both only for a mirror-symmetric model
        dphi = _PAIR_DPHI_DEG if model.mirror_symmetric else _ANISO_DPHI_DEG
        ti, to, dp = np.meshgrid(_PAIR_THETA_DEG, _PAIR_THETA_DEG, dphi, indexing="ij")
        pl = np.zeros(ti.size)
    else:
        ti, to, p0, dp = np.meshgrid(_PAIR_THETA_DEG, _PAIR_THETA_DEG, _ANISO_PHI_DEG,
                                     _ANISO_DPHI_DEG, indexing="ij")
        pl = p0.ravel()
    L = _dirs(ti.ravel(), pl)
    V = _dirs(to.ravel(), pl + dp.ravel())
    a = evaluate_pairs(model, L, V)
    b = evaluate_pairs(model, V, L)
    # a NaN value (e.g. an unmeasured bin of a measured table) is no evidence either way:
    # such pairs are left out and counted, never compared
    both = np.all(np.isfinite(a) & np.isfinite(b), axis=-1)
    n_missing = int(np.count_nonzero(~both))
    if not np.any(both):
        return float("nan"), n_missing, both.size
    a, b = a[both], b[both]
    scale = max(float(np.max(np.abs(a))), float(np.max(np.abs(b))), 1e-300)
    # floor: pairs where both values are ~1e-12 of the largest are rounding noise
    den = np.maximum(np.maximum(np.abs(a), np.abs(b)), 1e-12 * scale)
    return float(np.max(np.abs(a - b) / den)), n_missing, both.size


def reciprocity(model) -> float:
    """Largest relative asymmetry |f(L,V) − f(V,L)| / max(f(L,V), f(V,L)) over the pair set
    (pairs where a value is NaN left out; NaN when no pair has both values)."""
    return _reciprocity(model)[0]


def divergence_rate(values: np.ndarray, theta_deg=GRAZING_DEG) -> list[float]:
    """Slopes p_k = −Δ ln a / Δ ln cos θ_i between successive grazing angles (nan if a ≤ 0)."""
    v = np.asarray(values, dtype=np.float64)
    lc = np.log(np.cos(np.radians(np.asarray(theta_deg))))
    out = []
    for k in range(len(v) - 1):
        if v[k] > 0.0 and v[k + 1] > 0.0:
            out.append(float(-(math.log(v[k + 1]) - math.log(v[k])) / (lc[k + 1] - lc[k])))
        else:
            out.append(float("nan"))
    return out


def _peaks_at_normal(model, phi_deg: float = 0.0) -> bool:
    """True when, for θ_i = 30°, 60°, 80°, f(L, V) over V in the plane of incidence peaks at V = N.

    L at azimuth *phi_deg*; f is scanned over signed θ_o ∈ [−89°, 89°] in 0.5° steps
    (positive = the mirror side). A flat f (Lambert) does not count as a peak.
    """
    so = np.arange(-89.0, 89.0001, 0.5)
    for ti in (30.0, 60.0, 80.0):
        L = _dirs(np.full(so.size, ti), np.full(so.size, phi_deg))
        V = _dirs(np.abs(so), phi_deg + np.where(so >= 0.0, 180.0, 0.0))
        f = evaluate_pairs(model, L, V)
        for ch in range(f.shape[1]):
            col = f[:, ch]
            if not np.all(np.isfinite(col)) or col.max() <= 0.0:
                return False
            if col.max() - col.min() <= 1e-9 * col.max():
                return False  # flat: no peak anywhere
            if abs(so[int(np.argmax(col))]) > 0.25:
                return False
    return True


def check(model, *, tol: float = 1e-7, phi: float = 0.0) -> Verdict:
    """Reciprocity and energy verdict of *model*, computed (see the module docstring).

    Parameters
    ----------
    model : BRDF
        A brdfkit model (registered, pumped or otherwise derived).
    tol : float, keyword-only
        Albedo accuracy goal.
    phi : float, keyword-only
        Incidence azimuth of the energy part and the normal-peak scan, radians (any
        finite value; default 0). An isotropic model's verdict does not depend on it;
        the reciprocity pairs never do (an anisotropic model's cover seven absolute
        azimuths).

    Returns
    -------
    Verdict
    """
    if not isinstance(model, BRDF):
        hint = (f" (build it first: brdfkit.model({model!r}))" if isinstance(model, str) else "")
        raise BrdfkitError(f"check: model must be a brdfkit model (BRDF); got "
                           f"{type(model).__name__} {model!r}{hint}")
    ph = check_phi(phi)
    if ph.ndim:
        raise ParameterError(f"check: phi must be one number (radians); got an array of shape "
                           f"{ph.shape}")
    phi = float(ph)
    # an isotropic model is rotation invariant: its scans stay at azimuth 0 (the same
    # numbers for every phi)
    phi_at = 0.0 if model.isotropic else phi
    aniso = {"phi": phi, "anisotropic": not model.isotropic}
    d = model.to_dict()
    asym, n_missing, n_pairs = _reciprocity(model)
    if not math.isfinite(asym):
        recip = "undetermined"
    else:
        recip = "reciprocal" if asym <= RECIPROCITY_TOL else "not reciprocal"
    grid = np.asarray(ENERGY_GRID_DEG)
    r = stored_albedo(model, np.radians(grid), phi=phi_at, tol=tol)  # a material: kept on disk
    a = np.asarray(r.albedo).reshape(grid.size, -1)
    err = float(np.max(np.asarray(r.error)))
    notes: list[str] = []
    prov = model.provenance()
    if prov:  # a verdict on a representation of data (a surrogate, a table) says so
        notes.append(f"these verdicts are on {prov}")
    if n_missing:
        notes.append(f"reciprocity {'undetermined' if recip == 'undetermined' else 'judged'}"
                     f": {n_missing} of {n_pairs} pairs have no value (NaN) in one order and "
                     "were left out")
    if not r.success:
        notes.append(f"albedo not computed to the tolerance {tol:g}: {r.message}")
    if not np.all(np.isfinite(a)):
        # no verdict on energy from values that do not exist
        return Verdict(
            model=d["model"], params=d["params"], reciprocity=recip,
            max_asymmetry=asym, energy="undetermined", max_albedo=float("nan"),
            theta_max_deg=float("nan"), divergence_exponent=None, max_scale=None, notes=notes,
            albedo_error=float("inf"), pump=d.get("pump"), compensate=d.get("compensate"),
            status=_CODES.NONFINITE,
            detail="energy undetermined: the albedo is NaN or infinite", **aniso)

    # --- divergence from the asymptotics, per channel
    ig = [int(np.argmin(np.abs(grid - g))) for g in GRAZING_DEG]
    p_est = None
    slopes_worst: list[float] = []
    for ch in range(a.shape[1]):
        seq = a[ig, ch]
        sl = divergence_rate(seq)
        increasing = bool(np.all(np.diff(seq) > 0.0))
        if increasing and np.all(np.isfinite(sl[-2:])) and min(sl[-2:]) > 0.05:
            if p_est is None or sl[-1] > p_est:
                p_est = sl[-1]
                slopes_worst = sl
    if not slopes_worst:
        ch_max = int(np.argmax(a.max(axis=0)))
        slopes_worst = divergence_rate(a[ig, ch_max])

    # --- maximum, refined about the grid maximum (bounded models)
    flat_max = a.max(axis=1)
    k = int(np.argmax(flat_max))
    theta_max = float(grid[k])
    max_a = float(flat_max[k])
    if p_est is None and 0 < k < grid.size - 1 and grid[k] < 89.0:
        lo, hi = grid[k - 1], grid[k + 1]
        fine = np.linspace(lo, hi, 13)
        rf = np.asarray(stored_albedo(model, np.radians(fine), phi=phi_at, tol=tol).albedo
                        ).reshape(fine.size, -1)
        kf = int(np.argmax(rf.max(axis=1)))
        if rf.max(axis=1)[kf] > max_a:
            max_a = float(rf.max(axis=1)[kf])
            theta_max = float(fine[kf])

    if p_est is not None:
        energy = "diverges"
        max_scale = None
        p_rounded = float(round(p_est, 3))
        notes.append(
            f"albedo diverges at grazing incidence: a ∝ (cos θ_i)^-{p_rounded:g} "
            f"(log-log slopes {', '.join(f'{s:.3f}' for s in slopes_worst)} over "
            f"{', '.join(f'{g:g}' for g in GRAZING_DEG)} deg); a({GRAZING_DEG[-1]:g} deg) = "
            f"{max_a:.4g}")
    else:
        p_rounded = None
        # the error estimate where it matters: at the maximum (converged or not)
        err_max = float(np.max(np.asarray(r.error).reshape(grid.size, -1)[k])) \
            if theta_max == float(grid[k]) else err
        if not r.success and abs(max_a - 1.0) <= max(CONSERVE_SLACK, 10 * err_max):
            # the albedo is within its (unconverged) error of 1: no claim either way
            energy = "undetermined"
            max_scale = None
            notes.append(f"energy undetermined: max albedo {max_a:.6g} at {theta_max:g} deg "
                         f"is within its error estimate {err_max:.2g} of 1")
        elif max_a <= 1.0 + max(CONSERVE_SLACK, 10 * err):
            energy = "conserves"
            max_scale = None
        else:
            energy = "exceeds"
            max_scale = 1.0 / max_a
            notes.append(f"bounded but exceeds 1: max albedo {max_a:.6g} at {theta_max:g} deg; "
                         f"scale the reflectance by <= {max_scale:.6g} to conserve energy "
                         "(Lewis §4.2 b_j bound)")

    # --- other objections
    peaks = _peaks_at_normal(model, math.degrees(phi_at))
    if peaks:
        notes.append("reflected radiance always peaks at the normal (theta_r = 0) for every "
                     "incidence tested (Lewis §3.3-3.4 objection)")
    if energy != "diverges" and max_a > 0.0:
        a_graze = float(a[ig[1]].max())
        if a_graze < 0.5 * max_a:
            notes.append(f"dark at grazing incidence: a(89.9 deg) = {a_graze:.3g}, "
                         f"{100 * a_graze / max_a:.2g}% of its maximum (Neumann §1.2)")
    if recip == "not reciprocal":
        notes.append(f"not reciprocal: max relative asymmetry {asym:.3g}")
    if model.has_delta:
        notes.append("includes the energy of the specular delta term (specular_albedo)")

    kmin = int(np.argmin(a.min(axis=1)[grid <= 89.0]))
    grazing = {g: float(a[i].max()) for g, i in zip(GRAZING_DEG, ig, strict=True)}
    open_parts = [f"{part} undetermined" for part, v in (("reciprocity", recip),
                                                         ("energy", energy))
                  if v == "undetermined"]
    return Verdict(
        model=d["model"], params=d["params"], reciprocity=recip,
        max_asymmetry=asym, energy=energy, max_albedo=max_a, theta_max_deg=theta_max,
        divergence_exponent=p_rounded, max_scale=max_scale, notes=notes, grazing=grazing,
        slopes=slopes_worst, peaks_at_normal=peaks, albedo_error=err,
        min_albedo=float(a.min(axis=1)[kmin]), theta_min_deg=float(grid[kmin]),
        pump=d.get("pump"), compensate=d.get("compensate"),
        status=_CODES.UNDETERMINED if open_parts else _CODES.CONVERGED,
        detail=", ".join(open_parts), **aniso,
    )
