#!/usr/bin/env python3
"""Writes limn's example meshes (OBJ with OpenSubdiv tag lines) and examples.json, their index.

Run from anywhere: python3 examples/make_examples.py. The OBJ files are committed; this script
is how they were made, so that a change to one is a change to the code that makes it.
Faces are counter-clockwise seen from outside; tag lines use 0-based indices.
"""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def fmt(x):
    s = "%.6f" % x
    s = s.rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def write_obj(name, comment, points, faces, tags=()):
    lines = ["# " + line for line in comment.strip().splitlines()]
    lines += ["v %s %s %s" % tuple(fmt(c) for c in p) for p in points]
    lines += ["f " + " ".join(str(i + 1) for i in f) for f in faces]
    lines += list(tags)
    with open(os.path.join(HERE, name + ".obj"), "w") as out:
        out.write("\n".join(lines) + "\n")


def cube():
    p = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    idx = {q: i for i, q in enumerate(p)}
    # Each face as (axis, sign): corners ordered counter-clockwise seen from outside.
    faces = []
    for axis in range(3):
        for sign in (-1, 1):
            u, v = [a for a in range(3) if a != axis]
            corners = []
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                q = [0, 0, 0]
                q[axis], q[u], q[v] = sign, a, b
                corners.append(idx[tuple(q)])
            # (u, v, axis) is right-handed for axis 0 and 2 with the order above when sign > 0.
            right_handed = (axis, u, v) in ((0, 1, 2), (1, 2, 0), (2, 0, 1))
            if (sign > 0) != right_handed:
                corners.reverse()
            faces.append(corners)
    write_obj("cube", "Cube: 8 vertices, 6 quads; Catmull-Clark makes it a rounded box.", p, faces)


def torus(n_major=12, n_minor=8, R=1.0, r=0.4):
    points = []
    for i in range(n_major):
        a = 2 * math.pi * i / n_major
        for j in range(n_minor):
            b = 2 * math.pi * j / n_minor
            rr = R + r * math.cos(b)
            points.append((rr * math.cos(a), r * math.sin(b), -rr * math.sin(a)))
    vid = lambda i, j: (i % n_major) * n_minor + (j % n_minor)
    faces = [[vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)]
             for i in range(n_major) for j in range(n_minor)]
    # Outward orientation check on face 0: its normal points away from the tube centre.
    tags = []
    # An infinitely sharp ring around the tube (a meridian) and a semi-sharp ring along the
    # outer equator, plus the inner equator at sharpness 2.
    ring = [vid(0, j) for j in range(n_minor)] + [vid(0, 0)]
    outer = [vid(i, 0) for i in range(n_major)] + [vid(0, 0)]
    inner = [vid(i, n_minor // 2) for i in range(n_major)] + [vid(0, n_minor // 2)]
    for chain, s in ((ring, 10.0), (outer, 2.0), (inner, 1.0)):
        edges = []
        for a, b in zip(chain, chain[1:]):
            edges += [a, b]
        tags.append("t crease %d/1/0 %s %s" % (len(edges), " ".join(map(str, edges)), fmt(s)))
    write_obj("torus_creased",
              "Torus, 12 x 8 quads, with crease tags: one meridian ring infinitely sharp,\n"
              "the outer equator at sharpness 2, the inner one at 1.", points, faces, tags)


def icosahedron():
    t = (1 + math.sqrt(5)) / 2
    s = 1 / math.sqrt(1 + t * t)
    p = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
         (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    p = [(x * s, y * s, z * s) for x, y, z in p]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9),
         (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    write_obj("icosahedron", "Icosahedron: 12 vertices of valence 5, 20 triangles (Loop scheme).",
              p, [list(x) for x in f])


def pawn(segments=12):
    # The profile from the bottom centre up to the top, as (radius, height); the first and last
    # points are on the axis (poles, closed by triangle fans).
    profile = [(0.62, 0.0), (0.62, 0.12), (0.48, 0.22), (0.30, 0.34), (0.22, 0.70), (0.20, 1.00),
               (0.40, 1.08), (0.20, 1.16), (0.30, 1.34), (0.33, 1.52), (0.24, 1.72)]
    points = [(0.0, 0.0, 0.0)]
    for r, y in profile:
        for k in range(segments):
            a = 2 * math.pi * k / segments
            points.append((r * math.cos(a), y, -r * math.sin(a)))
    top = len(points)
    points.append((0.0, 1.80, 0.0))
    ring = lambda level, k: 1 + level * segments + (k % segments)
    faces = [[0, ring(0, k + 1), ring(0, k)] for k in range(segments)]  # bottom fan, facing down
    for level in range(len(profile) - 1):
        for k in range(segments):
            faces.append([ring(level, k), ring(level, k + 1), ring(level + 1, k + 1),
                          ring(level + 1, k)])
    last = len(profile) - 1
    faces += [[ring(last, k), ring(last, k + 1), top] for k in range(segments)]
    # The rim of the flat base and the collar are sharp.
    tags = []
    for level, s in ((0, 10.0), (6, 3.0)):
        edges = []
        for k in range(segments):
            edges += [ring(level, k), ring(level, k + 1)]
        tags.append("t crease %d/1/0 %s %s" % (len(edges), " ".join(map(str, edges)), fmt(s)))
    write_obj("pawn", "A chess pawn: a profile revolved in 12 steps, poles closed by triangle\n"
              "fans, the base rim infinitely sharp and the collar at sharpness 3.",
              points, faces, tags)


def grid(n=6):
    points = []
    for j in range(n + 1):
        for i in range(n + 1):
            x, z = -1 + 2 * i / n, 1 - 2 * j / n
            y = 0.35 * math.sin(1.8 * x) * math.cos(1.5 * z)
            points.append((x, y, z))
    vid = lambda i, j: j * (n + 1) + i
    faces = [[vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1)]
             for j in range(n) for i in range(n)]
    tags = ["t interpolateboundary 1/0/0 1", "t hole 1/0/0 %d" % (2 * n + 3)]
    write_obj("grid", "An open 6 x 6 grid of quads over a wavy height field: a boundary\n"
              "(interpolated edge-and-corner) and one face marked as a hole.", points, faces, tags)


EXAMPLES = [
    {"name": "cube", "title": "Cube", "scheme": "catmull-clark"},
    {"name": "torus_creased", "title": "Creased torus", "scheme": "catmull-clark"},
    {"name": "icosahedron", "title": "Loop icosahedron", "scheme": "loop"},
    {"name": "pawn", "title": "Pawn (revolved profile)", "scheme": "catmull-clark",
     "orbit": {"azimuthDeg": 30, "elevationDeg": 15}},
    {"name": "grid", "title": "Open grid with a boundary", "scheme": "catmull-clark",
     "orbit": {"azimuthDeg": 20, "elevationDeg": 50}},
]

if __name__ == "__main__":
    cube()
    torus()
    icosahedron()
    pawn()
    grid()
    for e in EXAMPLES:
        e["file"] = e["name"] + ".obj"
    with open(os.path.join(HERE, "examples.json"), "w") as out:
        json.dump(EXAMPLES, out, indent=2)
        out.write("\n")
