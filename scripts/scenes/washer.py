#!/usr/bin/env python3
"""Writes configs/scenes/washer.toml: Box3D's benchmark "washer" (shared/benchmarks.c, CreateWasher,
Box3D 30c67b5): 8,000 cubes tumbling in a kinematic drum that turns at 25 degrees a second.

Usage: python3 scripts/scenes/washer.py > configs/scenes/washer.toml
"""

import box3d as b

GRID = 20
A = 0.2  # cube half extent
MOTOR_DEGREES_PER_S = 25.0


def drum_hulls():
    """The drum's 40 hulls, in the drum's frame, in Box3D's order: for each of 36 segments
    of the rim (r 16..18, z -10..10) the rim piece, and after segments 0, 9, 18 and 27 a
    paddle (r 14..16)."""
    r0, r1, r2 = 14.0, 16.0, 18.0
    nd, pd = (0.0, 0.0, -10.0), (0.0, 0.0, 10.0)
    z_axis = (0.0, 0.0, 1.0)
    angle = b.div(b.PI, 18.0)
    q = b.quat_from_axis_angle(z_axis, angle)
    qo = b.quat_from_axis_angle(z_axis, b.mul(0.1, angle))
    u1 = (1.0, 0.0, 0.0)
    hulls = []
    for i in range(36):
        u2 = (1.0, 0.0, 0.0) if i == 35 else b.rotate(q, u1)
        a1 = b.inv_rotate(qo, u1)
        a2 = b.rotate(qo, u2)
        hulls.append([b.mul_add(nd, r1, a1), b.mul_add(nd, r2, a1), b.mul_add(nd, r1, a2), b.mul_add(nd, r2, a2),
                      b.mul_add(pd, r1, a1), b.mul_add(pd, r2, a1), b.mul_add(pd, r1, a2), b.mul_add(pd, r2, a2)])
        if i % 9 == 0:
            hulls.append([b.mul_add(nd, r0, u1), b.mul_add(nd, r1, u1), b.mul_add(nd, r0, u2), b.mul_add(nd, r1, u2),
                          b.mul_add(pd, r0, u1), b.mul_add(pd, r1, u1), b.mul_add(pd, r0, u2), b.mul_add(pd, r1, u2)])
        u1 = u2
    return hulls


def main():
    hulls = drum_hulls()
    omega = b.mul(b.div(b.PI, 180.0), MOTOR_DEGREES_PER_S)
    cubes = GRID ** 3
    start = -2.0 * A * GRID
    step = 4.0 * A
    print(f"""# Box3D's benchmark "washer" (shared/benchmarks.c, CreateWasher; Box3D 30c67b5): {cubes:,} cubes of
# half extent {A:g} (density 1000, friction 0.6) in a {GRID} x {GRID} x {GRID} grid {step:g} m apart, from
# ({start:g}, {start + 21:g}, {start:g}), inside a kinematic drum centred at (0, 21, 0) turning about z at
# {MOTOR_DEGREES_PER_S:g} degrees a second and drifting at (0.001, -0.002, 0) m/s, as Box3D's does: a rim of
# 36 hulls (radius 16 to 18, z from -10 to 10, open at both ends) and 4 paddles (radius 14 to 16);
# a floor box of half extents (60, 1, 60) at (0, -1, 0); gravity -10 (Box3D's); sleeping on
# (Box3D's default). The hulls' points are Box3D's, computed with its float32 arithmetic.
# Differs in: Box3D's drum is one kinematic body with 40 hull shapes; a Spindle body has one
# shape, so the drum here is 40 kinematic bodies, each with its origin at the drum's centre,
# the same hull in the same frame and the same velocities. A kinematic body turns about its
# origin, so together they move exactly as Box3D's drum (42 non-dynamic bodies, not 2).
# Written by scripts/scenes/washer.py; edit that and regenerate.
description = "Box3D washer: {cubes} cubes tumbling in a kinematic drum (40 hulls) turning at {MOTOR_DEGREES_PER_S:g} deg/s"

[settings]
gravity = [0, -10, 0]

[defaults]
shape = {{ box = [{A:g}, {A:g}, {A:g}] }}

[[body]]
type = "static"
shape = {{ box = [60, 1, 60] }}
position = [0, -1, 0]
""")
    for points in hulls:
        print(f"""[[body]]
type = "kinematic"
shape = {b.hull(points)}
position = [0, 21, 0]
velocity = [0.001, -0.002, 0]
angular_velocity = [0, 0, {b.number(omega)}]
""")
    print("# The cubes (the [defaults] shape), in Box3D's order: z fastest, then y, then x.")
    for i in range(GRID):
        for j in range(GRID):
            print(f"[[body]]\nposition = [{start + step * i:.6g}, {start + 21 + step * j:.6g}, {start:g}]\n"
                  f"copies = {{ count = [1, 1, {GRID}], step = [0, 0, {step:g}] }}\n")


if __name__ == "__main__":
    main()
