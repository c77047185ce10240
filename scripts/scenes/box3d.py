"""Box3D's float32 arithmetic and shape builders, for the scene generators in this folder.

Box3D (github.com/erincatto/box3d, 30c67b5) builds its benchmark shapes in float32 with
its own cosine/sine approximation (b3ComputeCosSin); these helpers repeat that arithmetic
operation by operation (each double result rounded to float32, which is exact for + - * /
and sqrt), so the points written into the scene files are Box3D's points, bit for bit.
"""

import math
import struct


def f32(x):
    """x rounded to the nearest float32, as a Python float."""
    return struct.unpack("f", struct.pack("f", x))[0]


PI = f32(3.14159265359)  # B3_PI


def add(a, b):
    return f32(a + b)


def sub(a, b):
    return f32(a - b)


def mul(a, b):
    return f32(a * b)


def div(a, b):
    return f32(a / b)


def sqrt(a):
    return f32(math.sqrt(a))


def compute_cos_sin(radians):
    """b3ComputeCosSin (src/math_functions.c): returns (cosine, sine)."""
    x = f32(math.remainder(radians, mul(2.0, PI)))  # b3UnwindAngle: remainderf is exact
    pi2 = mul(PI, PI)
    half_pi = mul(0.5, PI)
    if x < -half_pi:
        y = add(x, PI)
        y2 = mul(y, y)
        c = -div(sub(pi2, mul(4.0, y2)), add(pi2, y2))
    elif x > half_pi:
        y = sub(x, PI)
        y2 = mul(y, y)
        c = -div(sub(pi2, mul(4.0, y2)), add(pi2, y2))
    else:
        y2 = mul(x, x)
        c = div(sub(pi2, mul(4.0, y2)), add(pi2, y2))
    if x < 0.0:
        y = add(x, PI)
        t = mul(y, sub(PI, y))
        s = -div(mul(16.0, t), sub(mul(5.0, pi2), mul(4.0, t)))
    else:
        t = mul(x, sub(PI, x))
        s = div(mul(16.0, t), sub(mul(5.0, pi2), mul(4.0, t)))
    mag = sqrt(add(mul(s, s), mul(c, c)))
    inv = div(1.0, mag) if mag > 0.0 else 0.0
    return mul(c, inv), mul(s, inv)


def vadd(a, b):
    return tuple(add(x, y) for x, y in zip(a, b))


def mul_add(a, s, b):
    """b3MulAdd: a + s * b."""
    return tuple(add(x, mul(s, y)) for x, y in zip(a, b))


def mul_sub(a, s, b):
    """b3MulSub: a - s * b."""
    return tuple(sub(x, mul(s, y)) for x, y in zip(a, b))


def mul_sv(s, a):
    return tuple(mul(s, x) for x in a)


def cross(a, b):
    return (sub(mul(a[1], b[2]), mul(a[2], b[1])), sub(mul(a[2], b[0]), mul(a[0], b[2])),
            sub(mul(a[0], b[1]), mul(a[1], b[0])))


def dot(a, b):
    return add(add(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2]))


def normalize(a):
    """b3Normalize."""
    length_sq = dot(a, a)
    s = div(1.0, sqrt(length_sq))
    return mul_sv(s, a)


def quat_from_axis_angle(axis, radians):
    """b3MakeQuatFromAxisAngle: ((x, y, z), s)."""
    c, s = compute_cos_sin(mul(0.5, radians))
    return (mul(s, axis[0]), mul(s, axis[1]), mul(s, axis[2])), c


def rotate(q, v):
    """b3RotateVector."""
    t1 = cross(q[0], v)
    t2 = mul_add(t1, q[1], v)
    t3 = cross(q[0], t2)
    return mul_add(v, 2.0, t3)


def inv_rotate(q, v):
    """b3InvRotateVector."""
    t1 = cross(q[0], v)
    t2 = mul_sub(t1, q[1], v)
    t3 = cross(q[0], t2)
    return mul_add(v, 2.0, t3)


def cylinder(height, radius, y_offset, sides):
    """b3CreateCylinder's points (src/hull.c): `sides` around the y axis, bottom at y_offset."""
    points = []
    alpha = 0.0
    delta = div(mul(2.0, PI), float(sides))
    for _ in range(sides):
        c, s = compute_cos_sin(alpha)
        points.append((mul(radius, c), f32(y_offset), mul(radius, s)))
        points.append((mul(radius, c), add(y_offset, height), mul(radius, s)))
        alpha = add(alpha, delta)
    return points


def rock(radius):
    """b3CreateRock's points (src/hull.c): a Fibonacci lattice of 10 points on a sphere."""
    count = 10
    phi = div(add(1.0, sqrt(5.0)), 2.0)
    theta = div(mul(2.0, PI), phi)
    c, s = 1.0, 0.0
    dc, ds = compute_cos_sin(theta)
    points = []
    for i in range(count):
        z = sub(1.0, div(add(mul(2.0, float(i)), 1.0), float(count)))
        r_xy = sqrt(sub(1.0, mul(z, z)))
        points.append((mul(mul(radius, r_xy), c), mul(mul(radius, r_xy), s), mul(radius, z)))
        c, s = sub(mul(dc, c), mul(ds, s)), add(mul(ds, c), mul(dc, s))
    return points


def number(x):
    """A float32 value written so that it reads back exactly (shortest repr of the double)."""
    r = repr(float(x))
    return r[:-2] if r.endswith(".0") else r


def vec(v):
    return "[" + ", ".join(number(x) for x in v) + "]"


def hull(points):
    return "{ hull = [" + ", ".join(vec(p) for p in points) + "] }"
