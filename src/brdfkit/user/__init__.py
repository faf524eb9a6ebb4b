"""
Models from the user's own files
================================

A model a user writes in a file of their own — a Python file using
:mod:`brdfkit.formula`, or a BRDF Explorer ``.brdf`` file — is described once as a
:class:`~brdfkit.user.model.ModelDefinition` by its loader and built as a
:class:`~brdfkit.user.model.FormulaBRDF`, a model like any other. Layer 2 (like
``data``): it may import layers 0–2. The spec kinds ``PATH.py[:NAME]`` and ``PATH.brdf``
(:data:`brdfkit.spec.KINDS`) build them.

Modules
-------
- :mod:`brdfkit.user.model` — :class:`ModelDefinition`, :class:`FormulaBRDF`.
- :mod:`brdfkit.user.python_file` — a user's ``.py`` file → its definitions.
- :mod:`brdfkit.user.brdf_file` — a ``.brdf`` file → its definition.
"""
