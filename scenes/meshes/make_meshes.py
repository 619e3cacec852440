#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Writes the small obstacle meshes the scenes use, built from boxes (no downloads).

Object frame as for primitives: centred in x and y, standing on z = 0, facing +x.
  person.ply  0.35 (x) x 0.50 (y) x 1.75 (z) m: legs, feet, torso, arms, neck, head
  cow.obj     2.00 (x) x 0.70 (y) x 1.50 (z) m: legs, body, neck and head, tail
Run from anywhere: python3 scenes/meshes/make_meshes.py
"""
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def box(x0, x1, y0, y1, z0, z1):
    """8 corners and 12 triangles, counter-clockwise seen from outside."""
    v = [(x, y, z) for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)]
    # corner index = 4*iz + 2*iy + ix
    faces = [
        (0, 2, 3), (0, 3, 1),  # bottom (-z)
        (4, 5, 7), (4, 7, 6),  # top (+z)
        (0, 1, 5), (0, 5, 4),  # -y
        (2, 6, 7), (2, 7, 3),  # +y
        (0, 4, 6), (0, 6, 2),  # -x
        (1, 3, 7), (1, 7, 5),  # +x
    ]
    return v, faces


def merge(boxes):
    vertices, triangles = [], []
    for v, f in boxes:
        base = len(vertices)
        vertices += v
        triangles += [(a + base, b + base, c + base) for a, b, c in f]
    return vertices, triangles


def person():
    return merge([
        box(-0.100, 0.100, -0.170, -0.030, 0.08, 0.85),  # right leg
        box(-0.100, 0.100, 0.030, 0.170, 0.08, 0.85),    # left leg
        box(-0.100, 0.225, -0.170, -0.030, 0.00, 0.08),  # right foot
        box(-0.100, 0.225, 0.030, 0.170, 0.00, 0.08),    # left foot
        box(-0.125, 0.125, -0.200, 0.200, 0.85, 1.45),   # torso
        box(-0.070, 0.070, -0.250, -0.200, 0.80, 1.42),  # right arm
        box(-0.070, 0.070, 0.200, 0.250, 0.80, 1.42),    # left arm
        box(-0.050, 0.050, -0.050, 0.050, 1.45, 1.50),   # neck
        box(-0.100, 0.100, -0.090, 0.090, 1.50, 1.75),   # head
    ])


def cow():
    legs = [box(x, x + 0.14, y, y + 0.14, 0.0, 0.72)
            for x in (-0.70, 0.35) for y in (-0.28, 0.14)]
    return merge(legs + [
        box(-0.75, 0.55, -0.35, 0.35, 0.70, 1.35),  # body
        box(0.55, 0.75, -0.18, 0.18, 1.00, 1.40),   # neck
        box(0.75, 1.00, -0.15, 0.15, 1.05, 1.50),   # head
        box(-1.00, -0.75, -0.03, 0.03, 0.60, 1.30),  # tail
    ])


def write_ply(path, mesh):
    vertices, triangles = mesh
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\ncomment sonomap scenes/meshes/make_meshes.py\n")
        f.write(f"element vertex {len(vertices)}\n")
        f.write("property float x\nproperty float y\nproperty float z\n")
        f.write(f"element face {len(triangles)}\nproperty list uchar int vertex_indices\n")
        f.write("end_header\n")
        for v in vertices:
            f.write("%.4f %.4f %.4f\n" % v)
        for t in triangles:
            f.write("3 %d %d %d\n" % t)


def write_obj(path, mesh):
    vertices, triangles = mesh
    with open(path, "w") as f:
        f.write("# sonomap scenes/meshes/make_meshes.py\n")
        for v in vertices:
            f.write("v %.4f %.4f %.4f\n" % v)
        for a, b, c in triangles:
            f.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))


if __name__ == "__main__":
    write_ply(os.path.join(HERE, "person.ply"), person())
    write_obj(os.path.join(HERE, "cow.obj"), cow())
