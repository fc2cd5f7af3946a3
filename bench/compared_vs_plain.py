#!/usr/bin/env python3
"""What `reference: true` costs through the real server: each model drawn at 1024², adaptive
dicingRate 1, colour only, with and without the reference, on a `limn serve` with one worker.
Prints a Markdown table (bench/reference_results.md keeps runs of it).

    python3 bench/models/make_models.py /tmp/models         (the realistic models, once)
    python3 bench/compared_vs_plain.py [--limn build/bin/limn] [--models pawn,humanoid,octopus]
                                       [--model-dir /tmp/models] [--repeat 3]

Per model: one warm-up request of each kind, then --repeat of each; the table shows medians of
`timings` (totalMs is the worker's time for the request: parse to encode). "ratio" is compared /
plain; issue 25's goal is at most 1.5. `pawn` is examples/pawn.obj.
"""
import argparse
import json
import os
import statistics
import urllib.request

from serve import start_server

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def render(url, obj, reference):
    body = {"mesh": {"format": "obj", "scheme": "catmull-clark", "data": obj},
            "camera": {"width": 1024, "height": 1024}, "method": "adaptive",
            "params": {"dicingRate": 1}, "outputs": ["color"], "reference": reference}
    request = urllib.request.Request(url + "/v1/render", data=json.dumps(body).encode(),
                                     headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=600) as answer:
        reply = json.loads(answer.read())
    return reply["timings"], reply["stats"]["triangles"]


def medians(url, obj, reference, repeat):
    render(url, obj, reference)  # warm: the mesh, the reference's scene, the buffers
    runs = [render(url, obj, reference) for _ in range(repeat)]
    keys = ("approxMs", "rasterMs", "referenceMs", "metricsMs", "encodeMs", "totalMs")
    return {k: statistics.median(t.get(k, 0) for t, _ in runs) for k in keys}, runs[0][1]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limn", default=os.path.join(ROOT, "build/bin/limn"))
    parser.add_argument("--models", default="pawn,humanoid,octopus")
    parser.add_argument("--model-dir", default="/tmp/models")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    proc, url = start_server(args.limn)
    try:
        print("| model | triangles | plain ms | compared ms | ratio | approx | raster (plain / "
              "compared) | reference | metrics | encode (plain / compared) |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for name in args.models.split(","):
            path = (os.path.join(ROOT, "examples/pawn.obj") if name == "pawn"
                    else os.path.join(args.model_dir, name + ".obj"))
            obj = open(path).read()
            plain, triangles = medians(url, obj, False, args.repeat)
            compared, _ = medians(url, obj, True, args.repeat)
            print("| %s | %d | %.0f | %.0f | %.2f | %.0f | %.0f / %.0f | %.0f | %.0f | %.0f / %.0f |" % (
                name, triangles, plain["totalMs"], compared["totalMs"],
                compared["totalMs"] / plain["totalMs"], compared["approxMs"], plain["rasterMs"],
                compared["rasterMs"], compared["referenceMs"], compared["metricsMs"],
                plain["encodeMs"], compared["encodeMs"]), flush=True)
    finally:
        proc.terminate()
        proc.wait()


if __name__ == "__main__":
    main()
