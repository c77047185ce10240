#!/usr/bin/env python3
"""Writes configs/scenes/rain.toml: Box3D's benchmark "rain" (shared/benchmarks.c, CreateRain and
StepRain, Box3D 30c67b5), as far as a scene can hold it.

Usage: python3 scripts/scenes/rain.py > configs/scenes/rain.toml
"""

import box3d as b

GRID_COUNT = 10  # RAIN_GRID_COUNT (Release)
GRID_SIZE = 15.0  # RAIN_GRID_SIZE
GROUP_SIZE = 3  # RAIN_GROUP_SIZE (Release)
MESH_CELLS = 8  # b3CreateGridMesh(8, 8, ...)
TORUS_SEGMENTS = 16  # b3CreateTorusMesh(16, 16, ...)
TORUS_RADIUS = 0.25 * GRID_SIZE
TORUS_THICKNESS = 1.0
PELVIS = (0.0, 0.932087, -0.051708)  # Box3D's human: the pelvis bone's offset from the human's position


def sub3(a, c):
    return tuple(x - y for x, y in zip(a, c))


def cross3(a, c):
    return (a[1] * c[2] - a[2] * c[1], a[2] * c[0] - a[0] * c[2], a[0] * c[1] - a[1] * c[0])


def torus():
    """b3CreateTorusMesh's vertices and triangles (src/mesh.c), each triangle wound so that its
    front faces out of the tube (Spindle's meshes face the side they are counter-clockwise from)."""
    n = TORUS_SEGMENTS
    two_pi = b.mul(2.0, b.PI)
    vertices, centres = [], []
    for radial in range(n):
        for tubular in range(n):
            u = b.mul(b.div(float(tubular), float(n)), two_pi)
            v = b.mul(b.div(float(radial), float(n)), two_pi)
            cu, su = b.compute_cos_sin(u)
            cv, sv = b.compute_cos_sin(v)
            ring = b.add(TORUS_RADIUS, b.mul(TORUS_THICKNESS, cv))
            vertices.append((b.mul(ring, cu), b.mul(ring, su), b.mul(TORUS_THICKNESS, sv)))
            centres.append((TORUS_RADIUS * cu, TORUS_RADIUS * su, 0.0))
    triangles = []
    for r1 in range(n):
        r2 = (r1 + 1) % n
        for t1 in range(n):
            t2 = (t1 + 1) % n
            i1, i2, i3, i4 = r1 * n + t1, r1 * n + t2, r2 * n + t2, r2 * n + t1
            for tri in ((i1, i2, i3), (i3, i4, i1)):
                p = [vertices[i] for i in tri]
                normal = cross3(sub3(p[1], p[0]), sub3(p[2], p[0]))
                out = sub3(p[0], centres[tri[0]])
                if sum(x * y for x, y in zip(normal, out)) < 0:
                    tri = (tri[0], tri[2], tri[1])
                triangles.append(tri)
    return vertices, triangles


def main():
    span = GRID_SIZE * GRID_COUNT
    first = -0.5 * span + 0.5 * GRID_SIZE
    cells = GRID_COUNT * GRID_COUNT
    humans = cells * GROUP_SIZE
    vertices, triangles = torus()
    print(f"""# Box3D's benchmark "rain" (shared/benchmarks.c, CreateRain and StepRain; Box3D 30c67b5, its
# Release sizes), as far as a scene holds it: a {GRID_COUNT} x {GRID_COUNT} grid of {GRID_SIZE:g} m cells from
# ({first:g}, 0, {first:g}), each a static flat grid mesh of {MESH_CELLS} x {MESH_CELLS} cells ({GRID_SIZE:g} m square) and a static
# upright torus mesh (b3CreateTorusMesh(16, 16, {TORUS_RADIUS:g}, {TORUS_THICKNESS:g}): a ring of radius {TORUS_RADIUS:g} about z, tube radius
# {TORUS_THICKNESS:g}, {len(triangles)} triangles, Box3D's float32 points) half sunk in it; above every cell a group of
# {GROUP_SIZE} ragdolls 0.75 m apart along x, the human's position at y = 20 (its pelvis at 20.93); sleeping
# on, gravity -10 (Box3D's defaults); friction 0.6 and density 1000 (Box3D's defaults).
# Differs in: Box3D rains its humans in: at the steps with step & 0x2F == 0 (0, 16, 64, 80,
# 128, ...: two every 64 steps) it drops a new column of {GRID_COUNT} groups until all {GRID_COUNT} columns are in
# (step 272), then destroys a column and drops it again (steps 320, 336 and 384 of its
# 400-step benchmark); a scene cannot add or remove bodies while it runs, so here
# all {humans} ragdolls of the full grid fall together from step 0 and none is removed
# (`spindle bench` has no per-step script either). The ragdoll is Spindle's [[ragdoll]] (12
# bodies, 11 joints, friction torques of 5 and 2.5 N m) instead of Box3D's human (14 bodies,
# 13 joints with 1 Hz springs toward its pose and 5 N m friction motors, rolling resistance
# 0.2); each ragdoll's parts never collide with each other (its own collision group), where
# Box3D's humans leave out only jointed neighbours, the two thighs (a filter joint) and three
# parts that share a negative group with the other humans of their cell. Box3D's cell is one
# static body with the two meshes; here each mesh is a body of its own ({2 * cells} static bodies),
# the grid a heightfield of the same vertices (flat: its diagonals do not matter).
# Written by scripts/scenes/rain.py; edit that and regenerate.
description = "Box3D rain: {humans} ragdolls dropped on a {GRID_COUNT} x {GRID_COUNT} grid of mesh cells with tori"

[settings]
gravity = [0, -10, 0]

[[body]]
type = "static"
shape = {{ heightfield = {{ size = [{GRID_SIZE:g}, {GRID_SIZE:g}], cells = [{MESH_CELLS}, {MESH_CELLS}] }} }}
position = [{first:g}, 0, {first:g}]
copies = {{ count = [{GRID_COUNT}, 1, {GRID_COUNT}], step = [{GRID_SIZE:g}, 0, {GRID_SIZE:g}] }}

[[body]]
type = "static"
position = [{first:g}, 0, {first:g}]
copies = {{ count = [{GRID_COUNT}, 1, {GRID_COUNT}], step = [{GRID_SIZE:g}, 0, {GRID_SIZE:g}] }}
shape = {{ mesh = {{ vertices = [""")
    for v in vertices:
        print("  " + b.vec(v) + ",")
    print("], triangles = [")
    for i in range(0, len(triangles), 8):
        print("  " + ", ".join(f"[{a}, {c}, {d}]" for a, c, d in triangles[i:i + 8]) + ",")
    print("] } }\n")
    for k in range(GROUP_SIZE):
        x = first + 0.75 * k + PELVIS[0]
        print(f"[[ragdoll]]\nposition = [{x:g}, {20 + PELVIS[1]:g}, {first + PELVIS[2]:g}]\n"
              f"copies = {{ count = [{GRID_COUNT}, 1, {GRID_COUNT}], step = [{GRID_SIZE:g}, 0, {GRID_SIZE:g}] }}\n")


if __name__ == "__main__":
    main()
