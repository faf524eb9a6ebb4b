"""The Python blocks of the README and of docs/*.md run as printed (issue 20: the README's
pumping snippet used undefined names, its Mitsuba snippet crashed without ``wavefront()``).

Each file's ```` ```python```` blocks run in order in one namespace (as a reader pastes
them into one session), in an empty directory, so files they write land there.
docs/your-own-model.md is run whole, shell blocks too, by tests/test_your_own_model_guide.py.
The numbers the README states next to its snippets are checked where they are closed forms:
the pumped albedo is at most 1 (Neumann et al. 1999 eq. 17), a Lambertian RGB model's albedo
is its ρ_d, the compensated GGX's white furnace is 1 within the stated 1e-6.
"""

from __future__ import annotations

import pathlib

import numpy as np
import pytest
from test_your_own_model_guide import blocks

ROOT = pathlib.Path(__file__).resolve().parents[1]
FILES = ["README.md", "docs/compensation.md", "docs/rendering.md"]


def python_blocks(path: pathlib.Path) -> list[str]:
    return [body for lang, attrs, body in blocks(path.read_text())
            if lang == "python" and "file" not in attrs]


def test_every_doc_with_python_blocks_is_listed():
    have = {str(p.relative_to(ROOT)) for p in [ROOT / "README.md", *ROOT.glob("docs/*.md")]
            if python_blocks(p)}
    assert have == set(FILES) | {"docs/your-own-model.md"}


@pytest.mark.parametrize("name", FILES)
def test_python_blocks_run_as_printed(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    ns: dict = {"__name__": "__doc__"}
    found = python_blocks(ROOT / name)
    assert found, name
    for n, body in enumerate(found):
        exec(compile(body, f"{name} python block {n}", "exec"), ns)
    if name == "README.md":
        from brdfkit.analysis import albedo

        th = np.radians([0.0, 45.0, 85.0, 89.0])
        assert ns["res"].success and ns["res"].message.startswith("converged")
        assert np.all(albedo(ns["p2"], th).albedo <= 1.0 + 1e-9)  # eq. 17: a* <= 1
        np.testing.assert_allclose(albedo(ns["kc"], th).albedo, 1.0, atol=1e-6)  # furnace
        # Nielsen et al. eq. (1) at the mirror direction (R·V = 1): ρ_d/π + ρ_s (n + 2)/2π
        want = 0.2 / np.pi + 0.5 * 52 / (2 * np.pi)
        np.testing.assert_allclose(ns["m"].eval(ns["wi"], ns["wo"]), want, rtol=1e-12)
        f = np.ravel(ns["rgb"].eval(ns["wi"], ns["wo"]))  # channels differ by Δρ_d/π only
        np.testing.assert_allclose(f - f[0], (np.array([0.1, 0.2, 0.3]) - 0.1) / np.pi,
                                   atol=1e-12)
        img = np.asarray(ns["image"])
        assert img.shape == (64, 64, 3) and np.all(np.isfinite(img)) and img.max() > 0
