"""
Energy verdicts: reciprocity, albedo maximum, white furnace, divergence — with accuracy
=======================================================================================

One row of the energy table (:mod:`brdfkit.report.energy_table`) and one point of the
"energy against reciprocity" figure: what :func:`~brdfkit.analysis.check` decides,
plus the white furnace test, each number with the accuracy it rests on. Nothing is
computed a second way here: reciprocity is :func:`plausibility.reciprocity
<brdfkit.analysis.plausibility.reciprocity>` (the largest relative asymmetry over
check's pair set), the energy verdict, its maximum and the divergence are
:func:`~brdfkit.analysis.check`'s (Table 2's definitions), the albedos and their error
estimates the albedo engine's (:func:`~brdfkit.analysis.albedo`), E_avg is
:func:`~brdfkit.analysis.hemispherical_albedo`.

- **Reciprocity** — max |f(L,V) − f(V,L)| / max(f(L,V), f(V,L)) (relative). Its accuracy
  is float64 rounding of the model's own formula (no quadrature): a reciprocal formula
  gives 0 or ~1e-16, and the verdict "reciprocal" needs ≤
  :data:`~brdfkit.analysis.plausibility.RECIPROCITY_TOL` (1e-6).
- **Energy** — check's verdict (conserves / exceeds / diverges / undetermined), its
  maximum albedo and where (θ_i; for an anisotropic model also φ_i: the albedo is scanned
  over θ_i on check's grid × φ_i every 30°, and check is run at the φ_i of the maximum),
  with the engine's error estimate at the maximum.
- **White furnace** — a(θ_i) and the deficit 1 − a(θ_i) at θ_i = 0, 60, 80, 89°
  (:data:`FURNACE_DEG`) for the model as given: the caller gives the white settings
  (ρ = 1, F = 1 as each model has them); a negative deficit is a gain. For an anisotropic
  model the deficit is of the albedo averaged over φ_i (the 12 azimuths), and its range
  over φ_i is recorded. Each with the engine's error estimate.
- **E_avg** = 2 ∫₀¹ a(μ) μ dμ (ρ_hh, Kulla–Conty's E_avg; an anisotropic model's a
  averaged over φ_i; rule :data:`E_AVG_RULE`), with its error estimate.
- **Furnace deviation** (:func:`furnace_deviation`, the figure's energy axis) — the
  1 − a(θ_i) of largest magnitude over θ_i ≤ 89° on check's grid (0, 3, …, 87, 89°).

A number is never stated beyond its accuracy: :func:`bound_text` prints a value whose
magnitude is within its error as "0 (±err)", and the verdict's ``status`` is check's
(``STATUS["verdict"]``: undetermined when its accuracy cannot support a part).

Public objects
--------------
- :class:`EnergyVerdict` — the result (``to_dict``: the JSON row of ``brdfkit verdicts``).
- :func:`energy_verdict` — compute it for one model.
- :func:`furnace` — a(θ_i), 1 − a(θ_i) and the error estimate at given angles.
- :func:`furnace_deviation` — the largest white-furnace |1 − a| over θ_i ≤ 89°, signed.
- :func:`energy_reciprocity` — the figure's point: furnace deviation and asymmetry.
- :func:`bound_text` — a value with its accuracy, never more digits than it supports.
- :data:`FURNACE_DEG`, :data:`FURNACE_TOL`, :data:`ANISO_PHI_DEG`, :data:`E_AVG_RULE`.

References
----------
- [Lewis1993] Table 2 (the verdict's columns); [Neumann1999] §2.1 (divergence).
- Kulla & Conty 2017, "Revisiting physically based shading at Imageworks" (E(μ), E_avg,
  the white furnace test).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from brdfkit.analysis.albedo_engine import albedo
from brdfkit.analysis.hemispherical import hemispherical_albedo
from brdfkit.analysis.plausibility import ENERGY_GRID_DEG, check, reciprocity
from brdfkit.errors import BrdfkitError
from brdfkit.models._base import BRDF
from brdfkit.status import STATUS

__all__ = ["ANISO_PHI_DEG", "E_AVG_RULE", "FURNACE_DEG", "FURNACE_TOL", "EnergyVerdict",
           "bound_text", "energy_reciprocity", "energy_verdict", "furnace", "furnace_deviation"]

#: The white furnace angles of the table (degrees).
FURNACE_DEG = (0.0, 60.0, 80.0, 89.0)
#: The white furnace is passed ("a = 1") when |1 − a(θ)| ≤ this at every furnace angle
#: (beyond the engine's error): issue 22's criterion for the Kulla–Conty white furnace
#: (§4, "within 1e-5 of 1").
FURNACE_TOL = 1e-5
#: Incidence azimuths scanned for an anisotropic model's maximum and furnace (degrees):
#: every 30°, the full circle (no symmetry of the model is assumed; check then refines θ_i
#: at the best azimuth).
ANISO_PHI_DEG = tuple(float(p) for p in range(0, 360, 30))
#: E_avg's outer rule (Gauss–Legendre nodes in u = √μ, incidence azimuths): the default of
#: hemispherical_albedo for an isotropic model; for an anisotropic one 24 nodes × 8
#: azimuths, 288 full-azimuth albedos instead of 1152 (Ashikhmin–Shirley n = 100 took
#: 300 s with the default), its error estimate (reported) saying what that costs.
E_AVG_RULE = {True: (48, 16), False: (24, 8)}
_CODES = STATUS["verdict"]


def bound_text(value: float, error: float, *, digits: int = 4) -> str:
    """*value* with its accuracy: ``"0 (±err)"`` when |value| ≤ error, else the value to
    *digits* significant digits and ``± err`` (an infinite error: ``"value (±inf)"``)."""
    if not math.isfinite(value):
        return f"{value}"
    if math.isfinite(error) and abs(value) <= error:
        return f"0 (±{error:.1g})"
    return f"{value:.{digits}g} ± {error:.1g}"


def _check_model(model, func: str) -> None:
    if not isinstance(model, BRDF):
        hint = (f" (build it first: brdfkit.model({model!r}))" if isinstance(model, str)
                else "")
        raise BrdfkitError(f"{func}: model must be a brdfkit model (BRDF); got "
                           f"{type(model).__name__} {model!r}{hint}")


def _channels(x) -> np.ndarray:
    """(angles, C) from an engine array of shape (angles,) or (angles, C)."""
    x = np.asarray(x, dtype=np.float64)
    return x.reshape(x.shape[0], -1) if x.ndim else x.reshape(1, 1)


def _azimuths(model) -> np.ndarray:
    return np.radians(ANISO_PHI_DEG) if not model.isotropic else np.zeros(1)


def furnace(model, theta_deg=FURNACE_DEG, *, tol: float = 1e-7) -> dict:
    """The white furnace of *model* at *theta_deg* (degrees, each in [0, 90)).

    Returns ``{"theta_deg", "albedo", "deficit", "error"}`` (lists, one value per angle;
    a coloured model's worst channel, the one of largest 1 − a) and, for an anisotropic
    model, the albedo averaged over :data:`ANISO_PHI_DEG` with ``"deficit_min"``,
    ``"deficit_max"`` (the range over φ_i) and ``"phi_deg"`` (the azimuths). ``error``
    is the engine's estimate (for an anisotropic model, the largest over φ_i).
    """
    _check_model(model, "furnace")
    th = np.asarray(theta_deg, dtype=np.float64).reshape(-1)
    phis = _azimuths(model)
    r = albedo(model, np.radians(th)[:, None], phi=phis[None, :], tol=tol)
    a = np.asarray(r.albedo, dtype=np.float64).reshape(th.size, phis.size, -1)
    e = np.asarray(r.error, dtype=np.float64).reshape(th.size, phis.size, -1)
    mean = a.mean(axis=1)  # (angles, C): the trapezoidal rule over the full circle
    ch = np.argmin(mean, axis=1)  # the worst channel: the largest deficit
    rows = np.arange(th.size)
    out = {"theta_deg": th.tolist(), "albedo": mean[rows, ch].tolist(),
           "deficit": (1.0 - mean[rows, ch]).tolist(),
           "error": e.max(axis=1)[rows, ch].tolist()}
    if not model.isotropic:
        per_phi = a[rows, :, ch]  # (angles, azimuths)
        out.update({"deficit_min": (1.0 - per_phi.max(axis=1)).tolist(),
                    "deficit_max": (1.0 - per_phi.min(axis=1)).tolist(),
                    "phi_deg": list(ANISO_PHI_DEG)})
    return out


def furnace_deviation(model, *, tol: float = 1e-7) -> dict:
    """The figure's energy measure: the white-furnace deviation of largest magnitude over
    θ_i ≤ 89° on check's grid (0, 3, …, 87, 89°).

    Returns ``{"deviation", "theta_deg", "error"}``: 1 − a(θ_i) there (signed: positive a
    loss, negative a gain), its θ_i and the engine's error estimate. An anisotropic
    model's a is averaged over φ_i first (:func:`furnace`).
    """
    _check_model(model, "furnace_deviation")
    grid = [g for g in ENERGY_GRID_DEG if g <= 89.0]
    f = furnace(model, grid, tol=tol)
    k = int(np.argmax(np.abs(f["deficit"])))
    return {"deviation": float(f["deficit"][k]), "theta_deg": float(grid[k]),
            "error": float(f["error"][k])}


def energy_reciprocity(model, *, tol: float = 1e-7) -> dict:
    """One point of the "energy against reciprocity" figure: :func:`furnace_deviation`'s
    dict plus ``"asymmetry"``, check's reciprocity measure
    (:func:`~brdfkit.analysis.plausibility.reciprocity`, exact up to rounding)."""
    _check_model(model, "energy_reciprocity")
    return {**furnace_deviation(model, tol=tol), "asymmetry": reciprocity(model)}


@dataclass
class EnergyVerdict:
    """The energy verdict of one model (module docstring); ``status`` is check's
    (``STATUS["verdict"]``), ``success`` and ``message`` follow from it."""

    label: str
    model: dict
    reciprocity: str
    max_asymmetry: float
    energy: str
    max_albedo: float
    max_albedo_error: float
    theta_max_deg: float
    phi_max_deg: float | None
    divergence_exponent: float | None
    furnace: dict
    e_avg: float
    e_avg_error: float
    anisotropic: bool = False
    notes: list[str] = field(default_factory=list)
    status: int = 0
    detail: str = ""

    @property
    def reciprocal(self) -> bool:
        """True when the reciprocity verdict is "reciprocal"."""
        return self.reciprocity == "reciprocal"

    @property
    def success(self) -> bool:
        return _CODES.success(self.status)

    @property
    def message(self) -> str:
        return _CODES.describe(self.status, self.detail)

    def to_dict(self) -> dict:
        """JSON-ready: every field, ``reciprocal``, ``success`` and ``message``."""
        return {
            "label": self.label, "model": self.model,
            "reciprocal": self.reciprocal, "reciprocity": self.reciprocity,
            "max_asymmetry": float(self.max_asymmetry),
            "energy": self.energy, "max_albedo": float(self.max_albedo),
            "max_albedo_error": float(self.max_albedo_error),
            "theta_max_deg": float(self.theta_max_deg),
            "phi_max_deg": None if self.phi_max_deg is None else float(self.phi_max_deg),
            "divergence_exponent": (None if self.divergence_exponent is None
                                    else float(self.divergence_exponent)),
            "furnace": self.furnace, "e_avg": float(self.e_avg),
            "e_avg_error": float(self.e_avg_error), "anisotropic": self.anisotropic,
            "notes": list(self.notes), "status": int(self.status), "success": self.success,
            "message": self.message,
        }


def _azimuth_of_max(model, tol: float) -> float:
    """The incidence azimuth (degrees, one of :data:`ANISO_PHI_DEG`) of the largest albedo
    over check's θ_i grid × :data:`ANISO_PHI_DEG` (0 for an isotropic model, which does
    not depend on it). Azimuths whose maximum is within the error estimates of the largest
    tie (at θ_i = 0 every azimuth gives the same albedo): the first of them is taken."""
    if model.isotropic:
        return 0.0
    phis = _azimuths(model)
    r = albedo(model, np.radians(np.asarray(ENERGY_GRID_DEG))[:, None], phi=phis[None, :],
               tol=tol)
    shape = (len(ENERGY_GRID_DEG), phis.size, -1)
    a = np.asarray(r.albedo, dtype=np.float64).reshape(shape)
    e = np.asarray(r.error, dtype=np.float64).reshape(shape)
    a = np.where(np.isfinite(a), a, np.inf)  # a NaN albedo is where check must look
    flat = a.reshape(-1, phis.size, a.shape[-1]).transpose(1, 0, 2).reshape(phis.size, -1)
    where = np.argmax(flat, axis=1)  # per azimuth: its largest albedo and that one's error
    per_phi = flat[np.arange(phis.size), where]
    err = e.reshape(-1, phis.size, e.shape[-1]).transpose(1, 0, 2).reshape(phis.size, -1)[
        np.arange(phis.size), where]
    k = int(np.argmax(per_phi))
    if np.isfinite(per_phi[k]):
        # azimuths within the error estimates of the largest tie (at θ_i = 0 all are equal
        # but for the quadrature's error): the first of them is taken
        k = int(np.flatnonzero(per_phi >= per_phi[k] - err - err[k])[0])
    return ANISO_PHI_DEG[k]


def energy_verdict(model, *, label: str | None = None, tol: float = 1e-7) -> EnergyVerdict:
    """The energy verdict of *model* (module docstring).

    Parameters
    ----------
    model : BRDF
        The model at its white settings (ρ = 1, F = 1 as it has them): the furnace deficit
        is 1 − a of the model as given.
    label : str, keyword-only, optional
        The row's label (default: the model's name).
    tol : float, keyword-only
        The albedo engine's accuracy goal.

    Returns
    -------
    EnergyVerdict
    """
    _check_model(model, "energy_verdict")
    phi_deg = _azimuth_of_max(model, tol)
    phi = math.radians(phi_deg)
    v = check(model, tol=tol, phi=phi)
    f = furnace(model, tol=tol)
    n, n_phi = E_AVG_RULE[bool(model.isotropic)]
    h = hemispherical_albedo(model, n=n, n_phi=n_phi, tol=tol)
    # the engine's error estimate at the maximum: one more albedo there (check records the
    # largest estimate over its grid)
    if math.isfinite(v.theta_max_deg):
        rm = albedo(model, math.radians(min(v.theta_max_deg, 89.999)), phi=phi, tol=tol)
        err_max = float(np.max(np.asarray(rm.error)))
    else:  # no maximum (a NaN albedo: check's verdict is nonfinite)
        err_max = math.inf
    notes = list(v.notes)
    if not h.success:
        notes.append(f"E_avg: {h.message}")
    e_avg = np.asarray(h.value, dtype=np.float64).reshape(-1)
    e_err = np.asarray(h.error, dtype=np.float64).reshape(-1)
    k = int(np.argmin(e_avg))  # a coloured model: the worst channel
    return EnergyVerdict(
        label=label or model.name, model=model.to_dict(), reciprocity=v.reciprocity,
        max_asymmetry=v.max_asymmetry, energy=v.energy, max_albedo=v.max_albedo,
        max_albedo_error=err_max, theta_max_deg=v.theta_max_deg,
        phi_max_deg=None if model.isotropic else phi_deg,
        divergence_exponent=v.divergence_exponent, furnace=f, e_avg=float(e_avg[k]),
        e_avg_error=float(e_err[k]), anisotropic=not model.isotropic, notes=notes,
        status=v.status, detail=v.detail)
