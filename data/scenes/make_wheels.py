#!/usr/bin/env python3
"""Writes ../meshes/wheel.obj (a wheel of radius 1 ls in the x-y plane, axis z: a rim 0.1 ls deep
and 0.1 ls thick, four spokes 0.06 ls wide through the hub, 96 rim segments) and the two scenes
that spin it (docs/MOTION.md "Spinning and rolling bodies"): rolling_wheel.json, the wheel rolling along the ground y = -1 at
0.9c (w R = |v| in its centre frame: the contact point is at rest in the lab), and
spinning_wheel.json, the wheel spinning in place at a rim speed of 0.9c, seen along its axis.
Run from this folder; the outputs are committed."""
import json
import math

SEGMENTS = 96
R_OUT, R_IN, HALF = 1.0, 0.9, 0.05
SPOKE = 0.03


def box(verts, tris, lo, hi):
    base = len(verts)
    for z in (lo[2], hi[2]):
        for y in (lo[1], hi[1]):
            for x in (lo[0], hi[0]):
                verts.append((x, y, z))
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    for a, b, c, d in quads:
        tris.append((base + a, base + b, base + c))
        tris.append((base + a, base + c, base + d))


def wheel():
    verts, tris = [], []
    # The rim: an annulus prism, rings (outer front, outer back, inner front, inner back).
    for r in (R_OUT, R_IN):
        for z in (HALF, -HALF):
            for k in range(SEGMENTS):
                a = 2 * math.pi * k / SEGMENTS
                verts.append((r * math.cos(a), r * math.sin(a), z))
    of, ob, inf, inb = 0, SEGMENTS, 2 * SEGMENTS, 3 * SEGMENTS
    for k in range(SEGMENTS):
        n = (k + 1) % SEGMENTS
        for a0, a1, flip in ((of, ob, False), (inf, inb, True), (of, inf, True), (ob, inb, False)):
            t1 = (a0 + k, a1 + k, a1 + n)
            t2 = (a0 + k, a1 + n, a0 + n)
            if flip:
                t1, t2 = t1[::-1], t2[::-1]
            tris += [t1, t2]
    # Four spokes: two bars along x and y, through the hub.
    box(verts, tris, (-R_IN, -SPOKE, -SPOKE), (R_IN, SPOKE, SPOKE))
    box(verts, tris, (-SPOKE, -R_IN, -SPOKE), (SPOKE, R_IN, SPOKE))
    return verts, tris


def main():
    verts, tris = wheel()
    with open("../meshes/wheel.obj", "w") as f:
        f.write("# wheel of radius 1 ls, axis z (data/scenes/make_wheels.py)\n")
        for v in verts:
            f.write("v %.9g %.9g %.9g\n" % v)
        for t in tris:
            f.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))
    rolling = {
        "_about": "A wheel of radius 1 ls rolls along the ground y = -1 at 0.9c (docs/MOTION.md, Spinning and rolling bodies): velocity [0.9, 0, 0] "
                  "with angular_velocity [0, 0, -0.9] in its centre frame (w R = |v|: the contact point is at rest in the "
                  "lab, the top moves at 2v / (1 + v^2) = 0.9945c). It passes 5 ls in front of the camera at t = 5 s, "
                  "seen there at t = 10 s. "
                  "Written by make_wheels.py.",
        "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 70, "instant_delay": 5},
        "frames": {"start": 0, "end": 16, "fps": 10},
        "model": "relativistic",
        "tolerance": "vertex",
        "objects": [{"name": "wheel", "mesh": "../meshes/wheel.obj", "position": [-4.5, 0, 0], "t0": 0,
                     "velocity": [0.9, 0, 0], "angular_velocity": [0, 0, -0.9]}],
    }
    spinning = {
        "_about": "A wheel of radius 1 ls spins in place at a rim speed of 0.9c (angular_velocity 0.9 rad/s about z), "
                  "seen from 4 ls along its axis (docs/MOTION.md, Spinning and rolling bodies): the spokes appear as spirals phi0 + w (t_c - "
                  "sqrt(D^2 + r^2)), the rim's clocks run at sqrt(1 - 0.81) = 0.436 of the hub's (_PROPER_TIME). "
                  "Written by make_wheels.py.",
        "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 60, "instant_delay": 4},
        "frames": {"start": 0, "end": 7, "fps": 10},
        "model": "relativistic",
        "tolerance": "vertex",
        "objects": [{"name": "wheel", "mesh": "../meshes/wheel.obj", "position": [0, 0, 0],
                     "angular_velocity": [0, 0, 0.9]}],
    }
    for name, doc in (("rolling_wheel.json", rolling), ("spinning_wheel.json", spinning)):
        with open(name, "w") as f:
            json.dump(doc, f, indent=2)
            f.write("\n")


if __name__ == "__main__":
    main()
