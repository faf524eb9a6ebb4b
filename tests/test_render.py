"""Rendering (issue 11 §1–2): Lewis's sphere test configuration, its files, CLI and figures.

Every reference value is computed here, independently of brdfkit.render: pixel centres and
normals from the issue's formulas, radiance from closed forms (Lambert; Phong written in
the world frame with R = 2(N·L)N − L, so the renderer's per-pixel tangent frames are
checked too), ρ(V) of a non-reciprocal model by SciPy's dblquad over the light directions,
the sRGB transfer function from IEC 61966-2-1, the PNG decoded by Pillow and the EXR parsed
by a reader written below from the OpenEXR file layout.
"""

from __future__ import annotations

import json
import math
import struct

import numpy as np
import pytest
from click.testing import CliRunner

import brdfkit
from brdfkit.analysis import albedo
from brdfkit.cli import main
from brdfkit.errors import BrdfkitError, ParameterError
from brdfkit.models import DerivedBRDF
from brdfkit.render import (
    exposure_phi0,
    render_sphere,
    save_render,
    sphere_geometry,
    to_srgb8,
    transposed,
    write_exr,
)


def _normals(S):
    """Pixel centres and normals from the issue's formulas (row r, column c)."""
    r, c = np.meshgrid(np.arange(S), np.arange(S), indexing="ij")
    x = (c + 0.5) / S * 2 - 1
    y = 1 - (r + 0.5) / S * 2
    inside = x ** 2 + y ** 2 < 1
    z = np.sqrt(np.where(inside, 1 - x ** 2 - y ** 2, 0.0))
    return np.stack([x, y, z], axis=-1), inside


def test_geometry_pixel_centres_and_disc():
    g = sphere_geometry(4)
    # S = 4: centres at ±0.25, ±0.75; the corner pixels (0.75² + 0.75² > 1) lie outside
    assert np.allclose(g["x"], [-0.75, -0.25, 0.25, 0.75])
    assert np.allclose(g["y"], [0.75, 0.25, -0.25, -0.75])
    assert g["mask"].sum() == 12 and not g["mask"][0, 0] and g["mask"][0, 1]
    N, inside = _normals(4)
    assert np.array_equal(g["mask"], inside)
    assert np.allclose(g["normal"], np.where(inside[..., None], N, 0.0))


def test_lambert_sphere_closed_form():
    # E·ρ/π·max(N·L, 0) + L_a·ρ (the albedo of Lambert is ρ at every angle)
    S, phi, E, L_a, rho = 17, math.radians(40.0), 2.0, 0.3, 0.6
    r = render_sphere(brdfkit.model("lambert", rho_d=rho), phi_l=phi, ambient=L_a,
                      irradiance=E, size=S, antialias=1)
    N, inside = _normals(S)
    L = np.array([math.sin(phi), 0.0, math.cos(phi)])
    expect = np.where(inside, E * rho / math.pi * np.maximum(N @ L, 0.0) + L_a * rho, 0.0)
    assert r.radiance.shape == (S, S, 1)
    assert np.allclose(r.radiance[..., 0], expect, rtol=0, atol=1e-6)
    assert r.success and r.ambient_error < 1e-6


class _NumpyLambert(DerivedBRDF):
    """Lambert evaluated in NumPy (kernel None): the renderer's fallback path."""

    def __init__(self, rho):
        super().__init__(name="numpy-lambert", params=(), values={}, reciprocal=True)
        self.rho = rho

    def eval(self, wi, wo):
        wi, wo = np.asarray(wi), np.asarray(wo)
        return np.where((wi[..., 2] > 0) & (wo[..., 2] > 0), self.rho / math.pi, 0.0)


def test_model_without_kernel_closed_form():
    S, phi = 9, math.radians(100.0)
    r = render_sphere(_NumpyLambert(0.5), phi_l=phi, size=S, antialias=1)
    N, inside = _normals(S)
    L = np.array([math.sin(phi), 0.0, math.cos(phi)])
    assert np.allclose(r.radiance[..., 0], np.where(inside, 0.5 / math.pi
                                                    * np.maximum(N @ L, 0.0), 0.0), atol=1e-14)


def test_phong_pixels_by_hand_in_the_world_frame():
    # Lewis eq. (8) with F_s^P (eq. 5): f = k_d + k_s max(R·V, 0)^n/(N·L), R = 2(N·L)N − L,
    # evaluated with world vectors (no tangent frame), coloured k_d
    S, phi, E = 12, math.radians(50.0), 1.5
    k_d, k_s, n = np.array([0.1, 0.2, 0.3]), 0.8, 7.0
    m = brdfkit.model("phong", k_d=k_d.tolist(), k_s=k_s, n=n)
    r = render_sphere(m, phi_l=phi, irradiance=E, size=S, antialias=1)
    N, inside = _normals(S)
    L = np.array([math.sin(phi), 0.0, math.cos(phi)])
    V = np.array([0.0, 0.0, 1.0])
    for row, col in [(3, 8), (6, 6), (2, 4), (9, 10), (5, 1)]:
        nv = N[row, col]
        nl = nv @ L
        R = 2 * nl * nv - L
        f = k_d + k_s * max(R @ V, 0.0) ** n / nl if nl > 0 else 0 * k_d
        assert inside[row, col]
        assert np.allclose(r.radiance[row, col], E * f * max(nl, 0.0), rtol=1e-12, atol=1e-15)


def test_transposed_model_pixels_by_hand():
    # a derived model (brdfkit.render.transposed: the compiled kernel with its directions
    # exchanged) rendered like any model: E·f(V, L)·max(N·L, 0) with Lewis's Phong
    # f(S, V) = k_d + k_s max(R_S·V, 0)^n/(N·S), so f(V, L) = k_d + k_s max(R_V·L, 0)^n/(N·V)
    k_d, k_s, n = 0.05, 0.9, 12.0
    m = transposed(brdfkit.model("phong", k_d=k_d, k_s=k_s, n=n))
    assert m.name == "phong^T" and not m.reciprocal
    S, phi = 10, math.radians(70.0)
    r = render_sphere(m, phi_l=phi, size=S, antialias=1)
    N, _ = _normals(S)
    L = np.array([math.sin(phi), 0.0, math.cos(phi)])
    V = np.array([0.0, 0.0, 1.0])
    for row, col in [(4, 6), (2, 7), (7, 8), (5, 5)]:
        nv = N[row, col]
        R_V = 2 * (nv @ V) * nv - V
        f = k_d + k_s * max(R_V @ L, 0.0) ** n / (nv @ V)
        assert r.radiance[row, col, 0] == pytest.approx(f * max(nv @ L, 0.0), rel=1e-12)


def test_ambient_of_a_non_reciprocal_model_integrates_over_the_light():
    # ρ(V) = ∫ f(L', V) cos θ_L' dω_L' for Lewis's Phong (k_d = 0): k_s ∫ max(R_L'·V, 0)^n dω_L'.
    # At θ_V = 0 (centre pixel of an odd image) it is 2π/(n + 1) (Lewis eq. 16), while the
    # albedo a(0) = H_s/(N·S) = 2π/(n + 2) (eq. 19): the two integrals differ.
    from scipy.integrate import dblquad

    k_s, n, L_a, S = 1.0, 2.0, 1.0, 15
    m = brdfkit.model("phong", k_d=0.0, k_s=k_s, n=n)
    r = render_sphere(m, phi_l=0.0, ambient=L_a, irradiance=0.0, size=S, antialias=1)
    c = S // 2
    assert r.radiance[c, c, 0] == pytest.approx(2 * math.pi / (n + 1), abs=1e-6)
    # a pixel at θ_V ≈ 60° against SciPy's dblquad over the light hemisphere
    N, _ = _normals(S)
    row, col = c, 1
    theta_v = math.acos(N[row, col, 2])

    def integrand(t, p):  # L' at (t, p) in the pixel's local frame, V at θ_V, azimuth 0
        lx, lz = math.sin(t) * math.cos(p), math.cos(t)  # V has no y component
        vx, vz = math.sin(theta_v), math.cos(theta_v)
        rv = 2 * lz * vz - (lx * vx + lz * vz)  # R_L'·V with R_L' = 2(N·L')N − L'
        return k_s * max(rv, 0.0) ** n * math.sin(t)  # f·cos θ_L' = k_s (R·V)^n

    rho, _ = dblquad(integrand, 0, 2 * math.pi, 0, math.pi / 2, epsabs=1e-10)
    assert r.radiance[row, col, 0] == pytest.approx(L_a * rho, abs=2e-6)


def test_ambient_matches_the_albedo_engine_at_the_pixel_angles():
    # reciprocal model: L_a·a(θ_V), a computed by the engine directly at each pixel's angle
    m = brdfkit.model("modified-phong", rho_d=0.2, rho_s=0.6, n=200)
    S, L_a = 24, 0.7
    r = render_sphere(m, phi_l=0.3, ambient=L_a, irradiance=0.0, size=S, antialias=1)
    N, inside = _normals(S)
    theta = np.arccos(N[inside][:, 2])
    pick = np.argsort(theta)[:: max(1, theta.size // 25)]  # ~25 angles incl. near grazing
    a = albedo(m, theta[pick]).albedo
    got = r.radiance[..., 0][inside][pick]
    assert np.max(np.abs(got - L_a * a)) <= max(r.ambient_error, 1e-9) + 1e-7
    assert r.ambient_error < 1e-6 * L_a * 1.5


def test_exposure_phi0_and_srgb():
    # odd S: the centre pixel has N = V = L at Φ_L = 0, so the Lambert peak is E·ρ/π
    m = brdfkit.model("lambert", rho_d=0.5)
    assert exposure_phi0(m, size=9) == pytest.approx(math.pi / 0.5, rel=1e-12)
    # IEC 61966-2-1: sRGB(0.5) = 1.055·0.5^(1/2.4) − 0.055 = 0.7354 → 188; 0.002 → 12.92·0.002
    img = to_srgb8(np.array([[[0.25], [1.0e-3], [4.0]]]), 2.0)
    assert img[0, :, 0].tolist() == [188, round(255 * 12.92 * 0.002), 255]


def _read_exr(data: bytes):
    """A minimal reader written from the OpenEXR file layout (independent of the writer)."""
    magic, version = struct.unpack_from("<ii", data, 0)
    assert magic == 20000630 and version & 0xFF == 2
    pos, attrs = 8, {}
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        end2 = data.index(b"\0", end + 1)
        typ = data[end + 1:end2].decode()
        (size,) = struct.unpack_from("<i", data, end2 + 1)
        attrs[name] = (typ, data[end2 + 5:end2 + 5 + size])
        pos = end2 + 5 + size
    pos += 1
    chans, raw = [], attrs["channels"][1]
    p = 0
    while raw[p] != 0:
        end = raw.index(b"\0", p)
        pixel_type, _, xs, ys = struct.unpack_from("<iB3xii", raw, end + 1)
        chans.append((raw[p:end].decode(), pixel_type, xs, ys))
        p = end + 17
    xmin, ymin, xmax, ymax = struct.unpack("<iiii", attrs["dataWindow"][1])
    w, h = xmax - xmin + 1, ymax - ymin + 1
    offsets = struct.unpack_from(f"<{h}Q", data, pos)
    img = np.empty((h, w, len(chans)), dtype=np.float32)
    for off in offsets:
        y, size = struct.unpack_from("<ii", data, off)
        assert size == w * len(chans) * 4
        line = np.frombuffer(data, dtype="<f4", count=w * len(chans), offset=off + 8)
        img[y] = line.reshape(len(chans), w).T
    return attrs, chans, img


def test_exr_npy_png_round_trips(tmp_path, rng):
    rad = rng.random((5, 7, 3)) * 3.0
    write_exr(tmp_path / "a.exr", rad)
    attrs, chans, img = _read_exr((tmp_path / "a.exr").read_bytes())
    assert [c[0] for c in chans] == ["B", "G", "R"] and all(c[1:] == (2, 1, 1) for c in chans)
    assert attrs["compression"][1] == b"\0" and attrs["lineOrder"][1] == b"\0"
    for k in ("displayWindow", "pixelAspectRatio", "screenWindowCenter", "screenWindowWidth"):
        assert k in attrs
    assert np.array_equal(img[..., ::-1], rad.astype(np.float32))  # stored B, G, R

    from PIL import Image

    r = render_sphere(brdfkit.model("lambert", rho_d=[0.2, 0.5, 0.8]), phi_l=0.4, size=16)
    for ext in ("npy", "exr", "png"):
        save_render(r, tmp_path / f"s.{ext}", exposure=2.0)
    assert np.array_equal(np.load(tmp_path / "s.npy"), r.radiance)
    assert np.array_equal(_read_exr((tmp_path / "s.exr").read_bytes())[2][..., ::-1],
                          r.radiance.astype(np.float32))
    with Image.open(tmp_path / "s.png") as im:
        assert im.mode == "RGB" and im.size == (16, 16)
        assert np.array_equal(np.asarray(im), to_srgb8(r.radiance, 2.0))
        meta = json.loads(im.info["brdfkit"])
    assert meta["exposure"] == 2.0 and meta["model"]["model"] == "lambert"
    # the EXR carries the render's metadata too (issue 20: it had none), as a string attribute
    typ, raw = _read_exr((tmp_path / "s.exr").read_bytes())[0]["brdfkit"]
    exr_meta = json.loads(raw.decode())
    assert typ == "string" and exr_meta["model"] == r.metadata()["model"]
    assert exr_meta["phi_l_deg"] == pytest.approx(math.degrees(0.4))
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".brdfkit-")]


def test_input_errors():
    m = brdfkit.model("lambert")
    for kwargs, text in [({"phi_l": 4.0}, "phi_l"), ({"phi_l": 0.1, "size": 0}, "size"),
                         ({"phi_l": 0.1, "ambient": -1}, "ambient"),
                         ({"phi_l": 0.1, "engine": "path"}, "engine must be one of"),
                         ({"phi_l": 0.1, "spp": 16}, "takes no samples"),
                         ({"phi_l": 0.1, "engine": "mitsuba", "light_azimuth": 1.0},
                          "light_azimuth")]:
        with pytest.raises(BrdfkitError, match=text):
            render_sphere(m, **kwargs)
    with pytest.raises(BrdfkitError, match="brdfkit.model"):
        render_sphere("lambert", phi_l=0.0)
    r = render_sphere(brdfkit.model("lambert", rho_d=[0.1, 0.2, 0.3, 0.4]), phi_l=0, size=4)
    with pytest.raises(BrdfkitError, match="PNG holds 1"):
        save_render(r, "x.png", exposure=1.0)


def test_cli_render_sphere(tmp_path):
    out = tmp_path / "s.npy"
    res = CliRunner().invoke(main, ["render", "sphere", "phong", "-p", "k_d=0.3", "-p", "n=10",
                                    "--phi-l", "30", "--ambient", "0.2", "--size", "12",
                                    "--out", str(out), "--json"])
    assert res.exit_code == 0, res.output
    m = brdfkit.model("phong", k_d=0.3, n=10)
    ref = render_sphere(m, phi_l=math.radians(30), ambient=0.2, size=12)
    assert np.array_equal(np.load(out), ref.radiance)
    assert json.loads(res.output)["phi_l_deg"] == pytest.approx(30.0)
    png = tmp_path / "s.png"
    res = CliRunner().invoke(main, ["render", "sphere", "lambert", "--phi-l", "0", "--size", "9",
                                    "--out", str(png)])
    assert res.exit_code == 0, res.output
    from PIL import Image

    with Image.open(png) as im:
        assert np.asarray(im).max() == 255  # phi0 exposure: the Φ_L = 0 peak is just white
    for args, text in [(["--engine", "mitsuba", "--phi-l", "120"], "front hemisphere"),
                       (["--engine", "mitsuba", "--spp", "0"], "--spp must be"),
                       (["--phi-l", "200"], "[0, 180]"),
                       (["--spp", "16"], "takes no samples"),
                       (["--exposure", "-1"], "--exposure"),
                       (["--out", str(tmp_path / "x.jpg")], ".png or .exr or .npy")]:
        argv = ["render", "sphere", "lambert", "--phi-l", "10", "--out", str(png), *args]
        res = CliRunner().invoke(main, argv)
        assert res.exit_code == 2 and text in res.output, res.output
        assert res.output.count("\n") == 1


def test_lewis_sphere_figures(monkeypatch):
    from brdfkit.figures import FIGURES, lewis_spheres

    assert {"lewis-fig3", "lewis-fig4", "lewis-fig6", "lewis-fig10"} <= set(FIGURES)
    monkeypatch.setattr(lewis_spheres, "SIZE", 15)
    fig = FIGURES["lewis-fig4"]()
    assert len(fig.axes) == 6 * 3
    imgs = [ax.get_images()[0].get_array() for ax in fig.axes]
    # one exposure: the brightest Φ_L = 0 sphere (column 0) is just white, none brighter
    assert max(np.max(imgs[i]) for i in range(0, 18, 3)) == 255
    assert any("Lewis (1993) Fig. 4" in t.get_text() for t in fig.texts)


def test_light_azimuth_rotates_the_image():
    """Identity: for an isotropic model, lighting from azimuth ψ = π/2 (image up) is the
    ψ = 0 image turned a quarter turn counter-clockwise (the pixel grid maps onto itself)."""
    import math

    from brdfkit.render import render_sphere

    m = brdfkit.model("modified-phong", n=50)
    a = render_sphere(m, phi_l=0.6, size=32).radiance[..., 0]
    b = render_sphere(m, phi_l=0.6, light_azimuth=math.pi / 2, size=32).radiance[..., 0]
    np.testing.assert_allclose(b, np.rot90(a), atol=1e-12 * a.max())
    with pytest.raises(brdfkit.ParameterError, match="light_azimuth"):
        render_sphere(m, phi_l=0.6, light_azimuth=float("nan"), size=4)


def test_antialiased_rim_area_is_the_discs_and_centres_are_unchanged():
    # Ambient light only on a Lambertian sphere: the radiance is L_a·ρ wherever the sphere
    # is (its albedo, a closed form), so Σ pixels × pixel area = L_a·ρ × the disc's area
    # π (the image spans [−1, 1]²). The centre-only image gets the area wrong by its
    # staircase; the anti-aliased one within the midpoint rule's coverage error.
    S, L_a, rho = 48, 1.0, 0.5
    m = brdfkit.model("lambert", rho_d=rho)
    pix = (2.0 / S) ** 2
    aa = render_sphere(m, phi_l=0.0, ambient=L_a, irradiance=0.0, size=S, antialias=8)
    flat = render_sphere(m, phi_l=0.0, ambient=L_a, irradiance=0.0, size=S, antialias=1)
    area = math.pi * L_a * rho
    err_aa = abs(aa.radiance.sum() * pix - area) / area
    err_flat = abs(flat.radiance.sum() * pix - area) / area
    assert err_aa < 2e-3 and err_aa < err_flat / 3, (err_aa, err_flat)
    # every rim pixel holds a share of L_a·ρ in [0, L_a·ρ]; pixels away from the rim are
    # the exact centre values of the flat render
    r = aa.radiance[..., 0]
    assert np.all(r >= 0.0) and np.all(r <= L_a * rho * (1 + 1e-12))
    c = (np.arange(S) + 0.5) / S * 2 - 1
    rad = np.hypot(c[None, :], c[:, None])
    away = np.abs(rad - 1.0) > math.sqrt(2.0) / S
    np.testing.assert_array_equal(r[away], flat.radiance[..., 0][away])
    assert 0 < np.count_nonzero((r > 0) & (r < L_a * rho * (1 - 1e-9)))  # partial pixels
    with pytest.raises(ParameterError, match="antialias must be an integer from 1 to 16"):
        render_sphere(m, phi_l=0.0, size=8, antialias=0)


def test_terminator_pixels_are_those_the_line_n_dot_l_0_crosses():
    # L = +x: the terminator is the line x = 0 (N·L = N_x); for S = 8 it is the edge
    # between columns 3 and 4, so N·L > 0 holds at some corners of the column-4 pixels
    # and not at those on x = 0: exactly column 4 (8 rows) is crossed (by construction).
    from brdfkit.render.silhouette import terminator_pixels

    idx = terminator_pixels(8, (1.0, 0.0, 0.0))
    rows, cols = np.divmod(idx, 8)
    assert set(cols.tolist()) == {4} and sorted(rows.tolist()) == list(range(8))
    # L = +z (behind the viewer): N·L = N_z > 0 on the whole disc, no terminator
    assert terminator_pixels(8, (0.0, 0.0, 1.0)).size == 0


def test_exr_metadata_is_read_by_openexr(tmp_path):
    # a second reader: Mitsuba's Bitmap (the OpenEXR library) reads the string attribute
    mi = pytest.importorskip("mitsuba")
    r = render_sphere(brdfkit.model("lambert", rho_d=0.3), phi_l=0.2, size=8)
    save_render(r, tmp_path / "m.exr")
    old = mi.variant()  # restored after: other tests of this process keep theirs
    mi.set_variant("scalar_rgb")
    try:
        meta = json.loads(mi.Bitmap(str(tmp_path / "m.exr")).metadata()["brdfkit"])
    finally:
        if old is not None:
            mi.set_variant(old)
    assert meta["model"] == {"model": "lambert", "params": {"rho_d": 0.3}}
    assert meta["size"] == 8 and meta["engine"] == "direct"
