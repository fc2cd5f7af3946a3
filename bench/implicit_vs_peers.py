#!/usr/bin/python3
"""limn's marching cubes against VTK's and scikit-image's on the same sampled grids.

For each scene of configs/implicit and each resolution, `implicit_bench --dump` samples the field
on limn's grid (all threads, reported in Mvoxels/s) and writes the samples; then, on that same
file, this script times

  limn        `implicit_bench --march` on 1 and on 2 threads (render::parallelThreadLimit);
  VTK 9.1     vtkFlyingEdges3D on 1 and on 2 threads (vtkSMPTools.Initialize(n), each thread
              count in its own process, Debian's default SMP backend), and vtkMarchingCubes
              (serial);
  skimage     skimage.measure.marching_cubes (Lewiner, serial);

best of 5 each, sampling excluded. Every one returns points placed by linear interpolation on the
crossed cell edges and the triangles; the VTK filters are asked for nothing more (no normals,
gradients or scalars). Prints a Markdown table: times, speed ratios, triangle counts.

Every timed process runs with glibc's malloc told to keep freed memory (GLIBC_TUNABLES below):
on the development VM first touching fresh memory costs about 4 ms per MB, so with the default
allocator each run's time depends on whether its buffers came back from the last run (VTK's
Flying Edges allocates one byte per x edge, 47 MB at 360^3, which glibc always maps afresh).
--default-malloc measures with the default allocator instead.

    /usr/bin/python3 bench/implicit_vs_peers.py [build/bin/implicit_bench] [--resolutions 80,120,360]
                                                [--default-malloc]

Installs what it needs (Debian python3-vtk9 and python3-skimage) when they are missing.
"""
import json
import os
import subprocess
import sys
import tempfile
import time

SCENES = ["sphere_bite", "metaball_figure", "sphere_cylinder_cut"]
RUNS = 5
KEEP_FREED_MEMORY = "glibc.malloc.mmap_max=0:glibc.malloc.trim_threshold=17179869184"


def ensure_packages():
    missing = []
    try:
        import vtkmodules.vtkFiltersCore  # noqa: F401
    except ImportError:
        missing.append("python3-vtk9")
    try:
        import skimage.measure  # noqa: F401
    except ImportError:
        missing.append("python3-skimage")
    if not missing:
        return
    print(f"implicit_vs_peers: installing {' '.join(missing)}", file=sys.stderr)
    sudo = [] if os.geteuid() == 0 else ["sudo"]
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    subprocess.run(sudo + ["apt-get", "update", "-qq"], check=True, env=env)
    subprocess.run(sudo + ["apt-get", "install", "-y", "-qq", "--no-install-recommends"] + missing,
                   check=True, env=env, stdout=subprocess.DEVNULL)


def best_ms(run):
    best = float("inf")
    for _ in range(RUNS):
        start = time.perf_counter()
        result = run()
        best = min(best, (time.perf_counter() - start) * 1e3)
    return best, result


def vtk_times(path, shape, threads):
    """In its own process: VTK's SMP thread count is set once per process."""
    import numpy as np
    from vtkmodules.util import numpy_support
    from vtkmodules.vtkCommonCore import vtkSMPTools
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D, vtkMarchingCubes

    vtkSMPTools.Initialize(threads)
    image = vtkImageData()
    image.SetDimensions(shape[2], shape[1], shape[0])  # x fastest, as the file is written
    scalars = numpy_support.numpy_to_vtk(np.fromfile(path, dtype=np.float32), deep=1)
    image.GetPointData().SetScalars(scalars)

    def timed(filter_class):
        f = filter_class()
        f.SetInputData(image)
        f.SetValue(0, 0.0)
        f.ComputeNormalsOff()
        f.ComputeScalarsOff()
        f.ComputeGradientsOff()

        def run():
            f.Modified()
            f.Update()
            return f.GetOutput().GetNumberOfCells()
        return best_ms(run)

    out = {"backend": vtkSMPTools.GetBackend(),
           "threads": vtkSMPTools.GetEstimatedNumberOfThreads()}
    out["flyingEdgesMs"], out["flyingEdgesTriangles"] = timed(vtkFlyingEdges3D)
    if threads == 1:
        out["marchingCubesMs"], out["marchingCubesTriangles"] = timed(vtkMarchingCubes)
    return out


def run_json(command):
    return json.loads(subprocess.run(command, check=True, capture_output=True,
                                     text=True).stdout.strip().splitlines()[-1])


def skimage_times(path, shape):
    import numpy as np
    from skimage import measure
    volume = np.fromfile(path, dtype=np.float32).reshape(shape)
    ms, triangles = best_ms(lambda: len(measure.marching_cubes(volume, level=0.0)[1]))
    return {"ms": ms, "triangles": triangles}


def difference(theirs, ours):
    return f"{100.0 * (theirs - ours) / ours:+.2f}%"


def row(binary, scene, resolution, tmp):
    path = f"{tmp}/{scene}_{resolution}.f32"
    grid = run_json([binary, "--dump", scene, str(resolution), path])
    shape = grid["shape"]
    limn = {t: run_json([binary, "--march", scene, str(resolution), path, "--threads", str(t),
                         "--runs", str(RUNS)]) for t in (1, 2)}
    peer = [sys.executable, __file__, path, ",".join(map(str, shape))]
    vtk = {t: run_json(peer[:2] + ["--vtk"] + peer[2:] + [str(t)]) for t in (1, 2)}
    sk = run_json(peer[:2] + ["--skimage"] + peer[2:])
    sk_ms, sk_triangles = sk["ms"], sk["triangles"]
    ours = limn[1]["triangles"]
    assert limn[2]["triangles"] == ours
    cells = "x".join(str(n - 1) for n in reversed(shape))
    fe1, fe2 = vtk[1]["flyingEdgesMs"], vtk[2]["flyingEdgesMs"]
    l1, l2 = limn[1]["ms"], limn[2]["ms"]
    print(f"| {scene} | {cells} | {grid['mvoxelsPerS']:.1f} | {l1:.1f} | {l2:.1f} | {fe1:.1f} | "
          f"{fe2:.1f} | {vtk[1]['marchingCubesMs']:.1f} | {sk_ms:.1f} | {fe1 / l1:.2f}x | "
          f"{fe2 / l2:.2f}x | {vtk[1]['marchingCubesMs'] / l1:.2f}x | {sk_ms / l1:.2f}x | {ours} | "
          f"{difference(vtk[1]['flyingEdgesTriangles'], ours)} | "
          f"{difference(vtk[1]['marchingCubesTriangles'], ours)} | "
          f"{difference(sk_triangles, ours)} |", flush=True)
    return vtk[2]


def main():
    args = sys.argv[1:]
    if args and args[0] in ("--vtk", "--skimage"):
        shape = [int(n) for n in args[2].split(",")]
        times = vtk_times(args[1], shape, int(args[3])) if args[0] == "--vtk" else \
            skimage_times(args[1], shape)
        print(json.dumps(times))
        return
    ensure_packages()
    binary = "build/bin/implicit_bench"
    resolutions = [80, 120, 360]
    allocator = "freed memory kept (GLIBC_TUNABLES=" + KEEP_FREED_MEMORY + ")"
    while args:
        arg = args.pop(0)
        if arg == "--resolutions":
            resolutions = [int(r) for r in args.pop(0).split(",")]
        elif arg == "--default-malloc":
            allocator = "glibc's default malloc"
        else:
            binary = arg
    if allocator.startswith("freed"):
        os.environ["GLIBC_TUNABLES"] = KEEP_FREED_MEMORY
    print("| scene | grid (cells) | sampling Mvoxels/s | limn 1 thread ms | limn 2 threads ms | "
          "Flying Edges 1 thread ms | Flying Edges 2 threads ms | vtkMarchingCubes ms | "
          "scikit-image ms | Flying Edges / limn, 1 thread | Flying Edges / limn, 2 threads | "
          "vtkMarchingCubes / limn | scikit-image / limn | limn triangles | Flying Edges | "
          "vtkMarchingCubes | scikit-image |")
    print("|---|---|" + "---:|" * 15)
    with tempfile.TemporaryDirectory() as tmp:
        for scene in SCENES:
            for resolution in resolutions:
                smp = row(binary, scene, resolution, tmp)
                os.remove(f"{tmp}/{scene}_{resolution}.f32")
    print(f"\nVTK SMP backend {smp['backend']}, {smp['threads']} threads in the 2-thread runs; "
          f"{allocator}; triangle columns after limn's: the difference from limn's count.")


if __name__ == "__main__":
    main()
