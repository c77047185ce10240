#!/usr/bin/env python3
"""Writes configs/scenes/convex_vs_mesh.toml: Jolt's PerformanceTest "ConvexVsMesh"
(PerformanceTest/ConvexVsMeshScene.h, JoltPhysics 3b47ec3), body for body.

Usage: python3 scripts/scenes/convex_vs_mesh.py > configs/scenes/convex_vs_mesh.toml
"""

import math
import struct

N = 100  # cells per side
CELL = 3.0
MAX_HEIGHT = 5.0


def f32(x):
    return struct.unpack("f", struct.pack("f", x))[0]


def number(x):
    r = repr(float(x))
    return r[:-2] if r.endswith(".0") else r


def height(ix, iz):
    """Jolt's vertex height, in float32 (Jolt's Sin and Cos are float approximations; libm's here)."""
    s = f32(math.sin(f32(f32(ix * 50.0) / N)))
    c = f32(math.cos(f32(f32(iz * 50.0) / N)))
    return f32(MAX_HEIGHT * f32(s * c))


def main():
    span = N * CELL
    count = 21 * 4 * 21
    print(f"""# Jolt's PerformanceTest "ConvexVsMesh" (PerformanceTest/ConvexVsMeshScene.h; JoltPhysics 3b47ec3),
# body for body: a static terrain mesh of {N} x {N} cells of {CELL:g} m ({2 * N * N:,} triangles), heights
# {MAX_HEIGHT:g} sin(50 ix / {N}) cos(50 iz / {N}) at grid vertex (ix, iz), lifted by {MAX_HEIGHT:g} m and centred on the
# origin; {count:,} dynamic bodies, 21 x 21 of each of four shapes, 7.5 m apart in x and z from
# (-75, y, -75), the box (half extents 0.5, 0.75, 1) at y = 15, the sphere (radius 0.5) at 17, the
# capsule (half height 0.75, radius 0.5) at 19 and the square pyramid hull (apex (0, 1, 0), base
# corners (+-1, 0, 0), (0, 0, +-1)) at 21; friction 0.5 and restitution 0.6 on every body, the
# terrain too; density 1000 and gravity -9.81 (Jolt's defaults); sleeping on (Jolt's default).
# Differs in: Jolt creates the bodies x-major, then shape, then z; here one entry per shape
# (copies x fastest), so body order (and the hash) differ. Jolt's terrain is a mesh of these
# vertices; here it is a listed heightfield of the same vertices, each cell split along the same
# diagonal. Jolt sets 4 velocity and 1 position iterations for this scene; Spindle's own solver
# settings apply. Jolt's Sin and Cos are its float approximations; these heights use libm's,
# rounded to float32.
# Written by scripts/scenes/convex_vs_mesh.py; edit that and regenerate.
description = "Jolt ConvexVsMesh: {count} boxes, spheres, capsules and hulls dropped on a {N} x {N} cell terrain"

[defaults]
friction = 0.5
restitution = 0.6

[[body]]
type = "static"
position = [0, {MAX_HEIGHT:g}, 0]
shape = {{ heightfield = {{ size = [{span:g}, {span:g}], heights = [""")
    for iz in range(N + 1):
        print("  [" + ", ".join(number(height(ix, iz)) for ix in range(N + 1)) + "],")
    print("] } }\n")
    shapes = [
        "{ box = [0.5, 0.75, 1] }",
        "{ sphere = 0.5 }",
        "{ capsule = { half_height = 0.75, radius = 0.5 } }",
        "{ hull = [[0, 1, 0], [1, 0, 0], [-1, 0, 0], [0, 0, 1], [0, 0, -1]] }",
    ]
    for y, shape in enumerate(shapes):
        print(f"[[body]]\nshape = {shape}\nposition = [-75, {15 + 2 * y}, -75]\n"
              f"copies = {{ count = [21, 1, 21], step = [7.5, 0, 7.5] }}\n")


if __name__ == "__main__":
    main()
