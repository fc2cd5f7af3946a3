#!/usr/bin/python3
"""One POST /v1/compare against the same rows as separate POST /v1/render calls.

Usage: compare_vs_render.py URL MESH.obj[,MESH.obj...] [--size 1024] [--views 3]
       [--methods coarse,uniform:3,adaptive:1,silhouette] [--seed-azimuth DEG]

For each mesh: the views are orbit views (azimuth 0, 120, 240 at elevation 20, then more round
the ring); every method of every view is rendered alone with "reference": true, one request at
a time, then the same rows are asked for in one /v1/compare. Prints a Markdown table: wall time
of each, the server's reference time (per render; once per view in the comparison), and the
largest difference between a compare row's metrics and its render's. A server with the reference
cache on reuses the renders' tessellations in the comparison: start it with referenceCacheBytes
0 to compare like with like (bench/batch/README.md does)."""
import json
import sys
import time
import urllib.request


def post(url, body):
    request = urllib.request.Request(url, data=json.dumps(body).encode(), method="POST")
    start = time.perf_counter()
    with urllib.request.urlopen(request, timeout=600) as answer:
        data = json.loads(answer.read())
    return data, time.perf_counter() - start


def method_entry(text):
    name, _, value = text.partition(":")
    params = {}
    if value:
        params["level" if name == "uniform" else "dicingRate"] = float(value) if "." in value else int(value)
    return {"method": name, "params": params}


def largest_difference(a, b):
    worst = 0.0
    for group, values in a.items():
        for key, value in values.items():
            other = b[group][key]
            if isinstance(value, (int, float)) and value is not None and other is not None:
                worst = max(worst, abs(value - other) / max(1.0, abs(value)))
    return worst


def main():
    args = sys.argv[1:]
    options = {"--size": "1024", "--views": "3", "--methods": "coarse,uniform:3,adaptive:1,silhouette",
               "--seed-azimuth": "0"}
    positional = []
    while args:
        a = args.pop(0)
        if a in options:
            options[a] = args.pop(0)
        else:
            positional.append(a)
    url, meshes = positional[0].rstrip("/"), positional[1].split(",")
    size, views = int(options["--size"]), int(options["--views"])
    methods = [method_entry(m) for m in options["--methods"].split(",")]
    # --seed-azimuth moves the ring, so that a second run on the same server meets views its
    # reference cache has not seen.
    start = float(options["--seed-azimuth"])
    cameras = [{"orbit": {"azimuthDeg": start + 360.0 * i / views, "elevationDeg": 20}, "width": size,
                "height": size} for i in range(views)]
    print("| mesh | rows | separate renders s | their referenceMs (sum) | one compare s | its referenceMs (sum) | rows ms (sum) | speed-up | largest metric difference |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for path in meshes:
        mesh = {"format": "obj", "data": open(path).read()}
        if "loop" in path or "icosahedron" in path:
            mesh["scheme"] = "loop"
        renders, separate_s, separate_ref = {}, 0.0, 0.0
        for c, camera in enumerate(cameras):
            for m, method in enumerate(methods):
                body = dict(mesh=mesh, camera=camera, outputs=[], reference=True, **method)
                answer, seconds = post(url + "/v1/render", body)
                renders[(c, m)] = answer
                separate_s += seconds
                separate_ref += answer["timings"]["referenceMs"]
        table, compare_s = post(url + "/v1/compare", {"mesh": mesh, "cameras": cameras, "methods": methods})
        worst = 0.0
        for i, row in enumerate(table["rows"]):
            c, m = divmod(i, len(methods))
            alone = renders[(c, m)]
            assert alone["stats"]["triangles"] == row["stats"]["triangles"], (path, i)
            worst = max(worst, largest_difference(alone["metrics"], row["metrics"]))
        name = path.rsplit("/", 1)[-1]
        print(f"| {name} | {len(table['rows'])} | {separate_s:.2f} | {separate_ref:.0f} | {compare_s:.2f} | "
              f"{table['reference']['timings']['referenceMs']:.0f} | {table['timings']['rowsMs']:.0f} | "
              f"{separate_s / compare_s:.2f} | {worst:.1e} |")


main()
