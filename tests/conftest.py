"""Shared pytest configuration and fixtures.

- ``rng``: a seeded :class:`numpy.random.Generator` (Monte-Carlo tests take an
  explicit seed, see the brdfkit conventions).
- ``random_hemisphere(rng, n)``: uniformly distributed unit vectors on the
  upper hemisphere (z > 0), as a plain function fixture.
"""

from __future__ import annotations

import numpy as np
import pytest


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)


def _random_hemisphere(rng: np.random.Generator, n: int) -> np.ndarray:
    # Uniform on the hemisphere: z = u0 ~ U(0, 1], phi ~ U(0, 2 pi) (Archimedes).
    z = 1.0 - rng.random(n)
    phi = 2.0 * np.pi * rng.random(n)
    r = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)


@pytest.fixture
def random_hemisphere():
    return _random_hemisphere


# the explorer's browser tests: a live server and headless Chromium (module-scoped)
from explorer_harness import browser, server  # noqa: E402, F401
