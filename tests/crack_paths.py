#!/usr/bin/env python3
"""Measures of crack paths in a crack graph (NAME_cracks.json, fissure(1)).

staircase CRACKS.json [STEP [MIN]]
    For each crack at least MIN pixels long (default 160): its polyline length over the length of
    the same polylines sampled every STEP pixels along them (default 40), their ends kept. A path
    that zigzags at the scale of the elements is longer than its STEP-sampled course; a smooth one
    is not (a straight line gives 1). Prints "MEDIAN COUNT", the median over those cracks and how
    many there were; exits 1 when no crack is long enough.
"""
import json
import math
import sys


def sampled_length(points, step):
    """The length of the polyline through points sampled every step along it, its ends kept."""
    samples = [points[0]]
    travelled, next_at = 0.0, step
    for a, b in zip(points, points[1:]):
        seg = math.dist(a, b)
        while seg > 0.0 and travelled + seg >= next_at:
            t = (next_at - travelled) / seg
            samples.append((a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])))
            next_at += step
        travelled += seg
    if samples[-1] != points[-1]:
        samples.append(points[-1])
    return sum(math.dist(a, b) for a, b in zip(samples, samples[1:]))


def staircase(path, step, min_length):
    graph = json.load(open(path))
    w, h = graph["width"], graph["height"]
    ratios = []
    for crack in graph["cracks"]:
        if crack["length_px"] < min_length:
            continue
        full = coarse = 0.0
        for line in crack["polylines"]:
            points = [(u * w, v * h) for u, v in line]
            full += sum(math.dist(a, b) for a, b in zip(points, points[1:]))
            coarse += sampled_length(points, step)
        if coarse > 0.0:
            ratios.append(full / coarse)
    if not ratios:
        return None, 0
    ratios.sort()
    n = len(ratios)
    return (ratios[n // 2] if n % 2 else 0.5 * (ratios[n // 2 - 1] + ratios[n // 2])), n


def main(argv):
    if len(argv) < 3 or argv[1] != "staircase":
        sys.stderr.write(__doc__)
        return 2
    step = float(argv[3]) if len(argv) > 3 else 40.0
    min_length = float(argv[4]) if len(argv) > 4 else 160.0
    median, n = staircase(argv[2], step, min_length)
    if median is None:
        sys.stderr.write("%s: no crack of %g px or more\n" % (argv[2], min_length))
        return 1
    print("%.4f %d" % (median, n))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
