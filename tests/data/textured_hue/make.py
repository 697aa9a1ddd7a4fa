#!/usr/bin/env python3
"""Writes the texture of the textured-hue test (tests/unit/test_textured_hue.c; run once, the output
is committed).

cells.png  8x8 texels, a 4x4 checker of 2x2-texel cells in four colours, each cell's neighbours of
           other colours: pure red (255, 0, 0) and pure blue (0, 0, 255), whose other channels are
           exactly 0; brown (150, 70, 3), whose blue decodes to 0.00091, below 1e-3 (dark wood's,
           issue 25); and white (230, 230, 230).
scene.json (written by hand) lays it on a floor quad, a glossy dark-tinted "glass" panel beside it
           (albedo (0, 0.04, 0.02), specular 0.65: CesiumMilkTruck's windows), a point light and a sky.
"""
import os, struct, zlib

HERE = os.path.dirname(os.path.abspath(__file__))
R, B, N, W = (255, 0, 0), (0, 0, 255), (150, 70, 3), (230, 230, 230)
CELLS = [[R, B, N, W], [N, W, R, B], [B, R, W, N], [W, N, B, R]]


def png_bytes(w, h, rows):
    def chunk(t, d):
        c = struct.pack(">I", len(d)) + t + d
        return c + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    raw = b"".join(b"\0" + bytes(r) for r in rows)
    ihdr = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


rows = []
for y in range(8):
    row = []
    for x in range(8):
        row += CELLS[y // 2][x // 2]
    rows.append(row)
with open(os.path.join(HERE, "cells.png"), "wb") as f:
    f.write(png_bytes(8, 8, rows))
