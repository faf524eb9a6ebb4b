"""
Measured materials
==================

The data layer (layer 2 in ``docs/architecture.md``): tabulated and measured
BRDFs as brdfkit models.

- :mod:`brdfkit.data.merl` — the MERL ``.binary`` format read and written
  exactly, the reference reader's bins, the grid.
- :mod:`brdfkit.data.measured` — :class:`~brdfkit.data.measured.MeasuredBRDF`, a MERL
  table as a model (its compiled lookups).
- :mod:`brdfkit.data.surrogates` — compiled kernels and builders of the compact
  surrogates (NBRDF, NPF, ABC, SGD).
- :mod:`brdfkit.data.surrogate_model` — :class:`~brdfkit.data.surrogate_model.SurrogateBRDF`,
  a built-in material as a model, with its citations and licences.
- :mod:`brdfkit.data.catalog` — the 159 built-in materials (package data) and the
  material-spec dispatcher :func:`material` (``merl:NAME[@nbrdf|npf|abc|sgd]``,
  ``rgl:NAME``, ``nielsen:NAME``, a ``.binary`` path).

Public objects
--------------
:func:`material`, :func:`materials`, :func:`material_names`,
:func:`is_material_spec`, :class:`MaterialInfo`, :class:`SurrogateBRDF`,
:class:`MeasuredBRDF`, :class:`MerlTable`, :func:`read_binary`,
:func:`write_binary`, :func:`table_from_function`.

Data attribution: the MERL BRDF database — W. Matusik, H. Pfister, M. Brand,
L. McMillan, *A Data-Driven Reflectance Model*, ACM TOG 22(3), 2003 — is
licensed CC-BY-SA-4.0; results derived from it must keep this attribution.
The surrogates' own licences (NBRDF weights MIT © 2022 asztr; NPF, ABC, SGD
numbers public domain) and the RGL and Nielsen data are listed in
``brdfkit/data/files/README.md`` and in :func:`materials`.
"""

from brdfkit.data.catalog import (
    MaterialInfo,
    is_material_spec,
    material,
    material_names,
    materials,
)
from brdfkit.data.measured import MeasuredBRDF
from brdfkit.data.merl import MerlTable, read_binary, table_from_function, write_binary
from brdfkit.data.surrogates import SurrogateBRDF

__all__ = ["MaterialInfo", "MeasuredBRDF", "MerlTable", "SurrogateBRDF", "is_material_spec",
           "material", "material_names", "materials", "read_binary", "table_from_function",
           "write_binary"]
