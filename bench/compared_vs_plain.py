#!/usr/bin/env python3
"""What `reference: true` costs through the real server: each model drawn at 1024², adaptive
dicingRate 1, colour only, with and without the reference, on a `limn serve` with one worker.
Prints a Markdown table (bench/reference_results.md keeps runs of it).

    python3 bench/models/make_models.py /tmp/models         (the realistic models, once)
    python3 bench/compared_vs_plain.py [--limn build/bin/limn] [--models pawn,humanoid,octopus]
                                       [--model-dir /tmp/models] [--repeat 3] [--cold]
    python3 bench/compared_vs_plain.py --limn OLD,NEW [--repeat 10] [--cold]

Per model: one warm-up request of each kind, then --repeat of each; the table shows medians of
`timings` (totalMs is the worker's time for the request: parse to encode). "ratio" is compared /
plain; issue 25's goal is at most 1.5. `pawn` is examples/pawn.obj.

--cold moves one vertex by a micrometre in every request, so the reference's scene is never in
the server's cache (a new mesh, as a page that posts one sees).

With several binaries (--limn A,B,...) each gets its own server and the requests alternate
between them one at a time, so all see the same load on a shared machine; the table then shows
each one's compared totalMs side by side.
"""
import argparse
import json
import os
import statistics
import urllib.request

from serve import start_server

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
KEYS = ("approxMs", "rasterMs", "referenceMs", "metricsMs", "encodeMs", "totalMs")


class Model:
    """A model's OBJ text; with `cold`, a different mesh (one vertex moved) on every request."""

    def __init__(self, path, cold):
        self.lines = open(path).read().split("\n")
        self.cold = cold
        self.requests = 0

    def obj(self):
        if not self.cold:
            return "\n".join(self.lines)
        self.requests += 1
        lines = list(self.lines)
        first = next(i for i, line in enumerate(lines) if line.startswith("v "))
        fields = lines[first].split()
        fields[1] = repr(float(fields[1]) + self.requests * 1e-6)
        lines[first] = " ".join(fields)
        return "\n".join(lines)


def render(url, model, reference):
    body = {"mesh": {"format": "obj", "scheme": "catmull-clark", "data": model.obj()},
            "camera": {"width": 1024, "height": 1024}, "method": "adaptive",
            "params": {"dicingRate": 1}, "outputs": ["color"], "reference": reference}
    request = urllib.request.Request(url + "/v1/render", data=json.dumps(body).encode(),
                                     headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=600) as answer:
        reply = json.loads(answer.read())
    return reply["timings"], reply["stats"]["triangles"]


def medians(urls, model, reference, repeat):
    """Per server: the medians of `timings` over `repeat` requests, the servers taking turns."""
    for url in urls:
        render(url, model, reference)  # warm: the mesh, the reference's scene, the buffers
    runs = [[] for _ in urls]
    for _ in range(repeat):
        for k, url in enumerate(urls):
            runs[k].append(render(url, model, reference))
    return [({k: statistics.median(t.get(k, 0) for t, _ in r) for k in KEYS}, r[0][1])
            for r in runs]


def model_path(name, model_dir):
    return (os.path.join(ROOT, "examples/pawn.obj") if name == "pawn"
            else os.path.join(model_dir, name + ".obj"))


def one_binary(url, args):
    print("| model | triangles | plain ms | compared ms | ratio | approx | raster (plain / "
          "compared) | reference | metrics | encode (plain / compared) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name in args.models.split(","):
        model = Model(model_path(name, args.model_dir), args.cold)
        [(plain, triangles)] = medians([url], model, False, args.repeat)
        [(compared, _)] = medians([url], model, True, args.repeat)
        print("| %s | %d | %.0f | %.0f | %.2f | %.0f | %.0f / %.0f | %.0f | %.0f | %.0f / %.0f |" % (
            name, triangles, plain["totalMs"], compared["totalMs"],
            compared["totalMs"] / plain["totalMs"], compared["approxMs"], plain["rasterMs"],
            compared["rasterMs"], compared["referenceMs"], compared["metricsMs"],
            plain["encodeMs"], compared["encodeMs"]), flush=True)


def several_binaries(urls, names, args):
    print("| model | " + " | ".join("%s: plain / compared ms" % n for n in names) + " |")
    print("|---|" + "---:|" * len(names))
    for name in args.models.split(","):
        model = Model(model_path(name, args.model_dir), args.cold)
        plain = medians(urls, model, False, args.repeat)
        compared = medians(urls, model, True, args.repeat)
        print("| %s | " % name + " | ".join(
            "%.0f / %.0f" % (p["totalMs"], c["totalMs"])
            for (p, _), (c, _) in zip(plain, compared)) + " |", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limn", default=os.path.join(ROOT, "build/bin/limn"),
                        help="a limn binary, or several separated by commas")
    parser.add_argument("--models", default="pawn,humanoid,octopus")
    parser.add_argument("--model-dir", default="/tmp/models")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--cold", action="store_true",
                        help="a new mesh every request: the reference's scene is never cached")
    args = parser.parse_args()
    binaries = args.limn.split(",")
    servers = [start_server(b) for b in binaries]
    try:
        if len(servers) == 1:
            one_binary(servers[0][1], args)
        else:
            several_binaries([url for _, url in servers], binaries, args)
    finally:
        for proc, _ in servers:
            proc.terminate()
            proc.wait()


if __name__ == "__main__":
    main()
