"""
Export any model onto the MERL grid
===================================

:func:`export_merl` writes a model — analytic, pumped, fitted or measured — as a
MERL ``.binary`` file that every MERL tool reads (BRDF Explorer, ALTA, bbm,
Mitsuba pipelines).

Conventions
-----------
- **Bin centres.** Each bin holds f_r at the centre of its index coordinates:
  θ_h = ((i_h + ½)/90)²·π/2 (MERL's quadratic spacing), θ_d = (i_d + ½)/90·π/2,
  φ_d = (i_φ + ½)/180·π, φ_h = 0 (:func:`brdfkit.data.merl.bin_centres`). A
  nearest lookup of the written file at a bin centre returns the model's value
  there exactly (up to the float64 rounding of the channel scale).
- **Below the horizon.** Bins whose ω_i or ω_o lies at or below the horizon are
  written −1 (raw), the file format's mark for "not measured".
- **Channels.** A one-channel model is written grey (the same value in R, G, B);
  a three-channel model as RGB; more channels (spectra) are refused.
- **Measured materials** with the reference ``nearest`` lookup are written from
  their own table, raw value for raw value, so ``export`` of a ``.binary``
  material reproduces the file bit for bit; unmeasured bins stay unmeasured.
- Written atomically (:func:`brdfkit._io.write_atomic`): an interrupted export
  leaves no partial file.

Public objects
--------------
- :func:`export_merl` — a model to a ``.binary`` file.
- :func:`model_table` — a model on the MERL grid as a :class:`~brdfkit.data.MerlTable`.
"""

from __future__ import annotations

import numpy as np

from brdfkit.data.measured import MeasuredBRDF
from brdfkit.data.merl import MerlTable, table_from_function, write_binary
from brdfkit.errors import ParameterError
from brdfkit.models import BRDF

__all__ = ["export_merl", "model_table"]


def model_table(model: BRDF) -> MerlTable:
    """*model* tabulated on the MERL grid (module docstring: conventions).

    Raises
    ------
    ParameterError
        *model* is not a brdfkit model, has more than three channels, or gives
        a negative, NaN or infinite value above the horizon (the message
        counts them and names the first pair).
    """
    if not isinstance(model, BRDF):
        raise ParameterError(f"model must be a brdfkit model (brdfkit.model(...)); got "
                             f"{type(model).__name__}")
    if model.n_channels not in (None, 1, 3):
        raise ParameterError(f"{model.name}: a MERL file holds RGB (3 channels); the model has "
                             f"{model.n_channels} channels — evaluate it per RGB channel first")
    if isinstance(model, MeasuredBRDF) and model.values["lookup"] == "nearest":
        return MerlTable(model.table.raw.copy(), model.name)

    def f(wi, wo):
        vals = np.asarray(model.eval(wi, wo), dtype=np.float64)
        bad = ~np.isfinite(vals) | (vals < 0.0)
        if bad.any():
            k = int(np.argwhere(bad.reshape(bad.shape[0], -1).any(axis=1))[0, 0])
            raise ParameterError(
                f"{model.name}: cannot export: f_r must be finite and >= 0 above the horizon; "
                f"found {int(bad.sum())} bad values (the first {vals[k]!r} at wi = "
                f"{np.round(wi[k], 6).tolist()}, wo = {np.round(wo[k], 6).tolist()})")
        return vals

    return table_from_function(f, source=model.name)


def export_merl(model: BRDF, path) -> str:
    """Write *model* to *path* as a MERL ``.binary`` file, atomically; returns the path.

    See the module docstring for the bin-centre and below-horizon conventions.
    Raises :class:`~brdfkit.errors.ParameterError` as :func:`model_table` and
    :class:`~brdfkit.errors.BrdfkitError` for an unwritable path.
    """
    return write_binary(path, model_table(model))
