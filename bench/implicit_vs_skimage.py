#!/usr/bin/python3
"""limn's marching cubes against scikit-image's on the same sampled field and grid.

For each scene of configs/implicit and each resolution, `implicit_bench --dump` samples the
field on limn's grid (all threads, reported in Mvoxels/s), writes the samples, and times limn's
marching cubes on them on one thread; this script loads the same samples and times
skimage.measure.marching_cubes (Lewiner, single-threaded) on them, best of 5 each, and prints a
Markdown table with the speed ratio and both triangle counts. Both place vertices by linear
interpolation on the cell edges; sampling is not part of either time.

    /usr/bin/python3 bench/implicit_vs_skimage.py [build/bin/implicit_bench] [--resolutions 80,120,360]
"""
import json
import subprocess
import sys
import tempfile
import time

import numpy as np
from skimage import measure


def main():
    args = sys.argv[1:]
    binary = "build/bin/implicit_bench"
    resolutions = [80, 120, 360]
    while args:
        arg = args.pop(0)
        if arg == "--resolutions":
            resolutions = [int(r) for r in args.pop(0).split(",")]
        else:
            binary = arg
    scenes = ["sphere_bite", "metaball_figure", "sphere_cylinder_cut"]
    print("| scene | grid | sampling Mvoxels/s | limn MC ms | scikit-image ms | speed-up | "
          "limn triangles | scikit-image triangles | difference |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes:
            for resolution in resolutions:
                path = f"{tmp}/{scene}_{resolution}.f32"
                out = subprocess.run([binary, "--dump", scene, str(resolution), path],
                                     check=True, capture_output=True, text=True).stdout
                limn = json.loads(out)
                volume = np.fromfile(path, dtype=np.float32).reshape(limn["shape"])
                best = float("inf")
                for _ in range(5):
                    start = time.perf_counter()
                    _, faces, _, _ = measure.marching_cubes(volume, level=0.0)
                    best = min(best, (time.perf_counter() - start) * 1e3)
                ours, theirs = limn["triangles"], len(faces)
                grid = "x".join(str(n - 1) for n in reversed(limn["shape"]))
                print(f"| {scene} | {grid} | {limn['mvoxelsPerS']:.1f} | {limn['mcMs']:.1f} | "
                      f"{best:.1f} | {best / limn['mcMs']:.2f}x | {ours} | {theirs} | "
                      f"{100.0 * (ours - theirs) / theirs:+.2f}% |", flush=True)


if __name__ == "__main__":
    main()
