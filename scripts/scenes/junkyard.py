#!/usr/bin/env python3
"""Writes configs/scenes/junkyard.toml: Box3D's benchmark "junkyard" (shared/benchmarks.c,
CreateJunkyard and StepJunkyard, Box3D 30c67b5): 10,584 rocks dropped into a walled yard and
ploughed by a kinematic cylinder going round a circle of radius 35 m.

Usage: python3 scripts/scenes/junkyard.py > configs/scenes/junkyard.toml
"""

import box3d as b

LAYERS = 24
SIDE = 21  # X and Z run 0..20
RADIUS = 35.0  # the pusher's circle
DEGREES_PER_S = 6.0


def main():
    rock = b.rock(1.5)
    # The pusher: b3CreateCylinder(24, 4, 0, 16) on a body at (35, 0, 0); here the body sits
    # at the circle's centre and the cylinder's points are moved out by 35 m along x.
    pusher = [(b.add(p[0], RADIUS), p[1], p[2]) for p in b.cylinder(24.0, 4.0, 0.0, 16)]
    omega = b.mul(DEGREES_PER_S, b.div(b.PI, 180.0))
    rocks = LAYERS * SIDE * SIDE
    print(f"""# Box3D's benchmark "junkyard" (shared/benchmarks.c, CreateJunkyard and StepJunkyard; Box3D
# 30c67b5): {rocks:,} rocks (b3CreateRock(1.5): the hull of a 10-point Fibonacci lattice on a sphere of
# radius 1.5, Box3D's float32 points; density 1000, friction 0.6) in {LAYERS} layers of {SIDE} x {SIDE}, 4 m apart,
# from (-40, 25, -40); a floor box of half extents (120, 1, 120) at (0, -1, 0) and four walls 16 m
# high (half extents (1, 8, 50) at x = +-50, (50, 8, 1) at z = +-50, centres at y = 7); a kinematic
# pusher, a 16-sided cylinder of radius 4 and height 24 standing on the floor, going round the
# circle of radius {RADIUS:g} about the y axis at {DEGREES_PER_S:g} degrees a second, starting at (35, 0, 0) and
# heading for -z; gravity -10 (Box3D's); sleeping on (Box3D's default).
# Differs in: Box3D's floor and walls are five shapes of one static body (five static bodies
# here). Box3D moves its pusher with b3Body_SetTargetTransform every step (a velocity that
# reaches the next point of the circle, the orientation held fixed). A scene cannot set
# velocities over time, so here the pusher's body sits at the circle's centre with the
# cylinder 35 m out along x and turns at {DEGREES_PER_S:g} deg/s about y: the cylinder follows the same
# circle (along the arc, not the chords) but also turns about its own axis at {DEGREES_PER_S:g} deg/s (its
# surface slides 0.42 m/s against the rocks).
# Written by scripts/scenes/junkyard.py; edit that and regenerate.
description = "Box3D junkyard: {rocks} rocks in a walled yard ploughed by a kinematic cylinder"

[settings]
gravity = [0, -10, 0]

[defaults]
shape = {b.hull(rock)}

[[body]]
type = "static"
shape = {{ box = [120, 1, 120] }}
position = [0, -1, 0]

[[body]]
type = "static"
shape = {{ box = [1, 8, 50] }}
position = [-50, 7, 0]
copies = {{ count = [2, 1, 1], step = [100, 0, 0] }}

[[body]]
type = "static"
shape = {{ box = [50, 8, 1] }}
position = [0, 7, -50]
copies = {{ count = [1, 1, 2], step = [0, 0, 100] }}
""")
    print("# The rocks (the [defaults] shape), in Box3D's order: z fastest, then x, then y.")
    for y in range(LAYERS):
        for x in range(SIDE):
            print(f"[[body]]\nposition = [{-40 + 4 * x}, {4 * y + 25}, -40]\n"
                  f"copies = {{ count = [1, 1, {SIDE}], step = [0, 0, 4] }}\n")
    print(f"""[[body]]
type = "kinematic"
shape = {b.hull(pusher)}
position = [0, 0, 0]
angular_velocity = [0, {b.number(omega)}, 0]""")


if __name__ == "__main__":
    main()
