"""
Writing renders: linear NPY and OpenEXR, sRGB PNG with a stated exposure
========================================================================

- ``.npy`` — the linear radiance array (S, S, C), float64, as NumPy saves it.
- ``.exr`` — OpenEXR 2.0, single-part scanline, uncompressed, 32-bit FLOAT
  channels (``R``, ``G``, ``B`` for 3 channels, ``Y`` for 1, ``C0`` … otherwise),
  linear radiance. Written here (no OpenEXR package is needed): magic and
  version, the eight required header attributes, the offset table and one
  scanline per chunk, as the OpenEXR file layout specifies. The render's
  metadata (as the PNG's) is a ``string`` attribute ``brdfkit`` (JSON).
- ``.png`` — 8-bit sRGB (grey for 1 channel, RGB for 3): the displayed value
  is sRGB(min(1, k·L)) with the exposure k (see :func:`apply_exposure`), the
  IEC 61966-2-1 transfer function, rounded to the nearest of 0 … 255. The
  exposure, the rule that chose it and the render's metadata go into a
  ``tEXt`` chunk (keyword ``brdfkit``, JSON).

Every file is written atomically (:func:`brdfkit._io.write_atomic`).

Public objects
--------------
- :func:`save_render` — write a :class:`~brdfkit.render.sphere.SphereRender`
  (format from the suffix).
- :func:`write_npy`, :func:`write_exr`, :func:`write_png`.
- :func:`srgb_encode`, :func:`to_srgb8`.
- :data:`SUFFIXES`.

References
----------
- OpenEXR file layout, https://openexr.com/en/latest/OpenEXRFileLayout.html
- PNG (Third Edition) §5, §11 (IHDR, IDAT, tEXt, IEND).
- IEC 61966-2-1:1999 (sRGB transfer function).
"""

from __future__ import annotations

import json
import struct
import zlib

import numpy as np

from brdfkit import _io
from brdfkit.errors import BrdfkitError, ParameterError

__all__ = ["SUFFIXES", "save_render", "save_panels", "panels", "panel_gap", "write_radiance",
           "write_npy", "write_exr", "write_png", "srgb_encode", "to_srgb8",
           "exr_channel_names"]

#: Output formats, chosen by the file's suffix.
SUFFIXES = (".png", ".exr", ".npy")

_EXR_MAGIC = 20000630  # 0x762f3101
_EXR_VERSION = 2  # single-part scanline file, no flags
_EXR_FLOAT = 2  # pixel type FLOAT (32-bit IEEE)
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def srgb_encode(linear) -> np.ndarray:
    """IEC 61966-2-1 transfer function: linear [0, 1] → encoded [0, 1] (clamped to [0, 1])."""
    v = np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)  # displays show [0, 1]
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1.0 / 2.4) - 0.055)


def to_srgb8(radiance, exposure: float) -> np.ndarray:
    """uint8 sRGB of ``exposure · radiance``, shape (S, S, C) for C in (1, 3)."""
    k = _check_exposure(exposure)
    rad = _check_image(radiance, png=True)
    return np.rint(255.0 * srgb_encode(k * rad)).astype(np.uint8)


def _check_exposure(exposure) -> float:
    try:
        k = float(exposure)
    except (TypeError, ValueError):
        k = float("nan")
    if not (k > 0.0 and np.isfinite(k)):
        raise ParameterError(f"exposure must be a finite number > 0 (the factor from radiance "
                             f"to display value); got {exposure!r}")
    return k


def _check_image(radiance, *, png: bool = False) -> np.ndarray:
    rad = np.asarray(radiance, dtype=np.float64)
    if rad.ndim != 3 or rad.shape[0] < 1 or rad.shape[1] < 1 or rad.shape[2] < 1:
        raise BrdfkitError(f"radiance must be an array of shape (rows, columns, channels); got "
                           f"shape {rad.shape}")
    if png and rad.shape[2] not in (1, 3):
        raise BrdfkitError(f"a PNG holds 1 (grey) or 3 (RGB) channels; this render has "
                           f"{rad.shape[2]}: write .exr or .npy instead")
    return rad


def exr_channel_names(n_channels: int) -> list[str]:
    """The EXR channel names in channel order: Y; R, G, B; or C0, C1, …"""
    if n_channels == 1:
        return ["Y"]
    if n_channels == 3:
        return ["R", "G", "B"]
    return [f"C{i}" for i in range(n_channels)]


def _attr(name: str, type_name: str, value: bytes) -> bytes:
    return (name.encode() + b"\0" + type_name.encode() + b"\0" + struct.pack("<i", len(value))
            + value)


def exr_bytes(radiance, metadata: str | None = None) -> bytes:
    """An uncompressed scanline OpenEXR file of *radiance* (S_rows, S_cols, C), FLOAT; with
    *metadata*, a ``string`` attribute ``brdfkit`` holding it (UTF-8)."""
    rad = _check_image(radiance)
    height, width, C = rad.shape
    names = exr_channel_names(C)
    order = sorted(range(C), key=lambda i: names[i])  # channels are stored sorted by name
    chlist = b"".join(names[i].encode() + b"\0" + struct.pack("<iB3xii", _EXR_FLOAT, 0, 1, 1)
                      for i in order) + b"\0"
    box = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = (struct.pack("<ii", _EXR_MAGIC, _EXR_VERSION)
              + _attr("channels", "chlist", chlist)
              + _attr("compression", "compression", b"\0")  # NO_COMPRESSION
              + _attr("dataWindow", "box2i", box)
              + _attr("displayWindow", "box2i", box)
              + _attr("lineOrder", "lineOrder", b"\0")  # INCREASING_Y
              + _attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + _attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
              + _attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
              + (b"" if metadata is None else _attr("brdfkit", "string", metadata.encode()))
              + b"\0")
    line_bytes = width * C * 4
    chunk = 8 + line_bytes  # y, data size, then the data
    start = len(header) + 8 * height
    offsets = struct.pack(f"<{height}Q", *(start + k * chunk for k in range(height)))
    # (rows, C sorted, width) little-endian float32: each scanline holds channel after channel
    data = np.ascontiguousarray(rad[:, :, order].transpose(0, 2, 1), dtype="<f4")
    body = bytearray()
    for y in range(height):
        body += struct.pack("<ii", y, line_bytes)
        body += data[y].tobytes()
    return header + offsets + bytes(body)


def _png_chunk(kind: bytes, data: bytes) -> bytes:
    return (struct.pack(">I", len(data)) + kind + data
            + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))


def png_bytes(srgb8: np.ndarray, text: str | None = None) -> bytes:
    """A PNG file of uint8 (rows, cols, 1 | 3): grey or RGB, 8 bits, filter 0 on every row."""
    img = np.asarray(srgb8)
    if img.dtype != np.uint8 or img.ndim != 3 or img.shape[2] not in (1, 3):
        raise BrdfkitError(f"png_bytes needs uint8 (rows, cols, 1 or 3); got {img.dtype} "
                           f"{img.shape}")
    height, width, C = img.shape
    colour_type = 0 if C == 1 else 2  # grey, truecolour
    ihdr = struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)
    rows = np.concatenate([np.zeros((height, 1), np.uint8), img.reshape(height, width * C)],
                          axis=1)  # filter type 0 (None) before each row
    out = _PNG_SIGNATURE + _png_chunk(b"IHDR", ihdr)
    if text is not None:
        out += _png_chunk(b"tEXt", b"brdfkit\0" + text.encode("latin-1", "replace"))
    out += _png_chunk(b"IDAT", zlib.compress(rows.tobytes(), 6))
    return out + _png_chunk(b"IEND", b"")


def write_npy(path, radiance, *, option: str = "path") -> str:
    """Save *radiance* as ``.npy`` (float64), atomically."""
    rad = _check_image(radiance)
    _io.check_output_path(path, option=option, suffixes=(".npy",))
    return _io.write_atomic(path, lambda fh: np.save(fh, rad), option=option)


#: Largest value an EXR FLOAT channel (IEEE 32-bit) holds; larger radiance would be
#: written as inf.
EXR_MAX = float(np.finfo(np.float32).max)


def write_exr(path, radiance, *, metadata: dict | None = None, option: str = "path") -> str:
    """Save *radiance* as an uncompressed FLOAT OpenEXR file, atomically; *metadata*
    (JSON-ready) goes into a ``string`` attribute ``brdfkit``.

    Raises
    ------
    BrdfkitError
        A value is not finite or beyond :data:`EXR_MAX` (it would be written as inf).
    """
    _io.check_output_path(path, option=option, suffixes=(".exr",))
    values = np.asarray(radiance, dtype=np.float64)
    peak = float(np.max(np.abs(values))) if values.size else 0.0
    if not peak <= EXR_MAX:  # also NaN/inf
        raise BrdfkitError(
            f"{option} {path}: the radiance reaches {peak:.6g}, beyond the largest value of "
            f"an EXR 32-bit float channel ({EXR_MAX:.6g}; it would be written as inf); lower "
            "the light (irradiance/ambient) or write .npy (float64)")
    text = None if metadata is None else json.dumps(metadata, sort_keys=True, default=str)
    data = exr_bytes(radiance, text)
    return _io.write_atomic(path, lambda fh: fh.write(data), option=option)


def write_png(path, radiance, *, exposure: float, metadata: dict | None = None,
              option: str = "path") -> str:
    """Save sRGB(min(1, exposure·radiance)) as an 8-bit PNG, atomically.

    *metadata* (JSON-ready) goes into a ``tEXt`` chunk with keyword ``brdfkit``.
    """
    _io.check_output_path(path, option=option, suffixes=(".png",))
    img = to_srgb8(radiance, exposure)
    text = None if metadata is None else json.dumps(metadata, sort_keys=True, default=str)
    data = png_bytes(img, text)
    return _io.write_atomic(path, lambda fh: fh.write(data), option=option)


def save_render(render, path, *, exposure: float | None = None, exposure_rule: str = "",
                option: str = "path") -> str:
    """Write a render to *path*: ``.npy``/``.exr`` linear radiance, ``.png`` sRGB.

    Parameters
    ----------
    render : SphereRender
    path : str or os.PathLike
        The suffix chooses the format (:data:`SUFFIXES`).
    exposure : float, keyword-only
        PNG only: the factor k of the displayed value sRGB(min(1, k·L)).
        None: 1/peak of this image (its brightest pixel just unsaturated).
        Ignored for the linear formats.
    exposure_rule : str, keyword-only
        How *exposure* was chosen, recorded in the PNG's metadata (the EXR's records
        the render's metadata without an exposure).
    option : str, keyword-only
        How the caller names *path* in errors (the CLI passes ``"--out"``).
    """
    return write_radiance(path, render.radiance, exposure=exposure, metadata=render.metadata(),
                          exposure_rule=exposure_rule, option=option)


def write_radiance(path, radiance, *, exposure: float | None = None, metadata: dict,
                   exposure_rule: str = "", option: str = "path") -> str:
    """Write linear *radiance* (rows, cols, C) to *path*, the format from its suffix:
    ``.npy``; ``.exr`` with *metadata* as an attribute; ``.png`` at *exposure* (None: 1/peak,
    the brightest pixel just unsaturated) with *metadata*, the exposure and *exposure_rule*
    in its tEXt chunk."""
    p = _io.check_output_path(path, option=option, suffixes=SUFFIXES)
    suffix = p.lower().rsplit(".", 1)[-1]
    if suffix == "npy":
        return write_npy(p, radiance, option=option)
    if suffix == "exr":  # linear: no exposure
        return write_exr(p, radiance, metadata=metadata, option=option)
    if exposure is None:
        peak = float(np.max(radiance)) if np.size(radiance) else 0.0
        if not peak > 0.0:
            raise BrdfkitError("the image is black (peak radiance 0), so no exposure can be "
                               "derived from it; give an explicit exposure")
        exposure, exposure_rule = 1.0 / peak, "peak of this image"
    meta = dict(metadata, exposure=float(exposure), exposure_rule=exposure_rule)
    return write_png(p, radiance, exposure=exposure, metadata=meta, option=option)


def panels(images) -> np.ndarray:
    """Square images (S, S, C) side by side, left to right, :func:`panel_gap` black pixels
    apart: (S, n·S + (n − 1)·gap, C). One channel is repeated to three beside RGB ones
    (a grey model next to a coloured one); other channel counts must agree."""
    imgs = [np.asarray(a, dtype=np.float64) for a in images]
    chans = {a.shape[2] for a in imgs}
    if chans == {1, 3}:
        imgs = [np.repeat(a, 3, axis=2) if a.shape[2] == 1 else a for a in imgs]
    elif len(chans) > 1:
        raise BrdfkitError(f"the panels have {sorted(chans)} channels: only 1 and 3 mix "
                           "(grey shown as RGB); compare models of one channel count")
    S, C = imgs[0].shape[0], imgs[0].shape[2]
    gap = np.zeros((S, panel_gap(S), C))
    out = [imgs[0]]
    for a in imgs[1:]:
        out += [gap, a]
    return np.concatenate(out, axis=1)


def panel_gap(size: int) -> int:
    """Black pixels between panels: S/32, at least 1."""
    return max(1, size // 32)


def save_panels(images, path, *, exposure: float | None, metadata: dict,
                exposure_rule: str = "", option: str = "path") -> str:
    """Write :func:`panels` of *images* (renders' radiance) to *path* as
    :func:`write_radiance` does, with *metadata* (one exposure for every panel)."""
    return write_radiance(path, panels(images), exposure=exposure, metadata=metadata,
                          exposure_rule=exposure_rule, option=option)
