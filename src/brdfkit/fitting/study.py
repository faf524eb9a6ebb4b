"""
The fitting study of issue 10 §5: what the papers claim, answered by computation
================================================================================

A study is a set of batches (:mod:`brdfkit.fitting.batch`), each a resumable
CSV file under one directory, plus one derived file per batch. Re-running
:func:`run_study` with the same directory skips every finished row, so the
study is remade after a change of the fitting code by deleting the directory
(or the files of one part) and running it again.

Parts
-----
=============  =============================================================  ==================
part           fits (one batch file each: ``<part>/<name>.csv``)              material set
=============  =============================================================  ==================
nielsen        ``nielsen`` (Nielsen et al. 2015 eq. 3, Fresnel with η free,   all given
               started at :data:`ETA0`) as Phong (α = 0 held), Blinn–Phong
               (α = 1 held) and the α-mix (α free); each with loss l1 and l2,
               procedure "nielsen"
neumann        ``modified-phong`` and its one-times (``g = max``) pumped      the metals
               version (Neumann et al. 1999 eq. 16); losses perceptual and    (:func:`is_metal`)
               l2, procedure "auto"
anchors        ``lafortune`` (one lobe), loss ``ngan``                        those in Ngan's
                                                                              table
=============  =============================================================  ==================

Derived rows (``derived/<part>-<name>.csv``, one per fitted row, keyed with a
hash of the fitted parameters so a re-fit is re-derived): the plausibility
verdict (:func:`brdfkit.analysis.plausibility.check`: reciprocity, energy,
maximal albedo), Neumann's two maximal relative errors (:func:`relative_errors`)
and where the lobe sits in the incidence plane (:func:`lobe_position`).

The anchors part also evaluates Ngan et al.'s published Lafortune parameters
(read at run time from the file given, never copied: GPL) on the same
surrogate under the same metric (:func:`ngan_anchor_rows`).

Public objects
--------------
:data:`PARTS`, :data:`FIG1`, :func:`is_metal`, :class:`StudyBatch`,
:func:`study_batches`, :func:`run_study`, :func:`derived_row`,
:func:`relative_errors`, :func:`lobe_position`, :func:`read_ngan_table`,
:func:`ngan_model`, :func:`ngan_anchor_rows`, :data:`NGAN_CONVENTIONS`.

References
----------
- [Nielsen2015] "On optimal, minimal BRDF sampling for reflectance acquisition",
  §"Fitting Results and Observations", eq. (3), Fig. 1.
- [Neumann1999] "Reflectance models by pumping up the albedo function", §1.1, eq. (16).
- [Ngan2005] "Experimental analysis of BRDF models", EGSR 2005.
"""

from __future__ import annotations

import csv
import hashlib
import json
import math
import os
from dataclasses import dataclass, field

import numpy as np

from brdfkit.errors import BrdfkitError
from brdfkit.fitting.batch import (
    STATUS_ERROR,
    STATUS_NOT_CONVERGED,
    STATUS_OK,
    Job,
    fit_row,
    job_spec,
    read_rows,
    run_batch,
)

__all__ = ["PARTS", "FIG1", "ETA0", "METAL_WORDS", "is_metal", "StudyBatch", "study_batches",
           "run_study", "derived_row", "relative_errors", "lobe_position", "read_ngan_table",
           "ngan_model", "ngan_anchor_rows", "NGAN_CONVENTIONS", "NGAN_CHANNEL_SCALE"]

PARTS = ("nielsen", "neumann", "anchors")
#: The four materials of Nielsen et al.'s Fig. 1.
FIG1 = ("merl:two-layer-silver", "merl:violet-rubber", "merl:nickel", "merl:red-fabric2")
#: Start of the refractive index η of the Nielsen fits (a dielectric's typical index; η
#: is then fitted per channel within its declared bounds).
ETA0 = 1.5
#: Selection rule of the metals (Neumann part): a MERL name containing one of these words
#: and not "paint" (metallic paints are dielectric binders with flakes, not metals).
#: Hematite (an iron oxide mineral) is not on the list.
METAL_WORDS = ("alum", "bronze", "brass", "chrome", "nickel", "steel", "ss440", "tungsten",
               "two-layer-gold", "two-layer-silver")
#: Albedo tolerance of the plausibility check of every fitted model (check's default is
#: 1e-7; a verdict on max a ≤ 1 needs far less, and the check dominates the derived rows).
CHECK_TOL = 1e-5
#: Incidence angle (degrees) of the in-plane slice where the lobe's top and base are read.
SLICE_THETA_DEG = 30.0
#: The lobe's base: where the measured slice exceeds its floor by this fraction of its
#: peak height above the floor.
BASE_FRACTION = 0.1


#: The Neumann part's pumped models: (batch name stem, g of brdfkit.pumping.pump).
NEUMANN_PUMPS = (("pumped-phong", "max"), ("pumped-controlled-phong", "controlled"))
#: Every Neumann model: (batch name stem, label in the report).
NEUMANN_MODELS = (("phong", "Phong"), ("pumped-phong", "pumped Phong (g₁ = max)"),
                  ("pumped-controlled-phong", "pumped Phong (g₂ = controlled)"))


def is_metal(spec: str) -> bool:
    """True for a MERL material named as a metal (:data:`METAL_WORDS`, no "paint")."""
    name = str(spec).rsplit(":", 1)[-1]
    return "paint" not in name and any(w in name for w in METAL_WORDS)


@dataclass(frozen=True)
class StudyBatch:
    """One batch of the study: *model* fitted to every target with *loss*.

    ``params`` are starting values (``fit_row``'s ``params`` option), ``fixed`` the
    names held at them, ``pump`` pumps the model once with that g (``"max"``: g₁,
    ``"controlled"``: g₂; :func:`brdfkit.pumping.pump`)."""

    part: str
    name: str
    label: str
    model: str
    loss: str
    procedure: str
    targets: tuple
    params: dict = field(default_factory=dict)
    fixed: tuple = ()
    pump: str | None = None

    def path(self, directory) -> str:
        return os.path.join(os.fspath(directory), self.part, f"{self.name}.csv")

    def derived_path(self, directory) -> str:
        return os.path.join(os.fspath(directory), "derived", f"{self.part}-{self.name}.csv")

    def options(self) -> tuple:
        opts = {"seed": 0}
        if self.params:
            opts["params"] = json.dumps(self.params, sort_keys=True)
        if self.fixed:
            opts["fixed"] = json.dumps(list(self.fixed))
        if self.pump:
            opts.update(pump=self.pump, times=1)
        return tuple(sorted(opts.items()))

    def jobs(self) -> list[Job]:
        return [Job(self.model, t, loss=self.loss, procedure=self.procedure,
                    options=self.options()) for t in self.targets]


def study_batches(materials, *, parts=PARTS, ngan_names=None) -> list[StudyBatch]:
    """The batches of the chosen *parts* over *materials* (specs like ``merl:nickel``), in
    the order the parts are given.

    *ngan_names* (names in Ngan's table) restrict the anchors part; None: no restriction.
    """
    materials = tuple(materials)
    bad = [p for p in parts if p not in PARTS]
    if bad:
        raise BrdfkitError(f"parts must be among {', '.join(PARTS)}; got {', '.join(bad)}")
    out: list[StudyBatch] = []
    if "nielsen" in parts:
        variants = (("phong", "Phong (α = 0)", {"alpha": 0.0}, ("alpha",)),
                    ("blinn-phong", "Blinn–Phong (α = 1)", {"alpha": 1.0}, ("alpha",)),
                    ("alpha-mix", "α-mix (α free)", {}, ()))
        for loss in ("l1", "l2"):
            for name, label, params, fixed in variants:
                out.append(StudyBatch("nielsen", f"{name}-{loss}", label, "nielsen", loss,
                                      "nielsen", materials, {**params, "eta": ETA0}, fixed))
    if "neumann" in parts:
        metals = tuple(m for m in materials if is_metal(m))
        for loss in ("perceptual", "l2"):  # the plain fits first: the pumped ones are slow
            out.append(StudyBatch("neumann", f"phong-{loss}", "modified Phong",
                                  "modified-phong", loss, "auto", metals))
        # g₁ = max normalises the albedo at normal incidence to 1 (f/g₁ does not see a
        # common scale of ρ_d, ρ_s: fit holds it), so it cannot match a dark metal's level;
        # g₂ = controlled keeps the scale: both are fitted
        for name, g in NEUMANN_PUMPS:
            for loss in ("perceptual", "l2"):
                out.append(StudyBatch("neumann", f"{name}-{loss}", f"pumped modified Phong "
                                      f"(g = {g})", "modified-phong", loss, "auto", metals,
                                      pump=g))
    if "anchors" in parts:
        names = set(ngan_names) if ngan_names is not None else None
        targets = tuple(m for m in materials
                        if names is None or m.rsplit(":", 1)[-1] in names)
        out.append(StudyBatch("anchors", "lafortune-ngan", "Lafortune (one lobe)", "lafortune",
                              "ngan", "auto", targets))
    return sorted(out, key=lambda b: list(parts).index(b.part))  # stable within a part


def run_study(directory, *, materials, parts=PARTS, workers: int = 1, ngan_csv=None,
              derive: bool = True, progress=None) -> list:
    """Run (or resume) every batch of *parts* and, with *derive*, its derived rows.

    Returns the :class:`~brdfkit.fitting.batch.BatchReport` of each batch run, in order.
    *ngan_csv* (Ngan's table) is needed by the anchors part.
    """
    directory = os.fspath(directory)
    ngan = read_ngan_table(ngan_csv) if (ngan_csv and "anchors" in parts) else None
    if "anchors" in parts and ngan is None:
        raise BrdfkitError("the anchors part needs ngan_csv: the path of "
                           "merl_fits_lafortune_ngan2005.csv (see SOURCES.md; --ngan PATH), "
                           "or leave the part out (--parts nielsen,neumann)")
    reports = []
    for b in study_batches(materials, parts=parts, ngan_names=ngan):
        os.makedirs(os.path.dirname(b.path(directory)), exist_ok=True)
        if not b.targets:
            continue
        reports.append(run_batch(b.jobs(), out=b.path(directory), run_job=fit_row,
                                 workers=workers, progress=progress))
        if derive:
            os.makedirs(os.path.dirname(b.derived_path(directory)), exist_ok=True)
            reports.append(run_batch(derived_jobs(b, directory), out=b.derived_path(directory),
                                     run_job=derived_row, workers=workers, progress=progress))
        if b.part == "anchors":  # theirs on the same surrogates, as soon as ours are there
            rows = ngan_anchor_rows(read_rows(b.path(directory)), ngan)
            if rows:
                _write_csv(os.path.join(directory, "anchors", "ngan-comparison.csv"), rows)
    return reports


# --------------------------------------------------------------------------- derived rows
def params_hash(params_json: str) -> str:
    """Short hash of a fitted row's parameter JSON (keys derived rows to that fit)."""
    return hashlib.sha1(str(params_json).encode("utf-8")).hexdigest()[:10]


def derived_jobs(batch: StudyBatch, directory) -> list[Job]:
    """One job per finished fit row of *batch*: its parameters in the options, the
    procedure field keyed with their hash."""
    jobs = []
    for r in read_rows(batch.path(directory)):
        if r.get("status") not in (STATUS_OK, STATUS_NOT_CONVERGED):
            continue
        opts = {"params": r["params"], **({"pump": batch.pump} if batch.pump else {})}
        jobs.append(Job(r["model"], r["target"], loss=r["loss"],
                        procedure=f"{r['procedure']}@{params_hash(r['params'])}",
                        options=tuple(sorted(opts.items()))))
    return jobs


def _rebuild(job: Job):
    """The fitted model of a derived job (its row's spec, :func:`job_spec`) and its target."""
    from brdfkit.spec import ModelSpec

    return job_spec(job).build(), ModelSpec(job.target).build()


def derived_row(job: Job) -> dict:
    """Plausibility verdict, Neumann's two maximal relative errors and the lobe position
    of one fitted model (the job's ``params`` option) against its target."""
    from brdfkit.analysis.plausibility import check

    m, target = _rebuild(job)
    v = check(m, tol=CHECK_TOL)
    e_point, e_albedo = relative_errors(m, target)
    top, base = lobe_position(m, target)
    return {"energy": v.energy, "max_albedo": v.max_albedo,
            "theta_max_albedo_deg": v.theta_max_deg, "reciprocity": v.reciprocity,
            "e_point": e_point, "e_albedo": e_albedo, "top_ratio": top, "base_ratio": base}


def relative_errors(model, target) -> tuple[float, float]:
    """Neumann et al. §1.1's two errors, as true maxima (not the smooth power means the
    perceptual loss optimises; :mod:`brdfkit.fitting.losses`):

    e_point = max over samples and channels of |ln((m + τ)/(y + τ))|, m, y the
    cosine-weighted model and target on the fit's samples, τ the loss's floor;
    e_albedo = max over θ_i ∈ {0°, 10°, …, 80°} and channels of |ln(a_m/a_t)|.
    A log ratio e is a relative error of e^e − 1 (≈ e when small).
    """
    from brdfkit.fitting._problem import Problem
    from brdfkit.fitting.losses import TAU_REL
    from brdfkit.fitting.samples import albedo_from_values, merl_samples

    C = int(target.n_channels or 1)
    prob = Problem(model, target, merl_samples(), "perceptual", C)
    m = prob.evaluate(model, prob.samples.wi, prob.samples.wo) * prob.cos
    tau = TAU_REL * (prob.w @ prob.y) / np.sum(prob.w)
    e_point = float(np.max(np.abs(np.log((np.maximum(m, 0.0) + tau) / (prob.y + tau)))))
    wi, wo, wa, T = prob._anodes
    a_m = albedo_from_values(prob.evaluate(model, wi, wo), wa, T)
    tiny = 1e-12  # as the loss: an albedo of exactly 0 has an infinite log ratio
    e_albedo = float(np.max(np.abs(np.log(np.maximum(a_m, tiny)
                                          / np.maximum(prob.albedo_t, tiny)))))
    return e_point, e_albedo


def in_plane_slice(model, theta_i_deg: float, theta_o_deg) -> np.ndarray:
    """f·cos θ_i in the incidence plane, channel mean: light at θ_i (azimuth π), viewer at
    signed θ_o (> 0: the mirror side)."""
    ti = math.radians(theta_i_deg)
    to = np.radians(np.asarray(theta_o_deg, dtype=np.float64))
    wi = np.broadcast_to([-math.sin(ti), 0.0, math.cos(ti)], (to.size, 3)).copy()
    wo = np.stack([np.sin(to), np.zeros_like(to), np.cos(to)], axis=-1)
    f = np.asarray(model.eval(wi, wo), dtype=np.float64).reshape(to.size, -1)
    return np.nanmean(f, axis=1) * math.cos(ti)


def lobe_position(model, target, *, theta_i_deg: float = SLICE_THETA_DEG):
    """Where the fitted lobe sits against the measured one, in the incidence plane at
    θ_i (Nielsen: L2 fits "the tops of the specular highlights", L1 "the base").

    Returns ``(top, base)``: top = fitted / measured f·cos θ_i at the measured peak;
    base = width of the fitted slice above the measured base level / width of the
    measured one, the base level being the measured floor plus
    :data:`BASE_FRACTION` of the measured peak height above it (floor: the measured
    minimum over θ_o ∈ [−80°, 80°]). top = 1 and base = 1 are a perfect fit of each.
    """
    th = np.linspace(-80.0, 80.0, 641)  # 0.25° steps
    y = in_plane_slice(target, theta_i_deg, th)
    f = in_plane_slice(model, theta_i_deg, th)
    k = int(np.nanargmax(y))
    floor = float(np.nanmin(y))
    level = floor + BASE_FRACTION * (float(y[k]) - floor)
    step = th[1] - th[0]
    w_m = float(np.sum(y > level)) * step
    w_f = float(np.sum(f > level)) * step
    top = float(f[k] / y[k]) if y[k] > 0 else math.nan
    return top, (w_f / w_m if w_m > 0 else math.nan)


# --------------------------------------------------------------------------- Ngan anchors
#: MERL's colour scale of G and B, missing from the transcribed table (SOURCES.md §6).
NGAN_CHANNEL_SCALE = (1.0, 1.15, 1.66)
#: Readings of Ngan's (C_xy, C_z), which are unit vectors (2 C_xy² + C_z² = 1): the table
#: does not state how the lobe is evaluated with them (SOURCES.md: "my inference").
#: ``as-printed``: ρ_s (C_xy (u_x v_x + u_y v_y) + C_z u_z v_z)ⁿ;
#: ``peak-one``: C divided by max(|C_xy|, |C_z|) (a Phong lobe peaks at ρ_s);
#: ``normalised``: peak-one and ρ_s·(n + 2)/(2π) (an energy-normalised cosine lobe).
NGAN_CONVENTIONS = ("as-printed", "peak-one", "normalised")


def read_ngan_table(path) -> dict:
    """Ngan et al.'s Lafortune parameters by material name (read at run time; GPL data,
    never shipped): ``{name: {"rho_d": [3], "rho_s": [3], "C_xy", "C_z", "n"}}`` with G, B
    multiplied by :data:`NGAN_CHANNEL_SCALE`."""
    p = os.fspath(path)
    if not os.path.exists(p):
        raise BrdfkitError(f"ngan_csv {p!r} does not exist (merl_fits_lafortune_ngan2005.csv,"
                           " see shared/data/measured/SOURCES.md; --ngan PATH), or leave the "
                           "anchors part out (--parts nielsen,neumann)")
    out = {}
    with open(p, newline="", encoding="utf-8") as fh:
        for r in csv.DictReader(fh):
            v = [float(r[f"p{k}"]) for k in range(9)]
            s = NGAN_CHANNEL_SCALE
            out[r["material"]] = {"rho_d": [v[k] * s[k] for k in range(3)],
                                  "rho_s": [v[3 + k] * s[k] for k in range(3)],
                                  "C_xy": v[6], "C_z": v[7], "n": v[8]}
    return out


def ngan_model(entry: dict, convention: str = "peak-one"):
    """Ngan's Lafortune fit as a brdfkit ``lafortune`` model under *convention*
    (:data:`NGAN_CONVENTIONS`)."""
    from brdfkit.spec import ModelSpec

    if convention not in NGAN_CONVENTIONS:
        raise BrdfkitError(f"convention must be one of {', '.join(NGAN_CONVENTIONS)}; got "
                           f"{convention!r}")
    c_xy, c_z, n = entry["C_xy"], entry["C_z"], entry["n"]
    rho_s = list(entry["rho_s"])
    if convention != "as-printed":
        big = max(abs(c_xy), abs(c_z))
        c_xy, c_z = c_xy / big, c_z / big
    if convention == "normalised":
        rho_s = [r * (n + 2.0) / (2.0 * math.pi) for r in rho_s]
    return ModelSpec("lafortune", {"rho_d": entry["rho_d"], "rho_s": rho_s, "C_xy": c_xy,
                                   "C_z": c_z, "n": n}).build()


def ngan_metric(model, target) -> float:
    """Ngan et al.'s cosine-weighted RMS (loss ``ngan``) of *model* against *target* on
    the fit's samples."""
    from brdfkit.fitting._problem import Problem
    from brdfkit.fitting.samples import merl_samples

    prob = Problem(model, target, merl_samples(), "ngan", int(target.n_channels or 1))
    pred = prob.evaluate(model, prob.samples.wi, prob.samples.wo) * prob.cos
    return prob.loss_of(model, pred)


def ngan_anchor_rows(fit_rows, ngan: dict) -> list[dict]:
    """Per material of *fit_rows* (our lafortune fits, loss ngan) also in *ngan*: ours, theirs
    under every convention, the convention used (the one with the smallest median
    metric over the materials: the reading most favourable to their parameters) and
    the ratio ours / theirs (≤ 1: ours at least as good)."""
    import brdfkit

    rows = []
    for r in fit_rows:
        name = str(r["target"]).rsplit(":", 1)[-1]
        if name not in ngan or r.get("status") not in (STATUS_OK, STATUS_NOT_CONVERGED):
            continue
        target = brdfkit.data.material(r["target"])
        row = {"target": r["target"], "ours": float(r["metric_ngan"])}
        for conv in NGAN_CONVENTIONS:
            row[f"theirs_{conv}"] = ngan_metric(ngan_model(ngan[name], conv), target)
        rows.append(row)
    if not rows:
        return rows
    med = {c: float(np.median([r[f"theirs_{c}"] for r in rows])) for c in NGAN_CONVENTIONS}
    best = min(NGAN_CONVENTIONS, key=lambda c: med[c])
    for r in rows:
        r["convention"] = best
        r["theirs"] = r[f"theirs_{best}"]
        r["ratio"] = r["ours"] / r["theirs"] if r["theirs"] > 0 else math.nan
    return rows


def _write_csv(path, rows) -> None:
    """Write *rows* (dicts with their own columns) as CSV, atomically."""
    import io

    from brdfkit._io import write_atomic

    cols = list(dict.fromkeys(k for r in rows for k in r))

    def write(fh):
        text = io.StringIO()
        w = csv.DictWriter(text, fieldnames=cols, lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
        fh.write(text.getvalue().encode("utf-8"))

    write_atomic(path, write)


def read_study(directory, materials=None) -> dict:
    """Every batch file and derived file under *directory*: ``{(part, name): {"batch":
    StudyBatch-like dict, "rows": [...], "derived": {(target, params hash): row}}}``."""
    out = {}
    directory = os.fspath(directory)
    for part in PARTS:
        d = os.path.join(directory, part)
        if not os.path.isdir(d):
            continue
        for fn in sorted(os.listdir(d)):
            if not fn.endswith(".csv") or fn == "ngan-comparison.csv":
                continue
            name = fn[:-4]
            rows = [r for r in read_rows(os.path.join(d, fn))
                    if materials is None or r["target"] in materials]
            dpath = os.path.join(directory, "derived", f"{part}-{name}.csv")
            derived = {}
            for r in read_rows(dpath):
                if r.get("status") == STATUS_ERROR:
                    continue
                derived[(r["target"], r["procedure"].rsplit("@", 1)[-1])] = r
            for r in rows:
                r["derived"] = derived.get((r["target"], params_hash(r.get("params", ""))))
            out[(part, name)] = rows
    return out
