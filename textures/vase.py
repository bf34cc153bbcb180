#!/usr/bin/env python3
"""Writes textures/vase.obj: a small UV-mapped vase for the shell model's glaze and paint presets.

A surface of revolution 20 cm tall (a foot, a round belly, a narrow neck and a flared lip), open at
the top, closed by a flat base. Two UV charts, padded from each other and from the texture's border:
the side unwrapped (u around, from a seam on the -x side; v up the profile by arc length, at the
same cm per texture unit as u at the belly) and the base as a disc below it. The surface is one
piece: the side's seam and the base's rim are UV seams only (their positions are shared).
Positions in cm, outward-facing counter-clockwise faces. Deterministic: no randomness.

    python3 textures/vase.py [OUT.obj [AROUND ROWS]]

AROUND and ROWS (default 88 and 40) set the segments around and the rows up the side: the tests
make a coarse vase of a few hundred triangles with them.
"""

import math
import sys

AROUND = 88          # segments around
HEIGHT = 20.0        # cm
PROFILE_ROWS = 40    # rows up the side


def radius(z):
    """The profile: radius (cm) at height z (cm)."""
    t = z / HEIGHT
    belly = 5.6 * math.exp(-((t - 0.38) / 0.26) ** 2)
    neck = -1.5 * math.exp(-((t - 0.80) / 0.09) ** 2)
    lip = 0.9 * math.exp(-((t - 1.0) / 0.06) ** 2)
    return 3.2 + belly * 0.55 + neck + lip + 0.6 * (1.0 - t) ** 6


def main():
    global AROUND, PROFILE_ROWS
    out = sys.argv[1] if len(sys.argv) > 1 else "textures/vase.obj"
    if len(sys.argv) > 3:
        AROUND, PROFILE_ROWS = int(sys.argv[2]), int(sys.argv[3])
    # rows spaced evenly by arc length along the profile
    fine = [HEIGHT * i / 4000.0 for i in range(4001)]
    arc = [0.0]
    for a, b in zip(fine, fine[1:]):
        arc.append(arc[-1] + math.hypot(b - a, radius(b) - radius(a)))
    length = arc[-1]
    zs = []
    k = 0
    for j in range(PROFILE_ROWS + 1):
        target = length * j / PROFILE_ROWS
        while k < len(arc) - 2 and arc[k + 1] < target:
            k += 1
        f = (target - arc[k]) / (arc[k + 1] - arc[k])
        zs.append(fine[k] + f * (fine[k + 1] - fine[k]))

    # texture scale: the side chart spans u in [0.02, 0.98]; the same cm per unit along v
    r_max = max(radius(z) for z in fine)
    per_cm = 0.96 / (2.0 * math.pi * r_max)
    v_top = 0.98
    v_bottom = v_top - length * per_cm
    positions, uvs, faces = [], [], []

    def vertex(p):
        positions.append(p)
        return len(positions)

    def texcoord(t):
        uvs.append(t)
        return len(uvs)

    # the side: rows of positions, with a texture column for u = 0 and one for u = 1 at the seam
    side = []
    for j, z in enumerate(zs):
        r = radius(z)
        row = [vertex((r * math.cos(math.pi + 2 * math.pi * i / AROUND), r * math.sin(math.pi + 2 * math.pi * i / AROUND), z))
               for i in range(AROUND)]
        side.append(row)
    side_uv = []
    for j in range(len(zs)):
        v = v_bottom + (v_top - v_bottom) * j / PROFILE_ROWS
        side_uv.append([texcoord((0.02 + 0.96 * i / AROUND, v)) for i in range(AROUND + 1)])
    for j in range(PROFILE_ROWS):
        for i in range(AROUND):
            a, b = side[j][i], side[j][(i + 1) % AROUND]
            c, d = side[j + 1][(i + 1) % AROUND], side[j + 1][i]
            ta, tb, tc, td = side_uv[j][i], side_uv[j][i + 1], side_uv[j + 1][i + 1], side_uv[j + 1][i]
            if (i + j) % 2 == 0:
                faces.append(((a, ta), (b, tb), (c, tc)))
                faces.append(((a, ta), (c, tc), (d, td)))
            else:
                faces.append(((a, ta), (b, tb), (d, td)))
                faces.append(((b, tb), (c, tc), (d, td)))

    # the base: rings from the rim inwards, halving the count where the ring gets short; a disc
    # chart centred below the side chart
    r0 = radius(0.0)
    centre_uv = (0.5, v_bottom / 2.0)
    scale = min(per_cm, 0.9 * (v_bottom / 2.0) / r0)
    rings = [(r0, side[0])]
    count = AROUND
    rr = r0
    step = 2.0 * math.pi * r0 / AROUND
    while rr > 1.5 * step:
        rr -= step * 1.2
        if 2.0 * math.pi * rr / count < 0.55 * step and count % 2 == 0 and count > 6:
            count //= 2
        ring = [vertex((rr * math.cos(math.pi + 2 * math.pi * i / count), rr * math.sin(math.pi + 2 * math.pi * i / count), 0.0))
                for i in range(count)]
        rings.append((rr, ring))

    def ring_uv(rr, n):
        # the base seen from below: mirrored so that its faces keep a positive orientation in texture space
        return [texcoord((centre_uv[0] - scale * rr * math.cos(math.pi + 2 * math.pi * i / n),
                          centre_uv[1] + scale * rr * math.sin(math.pi + 2 * math.pi * i / n))) for i in range(n)]

    ring_tex = [ring_uv(rr, len(ring)) for rr, ring in rings]
    for q in range(len(rings) - 1):
        outer, inner = rings[q][1], rings[q + 1][1]
        to, ti = ring_tex[q], ring_tex[q + 1]
        no, ni = len(outer), len(inner)
        if no == ni:
            for i in range(no):
                a, b = outer[i], outer[(i + 1) % no]
                c, d = inner[(i + 1) % ni], inner[i]
                faces.append(((a, to[i]), (d, ti[i]), (c, ti[(i + 1) % ni])))
                faces.append(((a, to[i]), (c, ti[(i + 1) % ni]), (b, to[(i + 1) % no])))
        else:
            for i in range(ni):
                o0, o1, o2 = 2 * i, 2 * i + 1, (2 * i + 2) % no
                i0, i1 = i, (i + 1) % ni
                faces.append(((outer[o0], to[o0]), (inner[i0], ti[i0]), (outer[o1], to[o1])))
                faces.append(((outer[o1], to[o1]), (inner[i0], ti[i0]), (inner[i1], ti[i1])))
                faces.append(((outer[o1], to[o1]), (inner[i1], ti[i1]), (outer[o2], to[o2])))
    centre = vertex((0.0, 0.0, 0.0))
    tcentre = texcoord(centre_uv)
    last, lt = rings[-1][1], ring_tex[-1]
    for i in range(len(last)):
        j = (i + 1) % len(last)
        faces.append(((centre, tcentre), (last[j], lt[j]), (last[i], lt[i])))

    with open(out, "w") as f:
        f.write("# A vase for fissure's shell presets, written by textures/vase.py: %d vertices, %d triangles,\n"
                % (len(positions), len(faces)))
        f.write("# 20 cm tall, positions in cm; side and base unwrapped into two padded UV charts.\n")
        f.write("o vase\n")
        for p in positions:
            f.write("v %.6f %.6f %.6f\n" % p)
        for t in uvs:
            f.write("vt %.6f %.6f\n" % t)
        for face in faces:
            f.write("f %s\n" % " ".join("%d/%d" % c for c in face))


if __name__ == "__main__":
    main()
