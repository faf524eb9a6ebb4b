"""
Measured materials
==================

The data layer (layer 2 in ``docs/architecture.md``): tabulated and measured
BRDFs as brdfkit models.

- :mod:`brdfkit.data.merl` — the MERL ``.binary`` format read and written
  exactly, the reference reader's lookup, :class:`~brdfkit.data.merl.MeasuredBRDF`.

Data attribution: the MERL BRDF database — W. Matusik, H. Pfister, M. Brand,
L. McMillan, *A Data-Driven Reflectance Model*, ACM TOG 22(3), 2003 — is
licensed CC-BY-SA-4.0; results derived from it must keep this attribution.
"""

from brdfkit.data.merl import MeasuredBRDF, MerlTable, read_binary, write_binary

__all__ = ["MeasuredBRDF", "MerlTable", "read_binary", "write_binary"]
