#!/usr/bin/env python3
"""Writes closed triangle meshes under the file names of the original meshes
the *-mesh scenes read (luckyCat20K.obj, Armadillo.obj, cylinder.obj,
wheel.obj, turkey.obj), each with the original's bounding box, so the mesh
path (OBJ reading, inside test, sampling, vertices as particles) runs where
the originals are not installed (CI).

    scripts/stand_in_meshes.py OUTDIR

They are stand-ins for testing, not the originals: ellipsoids for the cat,
the armadillo and the turkey, a flat disk for the trampoline, a hollow
cylinder for the wheel's rim. Every face is wound counter-clockwise seen
from outside.
"""
import math
import os
import sys

# bounding boxes (min, max) of the original meshes, in their own frames
BOXES = {
    "luckyCat20K.obj": ((-0.6256, -0.4439, -0.1688), (0.4275, 0.5705, 0.6316)),
    "Armadillo.obj": ((-0.3812, -0.3461, -0.5830), (0.3812, 0.3462, 0.3252)),
    "turkey.obj": ((-0.6922, 0.0005, -0.8230), (0.6922, 0.8218, 0.8247)),
}


def ellipsoid(lo, hi, n_around=32, n_up=16):
    c = [(a + b) / 2 for a, b in zip(lo, hi)]
    r = [(b - a) / 2 for a, b in zip(lo, hi)]
    verts = [(c[0], c[1] + r[1], c[2])]  # top pole, then rings, then the bottom pole
    for i in range(1, n_up):
        th = math.pi * i / n_up
        for j in range(n_around):
            ph = 2 * math.pi * j / n_around
            verts.append((c[0] + r[0] * math.sin(th) * math.cos(ph), c[1] + r[1] * math.cos(th),
                          c[2] + r[2] * math.sin(th) * math.sin(ph)))
    verts.append((c[0], c[1] - r[1], c[2]))
    bottom = len(verts) - 1
    ring = lambda i, j: 1 + (i - 1) * n_around + j % n_around
    faces = []
    for j in range(n_around):
        faces.append((0, ring(1, j + 1), ring(1, j)))
        faces.append((bottom, ring(n_up - 1, j), ring(n_up - 1, j + 1)))
    for i in range(1, n_up - 1):
        for j in range(n_around):
            a, b, cc, d = ring(i, j), ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)
            faces += [(a, b, cc), (a, cc, d)]
    return verts, faces


def annulus_tube(axis_center, r_out, r_in, half, axis, n=48):
    """A closed hollow cylinder (r_in < radius < r_out, |axial| < half) about
    `axis` ('y' or 'z'); r_in = 0 gives a solid disk (centre vertices on the caps)."""
    def point(rad, ang, h):
        u, v = rad * math.cos(ang), rad * math.sin(ang)
        cx, cy, cz = axis_center
        return (cx + u, cy + h, cz + v) if axis == "y" else (cx + u, cy + v, cz + h)

    verts, faces = [], []
    rings = {}
    for key, rad, h in (("ot", r_out, half), ("ob", r_out, -half), ("it", r_in, half), ("ib", r_in, -half)):
        if rad == 0:
            continue
        rings[key] = len(verts)
        verts += [point(rad, 2 * math.pi * k / n, h) for k in range(n)]
    at = lambda key, k: rings[key] + k % n
    # with the axis 'y', angle increasing from +x toward +z: a ring runs clockwise seen from +y
    for k in range(n):
        faces += [(at("ob", k), at("ot", k), at("ot", k + 1)), (at("ob", k), at("ot", k + 1), at("ob", k + 1))]
    if r_in > 0:
        for k in range(n):
            faces += [(at("ib", k), at("it", k + 1), at("it", k)), (at("ib", k), at("ib", k + 1), at("it", k + 1))]
        for k in range(n):  # caps between the rings
            faces += [(at("ot", k), at("it", k), at("it", k + 1)), (at("ot", k), at("it", k + 1), at("ot", k + 1))]
            faces += [(at("ob", k), at("ib", k + 1), at("ib", k)), (at("ob", k), at("ob", k + 1), at("ib", k + 1))]
    else:
        top, bot = len(verts), len(verts) + 1
        verts += [point(0, 0, half), point(0, 0, -half)]
        for k in range(n):
            faces += [(top, at("ot", k + 1), at("ot", k)), (bot, at("ob", k), at("ob", k + 1))]
    if axis == "z":  # (x, y, z) -> (x, z', y') flips handedness: wind the other way
        faces = [(a, c, b) for a, b, c in faces]
    return verts, faces


def write_obj(path, verts, faces):
    with open(path, "w") as f:
        f.write("# stand-in mesh written by scripts/stand_in_meshes.py (not the original)\n")
        for v in verts:
            f.write("v %.6f %.6f %.6f\n" % v)
        for a, b, c in faces:
            f.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))


def signed_volume(verts, faces):
    vol = 0.0
    for a, b, c in faces:
        (x1, y1, z1), (x2, y2, z2), (x3, y3, z3) = verts[a], verts[b], verts[c]
        vol += (x1 * (y2 * z3 - y3 * z2) - x2 * (y1 * z3 - y3 * z1) + x3 * (y1 * z2 - y2 * z1)) / 6.0
    return vol


def main(argv):
    if len(argv) != 1:
        print(__doc__.strip().splitlines()[5].strip(), file=sys.stderr)
        return 2
    out = argv[0]
    os.makedirs(out, exist_ok=True)
    meshes = {name: ellipsoid(*box) for name, box in BOXES.items()}
    # the trampoline: a disk of radius 2.4 m, 0.08 m thick, about y
    meshes["cylinder.obj"] = annulus_tube((0, 0, 0), 2.3999, 0.0, 0.04, "y", n=96)
    # the wheel's rim: about z through (0, 0.24135, 0), outer radius 0.24135 m,
    # inner 0.209 m, 0.159 m wide (the procedural wheel's rim)
    meshes["wheel.obj"] = annulus_tube((0, 0.24135, 0), 0.24135, 0.209, 0.0795, "z", n=96)
    for name, (verts, faces) in meshes.items():
        if signed_volume(verts, faces) <= 0:
            print(f"stand_in_meshes.py: {name} is wound inside out", file=sys.stderr)
            return 1
        write_obj(os.path.join(out, name), verts, faces)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
