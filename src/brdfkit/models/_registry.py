"""The model registry and its dispatcher.

One registry maps canonical names to model classes; aliases resolve to the
canonical name. :func:`model` is the dispatcher: its error lists the valid
names.
"""

from __future__ import annotations

import difflib

from brdfkit.errors import UnknownModelError

MODELS: dict[str, type] = {}
_ALIASES: dict[str, str] = {}


def register(cls: type) -> type:
    """Class decorator: add a model class to :data:`MODELS` under its name and aliases.

    A class-level ``kernel`` (a Numba dispatcher) is held as a static method: a dispatcher
    is a descriptor, so read from an instance it would bind, giving a new bound method per
    model, and every cache keyed on ``model.kernel`` (compiled drivers of pumped models,
    swapped kernels) would miss for each new parameter value and compile again."""
    kernel = cls.__dict__.get("kernel")
    if kernel is not None and not isinstance(kernel, staticmethod):
        cls.kernel = staticmethod(kernel)
    for key in (cls.name, *cls.aliases):
        if key in MODELS or key in _ALIASES:
            raise RuntimeError(f"model name {key!r} registered twice")
    MODELS[cls.name] = cls
    for alias in cls.aliases:
        _ALIASES[alias] = cls.name
    return cls


def model_names() -> list[str]:
    """The canonical names of all registered models, in registration order."""
    return list(MODELS)


def resolve(name: str) -> type:
    """The model class registered under *name* or one of its aliases."""
    key = str(name).strip().lower().replace("_", "-")
    key = _ALIASES.get(key, key)
    if key not in MODELS:
        close = difflib.get_close_matches(key, [*MODELS, *_ALIASES], n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise UnknownModelError(
            f"unknown model {name!r}{hint}; valid names: " + ", ".join(MODELS)
        )
    return MODELS[key]


def model(name: str, /, **params):
    """Build the registered model *name* with the given parameters.

    Parameters
    ----------
    name : str
        Canonical name or alias (see :func:`model_names`).
    **params
        Parameter values; omitted ones take their defaults.

    Examples
    --------
    >>> import brdfkit
    >>> m = brdfkit.model("modified-phong", rho_d=0.2, rho_s=0.5, n=50)
    """
    return resolve(name)(**params)
