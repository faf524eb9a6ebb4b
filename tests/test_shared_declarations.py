"""Declarations written once (issue 18 §4): shared parameters, packed indices by name, the
MERL θ_h grid, the luminance weights.

References: the models' own values (a packed slot holds the parameter's value), the
expressions each former copy of the θ_h grid used (bit for bit), ITU-R BT.709-6 item 3.2
(Y = 0.2126 R + 0.7152 G + 0.0722 B) and Mitsuba 3's ``luminance()`` (0.212671, 0.715160,
0.072169).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import brdfkit
from brdfkit.colour import LUMINANCE, MITSUBA_LUMINANCE
from brdfkit.errors import ParameterError
from brdfkit.geometry import merl_theta_h
from brdfkit.models import BRDF, MODELS
from brdfkit.models._params import DIFFUSE_ALBEDO, DIFFUSE_PART, ETA, packed_indices

DEFAULT_PACKING = [name for name, cls in MODELS.items()
                   if cls._pack_channel is BRDF._pack_channel and cls._pack is BRDF._pack
                   and all(p.kind != "lobes" for p in cls.params)]


@pytest.mark.parametrize("name", DEFAULT_PACKING)
def test_packed_indices_name_the_slots_the_values_are_in(name):
    cls = MODELS[name]
    for example in cls.examples:
        m = brdfkit.model(name, **example)
        for p in cls.params:
            (i,) = packed_indices(cls.params, p.name)
            v = m.channel_values(0)[p.name]
            want = (0.0 if v is None else float(p.choices.index(v)) if p.kind == "choice"
                    else float(v))
            assert m.packed[0, i] == want, (name, p.name)


def test_packed_indices_reject_an_unknown_or_per_lobe_name():
    with pytest.raises(ParameterError, match="'nope'"):
        packed_indices(MODELS["microfacet"].params, "nope")
    with pytest.raises(ParameterError, match="no fixed slot"):
        packed_indices(MODELS["lafortune"].params, *[p.name for p in MODELS["lafortune"].params])


def test_eta_is_declared_once():
    etas = {name: next(p for p in cls.params if p.name == "eta")
            for name, cls in MODELS.items() if any(p.name == "eta" for p in cls.params)}
    assert set(etas) >= {"microfacet", "he-torrance", "nielsen", "torrance-sparrow",
                         "cook-torrance"}
    for name, p in etas.items():
        # the same declaration, at most with the family's own one-line doc
        assert (p.default, p.lower, p.upper, p.kind, p.lower_open, p.optional) == (
            ETA.default, ETA.lower, ETA.upper, ETA.kind, ETA.lower_open, ETA.optional), name
    assert etas["microfacet"] is ETA and etas["he-torrance"] is ETA


def test_the_two_diffuse_albedos_differ_only_by_default_and_doc():
    assert (DIFFUSE_PART.default, DIFFUSE_ALBEDO.default) == (0.2, 0.8)
    assert MODELS["lambert"].params == (DIFFUSE_ALBEDO,)
    assert DIFFUSE_PART in MODELS["modified-phong"].params


def test_merl_theta_h_is_every_former_copy_bit_for_bit():
    u = np.arange(90) + 0.5
    assert np.array_equal(merl_theta_h(u / 90.0), (u / 90.0) ** 2 * (0.5 * np.pi))  # merl.py
    for n in (90, 128, 2048):
        v = (np.arange(n) + 0.5) / n
        assert np.array_equal(merl_theta_h(v), v * v * (0.5 * math.pi))  # fitting/samples.py
        assert np.array_equal(merl_theta_h(v), v * v * 0.5 * math.pi)  # explorer/views.py
    assert merl_theta_h(1.0) == 0.5 * math.pi and merl_theta_h(0.0) == 0.0


def test_luminance_weights():
    np.testing.assert_array_equal(LUMINANCE, [0.2126, 0.7152, 0.0722])  # BT.709-6 item 3.2
    np.testing.assert_array_equal(MITSUBA_LUMINANCE, [0.212671, 0.715160, 0.072169])
    assert math.isclose(LUMINANCE.sum(), 1.0, abs_tol=1e-12)  # white has Y = 1
    assert np.max(np.abs(LUMINANCE / MITSUBA_LUMINANCE - 1.0)) < 1e-3
    from brdfkit.explorer import views

    assert views.LUMINANCE is LUMINANCE
