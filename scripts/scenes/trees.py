#!/usr/bin/env python3
"""Writes configs/scenes/trees.toml: Box3D's benchmark "trees100" (shared/benchmarks.c,
CreateTrees with scale 1, Box3D 30c67b5).

Usage: python3 scripts/scenes/trees.py > configs/scenes/trees.toml
"""

import math

import box3d as b

X_CELLS, Z_CELLS = 150, 200  # scale 1
CELL = 1.0
AMPLITUDE = 0.4
ROW_HZ, COLUMN_HZ = 0.05, 0.1
TREES = 50
SEGMENTS = 22
SIDES = 6


def segments():
    """The 22 cylinder hulls of a tree, bottom up, with each one's volume and centre height."""
    parts = []
    y, r, l = 1.0, 0.75, 1.5
    for _ in range(SEGMENTS):
        height = b.add(l, b.mul(2.0, r))
        y_offset = b.sub(y, r)
        points = b.cylinder(height, r, y_offset, SIDES)
        # A regular hexagonal prism: its centroid is on the axis, half way up.
        volume = 1.5 * math.sqrt(3.0) * r * r * height
        parts.append((points, volume, y_offset + 0.5 * height))
        y = b.add(y, height)
        r = b.mul(0.95, r)
    return parts


def main():
    parts = segments()
    centre_y = sum(v * c for _, v, c in parts) / sum(v for _, v, _ in parts)
    print(f"""# Box3D's benchmark "trees100" (shared/benchmarks.c, CreateTrees with scale 1; Box3D 30c67b5):
# {TREES} trees, each one dynamic body of {SEGMENTS} stacked six-sided cylinder hulls (b3CreateCylinder, radius
# 0.75 shrinking by 0.95 a segment, each 1.5 m plus two radii tall; Box3D's float32 points), standing
# at (0, 1, z) for z = -70, -67, ..., 77, density 1, friction 0.9, rolling resistance 0.05 (Box3D's
# material), each spun about z at (0.5 + 0.5 i / {TREES}) x 0.5 rad/s, alternating in sign (starting with -), its centre of mass moving
# at omega x (centre - origin) as Box3D sets it; on a static wave mesh of {X_CELLS} x {Z_CELLS} cells of
# {CELL:g} m, heights {AMPLITUDE:g} sin(2 pi {COLUMN_HZ:g} ix) sin(2 pi {ROW_HZ:g} iz) at vertex (ix, iz) counted from the
# (-75, -100) corner, that is {-AMPLITUDE:g} sin(2 pi x / {1 / COLUMN_HZ:g}) sin(2 pi z / {1 / ROW_HZ:g}) about the centre; gravity -10 (Box3D's);
# sleeping on (Box3D's default) with the trees' sleep threshold of 0.2 m/s.
# Differs in: Box3D's tree is a body with 22 hull shapes; here one compound body of 22 hull
# parts, so each manifold (a part against the mesh) takes its part's rolling radius, as each of
# Box3D's hull shapes has its own contact. That radius is a quarter of the hull's inner radius
# here, in every contact; Box3D takes a quarter in a contact between shapes but the whole inner
# radius in a hull's contact with a mesh (mesh_contact.c), so its trees roll against the mesh
# with 4x the resistance (given that here, the trees stay awake longer, not shorter:
# docs/benchmarks.md, session 31). Box3D's sleep
# threshold is per body; here it is the space's (only the trees are dynamic). The terrain is a
# generated heightfield: its heights use libm's sine where Box3D's use its float32
# approximation (b3ComputeCosSin), and each cell is split along the other diagonal (Box3D's
# runs from (ix, iz) to (ix + 1, iz + 1)). Box3D's trees25 and trees50 are the same
# scene with a 2x and 4x finer mesh: not built here.
# Written by scripts/scenes/trees.py; edit that and regenerate.
description = "Box3D trees100: {TREES} spinning trees of {SEGMENTS} hulls each falling on a {X_CELLS} x {Z_CELLS} m wave mesh"

[settings]
gravity = [0, -10, 0]
sleep_linear_threshold = 0.2

[[body]]
type = "static"
friction = 0.6  # Box3D's default: only the trees have 0.9
shape = {{ heightfield = {{ size = [{X_CELLS * CELL:g}, {Z_CELLS * CELL:g}], cells = [{X_CELLS}, {Z_CELLS}], amplitude = {-AMPLITUDE:g}, wavelength = [{1 / COLUMN_HZ:g}, {1 / ROW_HZ:g}] }} }}
""")
    compound = "{ compound = [\n" + "".join(f"  {{ shape = {b.hull(p)} }},\n" for p, _, _ in parts) + "] }"
    print(f"[defaults]\ndensity = 1\nfriction = 0.9\nrolling_resistance = 0.05\nshape = {compound}\n")
    z = -70.0
    omega = -0.5
    for i in range(TREES):
        w = (0.5 + 0.5 * i / TREES) * omega
        # omega x (centre - origin) with omega along z and the centre straight above the origin.
        vx = -w * centre_y
        print(f"[[body]]\nposition = [0, 1, {z:g}]\nangular_velocity = [0, 0, {b.number(b.f32(w))}]\n"
              f"velocity = [{b.number(b.f32(vx))}, 0, 0]\n")
        z += 3.0
        omega = -omega


if __name__ == "__main__":
    main()
