"""
The ``brdfkit`` scene-dict plugin of the Mitsuba bridge
=======================================================

``{"type": "brdfkit", "model": SPEC, PARAM: VALUE, …}`` in a Mitsuba scene
dict: ``SPEC`` a model name or material spec (``brdfkit.model(spec,
**params)``), per-channel values as comma-separated strings (``"eta": "0.2,
0.9, 1.1"``), optional ``"wavelengths": "450, 550, 650"`` (nm; the channels'
wavelengths), ``"pump": N`` (pump N times) and ``"pump_g": "max"|"controlled"``.
The plugin takes the route "auto" (:func:`brdfkit.render.mitsuba_bridge.mitsuba_bsdf`).

Public objects
--------------
- :func:`register_plugin` — register the plugin in a variant (once per variant);
  :func:`brdfkit.render.mitsuba_bridge.use_variant` calls it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from brdfkit._cache import bounded_cache
from brdfkit._specs import model as build_model
from brdfkit.errors import ParameterError
from brdfkit.models import BRDF
from brdfkit.pumping import pump
from brdfkit.render.mitsuba_variants import VARIANTS, import_mitsuba

__all__ = ["register_plugin"]

#: variants the plugin is registered in (one entry per variant; cleared: registered again)
_REGISTERED = bounded_cache("brdfkit.render.mitsuba_plugin._REGISTERED", maxsize=len(VARIANTS))


def _parse_value(name: str, value):
    """A property value: numbers as given, "a, b, c" strings as float lists."""
    if isinstance(value, str) and "," in value:
        try:
            return [float(x) for x in value.split(",")]
        except ValueError:
            raise ParameterError(
                f"brdfkit plugin: property {name!r} must be a number, a word or a "
                f"comma-separated list of numbers; got {value!r}") from None
    return value


def _model_from_props(props) -> tuple[BRDF, list | None]:
    """(model, wavelengths) from a scene dict's ``{"type": "brdfkit", …}`` properties."""
    if "model" not in props:
        raise ParameterError(
            'brdfkit plugin: property "model" is required (a model name such as '
            '"modified-phong" or a material spec such as "merl:nickel")')
    spec = str(props["model"])
    params: dict = {}
    wavelengths = None
    times = 0
    g = "max"
    for key in props.keys():
        value = _parse_value(key, props[key])
        if key in ("model", "id"):
            continue
        if key == "wavelengths":
            wavelengths = np.atleast_1d(np.asarray(value, dtype=np.float64))
        elif key == "pump":
            times = int(value)
        elif key == "pump_g":
            g = str(value)
        else:
            params[key] = value
    m = build_model(spec, **params)
    if times:
        m = pump(m, g, times=times)
    return m, wavelengths


def register_plugin(variant: str, make_bsdf: Callable) -> None:
    """Register ``{"type": "brdfkit", …}`` in the current Mitsuba *variant* (once).

    *make_bsdf* ``(props, model, wavelengths, variant, route)`` builds the BSDF
    (the bridge's route choice); the plugin calls it with route "auto".
    """
    if variant in _REGISTERED:
        return
    mi, _ = import_mitsuba()

    def plugin(props):
        model, wavelengths = _model_from_props(props)
        return make_bsdf(props, model, wavelengths, variant, "auto")

    mi.register_bsdf("brdfkit", plugin)
    _REGISTERED[variant] = True
