#!/usr/bin/env python3
"""Writes the texture images of scenes/textured.cfg (scenes/textures/*.png), our own content:
tiles.png, 128 x 128: 4 x 4 coloured tiles (hue across, lightness down) with dark grout lines
and a white marker in the top-left tile, so orientation and seams show in a render.
Plain Python (zlib), deterministic: re-running rewrites the same bytes.
    python3 scripts/make_textures.py [out_dir]"""
import colorsys
import os
import struct
import sys
import zlib


def write_png(path, width, height, rows):
    """rows: list of bytes objects, 3 * width bytes each (8-bit sRGB)."""
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    raw = b"".join(b"\x00" + r for r in rows)  # filter type 0 on every row
    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9))
    png += chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def tiles(size=128, n=4):
    cell = size // n
    rows = []
    for y in range(size):
        row = bytearray()
        for x in range(size):
            i, j = x // cell, y // cell
            fx, fy = x % cell, y % cell
            if fx < 2 or fy < 2:
                rgb = (0.12, 0.10, 0.09)  # grout
            elif i == 0 and j == 0 and 8 <= fx < 24 and 8 <= fy < 14:
                rgb = (1.0, 1.0, 1.0)  # marker bar: the top-left corner of the image
            else:
                h = (i + 0.5) / n
                l = 0.35 + 0.12 * j + 0.05 * ((fx + fy) % 8 < 4)  # a faint diagonal stripe
                rgb = colorsys.hls_to_rgb(h, l, 0.7)
            row += bytes(int(round(255 * min(1.0, max(0.0, c)))) for c in rgb)
        rows.append(bytes(row))
    return size, size, rows


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "scenes", "textures")
    os.makedirs(out, exist_ok=True)
    w, h, rows = tiles()
    write_png(os.path.join(out, "tiles.png"), w, h, rows)


if __name__ == "__main__":
    main()
