"""
One dispatcher for model names and material specs
=================================================

``brdfkit.model(spec, **params)`` resolves either kind of name, so every
function and command that takes a model takes a measured material too:

======================================  =================================================
spec                                    model
======================================  =================================================
``modified-phong`` (a registered name   the analytic model (:data:`brdfkit.MODELS`), built
or alias)                               with ``**params``
``merl:NAME[@nbrdf|npf|abc|sgd]``,      a built-in measured material
``rgl:NAME``, ``nielsen:NAME``          (:func:`brdfkit.data.material`); it has no
                                        parameters
``PATH.binary`` or an ``os.PathLike``   a MERL file as a
                                        :class:`~brdfkit.data.MeasuredBRDF`
                                        (parameter ``lookup``)
======================================  =================================================

An unknown name raises :class:`~brdfkit.errors.UnknownModelError` listing the
valid model names and the material-spec forms, with did-you-mean hints for
both (``nickel`` → ``merl:nickel``).

This module is the package root's (layer 2 in ``docs/architecture.md``): it
sits above ``models`` and ``data`` and is what :func:`brdfkit.model` is.

Public objects
--------------
- :func:`model` — build a model or a material from its spec.
- :func:`model_params` — the parameter declarations a spec accepts.
- :func:`canonical_name` — a spec's canonical name.
"""

from __future__ import annotations

from brdfkit.data.catalog import is_material_spec, material, suggest_material_specs
from brdfkit.errors import UnknownModelError
from brdfkit.models import resolve

__all__ = ["model", "model_params", "canonical_name", "is_material_spec", "SPEC_FORMS"]

#: How a material spec is written (for error messages and help texts).
SPEC_FORMS = ("merl:NAME[@nbrdf|@npf|@abc|@sgd], rgl:NAME, nielsen:NAME or a path to a "
              "MERL .binary file ('brdfkit materials' lists the built-in ones)")


def _unknown(spec, err: UnknownModelError) -> UnknownModelError:
    hints = suggest_material_specs(str(spec))
    hint = (" (did you mean the material " + " or ".join(repr(h) for h in hints) + "?)"
            if hints else "")
    return UnknownModelError(f"{err}{hint}; or a material spec: {SPEC_FORMS}")


def _registered(spec):
    try:
        return resolve(spec)
    except UnknownModelError as err:
        raise _unknown(spec, err) from None


def model(spec, /, **params):
    """Build the model or material named by *spec* (module docstring).

    Parameters
    ----------
    spec : str or os.PathLike
        A registered model name or alias, a built-in material spec, or a path
        to a MERL ``.binary`` file.
    **params
        Parameter values; omitted ones take their defaults. Built-in
        materials have none; a ``.binary`` material has ``lookup``.

    Raises
    ------
    UnknownModelError
        *spec* is neither a model nor a material; the message lists both.
    ParameterError
        A parameter the model does not declare, or a value outside its bounds.
    DataFileError
        A ``.binary`` path that cannot be read.

    Examples
    --------
    >>> import brdfkit
    >>> m = brdfkit.model("modified-phong", rho_s=0.5, n=50)
    >>> nickel = brdfkit.model("merl:nickel")
    """
    if is_material_spec(spec):
        m = material(spec)
        return m.with_params(**params) if params else m
    return _registered(spec)(**params)


def model_params(spec) -> tuple:
    """The parameter declarations (:class:`~brdfkit.Param`) *spec* accepts."""
    if is_material_spec(spec):
        return tuple(material(spec).params)
    return tuple(_registered(spec).params)


def canonical_name(spec) -> str:
    """The canonical name of a registered model, or the material's own name."""
    if is_material_spec(spec):
        return material(spec).name
    return _registered(spec).name
