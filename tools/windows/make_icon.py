"""Write nfwserver's Windows icon (an .ico of PNG images, 16 to 256 pixels) from a drawing in code.

The picture: a night-blue disc (the sky seen from the station), a tilted orbit and a satellite on it,
and an antenna's line of sight from the centre to the satellite.  Each size is drawn at 4x4
supersampling with numpy and written as a PNG with fixed zlib settings, so the bytes depend on this file
alone (tools/windows/build makes it on every build; nothing binary is kept in the repository).
Usage: ``python3 make_icon.py OUT.ico``.
"""

from __future__ import annotations

import struct
import sys
import zlib
from collections.abc import Callable
from pathlib import Path

import numpy as np
import numpy.typing as npt

SIZES = (16, 24, 32, 48, 64, 256)
SKY = (18, 38, 82)
RIM = (92, 150, 230)
ORBIT = (180, 210, 255)
SAT = (255, 196, 64)
BEAM = (120, 230, 160)


Array = npt.NDArray[np.float64]


def _coverage(size: int, inside: Callable[[Array, Array], npt.NDArray[np.bool_]]) -> Array:
    """Fraction (0..1) of each pixel where ``inside(x, y)`` holds, x and y in -1..1 (y up)."""
    k = 4
    n = size * k
    c = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    x, y = np.meshgrid(c, -c)
    mask = inside(x, y).astype(np.float64)
    cover: Array = mask.reshape(size, k, size, k).mean(axis=(1, 3))
    return cover


def _segment_distance(x: Array, y: Array, a: tuple[float, float], b: tuple[float, float]) -> Array:
    ax, ay = a
    bx, by = b
    dx, dy = bx - ax, by - ay
    t = np.clip(((x - ax) * dx + (y - ay) * dy) / (dx * dx + dy * dy), 0.0, 1.0)
    distance: Array = np.hypot(x - (ax + t * dx), y - (ay + t * dy))
    return distance


def draw(size: int) -> npt.NDArray[np.uint8]:
    """The icon at ``size`` x ``size`` pixels as RGBA bytes."""
    scale = max(1.0, 32.0 / size)  # thicker strokes at small sizes
    rgb = np.zeros((size, size, 3))
    alpha = np.zeros((size, size))

    def paint(cover: Array, colour: tuple[int, int, int]) -> None:
        nonlocal rgb, alpha
        rgb = rgb * (1 - cover[..., None]) + np.array(colour, dtype=np.float64) * cover[..., None]
        alpha = alpha * (1 - cover) + cover

    paint(_coverage(size, lambda x, y: x * x + y * y <= 0.96 ** 2), RIM)
    paint(_coverage(size, lambda x, y: x * x + y * y <= (0.96 - 0.07 * scale) ** 2), SKY)
    tilt = np.radians(28.0)

    def orbit(x: Array, y: Array) -> npt.NDArray[np.bool_]:
        u = x * np.cos(tilt) + y * np.sin(tilt)
        v = -x * np.sin(tilt) + y * np.cos(tilt)
        r = np.hypot(u / 0.78, v / 0.34)
        ring: npt.NDArray[np.bool_] = np.abs(r - 1.0) <= 0.045 * scale
        return ring

    paint(_coverage(size, orbit), ORBIT)
    angle = np.radians(58.0)
    su, sv = 0.78 * np.cos(angle), 0.34 * np.sin(angle)
    sx, sy = su * np.cos(tilt) - sv * np.sin(tilt), su * np.sin(tilt) + sv * np.cos(tilt)
    paint(_coverage(size, lambda x, y: _segment_distance(x, y, (0.0, -0.55), (sx, sy)) <= 0.035 * scale), BEAM)
    paint(_coverage(size, lambda x, y: np.hypot(x, y + 0.55) <= 0.09 * scale), BEAM)
    paint(_coverage(size, lambda x, y: np.hypot(x - sx, y - sy) <= 0.13 * min(scale, 1.6)), SAT)
    out = np.dstack([np.clip(np.rint(rgb), 0, 255), np.clip(np.rint(alpha * 255), 0, 255)])
    return out.astype(np.uint8)


def png(image: npt.NDArray[np.uint8]) -> bytes:
    """A PNG (RGBA, 8 bits) of ``image``; zlib level 9, so the same pixels give the same bytes."""
    height, width, _ = image.shape
    raw = b"".join(b"\x00" + image[row].tobytes() for row in range(height))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")


def ico(images: list[bytes], sizes: tuple[int, ...]) -> bytes:
    """An .ico holding the PNG ``images`` (Windows Vista and later read PNG entries at every size)."""
    offset = 6 + 16 * len(images)
    entries, blobs = b"", b""
    for size, data in zip(sizes, images):
        side = 0 if size >= 256 else size
        entries += struct.pack("<BBBBHHII", side, side, 0, 0, 1, 32, len(data), offset)
        offset += len(data)
        blobs += data
    return struct.pack("<HHH", 0, 1, len(images)) + entries + blobs


def main(argv: list[str]) -> int:
    Path(argv[0]).write_bytes(ico([png(draw(size)) for size in SIZES], SIZES))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
