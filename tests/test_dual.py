"""The formula contract of brdfkit._dual (one code object, Numba and Dr.Jit versions).

References: the contract stated in brdfkit._dual's docstring (names only, selects for
branches on values), and closed forms of the primitives.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from brdfkit._dual import drjit_version, formula, select, sqrt

dr = pytest.importorskip("drjit")

SCALE = 3.0


@formula(cache=False)
def _hypot_scaled(x, y):
    return SCALE * sqrt(select(x > 0.0, x * x + y * y, y * y))


@formula(cache=False)
def _uses_math(x):
    return math.sqrt(x)  # an attribute: Dr.Jit cannot rebind it


@formula(cache=False)
def _uses_builtin(x):
    return min(x, 1.0)  # a builtin: not a primitive


def test_one_code_object_two_versions():
    """The Numba and Dr.Jit versions of a formula are the same code, with each world's
    sqrt/select: 3·√(x² + y²) for x > 0 and 3|y| otherwise (closed form)."""
    from drjit.llvm import Float

    x = np.array([3.0, -3.0, 0.5])
    y = np.array([4.0, 4.0, 0.0])
    want = np.where(x > 0.0, 3.0 * np.hypot(x, y), 3.0 * np.abs(y))
    got_numba = np.array([_hypot_scaled(a, b) for a, b in zip(x, y, strict=True)])
    np.testing.assert_allclose(got_numba, want, rtol=1e-15)
    traced = drjit_version(_hypot_scaled)
    assert traced.__code__ is _hypot_scaled.py_func.__code__
    got = np.array(traced(Float(x.astype(np.float32)), Float(y.astype(np.float32))))
    np.testing.assert_allclose(got, want, rtol=1e-6)


def test_contract_is_checked():
    """Attribute access, builtins and non-formulas are refused with the name at fault."""
    with pytest.raises(TypeError, match="_uses_math uses LOAD_ATTR"):
        drjit_version(_uses_math)
    with pytest.raises(TypeError, match="_uses_builtin reads the global 'min'"):
        drjit_version(_uses_builtin)
    with pytest.raises(TypeError, match="is not a formula"):
        drjit_version(lambda x: x)
