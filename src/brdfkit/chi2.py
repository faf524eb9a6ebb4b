"""Moved to :mod:`brdfkit.analysis.chi2` (next to the other analyses).

This alias keeps ``import brdfkit.chi2`` / ``from brdfkit.chi2 import chi2_test`` working:
the name is bound to the very same module object. New code imports
:mod:`brdfkit.analysis.chi2`.
"""

import sys

from brdfkit.analysis import chi2 as _chi2

sys.modules[__name__] = _chi2
