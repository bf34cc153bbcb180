#!/usr/bin/env python3
"""Writes the grey-level maps of the "mud-perturbed" preset: textures/mud-young.png, mud-threshold.png
and mud-thickness.png, three independent smooth noises that scale Young's modulus, the threshold
stress and the thickness of the drying layer (thesis §5.9, Fig. 5.31). White (1.0) keeps the
preset's value, darker grey lowers it, down to LOW of each map.

Each map is a sum of cosine waves with whole numbers of periods across the image, so it tiles
seamlessly like the periodic mud it perturbs; amplitudes fall off with frequency (a 1/f^BETA
spectrum, a few centimetres of feature size on the 8 cm tile), phases come from a small
integer hash of (map, wave), so the images are the same on every machine and Python version.
Standard library only; deterministic.
Usage: python3 textures/mud_perturb.py [DIRECTORY]   (default: the directory of this script)
"""
import math
import os
import struct
import sys
import zlib

SIZE = 256
KMAX = 6      # highest frequency (periods across the image) of the waves
BETA = 1.5    # amplitude ~ 1 / |k|^BETA
# name, hash seed, lowest factor (black end of the map's range)
MAPS = [("mud-young.png", 11, 0.5), ("mud-threshold.png", 23, 0.4), ("mud-thickness.png", 37, 0.4)]


def hash01(*ints):
    """A 32-bit integer hash (xorshift-multiply) of the arguments, as a float in [0, 1)."""
    h = 0x9E3779B9
    for v in ints:
        h ^= (v & 0xFFFFFFFF)
        h = (h * 0x85EBCA6B) & 0xFFFFFFFF
        h ^= h >> 13
        h = (h * 0xC2B2AE35) & 0xFFFFFFFF
        h ^= h >> 16
    return h / 4294967296.0


def noise(seed):
    """SIZE x SIZE tileable noise normalised to [0, 1]."""
    waves = []
    for ky in range(-KMAX, KMAX + 1):
        for kx in range(0, KMAX + 1):
            if (kx == 0 and ky <= 0) or kx * kx + ky * ky > KMAX * KMAX:
                continue  # one of each +-k pair, no constant term
            amp = (kx * kx + ky * ky) ** (-BETA / 2)
            phase = 2 * math.pi * hash01(seed, kx + 64, ky + 64)
            waves.append((kx, ky, amp, phase))
    cx = [[math.cos(2 * math.pi * k * i / SIZE) for i in range(SIZE)] for k in range(KMAX + 1)]
    sx = [[math.sin(2 * math.pi * k * i / SIZE) for i in range(SIZE)] for k in range(KMAX + 1)]
    img = [[0.0] * SIZE for _ in range(SIZE)]
    for kx, ky, amp, phase in waves:
        # cos(a + b + phase) = cos(a) cos(b + phase) - sin(a) sin(b + phase), a along x, b along y
        for j in range(SIZE):
            b = 2 * math.pi * ky * j / SIZE + phase
            cb, sb = amp * math.cos(b), amp * math.sin(b)
            row, c, s = img[j], cx[kx], sx[kx]
            for i in range(SIZE):
                row[i] += c[i] * cb - s[i] * sb
    lo = min(min(r) for r in img)
    hi = max(max(r) for r in img)
    return [[(v - lo) / (hi - lo) for v in r] for r in img]


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
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    for name, seed, low in MAPS:
        n = noise(seed)
        rows = [[int(round(255 * (low + (1.0 - low) * v))) for v in line] for line in n]
        png(os.path.join(out, name), rows)


if __name__ == "__main__":
    main()
