#!/usr/bin/env python3
"""Analytic displacement through a running server: for each example mesh and displacement, the
methods patches and adaptive (dicing rate 1, 512 x 512, a fixed oblique view) with the reference,
against the same mesh undisplaced. Prints one Markdown row per (mesh, displacement, method):
outline error, triangles, approximation and reference times (bench/patches_results.md keeps them).

    build/bin/limn serve --listen 127.0.0.1:8099 &
    bench/displacement_bench.py [URL] [EXAMPLE ...]   # defaults: http://127.0.0.1:8099, cube icosahedron pawn
"""
import json, os, sys, urllib.request

URL = sys.argv[1] if len(sys.argv) > 1 else "http://127.0.0.1:8099"
EXAMPLES = sys.argv[2:] or ["cube", "icosahedron", "pawn"]
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCHEMES = {"icosahedron": "loop"}
DISPLACEMENTS = [
    ("none", None),
    ("bumps 0.02 x 4", {"function": "bumps", "amplitude": 0.02, "frequency": 4}),
    ("ripples -0.015 x 3", {"function": "ripples", "amplitude": -0.015, "frequency": 3}),
]


def post(body):
    req = urllib.request.Request(URL + "/v1/render", data=json.dumps(body).encode(),
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req) as r:
        return json.loads(r.read())


def row(example, label, displacement, method):
    obj = open(os.path.join(ROOT, "examples", example + ".obj")).read()
    body = {"mesh": {"format": "obj", "data": obj, "scheme": SCHEMES.get(example, "catmull-clark")},
            "camera": {"width": 512, "height": 512, "orbit": {"azimuthDeg": 35, "elevationDeg": 25}},
            "method": method, "params": {"dicingRate": 1}, "reference": True, "outputs": []}
    if displacement:
        body["displacement"] = displacement
    answer = post(body)
    if "error" in answer:
        raise SystemExit(f"{example} {label} {method}: {answer['error']}")
    t = answer["timings"]
    s = answer["stats"]
    print(f"| {example} | {label} | {method} | {answer['metrics']['silhouette']['hausdorffPx']:.3f} | "
          f"{s['triangles']} | {t['approxMs']:.1f} | {t['referenceMs']:.1f} | {s['referenceTriangles']} |")


print("| mesh | displacement | method | hausdorffPx | triangles | approx ms | reference ms | reference triangles |")
print("|---|---|---|---:|---:|---:|---:|---:|")
for example in EXAMPLES:
    for label, displacement in DISPLACEMENTS:
        for method in ("patches", "adaptive"):
            row(example, label, displacement, method)
