"""
Declarations a model is built from: its parameters and its lobes
================================================================

A model declares its parameters once (:class:`Param`: default, bounds, unit,
kind, doc); the command line, the fitter and the explorer read this
declaration, and :meth:`Param.validate` is the one check of a value (errors
name the model, the parameter, the allowed range and the value received).
:class:`Lobe` says where a model's energy concentrates, for lobe-aware
numerics. Both are re-exported by :mod:`brdfkit.models._base` and
:mod:`brdfkit.models`.

Public objects
--------------
- :class:`Param` — a declared parameter and its validation.
- :class:`Lobe` — a lobe's kind and angular half-width.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from brdfkit.errors import ParameterError

__all__ = ["Lobe", "MAX_CHANNELS", "Param"]

#: Most values of a per-channel (``colour``) or per-lobe (``lobes``) parameter. A
#: spectrum sampled every nanometre over the visible range (360-830 nm) has 471 values;
#: 1024 leaves room for that. Every image, table and kernel row grows with the channel
#: count: a 256x256 sphere render costs ~48 bytes per pixel and channel (measured, PNG
#: output), so 20000 channels asked for > 4 GB where 1024 take 3.2 GB at most.
MAX_CHANNELS = 1024


@dataclass(frozen=True)
class Lobe:
    """Where a model's reflected energy concentrates, for lobe-aware numerics.

    The albedo engine integrates in the frame of each lobe and the χ² sampling
    tests choose their resolution from ``width``.

    Attributes
    ----------
    kind : {"diffuse", "mirror", "half", "normal"}
        ``diffuse``: broad, no preferred direction beyond the cosine.
        ``mirror``: concentrated about the mirror direction R of the other
        direction (Phong-type, a function of R·V).
        ``half``: concentrated where the half vector H is near the normal
        (Blinn/microfacet-type, a function of N·H).
        ``normal``: concentrated about the normal (peaked separable models).
    width : float
        Angular half-width in radians (≈ the half-angle β at which the lobe
        falls to half its peak, in the variable of ``kind``).
    """

    kind: str
    width: float


@dataclass(frozen=True)
class Param:
    """A model parameter, declared once.

    Attributes
    ----------
    name : str
        The paper's symbol in ASCII (``rho_d``, ``k_s``, ``n``, ``m`` ...).
    default : float, str or bool
        Default value (a string for a choice parameter, a bool for a bool one).
    lower, upper : float
        Bounds; ``lower_open`` / ``upper_open`` make them strict.
    unit : str
        Unit ("1/sr", "rad", "" for dimensionless).
    doc : str
        One line: what it means and guidance on values.
    kind : {"scalar", "colour", "lobes", "choice", "bool"}
        ``colour``: may be given per channel (a 1-D sequence, RGB or a
        spectrum), broadcasting to a trailing channel axis of the output.
        ``lobes``: may be a 1-D sequence, one value per lobe.
        ``choice``: one of ``choices``.
        ``bool``: a flag (BRDF Explorer's ``bool NAME DEFAULT``): True/False,
        1/0 or the words ``true``/``false``/``1``/``0`` (any case; the command
        line's ``-p isotropic=false``), validated to a Python bool, packed for
        the kernel as 1.0/0.0; a fit holds it (never fitted).
    choices : tuple of str
        The allowed values of a choice parameter.
    optional : bool
        ``None`` is allowed and means "not given" (e.g. no index of refraction
        means F = 1). Packed for the kernel as 0.0, which kernels test for.
    """

    name: str
    default: float | str | bool
    lower: float = -math.inf
    upper: float = math.inf
    unit: str = ""
    doc: str = ""
    kind: str = "scalar"
    choices: tuple[str, ...] = ()
    lower_open: bool = False
    upper_open: bool = False
    optional: bool = False

    def bounds_text(self) -> str:
        """The allowed range as text, e.g. ``[0, 1]`` or ``(0, inf)``."""
        if self.kind == "choice":
            return "one of " + ", ".join(self.choices)
        if self.kind == "bool":
            return "true or false"
        lo = "(" if self.lower_open else "["
        hi = ")" if self.upper_open or math.isinf(self.upper) else "]"
        if math.isinf(self.lower):
            lo = "("
        return f"{lo}{_fmt(self.lower)}, {_fmt(self.upper)}{hi}"

    def validate(self, value, model: str):
        """Return *value* converted (float, float array, str, bool or None); raise if
        invalid."""
        if value is None and self.optional:
            return None
        if value is None:
            raise ParameterError(
                f"{model}: parameter {self.name!r} must be {self._expected()}; got None "
                "(only optional parameters take None)")
        if self.kind == "bool":
            return self._flag(value, model)
        if type(value) is float and self.kind != "choice" and self._inside(value):
            return value  # the common case (a fit builds a model per evaluation): no array
        if self.kind == "choice":
            if not isinstance(value, str) or value.lower() not in self.choices:
                raise ParameterError(
                    f"{model}: parameter {self.name!r} must be {self.bounds_text()}; got {value!r}"
                )
            return value.lower()
        try:
            arr = np.asarray(value, dtype=np.float64)
        except OverflowError:  # an int beyond float64 (e.g. 10**400)
            raise ParameterError(
                f"{model}: parameter {self.name!r} must lie in {self.bounds_text()}; got a "
                f"number too large for a float ({_short(value)})") from None
        except (TypeError, ValueError):
            raise ParameterError(
                f"{model}: parameter {self.name!r} must be a number in {self.bounds_text()}; "
                f"got {value!r}"
            ) from None
        if arr.ndim > 1 or (arr.ndim == 1 and self.kind == "scalar"):
            allowed = "a number" if self.kind == "scalar" else "a number or a 1-D sequence"
            raise ParameterError(
                f"{model}: parameter {self.name!r} must be {allowed}; got shape {arr.shape}"
            )
        if arr.ndim == 1 and arr.size == 0:
            raise ParameterError(f"{model}: parameter {self.name!r} is an empty sequence")
        if arr.ndim == 1 and arr.size > MAX_CHANNELS:
            what = "channels" if self.kind == "colour" else "lobes"
            raise ParameterError(
                f"{model}: parameter {self.name!r} takes at most MAX_CHANNELS = {MAX_CHANNELS} "
                f"values ({what}; memory grows with them); got {arr.size}")
        for x in np.atleast_1d(arr):
            if not self._inside(float(x)):
                raise ParameterError(
                    f"{model}: parameter {self.name!r} must lie in {self.bounds_text()}"
                    f"{' ' + self.unit if self.unit else ''}; got {_fmt(float(x))}"
                )
        return float(arr) if arr.ndim == 0 else arr.copy()

    def _expected(self) -> str:
        if self.kind == "choice":
            return self.bounds_text()
        if self.kind == "bool":
            return "true or false"
        return f"a number in {self.bounds_text()}"

    def _flag(self, value, model: str) -> bool:
        if isinstance(value, bool | np.bool_):
            return bool(value)
        if isinstance(value, int | float | np.integer | np.floating) and value in (0, 1):
            return bool(value)
        if isinstance(value, str) and value.strip().lower() in _FLAG_WORDS:
            return _FLAG_WORDS[value.strip().lower()]
        raise ParameterError(f"{model}: parameter {self.name!r} must be true or false "
                             f"(true/false, 1/0); got {value!r}")

    def _inside(self, x: float) -> bool:
        if not math.isfinite(x):
            return False
        lo_ok = x > self.lower if self.lower_open else x >= self.lower
        hi_ok = x < self.upper if self.upper_open else x <= self.upper
        return lo_ok and hi_ok

    def to_dict(self) -> dict:
        """JSON-ready description (used by ``brdfkit models --json``)."""
        d = {"name": self.name, "default": self.default, "kind": self.kind,
             "unit": self.unit, "doc": self.doc, "optional": self.optional}
        if self.kind == "choice":
            d["choices"] = list(self.choices)
        elif self.kind == "bool":
            d["bounds"] = self.bounds_text()
        else:
            d["lower"] = None if math.isinf(self.lower) else self.lower
            d["upper"] = None if math.isinf(self.upper) else self.upper
            d["bounds"] = self.bounds_text()
        return d


#: The words a bool parameter accepts (any case), and what they mean.
_FLAG_WORDS = {"true": True, "false": False, "1": True, "0": False}


def _short(value) -> str:
    """*value* as text, at most 40 characters (a 400-digit integer is not printed whole)."""
    text = str(value)
    return text if len(text) <= 40 else f"{text[:12]}...({len(text)} characters)"


def _fmt(x: float) -> str:
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return f"{x:g}"



def _check_beta(model: str, beta) -> float:
    try:
        b = float(beta)
    except (TypeError, ValueError):
        raise ParameterError(f"{model}: 'beta' must be a number (radians); got {beta!r}") from None
    if not (0.0 < b < math.pi / 2):
        raise ParameterError(
            f"{model}: 'beta' (half-angle) must lie in (0, pi/2) rad = (0, 90) deg; got {b:g} rad"
        )
    return b
