#!/usr/bin/env python3
"""Writes textures/heart.png: the grey-level threshold map of the "breaking heart" preset.

White (1.0) keeps the material's threshold stress; the heart is darker (0.45), so the threshold
there is lowered and cracks form only inside it (thesis Fig. 5.26). The edge is a smooth ramp a few
pixels wide (anti-aliased coverage, blurred) so the map averages smoothly over elements. Standard library only; deterministic.
Usage: python3 textures/heart.py [OUTPUT.png]   (default: heart.png next to this script)
"""
import os
import struct
import sys
import zlib

SIZE = 512
INSIDE = 0.45   # threshold factor inside the heart
RAMP = 4        # radius (pixels) of the two box blurs that soften the edge


def heart_value(x, y):
    """Implicit heart (x^2 + y^2 - 1)^3 - x^2 y^3: negative inside; x, y in about [-1.3, 1.3]."""
    a = x * x + y * y - 1.0
    return a * a * a - x * x * y * y * y


def coverage(px, py):
    """Fraction of a 4 x 4 grid of sub-samples of pixel (px, py) inside the heart."""
    inside = 0
    for sy in range(4):
        for sx in range(4):
            # heart coordinates: y up, the heart centred and filling ~70 % of the image
            x = (px + (sx + 0.5) / 4) / SIZE * 3.0 - 1.5
            y = 1.62 - (py + (sy + 0.5) / 4) / SIZE * 3.0
            inside += heart_value(x, y) <= 0.0
    return inside / 16.0


def box_blur(img, r):
    """Separable box blur of radius r with clamped edges (twice gives a smooth ramp)."""
    n = len(img)
    out = [[0.0] * n for _ in range(n)]
    for j in range(n):
        row = img[j]
        for i in range(n):
            s = 0.0
            for k in range(i - r, i + r + 1):
                s += row[min(max(k, 0), n - 1)]
            out[j][i] = s / (2 * r + 1)
    res = [[0.0] * n for _ in range(n)]
    for i in range(n):
        for j in range(n):
            s = 0.0
            for k in range(j - r, j + r + 1):
                s += out[min(max(k, 0), n - 1)][i]
            res[j][i] = s / (2 * r + 1)
    return res


def png(path, rows):
    raw = b"".join(b"\x00" + bytes(r) for r in rows)

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", SIZE, SIZE, 8, 0, 0, 0, 0))
    data += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "heart.png")
    cov = [[coverage(px, py) for px in range(SIZE)] for py in range(SIZE)]
    cov = box_blur(box_blur(cov, RAMP), RAMP)
    rows = [[int(round(255 * (1.0 - (1.0 - INSIDE) * c))) for c in line] for line in cov]
    png(out, rows)


if __name__ == "__main__":
    main()
