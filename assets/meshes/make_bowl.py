#!/usr/bin/env python3
"""Writes bowl.obj, the rigid bowl of assets/scenes/torus_on_mesh.toml (scene units: mm).

A closed surface of revolution about the y axis: the profile runs from the outer pole
(0, -R_OUT) up the outer sphere (radius R_OUT, centre at the origin) to the rim at
y = RIM_Y, across the flat rim to the inner sphere (radius R_IN, same centre), and down
it to the inner pole (0, -R_IN). Revolved in SEGMENTS steps: fans at the two poles, two
triangles per quad elsewhere, counter-clockwise seen from outside (the solid is the wall
between the spheres). Run `python3 make_bowl.py` here to regenerate it.
"""
import math

R_OUT, R_IN, RIM_Y = 14.0, 12.0, -2.0
SEGMENTS, ARC_STEPS = 48, 16


def arc(r, steps):
    # From the pole (angle 0: straight down) to the rim, excluding the pole itself.
    top = math.acos(-RIM_Y / r)  # angle from -y where y = RIM_Y
    return [(r * math.sin(top * i / steps), -r * math.cos(top * i / steps)) for i in range(1, steps + 1)]


def main():
    # Profile from the outer pole to the inner pole (the poles are single vertices).
    profile = arc(R_OUT, ARC_STEPS) + list(reversed(arc(R_IN, ARC_STEPS)))
    verts = [(0.0, -R_OUT, 0.0)]
    for s in range(SEGMENTS):
        a = 2 * math.pi * s / SEGMENTS
        for (r, y) in profile:
            verts.append((r * math.cos(a), y, -r * math.sin(a)))
    verts.append((0.0, -R_IN, 0.0))
    n = len(profile)
    idx = lambda s, i: 2 + (s % SEGMENTS) * n + i  # 1-based OBJ index of profile point i on meridian s
    faces = []
    for s in range(SEGMENTS):
        faces.append((1, idx(s + 1, 0), idx(s, 0)))  # outer pole fan
        for i in range(n - 1):
            a, b, c, d = idx(s, i), idx(s, i + 1), idx(s + 1, i + 1), idx(s + 1, i)
            faces.append((a, d, c))
            faces.append((a, c, b))
        faces.append((len(verts), idx(s, n - 1), idx(s + 1, n - 1)))  # inner pole fan
    with open("bowl.obj", "w") as f:
        f.write("# rigid bowl for torus_on_mesh.toml, written by make_bowl.py: outer radius %g, inner radius %g,\n"
                "# rim at y = %g (mm), %d segments, %d arc steps\n" % (R_OUT, R_IN, RIM_Y, SEGMENTS, ARC_STEPS))
        for v in verts:
            f.write("v %.9g %.9g %.9g\n" % v)
        for t in faces:
            f.write("f %d %d %d\n" % t)


if __name__ == "__main__":
    main()
