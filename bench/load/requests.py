#!/usr/bin/env python3
"""The request bodies of the load benchmarks (bench/load_mix.sh, bench/lanes_bench.sh), written
into a folder: small.json (the cube at 256^2, adaptive dicingRate 2, colour only), heavy.json (a
torus of U x V quads at 1024^2, adaptive, with the exact reference) and invalid.json (a face
naming a missing vertex: 422).

  bench/load/requests.py OUT_DIR [U V]      (default 32 16: 512 faces)
"""
import json
import math
import sys

CUBE = ("v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\nv -1 1 -1\nv 1 1 -1\nv -1 -1 -1\nv 1 -1 -1\n"
        "f 1 2 4 3\nf 3 4 6 5\nf 5 6 8 7\nf 7 8 2 1\nf 2 8 6 4\nf 7 1 3 5\n")


def torus_obj(u_count, v_count, big=1.0, small=0.35):
    lines = []
    for i in range(u_count):
        for j in range(v_count):
            u, v = 2 * math.pi * i / u_count, 2 * math.pi * j / v_count
            lines.append(f"v {(big + small * math.cos(v)) * math.cos(u):.6f} {small * math.sin(v):.6f} "
                         f"{(big + small * math.cos(v)) * math.sin(u):.6f}")
    for i in range(u_count):
        for j in range(v_count):
            a, b = i * v_count + j, ((i + 1) % u_count) * v_count + j
            c, d = ((i + 1) % u_count) * v_count + (j + 1) % v_count, i * v_count + (j + 1) % v_count
            lines.append(f"f {a + 1} {d + 1} {c + 1} {b + 1}")
    return "\n".join(lines) + "\n"


def main():
    out = sys.argv[1]
    u_count, v_count = (int(sys.argv[2]), int(sys.argv[3])) if len(sys.argv) > 3 else (32, 16)

    def write(name, request):
        with open(f"{out}/{name}", "w") as f:
            json.dump(request, f)

    write("small.json", {"mesh": {"format": "obj", "data": CUBE}, "camera": {"width": 256, "height": 256},
                         "method": "adaptive", "params": {"dicingRate": 2}, "outputs": ["color"]})
    # Seen from above at an angle.
    write("heavy.json", {"mesh": {"format": "obj", "data": torus_obj(u_count, v_count)},
                         "camera": {"width": 1024, "height": 1024, "eye": [0.5, 2.5, 2.5]},
                         "method": "adaptive", "outputs": ["color"], "reference": True})
    write("invalid.json", {"mesh": {"format": "obj", "data": "v 0 0 0\nv 1 0 0\nf 1 2 7\n"}})


if __name__ == "__main__":
    main()
