#!/usr/bin/env python3
"""Writes configs/scenes/convex_pile.toml: Box3D's benchmark "convex_pile" (shared/benchmarks.c,
CreateConvexPile, Box3D 30c67b5), body for body.

Usage: python3 scripts/scenes/convex_pile.py > configs/scenes/convex_pile.toml
"""

import box3d as b

COUNT_X, COUNT_Z, LAYERS = 8, 8, 80
AMPLITUDE = 2.0
POINT_COUNT = 32


class Random:
    """PEEL's BasicRandom, as Box3D keeps it (seed 42)."""

    def __init__(self, seed):
        self.state = seed

    def next(self):
        self.state = (self.state * 2147001325 + 715136305) & 0xFFFFFFFF
        return self.state

    def unit_float(self):  # [-0.5, 0.5]
        return b.sub(b.div(float(self.next() & 0xFFFF), 65535.0), 0.5)


def unit_random_point(rng):
    while True:
        p = (rng.unit_float(), rng.unit_float(), rng.unit_float())
        if not b.dot(p, p) > 0.25:
            return b.normalize(p)


def main():
    rng = Random(42)
    points = [b.mul_sv(AMPLITUDE, unit_random_point(rng)) for _ in range(POINT_COUNT)]
    scatter = 2.0 * AMPLITUDE
    count = COUNT_X * COUNT_Z * LAYERS
    print(f"""# Box3D's benchmark "convex_pile" (shared/benchmarks.c, CreateConvexPile; Box3D 30c67b5),
# body for body: {count:,} copies of one convex hull, the hull of {POINT_COUNT} points on a sphere of radius
# {AMPLITUDE:g} drawn with PEEL's random generator (seed 42, Box3D's float32 arithmetic), density 1000,
# friction 0.6, in {LAYERS} layers of {COUNT_X} x {COUNT_Z}, {scatter:g} m apart (layer i at y = 2 + 4 i), created
# in Box3D's order (x fastest, then z, then layer); a floor box of half extents (250, 1, 250) at
# (0, -1, 0); gravity -10 (Box3D's); sleeping on (Box3D's default).
# Differs in: nothing the scene format decides. Spindle builds its own hull from the
# same points (all 32 are hull vertices) and its own solver settings apply.
# Written by scripts/scenes/convex_pile.py; edit that and regenerate.
description = "Box3D convex_pile: {count} random 32-point hulls falling into a pile"

[settings]
gravity = [0, -10, 0]

[defaults]
shape = {b.hull(points)}

[[body]]
type = "static"
shape = {{ box = [250, 1, 250] }}
position = [0, -1, 0]
""")
    for layer in range(LAYERS):
        x0 = (0 - 0.5 * COUNT_X) * scatter
        z0 = (0 - 0.5 * COUNT_Z) * scatter
        y = AMPLITUDE + 2.0 * AMPLITUDE * layer
        print(f"[[body]]\nposition = [{x0:g}, {y:g}, {z0:g}]\n"
              f"copies = {{ count = [{COUNT_X}, 1, {COUNT_Z}], step = [{scatter:g}, 0, {scatter:g}] }}\n")


if __name__ == "__main__":
    main()
