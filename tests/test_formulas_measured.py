"""Measured materials as formulas: the Mitsuba bridge's traced route (issue 23).

The built-in surrogates (``merl:NAME`` NBRDF, ``@npf``, ``@abc``, ``@sgd``) and a MERL
``.binary`` table (MeasuredBRDF, nearest and linear lookup) give ``formulas()``: f_r as a
formula (:mod:`brdfkit.data.surrogate_formulas`, :mod:`brdfkit.data.merl_formulas`; the
tables read by ``row_at``, a ``dr.gather`` in the trace) and the cosine + GGX proxy
sampler of :mod:`brdfkit.user.proxy_sampler`.

References, each independent of the formulas under test:

- **Values**: the models' own evaluation (``model.eval``: the hand-written Numba kernels
  with branches and loops, NBRDF's blocked matrix-product driver, MERL's fast-index table
  loops — other code computing the same definitions). The Numba compilation of the
  formula equals it to 1e-12 relative (NBRDF: 1e-11 with an absolute floor, the driver
  reassociates its sums); the Dr.Jit trace (float32) to 5e-4. Pairs within float32
  rounding of a bin boundary of a nearest-bin lookup (NPF's D, F and G₁ cells, MERL
  ``nearest``) are left out of the float32 comparison: there the lookup jumps, and the
  bins are found here by an independent NumPy computation of the Rusinkiewicz angles.
- **Images**: the traced render (symbolic mode, the proxy sampler) against the wavefront
  route (``model.sample``/``pdf``: the tabulated sampler of :mod:`brdfkit.data.sampler`,
  a different sampler of the same f_r) with the two-sample block t-tests of
  tests/test_render_mitsuba.py: the same image within Monte-Carlo noise.
"""

from __future__ import annotations

import gc
import math

import numpy as np
import pytest
from traced_helpers import mirror_pairs

import brdfkit
from brdfkit._dual import formula, muladd
from brdfkit.data.measured import MeasuredBRDF
from brdfkit.data.merl import read_binary, table_from_function, write_binary
from brdfkit.tables import lookup, row_at

SURROGATES = ["merl:nickel", "merl:nickel@npf", "merl:nickel@abc", "merl:nickel@sgd"]
TABLES = ["file-nearest", "file-linear"]


@pytest.fixture(scope="module")
def merl_file(tmp_path_factory):
    """A real MERL .binary file: merl:nickel@abc tabulated at the bin centres (three
    different channels, unmeasured bins below the horizon), written and read back."""
    path = tmp_path_factory.mktemp("merl") / "nickel-abc.binary"
    write_binary(path, table_from_function(brdfkit.model("merl:nickel@abc").eval,
                                           source="nickel-abc"))
    return read_binary(path)


def _model(name: str, merl_file):
    if name == "file-nearest":
        return MeasuredBRDF(merl_file)
    if name == "file-linear":
        return MeasuredBRDF(merl_file, lookup="linear")
    return brdfkit.model(name)


def _pairs(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(light, view) float32-exact unit vectors above the horizon, half of the lights near
    the view's mirror direction (the specular peaks): traced_helpers.mirror_pairs."""
    view, light = mirror_pairs(np.random.default_rng(seed), n)
    return light, view

def _angles(light, view):
    """(θ_h, θ_d, φ_d) by Rusinkiewicz's rotations in NumPy (independent of the formulas)."""
    h = light + view
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    th = np.arccos(np.clip(h[:, 2], -1.0, 1.0))
    ph = np.arctan2(h[:, 1], h[:, 0])
    c, s = np.cos(ph), np.sin(ph)
    tx, ty = light[:, 0] * c + light[:, 1] * s, light[:, 1] * c - light[:, 0] * s
    ct, st = np.cos(th), np.sin(th)
    dx, dz = tx * ct - light[:, 2] * st, light[:, 2] * ct + tx * st
    return th, np.arccos(np.clip(dz, -1.0, 1.0)), np.arctan2(ty, dx)


def _away_from_edges(name, light, view, margin=1e-3):
    """Pairs whose nearest-bin coordinates lie more than *margin* (in bins) from a bin
    boundary (all pairs for the continuous lookups)."""
    th, td, pd = _angles(light, view)
    coords = []
    if name in ("merl:nickel@npf", "file-nearest"):
        coords += [np.sqrt(th / (0.5 * math.pi)) * 90.0, td / (0.5 * math.pi) * 90.0]
    if name == "merl:nickel@npf":  # G₁'s cells: u − ½ of each polar angle
        coords += [np.arccos(w[:, 2]) / (0.5 * math.pi) * 90.0 - 0.5 for w in (light, view)]
    if name == "file-nearest":
        coords.append(np.where(pd < 0.0, pd + math.pi, pd) / math.pi * 180.0)
    keep = np.ones(light.shape[0], bool)
    for u in coords:
        f = u - np.floor(u)
        keep &= (f > margin) & (f < 1.0 - margin)
    return keep


def _numba_eval(form, model, light, view) -> np.ndarray:
    """The Numba compilation of the formula, one call per pair and channel."""
    rows = np.ascontiguousarray(model.packed)
    return np.array([[form.eval(*light[k], *view[k], rows[c]) for c in range(rows.shape[0])]
                     for k in range(light.shape[0])])


@pytest.mark.parametrize("name", SURROGATES + TABLES)
def test_numba_formula_equals_model_eval(name, merl_file):
    model = _model(name, merl_file)
    form = model.formulas()
    light, view = _pairs(200, 1)
    want = model.eval(light, view)
    got = _numba_eval(form, model, light, view)
    if name == "merl:nickel":  # the driver reassociates the net's sums (~1e-13)
        np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-12 * want.max())
    else:
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=0.0)
    # below the horizon: 0 (the contract), as the model
    below = view * [1.0, 1.0, -1.0]
    assert np.all(_numba_eval(form, model, light[:5], below[:5]) == 0.0)


# --------------------------------------------------------------------------- Mitsuba
mi = pytest.importorskip("mitsuba")
dr = pytest.importorskip("drjit")

from traced_helpers import variant  # noqa: E402

from brdfkit.render.mitsuba_bridge import mitsuba_bsdf, wavefront  # noqa: E402
from brdfkit.render.mitsuba_sphere import sphere_scene  # noqa: E402


def _llvm(name: str = "llvm_ad_rgb") -> str:
    return variant(name, llvm=True)


@pytest.mark.parametrize("name", SURROGATES + TABLES)
def test_traced_eval_and_pdf(name, merl_file):
    """The traced BSDF (Dr.Jit, float32) against model.eval; its pdf is the proxy's."""
    from brdfkit.user.proxy_sampler import ProxyStrategy

    _llvm()
    model = _model(name, merl_file)
    bsdf = mitsuba_bsdf(model, route="traced")
    assert bsdf.traced
    light, view = _pairs(2000, 2)
    si = dr.zeros(mi.SurfaceInteraction3f, view.shape[0])
    si.wi = mi.Vector3f(view.T.astype(np.float32))
    wo = mi.Vector3f(light.T.astype(np.float32))
    got = np.array(bsdf.eval(mi.BSDFContext(), si, wo)).T / light[:, 2:3]
    want = model.eval(light, view)
    keep = _away_from_edges(name, light, view)
    assert keep.mean() > 0.9  # the comparison covers most pairs
    np.testing.assert_allclose(got[keep], want[keep], rtol=5e-4, atol=1e-5 * want.max())
    proxy = ProxyStrategy(*model.formulas().args)
    np.testing.assert_allclose(np.array(bsdf.pdf(mi.BSDFContext(), si, wo)),
                               proxy.pdf(light, view), rtol=2e-4, atol=1e-7)
    del bsdf
    gc.collect()


def test_table_row_gathers_out_of_range_as_zero(merl_file):
    """An index outside the table (a discarded lane's NaN included) reads 0, in bounds; the
    three channels of a bin are read from the one channel-interleaved array."""
    from brdfkit.traced_tables import TableRow, TracedTables, row_at_drjit

    _llvm()
    model = MeasuredBRDF(merl_file)
    k = model.formulas().tables
    tabs = TracedTables(model.packed, k, mi.Float, lambda v: mi.Color3f(*v))
    row = TableRow(list(model.packed[0, :k]), tabs)
    got = np.array(row_at_drjit(dr)(row, mi.Float([0.0, 1.0, 1458000.0, 1458001.0, math.nan])))
    assert np.all(got[:, [0, 3, 4]] == 0.0)
    want = model.packed[:, [1, 1458000]]
    np.testing.assert_allclose(got[:, 1:3], want, rtol=1e-7)
    assert row[0] == 0.0  # the lookup mode column, an ordinary column


@pytest.mark.parametrize("name", ["merl:nickel", "merl:nickel@npf", "file-linear"])
def test_traced_render_agrees_with_wavefront(name, merl_file):
    """Traced (proxy sampler, symbolic mode) and wavefront (tabulated sampler) renders of a
    sphere agree within Monte-Carlo noise; the traced images are finite."""
    from test_render_mitsuba import worst_p

    variant = _llvm()
    model = _model(name, merl_file)
    size, spp, k = 24, 16, 4
    kw = {"phi_l": math.radians(30.0), "ambient": 0.3, "irradiance": 1.0}

    def renders(bsdf):
        scene = mi.load_dict(sphere_scene(bsdf, size=size, variant=variant, **kw))
        return np.stack([np.array(mi.render(scene, spp=spp, seed=j)) for j in range(k)])

    traced = mitsuba_bsdf(model)
    assert traced.traced
    a = renders(traced)
    del traced
    gc.collect()
    wave = mitsuba_bsdf(model, route="wavefront")
    assert not wave.traced
    with wavefront():
        b = renders(wave)
    del wave
    gc.collect()
    assert np.all(np.isfinite(a)) and np.all(np.isfinite(b))
    p, level = worst_p(a, b=b)
    assert p > level, (p, level)
    assert worst_p(a, b=1.1 * b)[0] < level  # power: a 10 % brighter image is rejected


def test_one_table_design_serves_lookups_and_bins():
    """One row (traced_tables.TableRow) serves both kinds of table read in one formula: a
    compensation-style cubic lookup (tables.lookup) and a measured-style bin read at a
    computed column (tables.row_at); the trace equals the Numba formula on the packed row
    (float32 tolerance). Reference: the compiled formula, an independent implementation
    (tables._lookup and p[int(i)] in float64)."""
    from brdfkit._dual import compose, drjit_version
    from brdfkit.tables import build_lookup
    from brdfkit.traced_tables import TableRow, TracedTables

    _llvm()
    fns = [lambda m, a=a: (1.0 + a * m * m)[:, None] for a in (0.5, 1.0, 2.0)]
    blocks = [build_lookup(f).packed(0) for f in fns]
    width = max(b.size for b in blocks)
    k = 1  # one parameter column, then the lookup, then 8 bins per channel
    bins = np.arange(24.0).reshape(3, 8) + 0.25
    rows = np.array([np.concatenate([[2.0], blocks[c], np.zeros(width - blocks[c].size),
                                     bins[c]]) for c in range(3)])
    f = compose(_both, k=k, first_bin=k + width)
    mu = np.array([0.0, 0.3, 0.71, 1.0])
    got = np.array(drjit_version(f)(mi.Float(mu), mi.Float([0.0, 3.0, 5.0, 7.0]),
                                    TableRow([2.0], TracedTables(rows, k, mi.Float,
                                                                 lambda v: mi.Color3f(*v))))).T
    want = np.array([[f(m, j, rows[c]) for c in range(3)]
                     for m, j in zip(mu, [0.0, 3.0, 5.0, 7.0], strict=True)])
    np.testing.assert_allclose(got, want, rtol=1e-6)


k = first_bin = 0  # bound by compose in _both


def _both(mu, j, p):
    return p[0] * lookup(p, k, mu) + row_at(p, first_bin + j)


def test_muladd_is_fused_in_the_trace_and_not_in_numba():
    """muladd (the NBRDF net's multiply-adds): Numba a·b + c rounded twice (the kernels'
    value), Dr.Jit one fused rounding. Reference: exact arithmetic of a = b = 1 + 2⁻¹²,
    c = −1: a·b − 1 = 2⁻¹¹ + 2⁻²⁴ (exact in float32 when fused; the float32 product
    rounds 2⁻²⁴ away, to even)."""
    from brdfkit._dual import drjit_version

    _llvm()
    a = 1.0 + 2.0 ** -12
    assert muladd(a, a, -1.0) == a * a - 1.0  # float64, unfused: the kernels' order
    got = drjit_version(_fma_f)(mi.Float(a), mi.Float(a), mi.Float(-1.0))
    assert float(np.array(got)[0]) == 2.0 ** -11 + 2.0 ** -24


@formula
def _fma_f(a, b, c):
    return muladd(a, b, c)
