"""Numba's thread count in one place (brdfkit._threads): set inside a block, restored after,
never flipped when it already has the value; no other module sets it.

References: Numba's own get_num_threads before, inside and after the block, and a count of
set_num_threads calls (monkeypatched)."""

from __future__ import annotations

from pathlib import Path

import numba
import pytest

from brdfkit._threads import numba_threads

SRC = Path(__file__).resolve().parents[1] / "src" / "brdfkit"


def test_count_inside_and_restored():
    before = numba.get_num_threads()
    with numba_threads(1):
        assert numba.get_num_threads() == 1
    assert numba.get_num_threads() == before
    with pytest.raises(RuntimeError), numba_threads(1):
        raise RuntimeError("inside")
    assert numba.get_num_threads() == before  # restored on an exception too


def test_no_flip_when_unchanged(monkeypatch):
    calls = []
    real = numba.set_num_threads
    monkeypatch.setattr(numba, "set_num_threads", lambda n: (calls.append(n), real(n)))
    with numba_threads(1):
        for _ in range(3):
            with numba_threads(1):  # as every small eval inside a one-thread fit
                pass
        with numba_threads(None):
            pass
    assert calls == ([1, numba.get_num_threads()] if numba.get_num_threads() != 1 else [])


def test_only_one_module_sets_the_count():
    for path in SRC.rglob("*.py"):
        if path.name == "_threads.py":
            continue
        assert "set_num_threads(" not in path.read_text(), (
            f"{path}: set Numba's thread count through brdfkit._threads.numba_threads")
