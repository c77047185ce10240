#!/usr/bin/env python3
"""Writes configs/scenes/ragdolls.toml: Jolt's PerformanceTest "Ragdoll" scene
(PerformanceTest/RagdollScene.h) with Spindle's [[ragdoll]] humanoid on a generated
heightfield.

Jolt drops 4 x 4 piles, 4 m apart, of 10 ragdolls each, 0.6 m apart vertically, every
ragdoll in a "dead" pose turned by a random angle about the vertical. Here each pile
level is one [[ragdoll]] entry repeated 4 x 4 by `copies`, lying on its back and turned
by a multiple of the golden angle instead of a random one, so the file stays short and
the piles are not stacked in step.

Usage: python3 scripts/scenes/ragdolls.py > configs/scenes/ragdolls.toml
"""

import math

PILES_PER_AXIS = 4
PILE_SIZE = 10
HORIZONTAL_SEPARATION = 4.0  # m, Jolt's cHorizontalSeparation
VERTICAL_SEPARATION = 0.6  # m, Jolt's cVerticalSeparation
AMPLITUDE = 0.5  # m, the terrain's highest point
WAVELENGTH = 8.0  # m: the piles' centres fall on crests and troughs
GOLDEN_ANGLE = 180.0 * (3.0 - math.sqrt(5.0))  # degrees


def lying(yaw_degrees):
    """[w, x, y, z]: a quarter turn about x (the standing humanoid onto its back, head
    toward -z), then `yaw_degrees` about y."""
    half = math.radians(yaw_degrees) / 2
    c, s, r = math.cos(half), math.sin(half), math.sqrt(0.5)
    return [r * c, -r * c, r * s, r * s]


def main():
    first = -HORIZONTAL_SEPARATION * (PILES_PER_AXIS - 1) / 2
    print(f"""# Written by scripts/scenes/ragdolls.py; edit that, not this.
# Jolt's PerformanceTest "Ragdoll" scene: {PILES_PER_AXIS} x {PILES_PER_AXIS} piles of {PILE_SIZE} ragdolls, {HORIZONTAL_SEPARATION:g} m apart,
# the ragdolls of a pile {VERTICAL_SEPARATION:g} m apart, dropped on a terrain. How it differs from Jolt's:
# - the ragdoll is Spindle's [[ragdoll]] (12 boxes and capsules, 11 joints: docs/scenes.md)
#   instead of Jolt's Human.tof (23 parts, all swing-twist); the same friction,
#   restitution and damping as Human.tof's parts;
# - it lies on its back with its arms 45 degrees out, turned by multiples of the golden
#   angle, instead of Jolt's "dead_pose1" animation turned by random angles;
# - no motors: Jolt drives each ragdoll toward its pose with motors;
# - the terrain is a {AMPLITUDE:g} m sine heightfield instead of a Horizon Zero Dawn level
#   (Jolt's terrain2.bof), and each pile starts above its highest point rather than at
#   the ground below it (Jolt casts a ray).
description = "Jolt's Ragdoll performance scene: 16 piles of 10 ragdolls dropped on a heightfield"

[defaults]
friction = 1
restitution = 0.15
linear_damping = 0.05
angular_damping = 0.05

[[body]]
type = "static"
shape = {{ heightfield = {{ size = [30, 30], cells = [30, 30], amplitude = {AMPLITUDE:g}, wavelength = {WAVELENGTH:g} }} }}""")
    for i in range(PILE_SIZE):
        yaw = (i * GOLDEN_ANGLE) % 360
        q = ", ".join(f"{v:.6f}" for v in lying(yaw))
        y = AMPLITUDE + VERTICAL_SEPARATION * (i + 1)
        print(f"""
[[ragdoll]]
position = [{first:g}, {y:g}, {first:g}]
orientation = [{q}]  # on its back, turned {yaw:.1f} degrees
copies = {{ count = [{PILES_PER_AXIS}, 1, {PILES_PER_AXIS}], step = [{HORIZONTAL_SEPARATION:g}, 0, {HORIZONTAL_SEPARATION:g}] }}""")


if __name__ == "__main__":
    main()
