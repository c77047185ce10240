#!/usr/bin/env python3
"""Writes configs/scenes/large_world.toml: Box3D's benchmark "large_world" (shared/benchmarks.c,
CreateLargeWorld and StepLargeWorld, Box3D 30c67b5).

Usage: python3 scripts/scenes/large_world.py > configs/scenes/large_world.toml
"""

GRID = 1000  # STATIC_FLOOR_GRID (Release)
CELL = 10.0  # STATIC_FLOOR_CELL_SIZE
SPHERES = 100  # STATIC_FLOOR_SPHERES (Release)
DROP_INTERVAL = 5  # STATIC_FLOOR_DROP_INTERVAL


def main():
    half_span = 0.5 * CELL * GRID
    side = 1
    while side * side < SPHERES:
        side += 1
    inset = 0.1 * 2.0 * half_span
    usable = 2.0 * half_span - 2.0 * inset
    pitch = usable / side
    first = -half_span + inset + 0.5 * pitch
    floor_first = -half_span + 0.5 * CELL
    print(f"""# Box3D's benchmark "large_world" (shared/benchmarks.c, CreateLargeWorld and StepLargeWorld; Box3D
# 30c67b5, its Release sizes): a floor of {GRID} x {GRID} static bodies ({GRID * GRID:,}), each a box of half
# extents ({0.5 * CELL:g}, 0.25, {0.5 * CELL:g}) centred at y = 0, {CELL:g} m apart from ({floor_first:g}, 0, {floor_first:g}); {SPHERES} dynamic
# spheres of radius 0.5 (density 1000, friction 0.6: Box3D's defaults) at y = 1.5 on a {side} x {side} grid
# {pitch:g} m apart over the middle 80% of the floor; gravity -10, sleeping on (Box3D's defaults).
# What it measures: a step's cost with a million static bodies and a handful moving.
# Differs in: Box3D drops the spheres one at a time, one every {DROP_INTERVAL} steps from step {DROP_INTERVAL} (all in
# by step {DROP_INTERVAL * SPHERES}); a scene cannot add bodies while it runs, so here all {SPHERES} start at step 0.
# Box3D builds its floor boxes as hulls with invokeContactCreation set (every static shape enters
# its broadphase move buffer once); Spindle has no such flag and makes boxes.
# Written by scripts/scenes/large_world.py; edit that and regenerate.
description = "Box3D large_world: {SPHERES} spheres dropped on a floor of {GRID * GRID:,} static boxes"

[settings]
gravity = [0, -10, 0]

[[body]]
type = "static"
shape = {{ box = [{0.5 * CELL:g}, 0.25, {0.5 * CELL:g}] }}
position = [{floor_first:g}, 0, {floor_first:g}]
copies = {{ count = [{GRID}, 1, {GRID}], step = [{CELL:g}, 0, {CELL:g}] }}

# Box3D's sphere k is at grid cell (k % {side}, k / {side}): x varying fastest, as copies go.
[[body]]
shape = {{ sphere = 0.5 }}
position = [{first:g}, 1.5, {first:g}]
copies = {{ count = [{side}, 1, {side}], step = [{pitch:g}, 0, {pitch:g}] }}
""")


if __name__ == "__main__":
    main()
