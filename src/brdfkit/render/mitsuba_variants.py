"""
Mitsuba variants for the bridge: which ones, and the fallback when LLVM is missing
==================================================================================

``llvm_*`` variants need Debian's ``libllvm19`` (LLVM 15/16 load but abort on
microfacet kernels). :func:`select_variant` falls back to the matching
``scalar_*`` variant (``scalar_rgb`` for ``llvm_ad_mono``: the pip build has
no ``scalar_mono``) with a one-line warning saying why and how to fix it. In
scalar variants Mitsuba calls the BSDF once per path vertex from Python:
correct, and ~10⁴× slower (small images only).

Public objects
--------------
- :data:`FALLBACK`, :data:`VARIANTS` — the supported variants and each one's fallback.
- :func:`import_mitsuba` — ``(mitsuba, drjit)``, or an error saying how to install them;
  Mitsuba's log (its WARN/ERROR lines) is routed to stderr, so that it never mixes
  with a command's output on stdout.
- :func:`select_variant` — set a variant, or its fallback with a warning.
  (:func:`brdfkit.render.mitsuba_bridge.use_variant` also registers the plugin.)
"""

from __future__ import annotations

import sys
import warnings

from brdfkit._cache import memo
from brdfkit.errors import BrdfkitError, ParameterError

__all__ = ["FALLBACK", "VARIANTS", "import_mitsuba", "select_variant"]

#: The variants the bridge supports, and the scalar variant each falls back to.
FALLBACK = {"llvm_ad_rgb": "scalar_rgb", "llvm_ad_mono": "scalar_rgb",
            "llvm_ad_spectral": "scalar_spectral", "scalar_rgb": "scalar_rgb",
            "scalar_spectral": "scalar_spectral"}
VARIANTS = tuple(FALLBACK)


def import_mitsuba():
    """Import Mitsuba and Dr.Jit, with an error saying how to install them."""
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as exc:
        raise BrdfkitError(
            f"rendering through Mitsuba needs the packages mitsuba and drjit ({exc}); "
            "install them with: pip install mitsuba") from None
    _route_log(mi)
    return mi, dr


#: Once per process; the memo also keeps a Python reference to the appender.
@memo(maxsize=1)
def _route_log(mi):
    """Replace Mitsuba's log appenders (a StreamAppender on stdout) by one on stderr, plain
    text; progress bars are dropped (brdfkit shows its own). Returns the appender."""

    class StderrAppender(mi.Appender):
        def append(self, level, text):  # noqa: ARG002 (Mitsuba's signature)
            print(text, file=sys.stderr, flush=True)

        def log_progress(self, *args, **kwargs):
            pass

    logger = mi.logger() if hasattr(mi, "logger") else mi.Thread.thread().logger()
    appender = StderrAppender()
    logger.clear_appenders()
    logger.add_appender(appender)
    return appender


def select_variant(variant: str, *, stacklevel: int = 1) -> str:
    """Set Mitsuba's *variant*, or its scalar fallback when it cannot start.

    Parameters
    ----------
    variant : str
        One of :data:`VARIANTS`.
    stacklevel : int
        Of the fallback warning, counted from the caller (1: the caller of this
        function, 2: its caller).

    Returns
    -------
    str
        The variant in use: *variant*, or ``FALLBACK[variant]`` when an
        ``llvm_*`` variant cannot start (no usable LLVM); a one-line
        :class:`RuntimeWarning` then says why and how to fix it.
    """
    if variant not in FALLBACK:
        raise ParameterError(
            f"variant must be one of {', '.join(VARIANTS)}; got {variant!r}")
    mi, dr = import_mitsuba()
    try:
        mi.set_variant(variant)
        if variant.startswith("llvm"):
            # the LLVM backend starts lazily: compile and run one kernel to know it works
            x = mi.Float([1.0, 2.0])
            dr.eval(x * 2.0)
    except Exception as exc:  # Mitsuba/Dr.Jit raise plain exceptions for a missing LLVM
        used = FALLBACK[variant]
        reason = str(exc).strip().splitlines()[0][:160] if str(exc).strip() else type(exc).__name__
        warnings.warn(
            f"brdfkit: Mitsuba variant {variant} unavailable ({reason}); using {used} "
            "(slow) — fix: apt-get install libllvm19, or set DRJIT_LIBLLVM_PATH to "
            "libLLVM-19.so", RuntimeWarning, stacklevel=stacklevel + 1)
        mi.set_variant(used)
        variant = used
    return variant
