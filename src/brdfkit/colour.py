"""
Colour constants shared by the layers above
===========================================

- :data:`LUMINANCE` — the luminance Y of linear Rec. 709 / sRGB R, G, B:
  0.2126, 0.7152, 0.0722, the weights ITU-R BT.709-6 (item 3.2) and
  IEC 61966-2-1 (sRGB) specify. brdfkit's luminance (the explorer's curves).
- :data:`MITSUBA_LUMINANCE` — the same weights unrounded, 0.212671, 0.715160,
  0.072169 (derived from the Rec. 709 primaries and a D65 white of
  x, y = 0.3127, 0.3290 rounded differently), which Mitsuba 3's ``luminance()``
  uses: the Mitsuba bridge's wavefront route converts RGB to mono with them so
  that it agrees with Mitsuba's own conversion in the traced route (to 1e-5,
  ``tests/test_render_mitsuba.py``). They differ from :data:`LUMINANCE` by
  < 1e-4 relative.
"""

from __future__ import annotations

import numpy as np

__all__ = ["LUMINANCE", "MITSUBA_LUMINANCE"]

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
LUMINANCE.flags.writeable = False
MITSUBA_LUMINANCE = np.array([0.212671, 0.715160, 0.072169])
MITSUBA_LUMINANCE.flags.writeable = False
