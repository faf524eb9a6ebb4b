"""
The ``brdfkit`` scene-dict plugin of the Mitsuba bridge
=======================================================

``{"type": "brdfkit", "model": SPEC, PARAM: VALUE, …}`` in a Mitsuba scene
dict: ``SPEC`` a model name or material spec (``brdfkit.model(spec,
**params)``), per-channel values as comma-separated strings (``"eta": "0.2,
0.9, 1.1"``), optional ``"wavelengths": "450, 550, 650"`` (nm; the channels'
wavelengths), ``"pump": "max"|"controlled"`` and ``"times": K`` — the flat form of
:class:`brdfkit.spec.ModelSpec` (:meth:`~brdfkit.spec.ModelSpec.from_properties`); the old
``"pump": N`` (pump N times) with ``"pump_g"`` is still read.
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
from brdfkit.errors import ParameterError
from brdfkit.models import BRDF
from brdfkit.render.mitsuba_variants import VARIANTS, import_mitsuba
from brdfkit.spec import ModelSpec, property_value

__all__ = ["register_plugin"]

#: variants the plugin is registered in (one entry per variant; cleared: registered again)
_REGISTERED = bounded_cache("brdfkit.render.mitsuba_plugin._REGISTERED", maxsize=len(VARIANTS))


def _model_from_props(props) -> tuple[BRDF, list | None]:
    """(model, wavelengths) from a scene dict's ``{"type": "brdfkit", …}`` properties:
    the spec's flat form (:meth:`brdfkit.spec.ModelSpec.from_properties`) plus
    ``wavelengths``. The old ``"pump": N`` (a number: pump N times) with ``"pump_g"``
    is read as ``"pump": pump_g, "times": N``."""
    keys = [k for k in props.keys() if k not in ("id", "wavelengths")]
    flat = {k: props[k] for k in keys}
    old = flat.get("pump")
    numeric = isinstance(old, int | float) and not isinstance(old, bool)
    if numeric or "pump_g" in flat:  # the old form: a number of times, g apart
        if "times" in flat or not (numeric or old is None):
            raise ParameterError(
                'brdfkit plugin: give "pump": "max"|"controlled" with "times": K, or the old '
                f'"pump": N with "pump_g", not both; got pump={old!r}, '
                f'pump_g={flat.get("pump_g")!r}, times={flat.get("times")!r}')
        g, n = flat.pop("pump_g", "max"), int(old or 0)
        flat.update(pump=g if n else None, times=n if n else None)
    wavelengths = None
    if "wavelengths" in props.keys():
        given = property_value("wavelengths", props["wavelengths"], where="brdfkit plugin")
        wavelengths = np.atleast_1d(np.asarray(given, dtype=np.float64))
    return ModelSpec.from_properties(flat).build(), wavelengths


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
