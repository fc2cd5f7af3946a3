#!/usr/bin/env python3
"""The cost of anti-aliasing ("antialias": 1, 4, 8, 16) per method, through a limn server.

Starts `build/bin/limn serve` on a free loopback port (or uses --server URL), renders the
example pawn with each method at each sample count, colour only, and prints a Markdown table of
the median raster time, the median whole request (server's totalMs) and the ratio to
"antialias": 1 measured in the same run; with --reference, also the reference's time (its
outline pixels get one ray per sample). bench/antialias_results.md keeps the last run.

  bench/antialias_bench.py [--size PX] [--repeat N] [--reference] [--server URL]
"""
import argparse
import json
import os
import socket
import statistics
import subprocess
import sys
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
METHODS = [("coarse", {}), ("uniform", {"level": 3}), ("adaptive", {"dicingRate": 1}),
           ("silhouette", {}), ("patches", {"dicingRate": 1})]
SAMPLES = [1, 4, 8, 16]


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def post(url, body):
    request = urllib.request.Request(url + "/v1/render", data=json.dumps(body).encode(),
                                     headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=120) as answer:
        return json.load(answer)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--reference", action="store_true")
    parser.add_argument("--server")
    args = parser.parse_args()

    server = None
    url = args.server
    if not url:
        port = free_port()
        server = subprocess.Popen([os.path.join(ROOT, "build/bin/limn"), "serve", "--listen",
                                   f"127.0.0.1:{port}", "--workers", "1"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        url = f"http://127.0.0.1:{port}"
        for _ in range(100):
            try:
                urllib.request.urlopen(url + "/readyz", timeout=1)
                break
            except OSError:
                time.sleep(0.1)
    try:
        obj = open(os.path.join(ROOT, "examples/pawn.obj")).read()
        print(f"| method | antialias | raster ms | request ms | raster / 1 | request / 1 |"
              + (" reference ms |" if args.reference else ""))
        print("|---|---:|---:|---:|---:|---:|" + ("---:|" if args.reference else ""))
        for method, params in METHODS:
            base = None
            for samples in SAMPLES:
                body = {"mesh": {"format": "obj", "data": obj}, "method": method,
                        "params": params, "camera": {"width": args.size, "height": args.size},
                        "outputs": ["color"], "antialias": samples,
                        "reference": args.reference}
                post(url, body)  # warm: the surface and the framebuffers
                runs = [post(url, body)["timings"] for _ in range(args.repeat)]
                raster = statistics.median(t["rasterMs"] for t in runs)
                total = statistics.median(t["totalMs"] for t in runs)
                if base is None:
                    base = (raster, total)
                row = (f"| {method} | {samples} | {raster:.1f} | {total:.1f} | "
                       f"{raster / base[0]:.2f} | {total / base[1]:.2f} |")
                if args.reference:
                    row += f" {statistics.median(t['referenceMs'] for t in runs):.1f} |"
                print(row, flush=True)
    finally:
        if server:
            server.terminate()
            server.wait()


if __name__ == "__main__":
    sys.exit(main())
