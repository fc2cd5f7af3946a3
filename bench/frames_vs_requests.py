#!/usr/bin/env python3
"""Animation through a running server: one /v1/render request with 30 frames of a breathing
example mesh (method patches, 512 x 512, dicing rate 4; the first frame's tessellation re-evaluated
for the others) against the same request with params.retessellateFrames (every frame diced anew)
and against 30 separate requests of the same frames. Prints one Markdown row per example
(bench/patches_results.md keeps them).

    build/bin/limn serve --listen 127.0.0.1:8099 &
    bench/frames_vs_requests.py [URL] [EXAMPLE ...]   # defaults: http://127.0.0.1:8099, torus_creased pawn cube
"""
import json, math, os, time, urllib.request, sys

URL = sys.argv[1] if len(sys.argv) > 1 else "http://127.0.0.1:8099"
EXAMPLES = sys.argv[2:] or ["torus_creased", "pawn", "cube"]
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def post(body):
    req = urllib.request.Request(URL + "/v1/render", data=json.dumps(body).encode(), headers={"Content-Type": "application/json"})
    t = time.perf_counter()
    with urllib.request.urlopen(req) as r:
        answer = json.loads(r.read())
    return answer, (time.perf_counter() - t) * 1000


def measure(name):
    obj = open(os.path.join(ROOT, "examples", name + ".obj")).read()
    lines = obj.splitlines()
    points = [[float(x) for x in l.split()[1:4]] for l in lines if l.startswith("v ")]
    cx = [sum(p[k] for p in points) / len(points) for k in range(3)]
    frames = []
    for f in range(30):
        s = 1 + 0.25 * math.sin(2 * math.pi * f / 30)
        frames.append([[cx[k] + (p[k] - cx[k]) * s for k in range(3)] for p in points])
    camera = {"width": 512, "height": 512, "eye": [2.5, 2.0, 3.5]}
    base = {"mesh": {"format": "obj", "data": obj}, "camera": camera, "method": "patches", "params": {"dicingRate": 4}, "outputs": ["color"]}
    post(dict(base))  # warm up
    answer, batch = post(dict(base, frames=frames))
    assert len(answer["frames"]) == 30, answer.get("error")
    anew = dict(base, frames=frames, params={"dicingRate": 4, "retessellateFrames": True})
    _, diced = post(anew)
    single = 0
    for f in range(30):
        it = iter(frames[f])
        text = "\n".join(("v %.9g %.9g %.9g" % tuple(next(it))) if l.startswith("v ") else l for l in lines)
        _, ms = post(dict(base, mesh={"format": "obj", "data": text}))
        single += ms
    per = [fr["approxMs"] + fr["rasterMs"] for fr in answer["frames"]]
    print(f"| {name} | {len(points)} | {batch/30:.1f} | {diced/30:.1f} | {single/30:.1f} | {diced/batch:.2f}x | {single/batch:.2f}x | {sum(per)/30:.1f} | {answer['stats']['patchTable']['tableMs']:.1f} |")


print("| mesh | points | ms/frame, one request (tessellation reused) | ms/frame, one request (retessellateFrames) | ms/frame, 30 requests | retessellated / reused | 30 requests / reused | engine ms/frame (approx + raster), reused | table ms |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
for example in EXAMPLES:
    measure(example)
