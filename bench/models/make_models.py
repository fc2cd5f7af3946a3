#!/usr/bin/env python3
"""Writes limn's realistic corpus: control meshes shaped like the models users bring.

    python3 bench/models/make_models.py OUT_DIR     # writes OUT_DIR/<name>.obj and index.json

Each model is built by code from a few parts (swept tubes with pole, n-gon or open ends; lathed
profiles; boxes with creases; open sheets), so the corpus is reproducible and free of licences.
The parts are what real models are made of and what limn's methods find hard: poles of high
valence (tube ends), faces of 5 to 12 sides (n-gon caps), parts thinner than a pixel at 1024^2
(fingers, legs, tendrils, slats, stems), open shells and sheets seen edge-on (leaves, garments,
shades, wings), creases and corners (hard-surface products), triangles mixed with quads, and
Loop meshes (all triangles). Pieces intersect but are not joined, as in most production models.

Every model has 500-20,000 faces. index.json lists name, category, scheme, faces, traits, and
whether the model is held out: held-out models were not looked at while limn was tuned
(bench/fidelity_views.py reports them separately).
"""
import json
import math
import os
import random
import sys


class Mesh:
    def __init__(self):
        self.points, self.faces, self.creases, self.corners = [], [], [], []

    def add_point(self, p):
        self.points.append(tuple(p))
        return len(self.points) - 1

    def add_face(self, vertices):
        self.faces.append(list(vertices))

    def crease(self, a, b, sharpness):
        self.creases.append((a, b, sharpness))

    def triangulated(self):
        """Quads split along a diagonal, n-gons fanned: for Loop models."""
        out = Mesh()
        out.points = list(self.points)
        out.creases, out.corners = list(self.creases), list(self.corners)
        for f in self.faces:
            for k in range(1, len(f) - 1):
                out.faces.append([f[0], f[k], f[k + 1]])
        return out


# ---- small vector helpers ----

def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def mul(a, s):
    return tuple(x * s for x in a)


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    n = math.sqrt(sum(x * x for x in a)) or 1.0
    return tuple(x / n for x in a)


def frame(tangent, previous_normal=None):
    """A normal and binormal perpendicular to `tangent`, turned as little as possible."""
    t = norm(tangent)
    n = previous_normal or ((0, 0, 1) if abs(t[2]) < 0.9 else (1, 0, 0))
    n = norm(sub(n, mul(t, sum(x * y for x, y in zip(n, t)))))
    return n, cross(t, n)


# ---- parts ----

def tube(mesh, path, radii, sides, start="pole", end="pole", flatten=1.0, crease_ends=0.0):
    """A generalised cylinder along `path` (points) with one radius per point. Ends: "pole" (a
    fan of triangles around one vertex: valence `sides`), "ngon" (one face of `sides` sides),
    or "open" (a boundary). `flatten` squashes the section (leaves' stems, blades)."""
    rings, normal = [], None
    for i, c in enumerate(path):
        tangent = sub(path[min(i + 1, len(path) - 1)], path[max(i - 1, 0)])
        normal, binormal = frame(tangent, normal)
        ring = []
        for k in range(sides):
            a = 2 * math.pi * k / sides
            offset = add(mul(normal, math.cos(a) * radii[i]), mul(binormal, math.sin(a) * radii[i] * flatten))
            ring.append(mesh.add_point(add(c, offset)))
        rings.append(ring)
    for r0, r1 in zip(rings, rings[1:]):
        for k in range(sides):
            mesh.add_face([r0[k], r0[(k + 1) % sides], r1[(k + 1) % sides], r1[k]])

    def close(ring, tip, outward):
        if outward == "open":
            return
        if outward == "ngon":
            mesh.add_face(ring if tip == "end" else ring[::-1])
        else:
            direction = sub(path[-1], path[-2]) if tip == "end" else sub(path[0], path[1])
            centre = path[-1] if tip == "end" else path[0]
            radius = radii[-1] if tip == "end" else radii[0]
            pole = mesh.add_point(add(centre, mul(norm(direction), 0.6 * radius)))
            for k in range(sides):
                a, b = ring[k], ring[(k + 1) % sides]
                mesh.add_face([a, b, pole] if tip == "end" else [b, a, pole])
        if crease_ends > 0:
            for k in range(sides):
                mesh.crease(ring[k], ring[(k + 1) % sides], crease_ends)

    close(rings[0], "start", start)
    close(rings[-1], "end", end)
    return rings


def lathe(mesh, profile, sides, top="pole", bottom="pole", creases=()):
    """A surface of revolution about +y of `profile` [(radius, y), ...] from bottom to top;
    `creases`: indices of profile rings made sharp (value, index)."""
    path = [(0, y, 0) for _, y in profile]
    rings = []
    for r, y in profile:
        ring = [mesh.add_point((r * math.cos(2 * math.pi * k / sides), y, -r * math.sin(2 * math.pi * k / sides)))
                for k in range(sides)]
        rings.append(ring)
    for r0, r1 in zip(rings, rings[1:]):
        for k in range(sides):
            mesh.add_face([r0[k], r0[(k + 1) % sides], r1[(k + 1) % sides], r1[k]])
    for end, ring, y in (("bottom", rings[0], profile[0][1]), ("top", rings[-1], profile[-1][1])):
        kind = bottom if end == "bottom" else top
        if kind == "open":
            continue
        if kind == "ngon":
            mesh.add_face(ring[::-1] if end == "bottom" else ring)
            continue
        pole = mesh.add_point((0, y, 0))
        for k in range(sides):
            a, b = ring[k], ring[(k + 1) % sides]
            mesh.add_face([b, a, pole] if end == "bottom" else [a, b, pole])
    for sharpness, i in creases:
        ring = rings[i]
        for k in range(sides):
            mesh.crease(ring[k], ring[(k + 1) % sides], sharpness)
    del path
    return rings


def box(mesh, centre, size, segments=(2, 2, 2), crease=0.0):
    """An axis-aligned box of quads, `segments` per axis; `crease` on its 12 edges."""
    cx, cy, cz = centre
    sx, sy, sz = size
    nx, ny, nz = segments
    index = {}

    def point(i, j, k):
        key = (i, j, k)
        if key not in index:
            index[key] = mesh.add_point((cx + sx * (i / nx - 0.5), cy + sy * (j / ny - 0.5), cz + sz * (k / nz - 0.5)))
        return index[key]

    def grid(fixed_axis, value, flip):
        dims = [nx, ny, nz]
        a, b = [d for d in range(3) if d != fixed_axis]
        for u in range(dims[a]):
            for v in range(dims[b]):
                quad = []
                for du, dv in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    c = [0, 0, 0]
                    c[fixed_axis], c[a], c[b] = value, u + du, v + dv
                    quad.append(point(*c))
                mesh.add_face(quad[::-1] if flip else quad)

    grid(0, 0, True), grid(0, nx, False)  # faces wound counter-clockwise seen from outside
    grid(1, 0, False), grid(1, ny, True)
    grid(2, 0, True), grid(2, nz, False)
    if crease > 0:
        dims = [nx, ny, nz]
        for axis in range(3):
            o1, o2 = [d for d in range(3) if d != axis]
            for e1 in (0, dims[o1]):
                for e2 in (0, dims[o2]):
                    for t in range(dims[axis]):
                        c0, c1 = [0, 0, 0], [0, 0, 0]
                        c0[axis], c1[axis] = t, t + 1
                        c0[o1] = c1[o1] = e1
                        c0[o2] = c1[o2] = e2
                        mesh.crease(point(*c0), point(*c1), crease)


def sheet(mesh, origin, u_axis, v_axis, nu, nv, shape=lambda s, t: (0.0, 1.0)):
    """An open sheet of nu x nv quads over s, t in [0, 1]: shape(s, t) gives (bend along the
    sheet's normal, width factor across it): leaves, petals, cloth, wings, ears."""
    normal = norm(cross(u_axis, v_axis))
    rows = []
    for j in range(nv + 1):
        t = j / nv
        row = []
        for i in range(nu + 1):
            s = i / nu
            bend, width = shape(s, t)
            p = add(origin, add(mul(u_axis, (s - 0.5) * width), add(mul(v_axis, t), mul(normal, bend))))
            row.append(mesh.add_point(p))
        rows.append(row)
    for j in range(nv):
        for i in range(nu):
            mesh.add_face([rows[j][i], rows[j][i + 1], rows[j + 1][i + 1], rows[j + 1][i]])
    return rows


def curve(points_fn, n):
    return [points_fn(i / (n - 1)) for i in range(n)]


def taper(n, r0, r1, bulge=0.0):
    return [r0 + (r1 - r0) * (i / (n - 1)) + bulge * math.sin(math.pi * i / (n - 1)) for i in range(n)]


# ---- models ----
# Each returns (mesh, traits). rng: random.Random seeded by the model's name.

def humanoid(rng, fingers=True, sides=12):
    m = Mesh()
    # Torso and head: lathed, poles at top and bottom.
    lathe(m, [(0.0001, 0.0), (0.28, 0.05), (0.34, 0.4), (0.3, 0.8), (0.36, 1.1), (0.14, 1.25), (0.12, 1.35),
              (0.2, 1.45), (0.22, 1.6), (0.16, 1.75), (0.02, 1.8)], sides * 2, top="pole", bottom="pole")
    for side in (-1, 1):
        arm = curve(lambda t: (side * (0.35 + 0.55 * t), 1.05 - 0.45 * t * t, 0.05 * t), 10)
        tube(m, arm, taper(10, 0.08, 0.05), sides)
        leg = curve(lambda t: (side * 0.15, 0.05 - 0.95 * t, 0.03 * math.sin(3 * t)), 12)
        tube(m, leg, taper(12, 0.12, 0.06), sides, end="ngon")
        foot = curve(lambda t: (side * 0.15, -0.92, 0.0 + 0.22 * t), 5)
        tube(m, foot, taper(5, 0.07, 0.05), 8, start="ngon", end="ngon", flatten=0.6)
        if fingers:
            hand = arm[-1]
            for f in range(5):
                spread = (f - 2) * 0.018
                finger = curve(lambda t: (hand[0] + side * 0.1 * t, hand[1] - 0.02 - 0.02 * t, hand[2] + spread + 0.01 * t), 6)
                tube(m, finger, taper(6, 0.0085, 0.006), 6, start="ngon")
    return m, ["poles", "thin fingers", "n-gon caps"]


def quadruped(rng, sides=12):
    m = Mesh()
    body = curve(lambda t: (-0.8 + 1.6 * t, 0.8 + 0.05 * math.sin(math.pi * t), 0), 14)
    tube(m, body, taper(14, 0.22, 0.26, 0.08), sides * 2)
    neck = curve(lambda t: (0.8 + 0.3 * t, 0.85 + 0.45 * t, 0), 8)
    tube(m, neck, taper(8, 0.14, 0.12), sides)
    head = curve(lambda t: (1.05 + 0.4 * t, 1.3 - 0.1 * t, 0), 8)
    tube(m, head, taper(8, 0.14, 0.06, 0.05), sides, start="ngon")
    for dx in (-0.65, 0.65):
        for dz in (-0.14, 0.14):
            leg = curve(lambda t: (dx, 0.7 - 0.7 * t, dz), 10)
            tube(m, leg, taper(10, 0.07, 0.03), 8, end="ngon")
    tail = curve(lambda t: (-0.8 - 0.6 * t, 0.85 + 0.3 * math.sin(2.5 * t), 0.1 * math.sin(4 * t)), 16)
    tube(m, tail, taper(16, 0.04, 0.004), 6)
    for dz in (-0.06, 0.06):  # ears: open sheets
        sheet(m, (1.15, 1.38, dz), (0.0, 0.0, 0.08), (0.02, 0.16, 0.0), 4, 6,
              lambda s, t: (0.02 * math.sin(math.pi * s), 1.0 - t * 0.9))
    return m, ["poles", "thin tail and legs", "open-sheet ears"]


def octopus(rng, arms=8, sides=10):
    m = Mesh()
    lathe(m, [(0.0001, 0.3), (0.3, 0.35), (0.45, 0.7), (0.4, 1.1), (0.2, 1.35), (0.001, 1.4)], 24)
    for a in range(arms):
        ang = 2 * math.pi * a / arms
        arm = curve(lambda t: ((0.3 + 1.2 * t) * math.cos(ang), 0.35 - 0.3 * t + 0.15 * math.sin(6 * t + a),
                               (0.3 + 1.2 * t) * math.sin(ang) + 0.2 * math.sin(5 * t)), 24)
        tube(m, arm, taper(24, 0.1, 0.005), sides)
    return m, ["poles", "tapering tentacles to sub-pixel tips"]


def bird(rng, sides=12):
    m = Mesh()
    body = curve(lambda t: (-0.5 + t, 0.6 + 0.1 * math.sin(math.pi * t), 0), 12)
    tube(m, body, taper(12, 0.12, 0.12, 0.12), sides * 2)
    beak = curve(lambda t: (0.5 + 0.25 * t, 0.65, 0), 5)
    tube(m, beak, taper(5, 0.05, 0.003), 6, start="ngon")
    for side in (-1, 1):  # wings: open sheets, thin at the tip
        sheet(m, (0.0, 0.65, side * 0.1), (0.3, 0.0, 0.0), (0.0, 0.05, side * 0.8), 8, 12,
              lambda s, t: (0.05 * math.sin(math.pi * t), 1.0 - 0.7 * t))
        leg = curve(lambda t: (0.0, 0.5 - 0.5 * t, side * 0.06), 8)
        tube(m, leg, taper(8, 0.012, 0.008), 6, end="ngon")
    return m, ["open-sheet wings seen edge-on", "thin legs", "sharp beak"]


def snake(rng, sides=12):
    m = Mesh()
    body = curve(lambda t: (2.0 * t, 0.1 + 0.05 * math.sin(9 * t), 0.4 * math.sin(10 * t)), 120)
    tube(m, body, taper(120, 0.08, 0.005, 0.04), sides)
    return m, ["long tube", "sub-pixel tail"]


def fish(rng, sides=10):
    m = Mesh()
    body = curve(lambda t: (-0.6 + 1.2 * t, 0.0, 0.0), 16)
    tube(m, body, taper(16, 0.02, 0.05, 0.25), sides, start="ngon", end="ngon", flatten=0.5)
    sheet(m, (-0.65, -0.02, 0.0), (0.0, 0.4, 0.0), (-0.3, 0.0, 0.0), 6, 5,
          lambda s, t: (0.0, 0.3 + t))  # tail fin
    sheet(m, (0.0, 0.12, 0.0), (0.3, 0.0, 0.0), (0.0, 0.2, 0.0), 6, 4,
          lambda s, t: (0.0, 1.0 - 0.8 * t))  # dorsal fin
    return m, ["pentagon and decagon caps", "fins as open sheets seen edge-on"]


def insect(rng):
    m = Mesh()
    for x, r in ((-0.4, 0.2), (0.0, 0.12), (0.25, 0.1)):
        lathe_part = curve(lambda t: (x - r + 2 * r * t, 0.3, 0.0), 8)
        tube(m, lathe_part, taper(8, 0.01, 0.01, r), 10)
    for i in range(3):
        for side in (-1, 1):
            leg = curve(lambda t: (0.05 * i - 0.05 + 0.1 * t, 0.3 - 0.3 * t + 0.15 * math.sin(math.pi * t),
                                   side * (0.1 + 0.4 * t)), 10)
            tube(m, leg, taper(10, 0.008, 0.004), 5, end="ngon")
    for side in (-1, 1):
        antenna = curve(lambda t: (0.33 + 0.3 * t, 0.35 + 0.25 * t, side * 0.05 * (1 + 2 * t)), 10)
        tube(m, antenna, taper(10, 0.004, 0.002), 5)
    return m, ["sub-pixel legs and antennae", "pentagon caps"]


def alien(rng):
    m = Mesh()
    lathe(m, [(0.001, 0), (0.4, 0.1), (0.5, 0.6), (0.3, 1.0), (0.001, 1.1)], 28)
    for k in range(12):
        ang = 2 * math.pi * k / 12
        spike = curve(lambda t: ((0.45 + 0.4 * t) * math.cos(ang), 0.6 + 0.2 * t, (0.45 + 0.4 * t) * math.sin(ang)), 6)
        tube(m, spike, taper(6, 0.06, 0.01), 7, start="ngon", end="pole")
    return m, ["valence-28 poles", "heptagon caps", "spikes"]


def bevelled_box(rng):
    m = Mesh()
    box(m, (0, 0, 0), (2.0, 1.0, 1.2), (12, 6, 8), crease=3.0)
    box(m, (0, 0.7, 0), (0.6, 0.4, 0.4), (4, 3, 3), crease=10.0)
    return m, ["semi-sharp creases", "infinitely sharp box", "flat faces edge-on"]


def phone(rng):
    m = Mesh()
    box(m, (0, 0, 0), (0.7, 1.4, 0.08), (10, 20, 2), crease=1.5)
    box(m, (0.2, 0.55, 0.05), (0.15, 0.15, 0.03), (3, 3, 1), crease=10.0)
    return m, ["thin slab seen edge-on", "creases"]


def mug(rng):
    m = Mesh()
    lathe(m, [(0.0001, 0), (0.4, 0.0), (0.42, 0.05), (0.42, 0.9), (0.4, 0.95), (0.36, 0.95), (0.36, 0.1),
              (0.0001, 0.1)], 32, top="pole", bottom="pole", creases=((2.0, 1), (2.0, 4)))
    handle = curve(lambda t: (0.42 + 0.25 * math.sin(math.pi * t), 0.2 + 0.6 * t, 0), 12)
    tube(m, handle, [0.04] * 12, 8, start="ngon", end="ngon")
    return m, ["thin wall", "creased rims", "octagon caps"]


def bolt(rng):
    m = Mesh()
    lathe(m, [(0.3, 0.0), (0.3, 0.2)], 6, top="ngon", bottom="ngon", creases=((10.0, 0), (10.0, 1)))
    rings = lathe(m, [(0.12, 0.2)] + [(0.12 + 0.015 * (i % 2), 0.2 + 0.04 * i) for i in range(1, 30)], 16,
                  top="ngon", bottom="open")
    return m, ["hexagon caps with infinitely sharp rims", "thread ridges", "16-gon cap"]


def gear(rng, teeth=24):
    m = Mesh()
    profile = []
    n = teeth * 4
    for k in range(n):
        r = 1.0 if (k // 2) % 2 == 0 else 0.85
        profile.append(r)
    top, bottom = [], []
    for k in range(n):
        a = 2 * math.pi * k / n
        bottom.append(m.add_point((profile[k] * math.cos(a), 0.0, -profile[k] * math.sin(a))))
        top.append(m.add_point((profile[k] * math.cos(a), 0.2, -profile[k] * math.sin(a))))
    for k in range(n):
        m.add_face([bottom[k], bottom[(k + 1) % n], top[(k + 1) % n], top[k]])
        m.crease(bottom[k], bottom[(k + 1) % n], 10.0)
        m.crease(top[k], top[(k + 1) % n], 10.0)
    m.add_face(top)
    m.add_face(bottom[::-1])
    return m, [f"two {n}-gon faces", "infinitely sharp rims", "teeth"]


def bottle(rng):
    m = Mesh()
    lathe(m, [(0.0001, 0), (0.35, 0.0), (0.38, 0.1), (0.38, 0.9), (0.3, 1.1), (0.1, 1.25), (0.1, 1.5),
              (0.12, 1.52), (0.09, 1.54), (0.085, 1.3), (0.33, 1.05), (0.35, 0.12)], 24, bottom="pole",
          top="open", creases=((1.0, 1),))
    return m, ["open shell seen edge-on at the lip", "thin wall"]


def table(rng):
    m = Mesh()
    box(m, (0, 1.0, 0), (2.0, 0.06, 1.0), (16, 1, 8), crease=2.0)
    for x in (-0.9, 0.9):
        for z in (-0.4, 0.4):
            leg = curve(lambda t: (x, 1.0 - t, z), 10)
            tube(m, leg, taper(10, 0.025, 0.012), 8, start="ngon", end="ngon")
    return m, ["thin legs", "thin top edge-on", "octagon caps"]


def chair(rng):
    m = Mesh()
    box(m, (0, 0.5, 0), (0.5, 0.04, 0.5), (6, 1, 6), crease=2.0)
    for x in (-0.22, 0.22):
        for z in (-0.22, 0.22):
            leg = curve(lambda t: (x, 0.5 - 0.5 * t, z), 6)
            tube(m, leg, [0.015] * 6, 6, start="ngon", end="ngon")
        back = curve(lambda t: (x, 0.5 + 0.5 * t, -0.22 - 0.05 * t), 8)
        tube(m, back, [0.015] * 8, 6, start="ngon", end="ngon")
    for y in (0.7, 0.85, 0.98):
        rung = curve(lambda t: (-0.22 + 0.44 * t, y, -0.22 - 0.05 * (y - 0.5) / 0.5), 8)
        tube(m, rung, [0.008] * 8, 6, start="ngon", end="ngon")
    return m, ["sub-pixel rungs", "hexagon caps"]


def lamp(rng):
    m = Mesh()
    lathe(m, [(0.0001, 0), (0.3, 0.0), (0.3, 0.05), (0.05, 0.08), (0.0001, 0.09)], 24)
    pole = curve(lambda t: (0, 0.08 + 1.2 * t, 0), 12)
    tube(m, pole, [0.012] * 12, 8, start="ngon", end="ngon")
    lathe(m, [(0.35, 1.0), (0.3, 1.15), (0.2, 1.35)], 32, top="open", bottom="open")  # shade: open shell
    return m, ["open shell (shade)", "thin pole"]


def shelf(rng):
    m = Mesh()
    for y in (0.0, 0.4, 0.8, 1.2):
        box(m, (0, y, 0), (1.2, 0.02, 0.3), (12, 1, 3), crease=10.0)
    for x in (-0.6, 0.6):
        box(m, (x, 0.6, 0), (0.02, 1.22, 0.3), (1, 12, 3), crease=10.0)
    return m, ["thin boards edge-on", "infinitely sharp edges"]


def column(rng):
    m = Mesh()
    profile = [(0.5, 0.0), (0.5, 0.1), (0.35, 0.15)]
    profile += [(0.3 - 0.02 * math.sin(math.pi * i / 20), 0.15 + 0.1 * i) for i in range(21)]
    profile += [(0.4, 2.3), (0.5, 2.4)]
    lathe(m, profile, 32, top="ngon", bottom="ngon", creases=((10.0, 0), (10.0, len(profile) - 1)))
    return m, ["32-gon caps with sharp rims", "fluted shaft"]


def fence(rng, slats=20):
    m = Mesh()
    for i in range(slats):
        box(m, (-1.0 + 2.0 * i / (slats - 1), 0.5, 0), (0.03, 1.0, 0.01), (1, 6, 1), crease=2.0)
    for y in (0.2, 0.8):
        box(m, (0, y, 0.015), (2.1, 0.04, 0.02), (20, 1, 1), crease=2.0)
    return m, ["many sub-pixel slats edge-on"]


def plant(rng, leaves=10, tendrils=8):
    m = Mesh()
    stem = curve(lambda t: (0.05 * math.sin(4 * t), 1.5 * t, 0.05 * math.cos(3 * t)), 20)
    tube(m, stem, taper(20, 0.03, 0.008), 8, start="ngon")
    for k in range(leaves):
        y = 0.2 + 1.2 * k / leaves
        ang = 2.4 * k
        d = (math.cos(ang), 0.3, math.sin(ang))
        side = norm(cross(d, (0, 1, 0)))
        sheet(m, (0, y, 0), mul(side, 0.18), mul(d, 0.5), 6, 10,
              lambda s, t: (0.04 * math.sin(math.pi * t) + 0.03 * (s - 0.5) ** 2 * 4,
                            math.sin(math.pi * min(t * 1.1, 1.0)) + 0.02))
    for k in range(tendrils):
        ang = 2 * math.pi * k / tendrils + rng.random()
        tendril = curve(lambda t: (0.4 * t * math.cos(ang) + 0.05 * math.sin(12 * t),
                                   1.2 + 0.4 * t + 0.05 * math.cos(12 * t), 0.4 * t * math.sin(ang)), 24)
        tube(m, tendril, taper(24, 0.006, 0.002), 5, start="ngon")
    for k in range(3):  # a flower as a decagon disc
        lathe(m, [(0.08, 1.5 + 0.05 * k), (0.1, 1.52 + 0.05 * k)], 10, top="ngon", bottom="ngon")
    return m, ["leaves as open sheets", "sub-pixel tendrils", "pentagon and decagon faces"]


def tree(rng):
    m = Mesh()

    def branch(start, direction, length, radius, depth):
        path = curve(lambda t: add(start, add(mul(direction, length * t),
                                             (0.03 * math.sin(7 * t), 0, 0.03 * math.cos(5 * t)))), 8)
        tube(m, path, taper(8, radius, radius * 0.6), 8 if depth < 2 else 6, start="ngon", end="pole")
        if depth >= 3:
            return
        for k in range(3):
            ang = 2 * math.pi * k / 3 + rng.random()
            d = norm(add(direction, (0.8 * math.cos(ang), 0.3, 0.8 * math.sin(ang))))
            branch(path[-1], d, length * 0.6, radius * 0.55, depth + 1)

    branch((0, 0, 0), (0, 1, 0), 1.0, 0.08, 0)
    return m, ["branching thin tubes", "many poles"]


def flower(rng, petals=12):
    m = Mesh()
    stem = curve(lambda t: (0.02 * math.sin(5 * t), 1.0 * t, 0), 12)
    tube(m, stem, [0.012] * 12, 6, start="ngon")
    lathe(m, [(0.0001, 0.98), (0.08, 1.0), (0.06, 1.04), (0.0001, 1.05)], 12)
    for k in range(petals):
        ang = 2 * math.pi * k / petals
        d = (math.cos(ang), 0.25, math.sin(ang))
        side = norm(cross(d, (0, 1, 0)))
        sheet(m, (0.06 * math.cos(ang), 1.02, 0.06 * math.sin(ang)), mul(side, 0.12), mul(d, 0.35), 5, 8,
              lambda s, t: (0.03 * math.sin(math.pi * t), math.sin(math.pi * (0.15 + 0.85 * t))))
    return m, ["petals as open sheets", "valence-12 poles"]


def fern(rng, leaflets=24):
    m = Mesh()
    rachis = curve(lambda t: (0, 1.2 * t, 0.3 * t * t), 24)
    tube(m, rachis, taper(24, 0.01, 0.003), 5, start="ngon")
    for k in range(leaflets):
        t = 0.1 + 0.85 * k / leaflets
        base = (0, 1.2 * t, 0.3 * t * t)
        side = 1 if k % 2 else -1
        sheet(m, base, (0.0, 0.0, 0.04), (side * 0.3 * (1 - t), 0.05, 0.0), 3, 6,
              lambda s, tt: (0.01 * math.sin(math.pi * tt), 1.0 - tt))
    return m, ["many thin leaflets (open sheets)", "thin rachis"]


def cactus(rng):
    m = Mesh()
    sides = 36
    rings = []
    for j in range(16):
        y = 1.2 * j / 15
        r = 0.25 * math.sin(math.pi * (0.1 + 0.85 * j / 15)) + 0.02
        ring = []
        for k in range(sides):
            a = 2 * math.pi * k / sides
            rr = r * (1.0 if k % 3 == 0 else 0.9)
            ring.append(m.add_point((rr * math.cos(a), y, -rr * math.sin(a))))
        rings.append(ring)
    for r0, r1 in zip(rings, rings[1:]):
        for k in range(sides):
            m.add_face([r0[k], r0[(k + 1) % sides], r1[(k + 1) % sides], r1[k]])
            if k % 3 == 0:
                m.crease(r0[k], r1[k], 2.5)
    m.add_face(rings[0][::-1])
    m.add_face(rings[-1])
    return m, ["36-gon caps", "ribs as creases"]


def skirt(rng):
    m = Mesh()
    lathe(m, [(0.3 + 0.35 * t + 0.03 * math.sin(12 * t), 1.0 - 0.8 * t) for t in [i / 20 for i in range(21)]][::-1],
          48, top="open", bottom="open")
    return m, ["open shell", "boundaries seen edge-on"]


def shirt(rng):
    m = Mesh()
    lathe(m, [(0.35, 0.0), (0.36, 0.5), (0.34, 0.9), (0.2, 1.0)], 32, top="open", bottom="open")
    for side in (-1, 1):
        sleeve = curve(lambda t: (side * (0.3 + 0.5 * t), 0.85 - 0.3 * t, 0), 10)
        tube(m, sleeve, taper(10, 0.12, 0.09), 16, start="open", end="open")
    return m, ["open shells: body and sleeves", "boundaries seen end-on"]


def hat(rng):
    m = Mesh()
    lathe(m, [(0.5, 0.0), (0.25, 0.01), (0.24, 0.3), (0.0001, 0.32)], 40, bottom="open", top="pole")
    return m, ["brim as an open sheet edge-on", "valence-40 pole"]


def sandal(rng):
    m = Mesh()
    sole = sheet(m, (0, 0, 0), (0.35, 0, 0), (0, 0, 1.0), 8, 24,
                 lambda s, t: (0.0, 0.6 + 0.4 * math.sin(math.pi * t)))
    for t in (0.25, 0.5, 0.75):
        strap = curve(lambda u: (-0.15 + 0.3 * u, 0.12 * math.sin(math.pi * u), t), 10)
        tube(m, strap, [0.01] * 10, 6, start="ngon", end="ngon", flatten=0.3)
    del sole
    return m, ["open sole sheet edge-on", "thin flat straps"]


def scarf(rng):
    m = Mesh()
    sheet(m, (0, 0, 0), (0.2, 0, 0), (0, 0, 2.0), 6, 60,
          lambda s, t: (0.15 * math.sin(8 * t + 3 * s), 1.0))
    return m, ["long open sheet folded", "edge-on folds"]


# ---- dense scenes: several parts of the models above in one mesh (5,000-20,000 faces) ----

def placed(parts, mesh=None):
    """One mesh of several (mesh, turn about y in radians, offset) parts, as a scene file holds
    many objects in one mesh."""
    out = mesh or Mesh()
    for part, turn, offset in parts:
        base = len(out.points)
        c, s = math.cos(turn), math.sin(turn)
        for x, y, z in part.points:
            out.add_point((c * x + s * z + offset[0], y + offset[1], -s * x + c * z + offset[2]))
        for f in part.faces:
            out.add_face([v + base for v in f])
        for a, b, sharpness in part.creases:
            out.crease(a + base, b + base, sharpness)
    return out


def crowd(rng):
    people = [(humanoid(rng, sides=16)[0], rng.uniform(-0.6, 0.6), (1.1 * (k % 2) - 0.55, 0, 1.2 * (k // 2)))
              for k in range(4)]
    return placed(people), ["four figures: poles, thin fingers side by side", "n-gon caps", "6,000+ faces"]


def grove(rng):
    plants = [(plant(rng)[0], rng.uniform(0, 6.3), (0.9 * k - 0.9, 0, 0.3 * (k % 2))) for k in range(3)]
    return placed(plants), ["three plants: leaves as open sheets overlapping", "sub-pixel tendrils",
                            "5,000+ faces"]


def workshop(rng):
    # 16 teeth: 64-gon caps, the largest face limn takes by default (limits.maxFaceSize).
    parts = [(gear(rng, teeth=16)[0], 0.3 * k, (2.05 * (k % 3) - 2.05, 0.25 * (k // 3), 2.1 * (k // 3)))
             for k in range(9)]
    parts += [(bolt(rng)[0], 0.0, (0.7 * (k % 5) - 1.4, 0, -1.5 - 0.7 * (k // 5))) for k in range(10)]
    return placed(parts), ["gears and bolts: infinitely sharp rims", "hexagon caps", "5,000+ faces"]


MODELS = [
    # name, function, category, scheme, held out
    ("humanoid", humanoid, "character", "catmull-clark", False),
    ("quadruped", quadruped, "creature", "catmull-clark", False),
    ("octopus", octopus, "creature", "catmull-clark", False),
    ("bird", bird, "creature", "catmull-clark", True),
    ("snake", snake, "creature", "loop", False),
    ("fish", fish, "creature", "catmull-clark", False),
    ("insect", insect, "creature", "catmull-clark", True),
    ("alien", alien, "character", "catmull-clark", False),
    ("bevelled_box", bevelled_box, "hard surface", "catmull-clark", False),
    ("phone", phone, "hard surface", "catmull-clark", True),
    ("mug", mug, "hard surface", "catmull-clark", False),
    ("bolt", bolt, "hard surface", "catmull-clark", False),
    ("gear", gear, "hard surface", "catmull-clark", True),
    ("bottle", bottle, "hard surface", "loop", False),
    ("table", table, "furniture", "catmull-clark", False),
    ("chair", chair, "furniture", "catmull-clark", True),
    ("lamp", lamp, "furniture", "catmull-clark", False),
    ("shelf", shelf, "furniture", "catmull-clark", False),
    ("column", column, "architecture", "catmull-clark", False),
    ("fence", fence, "architecture", "catmull-clark", True),
    ("plant", plant, "plant", "catmull-clark", False),
    ("tree", tree, "plant", "catmull-clark", False),
    ("flower", flower, "plant", "loop", True),
    ("fern", fern, "plant", "catmull-clark", False),
    ("cactus", cactus, "plant", "catmull-clark", False),
    ("skirt", skirt, "garment", "catmull-clark", False),
    ("shirt", shirt, "garment", "catmull-clark", True),
    ("hat", hat, "garment", "catmull-clark", False),
    ("sandal", sandal, "garment", "catmull-clark", False),
    ("scarf", scarf, "garment", "loop", False),
    ("crowd", crowd, "scene", "catmull-clark", False),
    ("grove", grove, "scene", "catmull-clark", False),
    ("workshop", workshop, "scene", "catmull-clark", True),
]

MIN_FACES, MAX_FACES = 500, 20000


def refine_to_size(mesh):
    """Splits every quad into four (a uniform Catmull-Clark topology step, positions linear)
    until the model has at least MIN_FACES faces: the shapes keep their parts and traits."""
    while len(mesh.faces) < MIN_FACES:
        out = Mesh()
        out.points = list(mesh.points)
        edge_mid, creases = {}, {}
        for a, b, s in mesh.creases:
            creases[(min(a, b), max(a, b))] = s

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in edge_mid:
                edge_mid[key] = out.add_point(mul(add(out.points[a], out.points[b]), 0.5))
                if key in creases:
                    out.crease(a, edge_mid[key], creases[key])
                    out.crease(edge_mid[key], b, creases[key])
            return edge_mid[key]

        for f in mesh.faces:
            centre = out.add_point(mul(tuple(map(sum, zip(*[mesh.points[v] for v in f]))), 1.0 / len(f)))
            n = len(f)
            for k in range(n):
                out.add_face([f[k], mid(f[k], f[(k + 1) % n]), centre, mid(f[k - 1], f[k])])
        mesh = out
    return mesh


def write_obj(path, mesh, scheme, comment):
    with open(path, "w") as out:
        out.write("# %s\n# scheme %s\n" % (comment, scheme))
        for p in mesh.points:
            out.write("v %.6f %.6f %.6f\n" % p)
        for f in mesh.faces:
            out.write("f " + " ".join(str(v + 1) for v in f) + "\n")
        for a, b, s in mesh.creases:
            out.write("t crease 2/1/0 %d %d %g\n" % (a, b, s))


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out_dir = sys.argv[1]
    os.makedirs(out_dir, exist_ok=True)
    index = []
    for name, make, category, scheme, held_out in MODELS:
        mesh, traits = make(random.Random(name))
        if scheme == "loop":
            mesh = mesh.triangulated()
        elif len(mesh.faces) < MIN_FACES:
            mesh = refine_to_size(mesh)
        if not MIN_FACES <= len(mesh.faces) <= MAX_FACES:
            sys.exit("%s has %d faces, outside %d-%d" % (name, len(mesh.faces), MIN_FACES, MAX_FACES))
        sizes = sorted({len(f) for f in mesh.faces})
        write_obj(os.path.join(out_dir, name + ".obj"), mesh, scheme, "limn realistic corpus: " + name)
        index.append({"name": name, "category": category, "scheme": scheme, "faces": len(mesh.faces),
                      "faceSizes": sizes, "creases": len(mesh.creases), "traits": traits,
                      "heldOut": held_out})
    with open(os.path.join(out_dir, "index.json"), "w") as out:
        json.dump(index, out, indent=1)
    for m in index:
        print("%-13s %-13s %-13s %6d faces  sides %s%s" % (m["name"], m["category"], m["scheme"], m["faces"],
                                                          ",".join(map(str, m["faceSizes"])),
                                                          "  (held out)" if m["heldOut"] else ""))


if __name__ == "__main__":
    main()
