"""
The built-in materials and the material-spec dispatcher
=======================================================

brdfkit ships compact surrogates of 159 measured materials as package data
(``brdfkit/data/files/``, about 2 MB; attribution and licences in its
``README.md``): the 100 MERL materials, each in four representations (NBRDF by
default; NPF, ABC and SGD as alternatives), 51 isotropic RGL-EPFL materials and
8 materials of Nielsen et al. 2015 (NBRDF). Files are read lazily, once, through
:mod:`importlib.resources`; each material is built once and cached.

Material specs
--------------
======================================  ==========================================
spec                                    material
======================================  ==========================================
``merl:NAME``                           MERL material NAME, NBRDF surrogate
``merl:NAME@nbrdf|@npf|@abc|@sgd``      the same material, chosen surrogate
``rgl:NAME``                            RGL-EPFL material (``_rgb`` suffix optional)
``nielsen:NAME``                        Nielsen et al. 2015 material
``PATH.binary`` (or an ``os.PathLike``) a MERL ``.binary`` file
                                        (:class:`~brdfkit.data.measured.MeasuredBRDF`)
======================================  ==========================================

Names are case-insensitive; ``-`` and ``_`` are interchangeable. An unknown
name raises :class:`~brdfkit.errors.UnknownModelError` naming the spec and the
closest valid names.

Public objects
--------------
- :func:`material` — resolve a spec to a model.
- :func:`materials` — the catalog: one :class:`MaterialInfo` per material;
  :func:`material_info` — the entry of one spec.
- :func:`material_names` — the built-in specs.
- :func:`suggest_material_specs` — did-you-mean hints for a bare material name.
- :func:`is_material_spec` — whether a string is a material spec (for the
  dispatcher that also resolves model names).
- :func:`normal_albedo` — directional albedo at θ_i = 0 by a 1-D quadrature.
- :func:`data_file` — path-like of a shipped data file.

References
----------
See :mod:`brdfkit.data.surrogates` (papers) and ``brdfkit/data/files/README.md``
(origin of every file, licences).
"""

from __future__ import annotations

import csv
import difflib
import io
import math
import os
from dataclasses import dataclass
from importlib import resources

import numpy as np

from brdfkit._cache import memo
from brdfkit.data.measured import MeasuredBRDF
from brdfkit.data.merl import read_binary
from brdfkit.data.surrogates import (
    REPRESENTATIONS,
    SGD_FIELDS,
    SOURCES,
    SurrogateBRDF,
    abc_material,
    nbrdf_material,
    npf_material,
    sgd_material,
)
from brdfkit.errors import DataFileError, UnknownModelError

__all__ = ["MaterialInfo", "material", "material_info", "materials", "material_names",
           "is_material_spec",
           "suggest_material_specs",
           "normal_albedo", "data_file", "MATERIAL_SOURCES"]

#: Material-spec prefixes (data sources).
MATERIAL_SOURCES = tuple(SOURCES)

_NBRDF_FILES = {"merl": "merl100_nbrdf_sztrajman2021.npz",
                "rgl": "rgl51_isotropic_nbrdf_sztrajman2021.npz",
                "nielsen": "nielsen8_nbrdf_sztrajman2021.npz"}
_NPF_FILE = "merl100_npf_bagher2016.f32"
_NPF_ROWS_FILE = "merl_npf_bagher2016_rows.txt"
_ABC_FILE = "merl_fits_abc_low2012.csv"
_SGD_FILE = "merl_fits_sgd_bagher2012.csv"
_NPF_SHAPE = (256, 512, 3)  # [rows][columns][RGB], little-endian float32


def data_file(name: str):
    """The shipped data file *name* (a :class:`importlib.resources` traversable)."""
    f = resources.files("brdfkit.data").joinpath("files", name)
    if not f.is_file():
        raise DataFileError(f"brdfkit/data/files/{name}: missing from the installed package "
                            "(package data not installed?)")
    return f


# --------------------------------------------------------------------------- file readers
@memo(maxsize=4)  # one per NBRDF file (merl, rgl, nielsen); ~3 MB in all
def _nbrdf_weights(source: str) -> dict:
    name = _NBRDF_FILES[source]
    with data_file(name).open("rb") as fh:
        z = np.load(io.BytesIO(fh.read()), allow_pickle=False)
        arrays = {k: z[k] for k in ("W1", "b1", "W2", "b2", "W3", "b3")}
        names = [str(s) for s in z["names"]]
    for k, a in arrays.items():
        if a.shape[0] != len(names):
            raise DataFileError(f"brdfkit/data/files/{name}: {k} has {a.shape[0]} entries; "
                                f"expected one per material ({len(names)})")
    return {"names": names, "index": {n: i for i, n in enumerate(names)}, **arrays}


@memo(maxsize=1)  # the one NPF file (~1.3 MB)
def _npf_table() -> tuple[np.ndarray, dict]:
    raw = data_file(_NPF_FILE).read_bytes()
    expected = 4 * math.prod(_NPF_SHAPE)
    if len(raw) != expected:
        raise DataFileError(f"brdfkit/data/files/{_NPF_FILE}: expected {expected} bytes "
                            f"(float32 {_NPF_SHAPE}); found {len(raw)}")
    table = np.frombuffer(raw, dtype="<f4").reshape(_NPF_SHAPE)
    rows = {}
    for line in data_file(_NPF_ROWS_FILE).read_text().splitlines():
        if line.strip():
            i, name = line.split()
            rows[name] = int(i)
    return table, rows


def _read_csv(name: str) -> dict:
    text = data_file(name).read_text()
    return {r["material"]: r for r in csv.DictReader(io.StringIO(text))}


@memo(maxsize=1)  # the one ABC file
def _abc_rows() -> dict:
    return _read_csv(_ABC_FILE)


@memo(maxsize=1)  # the one SGD file
def _sgd_rows() -> dict:
    return _read_csv(_SGD_FILE)


@memo(maxsize=4)  # one per source
def _names(source: str) -> tuple[str, ...]:
    return tuple(_nbrdf_weights(source)["names"])


def _key(name: str) -> str:
    return name.strip().lower().replace("_", "-")


@memo(maxsize=4)  # one per source
def _lookup(source: str) -> dict:
    """Normalised name → canonical name (RGL: also without the ``_rgb`` suffix)."""
    out = {}
    for n in _names(source):
        out[_key(n)] = n
        if source == "rgl" and n.endswith("_rgb"):
            out[_key(n[:-4])] = n
    return out


# --------------------------------------------------------------------------- building
# every built-in material (459 with the NPF, ABC and SGD fits; a few kB each before a
# sampler is built), so the same spec gives the same object
@memo(maxsize=512)
def _build(source: str, name: str, representation: str) -> SurrogateBRDF:
    if representation == "nbrdf":
        w = _nbrdf_weights(source)
        i = w["index"][name]
        return nbrdf_material(source, name, w["W1"][i], w["b1"][i], w["W2"][i], w["b2"][i],
                              w["W3"][i], w["b3"][i])
    if representation == "npf":
        table, rows = _npf_table()
        return npf_material(name, table[rows[name]])
    if representation == "abc":
        r = _abc_rows()[name]
        return abc_material(name, [float(r[f"kD_{c}"]) for c in "rgb"],
                            [float(r[f"A_{c}"]) for c in "rgb"], float(r["B"]), float(r["C"]),
                            float(r["ior"]))
    r = _sgd_rows()[name]
    return sgd_material(name, {f: [float(r[f"{f}_{c}"]) for c in "rgb"] for f in SGD_FIELDS})


def is_material_spec(spec) -> bool:
    """True for ``source:…`` specs of a known source, ``.binary`` paths and path objects."""
    if isinstance(spec, os.PathLike):
        return True
    if not isinstance(spec, str):
        return False
    s = spec.strip()
    if s.lower().endswith(".binary"):
        return True
    source, sep, _ = s.partition(":")
    return bool(sep) and source.lower() in MATERIAL_SOURCES


def material(spec):
    """The material of *spec* (module docstring) as a brdfkit model.

    Returns
    -------
    SurrogateBRDF or MeasuredBRDF
        Built-in materials are cached: the same spec gives the same object.

    Raises
    ------
    UnknownModelError
        Unknown source, name or representation (naming the spec and the closest
        valid names).
    DataFileError
        A ``.binary`` path that cannot be read (see :func:`~brdfkit.data.read_binary`).
    """
    if isinstance(spec, os.PathLike) or (isinstance(spec, str)
                                         and spec.strip().lower().endswith(".binary")):
        path = os.fspath(spec)
        return MeasuredBRDF(read_binary(path),
                            name=f"merl-file:{os.path.basename(path)}")
    if not isinstance(spec, str):
        raise UnknownModelError(f"material spec must be a string or a path; got "
                                f"{type(spec).__name__} {spec!r}")
    text = spec.strip()
    source, sep, rest = text.partition(":")
    source = source.lower()
    if not sep or source not in MATERIAL_SOURCES:
        raise UnknownModelError(
            f"material spec {spec!r}: expected SOURCE:NAME with SOURCE one of "
            f"{', '.join(MATERIAL_SOURCES)} (merl:NAME[@{'|'.join(REPRESENTATIONS)}]), or a "
            "path to a .binary file")
    name, at, rep = rest.partition("@")
    rep = rep.strip().lower() if at else "nbrdf"
    if rep not in REPRESENTATIONS:
        close = difflib.get_close_matches(rep, REPRESENTATIONS, n=1)
        hint = f" (did you mean @{close[0]}?)" if close else ""
        raise UnknownModelError(f"material spec {spec!r}: unknown representation {rep!r}"
                                f"{hint}; valid: {', '.join(REPRESENTATIONS)}")
    if rep != "nbrdf" and source != "merl":
        raise UnknownModelError(f"material spec {spec!r}: {source} materials exist only as "
                                "NBRDF; NPF, ABC and SGD fits exist for merl: materials only")
    lookup = _lookup(source)
    canonical = lookup.get(_key(name))
    if canonical is None:
        close = difflib.get_close_matches(_key(name), [_key(n) for n in _names(source)], n=3,
                                          cutoff=0.5)
        close = [lookup[c] for c in close]
        hint = (" (did you mean " + ", ".join(f"'{source}:{c}'" for c in close) + "?)"
                if close else "")
        raise UnknownModelError(
            f"material spec {spec!r}: no {source} material named {name.strip()!r}{hint}; "
            + (f"valid: {', '.join(_names(source))}" if len(_names(source)) <= 10 else
               f"{len(_names(source))} {source} materials, listed by 'brdfkit materials' "
               "(brdfkit.data.materials())"))
    return _build(source, canonical, rep)


def suggest_material_specs(name: str, *, n: int = 2) -> list[str]:
    """Built-in specs whose material name is close to *name* (a bare ``nickel`` →
    ``merl:nickel``), best first; for did-you-mean hints of the model dispatcher."""
    key = _key(str(name).partition("@")[0].rpartition(":")[2])
    if not key:
        return []
    candidates = {}
    for source in MATERIAL_SOURCES:
        for k, canonical in _lookup(source).items():
            candidates.setdefault(k, f"{source}:{canonical}")
    close = difflib.get_close_matches(key, list(candidates), n=n, cutoff=0.75)
    return list(dict.fromkeys(candidates[c] for c in close))


def material_names(*, representations: bool = False) -> list[str]:
    """The built-in specs: ``merl:NAME``, ``rgl:NAME``, ``nielsen:NAME`` (159); with
    *representations*, also ``merl:NAME@npf|abc|sgd`` (459)."""
    out = []
    for source in MATERIAL_SOURCES:
        for n in _names(source):
            out.append(f"{source}:{n}")
            if representations and source == "merl":
                out.extend(f"merl:{n}@{r}" for r in REPRESENTATIONS[1:])
    return out


# --------------------------------------------------------------------------- the catalog
def normal_albedo(model, *, n: int = 2048) -> np.ndarray:
    """Directional albedo at normal incidence, a(0) = 2π ∫ f(θ_o) cos θ_o sin θ_o dθ_o.

    At θ_i = 0 an isotropic BRDF depends on θ_o only (θ_h = θ_d = θ_o/2), so the
    hemisphere integral is 1-D. Midpoint rule in u with θ_o = (π/2)u² (nodes dense
    near the specular peak at θ_o = 0, as MERL's θ_h bins): for the 100 MERL NBRDF
    materials n = 2048 agrees with n = 8192 to < 1e-4 relative. Returns (C,).

    A second method beside the albedo engine (:func:`brdfkit.analysis.albedo`, which
    states an error estimate): kept because the catalog's stored albedos and
    ``brdfkit data convert --json``'s ``normal_albedo`` are its numbers;
    ``tests/test_albedo.py`` checks it against the engine to its stated 1e-4.
    """
    u = (np.arange(n) + 0.5) / n
    # MERL's θ_h grid (geometry.merl_theta_h) in its own rounding order, kept so that the
    # albedos `brdfkit materials` and `export --json` print stay bit for bit the same
    theta = 0.5 * math.pi * u * u
    jac = math.pi * u  # dθ/du
    wo = np.stack([np.sin(theta), np.zeros(n), np.cos(theta)], axis=-1)
    wi = np.array([0.0, 0.0, 1.0])
    f = np.asarray(model.eval(wi, wo)).reshape(n, -1)
    w = 2.0 * math.pi * np.cos(theta) * np.sin(theta) * jac / n
    return w @ f


@dataclass(frozen=True)
class MaterialInfo:
    """One built-in material in the catalog.

    Attributes
    ----------
    name : str
        Its spec (``merl:nickel``, ``merl:nickel@npf``, ``rgl:…``).
    source, material, representation : str
        Data source, the source's material name, surrogate.
    licence : str
        Licences of the measured data and of the fitted numbers.
    citation : str
        Measurement and surrogate papers.
    albedo : tuple of float
        Diffuse-albedo estimate (RGB): the directional albedo at normal
        incidence, a(0), of the surrogate (:func:`normal_albedo`; for glossy
        materials it includes the specular lobe's energy).
    rho_d : tuple of float or None
        The fit's own diffuse albedo (NPF ρ_d, ABC k_D, SGD ρ_d); None for NBRDF.
    """

    name: str
    source: str
    material: str
    representation: str
    licence: str
    citation: str
    albedo: tuple[float, float, float]
    rho_d: tuple[float, float, float] | None

    def to_dict(self) -> dict:
        return {"name": self.name, "source": self.source, "material": self.material,
                "representation": self.representation, "licence": self.licence,
                "citation": self.citation, "albedo": list(self.albedo),
                "rho_d": None if self.rho_d is None else list(self.rho_d)}


@memo(maxsize=512)  # one per built-in material (459), a few numbers each
def _info(spec: str) -> MaterialInfo:
    m = material(spec)
    a = tuple(round(float(x), 6) for x in normal_albedo(m))
    rd = None if m.rho_d is None else tuple(round(float(x), 6) for x in m.rho_d)
    return MaterialInfo(name=m.name, source=m.source, material=m.material,
                        representation=m.representation, licence=m.licence,
                        citation=m.citation, albedo=a, rho_d=rd)


def material_info(spec) -> MaterialInfo:
    """The catalog entry of one built-in material spec (its albedo estimate computed for that
    material alone). Raises UnknownModelError as :func:`material`, and for a ``.binary``
    path, which has no catalog entry."""
    m = material(spec)
    if not isinstance(m, SurrogateBRDF):
        raise UnknownModelError(f"{spec!r} is not a built-in material (a .binary file has no "
                                "catalog entry); 'brdfkit materials' lists the built-in ones")
    return _info(m.name)


def materials(*, representations: bool = False) -> list[MaterialInfo]:
    """The catalog: every built-in material (159; with *representations* also the NPF,
    ABC and SGD fits of the MERL materials, 459), in source then file order. The albedo
    estimates are computed on first use (~1 s) and cached."""
    return [_info(s) for s in material_names(representations=representations)]
