"""The MERL .binary format: exact I/O, the reference reader's lookup, MeasuredBRDF.

References used here (independent of the code under test):
- the file layout and the lookup formulas of MERL's BRDFRead.cpp as stated in issue 9
  (re-implemented below in NumPy from those formulas, not from brdfkit's code);
- RED/GREEN/BLUE_SCALE = 1/1500, 1.15/1500, 1.66/1500 (BRDFRead.cpp);
- closed forms: a bin centre maps back to itself (u = i + 1/2 in index coordinates).
"""

from __future__ import annotations

import math
import os
import time

import numpy as np
import pytest

import brdfkit
from brdfkit.data.measured import MeasuredBRDF
from brdfkit.data.merl import (
    N_BINS,
    SHAPE,
    MerlTable,
    bin_centres,
    half_diff_to_directions,
    merl_indices,
    read_binary,
    table_from_function,
    write_binary,
)
from brdfkit.errors import BrdfkitError, DataFileError

FILE_BYTES = 12 + 3 * 90 * 90 * 180 * 8


# ----------------------------------------------------------------- independent reference
def _rotate(v, axis, angle):
    """Rodrigues' rotation, as BRDFRead.cpp's rotate_vector."""
    c, s = np.cos(angle)[..., None], np.sin(angle)[..., None]
    cross = np.cross(axis, v)
    return v * c + axis * np.sum(axis * v, axis=-1, keepdims=True) * (1 - c) + cross * s


def reference_index(wi, wo):
    """BRDFRead.cpp: std_coords_to_half_diff_coords + the three *_index functions."""
    h = wi + wo
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    theta_h = np.arccos(np.clip(h[..., 2], -1, 1))
    phi_h = np.arctan2(h[..., 1], h[..., 0])
    tmp = _rotate(wi, np.array([0.0, 0.0, 1.0]), -phi_h)
    d = _rotate(tmp, np.array([0.0, 1.0, 0.0]), -theta_h)
    theta_d = np.arccos(np.clip(d[..., 2], -1, 1))
    phi_d = np.arctan2(d[..., 1], d[..., 0])
    ih = np.where(theta_h <= 0, 0, np.sqrt(theta_h / (np.pi / 2) * 90 * 90).astype(np.int64))
    ih = np.clip(ih, 0, 89)
    idd = np.clip((theta_d / (np.pi / 2) * 90).astype(np.int64), 0, 89)
    pd = np.where(phi_d < 0, phi_d + np.pi, phi_d)
    ip = np.clip((pd / np.pi * 180).astype(np.int64), 0, 179)
    return ip + 180 * idd + 180 * 90 * ih


def _random_pairs(rng, n):
    def hemi(n):
        z = 1.0 - rng.random(n)
        phi = 2 * np.pi * rng.random(n)
        r = np.sqrt(1 - z * z)
        return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)
    return hemi(n), hemi(n)


@pytest.fixture(scope="module")
def raw_table():
    # a table of our own making: smooth positive values with a few unmeasured (-1) bins
    rng = np.random.default_rng(7)
    raw = rng.random((3, *SHAPE)) * 100.0 + 1.0
    raw[:, 5, 80:, :] = -1.0  # unmeasured, as MERL's grazing theta_d bins
    return raw


@pytest.fixture(scope="module")
def merl_file(tmp_path_factory, raw_table):
    path = tmp_path_factory.mktemp("merl") / "own.binary"
    with open(path, "wb") as fh:  # written here byte by byte from the layout, not by brdfkit
        np.array([90, 90, 180], dtype="<i4").tofile(fh)
        raw_table.astype("<f8").tofile(fh)
    return path


# ----------------------------------------------------------------- I/O
def test_read_matches_layout_and_scales(merl_file, raw_table):
    t = read_binary(merl_file)
    assert t.raw.shape == (3, 90, 90, 180)
    np.testing.assert_array_equal(t.raw, raw_table)
    scales = np.array([1 / 1500, 1.15 / 1500, 1.66 / 1500])
    np.testing.assert_array_equal(t.values[1, 3, 4, 5], raw_table[1, 3, 4, 5] * scales[1])
    assert not t.valid[0, 5, 85, 3] and t.valid[0, 5, 79, 3]
    assert t.valid_fraction == pytest.approx(1 - 10 * 180 / N_BINS)


def test_write_read_round_trip_is_bit_exact(merl_file, tmp_path):
    out = tmp_path / "copy.binary"
    write_binary(out, read_binary(merl_file))
    assert out.read_bytes() == merl_file.read_bytes()
    # and from scaled values: read(write(values)) reproduces the values to 1 ulp
    t = read_binary(merl_file)
    out2 = tmp_path / "from_values.binary"
    write_binary(out2, t.values)
    np.testing.assert_allclose(read_binary(out2).values, t.values, rtol=2.3e-16, atol=0)


def test_write_is_atomic_and_checks_the_path(tmp_path, merl_file):
    t = read_binary(merl_file)
    with pytest.raises(BrdfkitError, match="does not exist"):
        write_binary(tmp_path / "nope" / "x.binary", t)
    with pytest.raises(BrdfkitError, match="directory"):
        write_binary(tmp_path, t)
    write_binary(tmp_path / "x.binary", t)
    assert sorted(os.listdir(tmp_path)) == ["x.binary"]  # no temporary file left


def _write_bytes(path, data: bytes):
    path.write_bytes(data)
    return path


@pytest.mark.parametrize("mutate, needle", [
    (lambda b: b[:8], "header"),
    (lambda b: b"", "header"),
    (lambda b: np.array([90, 90, 360], "<i4").tobytes() + b[12:], "(90, 90, 360)"),
    (lambda b: np.array([180, 90, 90], "<i4").tobytes() + b[12:], "(180, 90, 90)"),
    (lambda b: np.array([90, 45, 180], "<i4").tobytes() + b[12:],
     "expected dimensions (90, 90, 180); found (90, 45, 180)"),
    (lambda b: np.array([90, 90, 180], ">i4").tobytes() + b[12:],  # big-endian
     "found (90, 90, 180) read big-endian"),
    # other bytes are not echoed (the explorer reports this message for a request's path)
    (lambda b: b"TOPSECRETKEY" + b[12:], "found bytes that are not table dimensions"),
    (lambda b: b[:-8], f"expected {FILE_BYTES} bytes"),
    (lambda b: b[:-8], f"found {FILE_BYTES - 8}"),
    (lambda b: b + b"\0" * 8, "too long"),
    (lambda b: b + b"\0" * 8, f"found {FILE_BYTES + 8}"),
    (lambda b: b[:100] + np.array([np.nan]).tobytes() + b[108:], "NaN"),
    (lambda b: b[:100] + np.array([-np.inf]).tobytes() + b[108:], "1 NaN/inf"),
    (lambda b: b[:12] + np.full(3 * N_BINS, -1.0).tobytes(), "every entry"),
])
def test_malformed_files_name_file_and_field(tmp_path, merl_file, mutate, needle):
    bad = _write_bytes(tmp_path / "bad.binary", mutate(merl_file.read_bytes()))
    with pytest.raises(DataFileError) as exc:
        read_binary(bad)
    assert str(bad) in str(exc.value)
    assert needle in str(exc.value)


def test_not_a_file(tmp_path):
    with pytest.raises(DataFileError, match="no such file"):
        read_binary(tmp_path / "missing.binary")
    with pytest.raises(DataFileError, match="not a regular file"):
        read_binary(tmp_path)


def test_fuzz_truncations_and_header_corruptions(tmp_path, merl_file, raw_table):
    """Seeded fuzz: random truncations, random header bytes, random bit flips of the
    header, random trailing bytes. Each read either raises DataFileError naming the file
    or — only when the bytes still are a valid file — returns the original table; none
    crashes with another exception or hangs."""
    rng = np.random.default_rng(11)
    good = merl_file.read_bytes()
    for k in range(28):  # 35 MB files: each full-size case costs ~0.2 s to write
        kind = k % 4
        if kind == 0:  # truncated: mostly within the header or early data, some late
            cut = int(rng.integers(0, 200)) if k % 8 == 0 else int(rng.integers(0, len(good)))
            b = good[:cut]
        elif kind == 1:  # random header bytes
            b = rng.integers(0, 256, 12, dtype=np.uint8).tobytes() + good[12:]
        elif kind == 2:  # one to three bit flips in the header
            h = bytearray(good[:12])
            for _ in range(int(rng.integers(1, 4))):
                h[int(rng.integers(0, 12))] ^= 1 << int(rng.integers(0, 8))
            b = bytes(h) + good[12:]
        else:  # trailing garbage
            b = good + rng.integers(0, 256, int(rng.integers(1, 64)), dtype=np.uint8).tobytes()
        p = _write_bytes(tmp_path / f"f{k}.binary", b)
        valid = b[:12] == good[:12] and len(b) == len(good)
        t0 = time.perf_counter()
        try:
            t = read_binary(p)
        except DataFileError as exc:
            assert str(p) in str(exc) and not valid
        else:
            assert valid
            np.testing.assert_array_equal(t.raw, raw_table)
        assert time.perf_counter() - t0 < 5.0
        p.unlink()


# ----------------------------------------------------------------- lookup
def test_indices_agree_with_the_reference_formulas(rng):
    wi, wo = _random_pairs(rng, 200_000)
    np.testing.assert_array_equal(merl_indices(wi, wo), reference_index(wi, wo))
    # edge cases: normal incidence and exitance, the mirror pair, grazing
    g = math.cos(math.radians(89.999))
    edge_i = np.array([[0, 0, 1.0], [0.6, 0, 0.8], [math.sqrt(1 - g * g), 0, g], [0, 0, 1.0]])
    edge_o = np.array([[0, 0, 1.0], [-0.6, 0, 0.8], [0, math.sqrt(1 - g * g), g], [0.6, 0, 0.8]])
    np.testing.assert_array_equal(merl_indices(edge_i, edge_o), reference_index(edge_i, edge_o))


def _reference_coords(wi, wo):
    """The reference's continuous index coordinates (u_θh, u_θd, u_φd) before the floor,
    and sin θ_d = |(d_x, d_y)|."""
    h = wi + wo
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    theta_h = np.arccos(np.clip(h[..., 2], -1, 1))
    phi_h = np.arctan2(h[..., 1], h[..., 0])
    d = _rotate(_rotate(wi, np.array([0.0, 0.0, 1.0]), -phi_h), np.array([0.0, 1.0, 0.0]),
                -theta_h)
    pd = np.arctan2(d[..., 1], d[..., 0])
    pd = np.where(pd < 0, pd + np.pi, pd)
    return (np.sqrt(theta_h / (np.pi / 2) * 8100), np.arccos(np.clip(d[..., 2], -1, 1))
            / (np.pi / 2) * 90, pd / np.pi * 180, np.hypot(d[..., 0], d[..., 1]))


def _adversarial_pairs(rng, n):
    """Pairs on or within rounding of bin boundaries: θ_h = (k/90)²·π/2, θ_d = k·π/180,
    φ_d = k·π/180 (k random, all three axes at once), each shifted by 0 or ±1e-16 ...
    ±1e-10 rad, at φ_h = 0, a multiple of π/2 or random; then pairs in the plane of
    incidence (d_y = ±0, φ_d = 0 or π), wi = wo (d = n) and normal incidence."""
    def shift(size):
        return rng.choice([0.0, 1e-16, 3e-16, 1e-15, 1e-13, 1e-10], size) * rng.choice(
            [-1.0, 1.0], size)

    th = (rng.integers(0, 91, n) / 90) ** 2 * (np.pi / 2) + np.abs(shift(n))
    td = rng.integers(0, 91, n) * (np.pi / 180) + np.abs(shift(n))
    pd = rng.integers(0, 181, n) * (np.pi / 180) + shift(n)
    wi, wo = half_diff_to_directions(th, td, pd)
    phi_h = np.where(rng.random(n) < 0.5, rng.integers(0, 4, n) * (np.pi / 2),
                     rng.random(n) * 2 * np.pi)
    c, s = np.cos(phi_h)[:, None], np.sin(phi_h)[:, None]

    def rot(w):
        return np.stack([w[:, 0] * c[:, 0] - w[:, 1] * s[:, 0],
                         w[:, 0] * s[:, 0] + w[:, 1] * c[:, 0], w[:, 2]], axis=-1)

    m = n // 10
    ti, to = rng.random(m) * (np.pi / 2), rng.random(m) * (np.pi / 2)
    po = np.where(rng.random(m) < 0.5, 0.0, np.pi)
    plane_i = np.stack([np.sin(ti), np.zeros(m), np.cos(ti)], -1)
    plane_o = np.stack([np.sin(to) * np.cos(po), np.zeros(m), np.cos(to)], -1)
    same = _random_pairs(rng, m)[0]
    normal = np.tile([0.0, 0.0, 1.0], (m, 1))
    return (np.concatenate([rot(wi), plane_i, same, normal, same]),
            np.concatenate([rot(wo), plane_o, same, same, normal]))


def test_fast_index_is_the_formula_index_on_1e7_pairs(rng):
    """The lookup's index without acos/atan2 (exact step tables + boundary side tests)
    against the acos/atan2 formulas, bit for bit: 1e7 random pairs, then 1e6 pairs on and
    within rounding of every kind of bin boundary, where a wrong table or margin shows."""
    for _ in range(5):
        # uniform on the hemisphere: normalised Gaussian triples, z made positive (faster
        # than _random_pairs' trigonometry for this many pairs)
        g = rng.standard_normal((2, 2_000_000, 3))
        g[..., 2] = np.abs(g[..., 2])
        g /= np.sqrt(np.einsum("...k,...k->...", g, g))[..., None]
        wi, wo = g
        np.testing.assert_array_equal(merl_indices(wi, wo),
                                      merl_indices(wi, wo, method="formula"))
    wi, wo = _adversarial_pairs(rng, 720_000)
    assert wi.shape[0] >= 1_000_000
    fast = merl_indices(wi, wo)
    formula = merl_indices(wi, wo, method="formula")
    np.testing.assert_array_equal(fast, formula)
    # tables switched off (as where acos would not step cleanly): the formulas, unchanged
    from brdfkit.data import _merl_index as mi

    Q = mi._index_tables().copy()
    Q[mi._Q_OK] = 0.0
    Q.flags.writeable = False  # the type the compiled loop has already seen
    out = np.empty(wi.shape[0], dtype=np.int64)
    mi._indices(wi, wo, Q, out)
    np.testing.assert_array_equal(out, formula)
    assert mi._index_tables()[mi._Q_OK] == 1.0  # this machine's acos steps cleanly
    # and against the reference written above (Rodrigues rotations): an axis's index may
    # differ only where the reference's coordinate is within rounding of a boundary, as
    # its formula's conditioning gives it. d carries an absolute error δ ≈ 1e-15 +
    # 1e-15/sin θ_h (acos near 1: h_z rounded by ~2 ulp moves θ_h by ~4e-16/sin θ_h rad,
    # which rotates d); θ_h and θ_d then move by ~δ rad (×57.3 bins/rad), φ_d by δ/sin θ_d
    # (undefined at θ_d = 0, wi = wo; sin θ_d from |(d_x, d_y)|, as acos near 1 would
    # overstate it). Plus 1e-9 bins for the rest. wi = −wo (h = 0: the reference divides
    # by 0) is left out.
    sub = slice(0, 300_000)
    with np.errstate(divide="ignore", invalid="ignore"):  # h = 0: NaN, left out below
        ref = reference_index(wi[sub], wo[sub])
        differ = fast[sub] != ref
        uh, ud, up, sd = _reference_coords(wi[sub][differ], wo[sub][differ])
    a, b = fast[sub][differ], ref[differ]
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = 1e-15 + 1e-15 / np.sin((uh / 90) ** 2 * (np.pi / 2))
        tol_theta = 1e-9 + 57.3 * delta
        tol_phi = 1e-9 + 57.3 * delta / sd
    defined = np.isfinite(uh)
    for u, axis, tol in ((uh, a // 16200 != b // 16200, tol_theta),
                         (ud, (a // 180) % 90 != (b // 180) % 90, tol_theta),
                         (up, a % 180 != b % 180, tol_phi)):
        axis &= defined
        assert np.all(np.abs(u - np.round(u))[axis] < tol[axis])


def test_nearest_eval_is_the_reference_lookup(merl_file, rng):
    t = read_binary(merl_file)
    m = MeasuredBRDF(t)
    wi, wo = _random_pairs(rng, 50_000)
    idx = reference_index(wi, wo)
    vals = t.raw.reshape(3, -1)[:, idx].T * np.array([1 / 1500, 1.15 / 1500, 1.66 / 1500])
    got = m.eval(wi, wo)
    assert got.shape == (50_000, 3)
    measured = (t.raw.reshape(3, -1)[:, idx] >= 0).T
    np.testing.assert_array_equal(got[measured], vals[measured])
    assert np.all(np.isnan(got[~measured]))  # unmeasured: NaN, never 0 or a clamp
    assert m.eval(wi * [1, 1, -1], wo).max() == 0.0  # below the horizon


def test_linear_lookup_reproduces_bin_centres(merl_file):
    # at a bin centre the trilinear weights are (1, 0, ...): the bin's own value
    t = read_binary(merl_file)
    m = MeasuredBRDF(t, lookup="linear")
    th, td, pd = bin_centres()
    ih, idd, ip = np.array([3, 20, 60, 85]), np.array([0, 10, 25, 2]), np.array([0, 17, 90, 179])
    assert np.all(th[ih] + td[idd] < np.pi / 2)  # both directions above the horizon
    wi, wo = half_diff_to_directions(th[ih], td[idd], pd[ip])
    got = m.eval(wi, wo)
    want = t.values[:, ih, idd, ip].T
    np.testing.assert_allclose(got, want, rtol=1e-9)


def test_linear_is_continuous_and_skips_unmeasured(merl_file):
    t = read_binary(merl_file)
    m = MeasuredBRDF(t, lookup="linear")
    th, td, pd = bin_centres()
    # theta_h bin 5 has theta_d >= 80 unmeasured: interpolation uses the measured neighbours
    wi, wo = half_diff_to_directions(th[5], td[85], pd[30])
    v = m.eval(wi, wo)
    assert np.all(np.isfinite(v))
    # halfway between two theta_d centres (measured): the mean of the two bins
    wi, wo = half_diff_to_directions(th[40], 0.5 * (td[20] + td[21]), pd[30])
    np.testing.assert_allclose(m.eval(wi, wo), 0.5 * (t.values[:, 40, 20, 30]
                                                      + t.values[:, 40, 21, 30]), rtol=1e-9)


def test_reciprocity_of_the_lookup(merl_file, rng):
    m = MeasuredBRDF(read_binary(merl_file))
    wi, wo = _random_pairs(rng, 20_000)
    a, b = m.eval(wi, wo), m.eval(wo, wi)
    ok = np.isfinite(a) & np.isfinite(b)
    # the phi_d fold maps (wo, wi) to the same bin except within rounding of a bin boundary
    assert np.mean(a[ok] == b[ok]) > 0.999


def test_tabulated_model_round_trip(tmp_path):
    # a model of our own tabulated, written, read and looked up: at bin centres the
    # nearest lookup returns the model's value there (to the 1-ulp scale round trip)
    model = brdfkit.model("modified-phong", rho_d=[0.1, 0.2, 0.3], rho_s=0.5, n=20)
    t = table_from_function(model.eval, source="modified-phong")
    write_binary(tmp_path / "phong.binary", t)
    m = MeasuredBRDF(read_binary(tmp_path / "phong.binary"))
    th, td, pd = bin_centres()
    wi, wo = half_diff_to_directions(th[[2, 30, 60]], td[[5, 30, 60]], pd[[10, 90, 150]])
    np.testing.assert_allclose(m.eval(wi, wo), model.eval(wi, wo), rtol=1e-12)
    assert not t.valid[:, 89, 89, 0].any()  # both directions below the horizon: unmeasured


def test_measured_model_is_a_model(merl_file):
    from brdfkit.analysis import albedo

    m = MeasuredBRDF(read_binary(merl_file), lookup="linear")
    assert m.to_dict() == {"model": m.name, "params": {"lookup": "linear"}}
    assert m.with_params(lookup="nearest").to_dict()["params"] == {"lookup": "nearest"}
    with pytest.raises(BrdfkitError, match="lookup"):
        m.with_params(lookup="cubic")
    r = albedo(m, [0.0, 0.5])
    assert r.albedo.shape == (2, 3)
    assert np.all(np.isfinite(r.albedo) | (r.status[:, None] == 3))


def test_from_values_rejects_nan():
    with pytest.raises(BrdfkitError, match="finite"):
        MerlTable.from_values(np.full((3, *SHAPE), np.nan))


def test_blocked_drivers_equal_the_per_channel_kernel(merl_file, rng):
    """The blocked 3-channel drivers (bins found, then read) against the per-channel kernel
    that the engines use (one planar row per channel), called pair by pair: the same
    values bit for bit, NaN and 0 included, on random pairs with some below the horizon
    and an unmeasured region."""
    t = read_binary(merl_file)
    wi, wo = _random_pairs(rng, 1000)
    wi[::7, 2] *= -1.0  # below the horizon
    wi[::5], wo[::5] = half_diff_to_directions(bin_centres()[0][5], np.radians(85.0),
                                               rng.random(200) * np.pi)  # unmeasured bins
    for lookup in ("nearest", "linear"):
        m = MeasuredBRDF(t, lookup=lookup)
        want = np.array([[m.kernel(*a, *b, m.packed[c]) for c in range(3)]
                         for a, b in zip(wi, wo, strict=True)])
        assert (want == 0).any()  # below the horizon
        # unmeasured: NaN (nearest); linear interpolates from the measured θ_h neighbours
        assert np.isnan(want).any() == (lookup == "nearest")
        np.testing.assert_array_equal(m.eval(wi, wo), want)


def test_bin_centre_pairs_are_half_diff_to_directions():
    """table_from_function's compiled bin-centre pairs: bit for bit the NumPy
    half_diff_to_directions at the bin_centres grid (the documented convention)."""
    from brdfkit.data.merl import _centre_pairs

    th, td, pd = bin_centres()
    wi, wo = half_diff_to_directions(*np.meshgrid(th, td, pd, indexing="ij"))
    wi, wo = wi.reshape(-1, 3), wo.reshape(-1, 3)
    up = (wi[:, 2] > 0) & (wo[:, 2] > 0)
    a, b, u = np.empty((N_BINS, 3)), np.empty((N_BINS, 3)), np.empty(N_BINS, dtype=bool)
    m = _centre_pairs(np.sin(th), np.cos(th), np.sin(td), np.cos(td), np.sin(pd),
                      np.cos(pd), a, b, u)
    np.testing.assert_array_equal(u, up)
    assert m == up.sum() == 1_096_216
    np.testing.assert_array_equal(a[:m], wi[up])
    np.testing.assert_array_equal(b[:m], wo[up])
