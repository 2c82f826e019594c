"""The pixels the turtles' pens have drawn: what `color_sensor` reads under a turtle.

turtlesim draws its trails into a 500×500 image (45 px to the metre) that starts fully
transparent white; the background colour is painted below it, so the colour sensor sees
(255, 255, 255) where nothing was drawn and the pen's colour where a trail is. Lines are
drawn as Qt draws them with antialiasing off: square caps, `width` pixels across.
"""

from __future__ import annotations

import math
import struct
import zlib

__all__ = ['PathImage']

SIZE = 500
METER = 45  # pixels per metre: the height of turtlesim's turtle images


class PathImage:
    """An RGBA raster, row-major, y down (as Qt's image)."""

    def __init__(self, size: int = SIZE) -> None:
        self.size = size
        self.pixels = bytearray(b'\xff\xff\xff\x00' * (size * size))

    def clear(self) -> None:
        """Fully transparent white again (turtlesim's clear())."""
        self.pixels[:] = b'\xff\xff\xff\x00' * (self.size * self.size)

    def pixel(self, px: float, py: float) -> tuple[int, int, int]:
        """The colour at a point in pixels (rounded as QPointF.toPoint does)."""
        x, y = _round(px), _round(py)
        if not (0 <= x < self.size and 0 <= y < self.size):
            return (0, 0, 0)
        i = 4 * (y * self.size + x)
        return (self.pixels[i], self.pixels[i + 1], self.pixels[i + 2])

    def line(self, x0: float, y0: float, x1: float, y1: float,
             rgb: tuple[int, int, int], width: int) -> None:
        """A pen stroke from (x0, y0) to (x1, y1) in pixels: a `width`-wide square at each
        step of the line, which is Qt's square-capped aliased stroke to within a pixel."""
        steps = max(1, math.ceil(max(abs(x1 - x0), abs(y1 - y0))))
        half = max(1, width) / 2.0
        colour = bytes((*rgb, 255))
        size = self.size
        for k in range(steps + 1):
            cx = x0 + (x1 - x0) * k / steps
            cy = y0 + (y1 - y0) * k / steps
            left, right = max(0, math.ceil(cx - half)), min(size - 1, math.ceil(cx + half) - 1)
            top, bottom = max(0, math.ceil(cy - half)), min(size - 1, math.ceil(cy + half) - 1)
            for y in range(top, bottom + 1):
                row = 4 * y * size
                for x in range(left, right + 1):
                    self.pixels[row + 4 * x:row + 4 * x + 4] = colour

    def png(self) -> bytes:
        """The raster as a PNG (RGBA), so a viewer that joins late sees every trail."""
        raw = b''.join(b'\x00' + bytes(self.pixels[4 * y * self.size:4 * (y + 1) * self.size])
                       for y in range(self.size))
        header = struct.pack('>IIBBBBB', self.size, self.size, 8, 6, 0, 0, 0)
        return (b'\x89PNG\r\n\x1a\n' + _chunk(b'IHDR', header) +
                _chunk(b'IDAT', zlib.compress(raw, 6)) + _chunk(b'IEND', b''))


def _chunk(kind: bytes, data: bytes) -> bytes:
    return (struct.pack('>I', len(data)) + kind + data +
            struct.pack('>I', zlib.crc32(kind + data) & 0xFFFFFFFF))


def _round(value: float) -> int:
    # Qt's qRound: halves away from zero
    return math.floor(value + 0.5) if value >= 0 else -math.floor(-value + 0.5)
