#!/usr/bin/env python3
"""Every method on every view: the realistic corpus (bench/models) from seeded random views,
through a real `limn serve`, against the exact reference. Prints Markdown
(bench/fidelity_results.md keeps the last run).

    python3 bench/fidelity_views.py [--limn build/bin/limn] [--size 1024] [--views 2] [--seed 1]
                                    [--models a,b] [--max-level 4] [--json OUT.json]
    python3 bench/fidelity_views.py --from-json OUT.json    (the tables again, from a saved run)

Per view, one POST /v1/compare (one reference, every method measured against it): adaptive
dicingRate 1, silhouette, patches dicingRate 1, and uniform levels 1..max-level. Targets (issue
26): outlineHausdorffPx <= 0.5 px for adaptive, <= 1 px for silhouette and patches, on >= 99%
of views, none over 2 px; silhouette at most 25% of the triangles of the smallest uniform level
that is as accurate (outlineHausdorffPx) from the same view, on >= 90% of views.

Views: eye in a uniformly random direction at 1.5-4 bounding radii from the bounding box's
centre, looking at it, fov 20-60 degrees, up the world's +y unless nearly parallel, one view in
four orthographic (height 2-3 radii). The held-out models (index.json) are reported apart.
"""
import argparse
import json
import math
import os
import random
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

from serve import start_server

HERE = os.path.dirname(os.path.abspath(__file__))
TARGETS = {"adaptive:1": 0.5, "silhouette": 1.0, "patches:1": 1.0}


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--limn", default=os.path.join(HERE, "..", "build", "bin", "limn"))
    p.add_argument("--size", type=int, default=1024)
    p.add_argument("--views", type=int, default=2)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--models", default="")
    p.add_argument("--max-level", type=int, default=4)
    p.add_argument("--json", default="", help="also write every view's numbers to this file")
    p.add_argument("--from-json", default="", help="print the tables of a run saved with --json, "
                   "rendering nothing")
    return p.parse_args()


def bounds(obj_text):
    lo, hi = [1e300] * 3, [-1e300] * 3
    for line in obj_text.splitlines():
        if line.startswith("v "):
            p = [float(x) for x in line.split()[1:4]]
            lo = [min(a, b) for a, b in zip(lo, p)]
            hi = [max(a, b) for a, b in zip(hi, p)]
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    radius = math.dist(lo, hi) / 2
    return centre, radius


def random_view(rng, centre, radius, size):
    z = rng.uniform(-1, 1)
    a = rng.uniform(0, 2 * math.pi)
    d = (math.sqrt(1 - z * z) * math.cos(a), z, math.sqrt(1 - z * z) * math.sin(a))
    distance = rng.uniform(1.5, 4.0) * radius
    eye = [c + distance * x for c, x in zip(centre, d)]
    up = [0, 1, 0] if abs(d[1]) < 0.95 else [0, 0, 1]
    camera = {"eye": eye, "target": centre, "up": up, "width": size, "height": size,
              "fovYDeg": rng.uniform(20, 60)}
    if rng.random() < 0.25:
        camera["projection"] = "orthographic"
        camera["orthoHeight"] = rng.uniform(2, 3) * radius
    return camera


def post(url, body):
    request = urllib.request.Request(url, data=json.dumps(body).encode(),
                                     headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(request, timeout=900) as answer:
            return json.loads(answer.read())
    except urllib.error.HTTPError as e:
        return {"httpError": e.code, "body": e.read().decode(errors="replace")[:300]}


def methods(max_level):
    rows = [{"method": "adaptive", "params": {"dicingRate": 1}, "label": "adaptive:1"},
            {"method": "silhouette", "label": "silhouette"},
            {"method": "patches", "params": {"dicingRate": 1}, "label": "patches:1"}]
    rows += [{"method": "uniform", "params": {"level": k}, "label": "uniform:%d" % k}
             for k in range(1, max_level + 1)]
    return rows


def measure(url, model, obj, camera, max_level):
    body = {"mesh": {"format": "obj", "data": obj, "scheme": model["scheme"]}, "cameras": [camera],
            "methods": methods(max_level)}
    start = time.time()
    answer = post(url + "/v1/compare", body)
    seconds = time.time() - start
    if "httpError" in answer:
        return {"error": "%s %s" % (answer["httpError"], answer["body"]), "seconds": seconds}
    rows = {}
    for row in answer["rows"]:
        if "error" in row:
            rows[row["label"]] = {"error": row["error"]["message"][:120]}
            continue
        s = row["metrics"].get("silhouette", {})
        rows[row["label"]] = {"px": s.get("outlineHausdorffPx"), "triangles": row["stats"]["triangles"],
                              "ms": row["timings"]["approxMs"] + row["timings"]["rasterMs"]}
    reference = answer["reference"]["cameras"][0]
    return {"rows": rows, "seconds": seconds, "referenceWarnings": reference.get("warnings", []),
            "accuracyPx": reference.get("accuracyPx")}


def uniform_share(view, max_level):
    """The silhouette's triangles and time over those of the smallest uniform level that is as
    accurate from the same view: (share, time ratio, level, bound). When no level up to
    max_level is, the as-accurate level is above it, with at least 4x the triangles of max_level
    and no less time: the share and time ratio are then upper bounds (bound True), against 4x the
    triangles and the time of max_level. None when there is no silhouette or uniform row."""
    s = view["rows"].get("silhouette", {})
    if s.get("px") is None:
        return None
    for k in range(1, max_level + 1):
        u = view["rows"].get("uniform:%d" % k, {})
        if u.get("px") is not None and u["px"] <= max(s["px"], 1e-3):
            return s["triangles"] / u["triangles"], s["ms"] / max(u["ms"], 1e-3), k, False
    top = view["rows"].get("uniform:%d" % max_level, {})
    if top.get("px") is None:
        return None
    return s["triangles"] / (4 * top["triangles"]), s["ms"] / max(top["ms"], 1e-3), max_level + 1, True


def share_text(share):
    if not share:
        return "none"
    if share[3]:
        return "< %.1f%% (> %d)" % (100 * share[0], share[2] - 1)
    return "%.0f%% (%d)" % (100 * share[0], share[2])


def summarise(results, label):
    lines = ["### %s" % label, "",
             "| method | target px | views within | share within | worst px (model, view) | over 2 px |",
             "|---|---:|---:|---:|---|---:|"]
    for method, target in TARGETS.items():
        values = [(v["rows"][method]["px"], v["model"], v["view"]) for v in results
                  if "rows" in v and v["rows"].get(method, {}).get("px") is not None]
        failed = sum(1 for v in results if "rows" not in v or v["rows"].get(method, {}).get("px") is None)
        within = sum(1 for px, _, _ in values if px <= target)
        total = len(values) + failed
        worst = max(values) if values else (float("nan"), "-", "-")
        over2 = sum(1 for px, _, _ in values if px > 2)
        lines.append("| %s | %.1f | %d / %d | %.1f%% | %.3f (%s, %s) | %d |" % (
            method, target, within, total, 100.0 * within / max(total, 1), worst[0], worst[1], worst[2], over2))
    shares = [uniform_share(v, MAX_LEVEL) for v in results if "rows" in v and v["faces"] > 500]
    known = [s for s in shares if s]
    if shares:
        le25 = sum(1 for s in known if s[0] <= 0.25)
        faster = sum(1 for s in known if s[1] < 1)
        median = sorted(s[0] for s in known)[len(known) // 2] if known else float("nan")
        bounded = sum(1 for s in known if s[3])
        lines += ["", "Silhouette vs the smallest as-accurate uniform level (models over 500 faces): "
                  "%d views, %d with a level up to %d as accurate and %d more accurate than level %d "
                  "(share bounded above by 4x level %d's triangles); share of its triangles <= 25%% on "
                  "%d (%.0f%% of all), median share %.0f%%; faster on %d." % (
                      len(shares), len(known) - bounded, MAX_LEVEL, bounded, MAX_LEVEL, MAX_LEVEL, le25,
                      100.0 * le25 / len(shares), 100 * median, faster)]
    return lines


def per_model(results):
    lines = ["| model | faces | scheme | held out | view | adaptive:1 px | silhouette px | patches:1 px | "
             "silhouette tris | share of uniform (level) | reference warnings |",
             "|---|---:|---|---|---:|---:|---:|---:|---:|---|---|"]
    for v in results:
        if "rows" not in v:
            lines.append("| %s | %d | %s | %s | %d | error: %s | | | | | |" % (
                v["model"], v["faces"], v["scheme"], "yes" if v["heldOut"] else "", v["view"], v["error"][:80]))
            continue

        def px(label):
            r = v["rows"].get(label, {})
            return "%.3f" % r["px"] if r.get("px") is not None else "err"

        share = uniform_share(v, MAX_LEVEL)
        lines.append("| %s | %d | %s | %s | %d | %s | %s | %s | %s | %s | %s |" % (
            v["model"], v["faces"], v["scheme"], "yes" if v["heldOut"] else "", v["view"], px("adaptive:1"),
            px("silhouette"), px("patches:1"), v["rows"].get("silhouette", {}).get("triangles", "-"),
            share_text(share),
            "; ".join(w[:70] for w in v["referenceWarnings"])))
    return lines


MAX_LEVEL = 4


def measure_all(args):
    """Every view of every model through one server: the list of views' numbers."""
    models_dir = tempfile.mkdtemp(prefix="limn-models-")
    subprocess.run([sys.executable, os.path.join(HERE, "models", "make_models.py"), models_dir],
                   check=True, stdout=subprocess.DEVNULL)
    index = json.load(open(os.path.join(models_dir, "index.json")))
    if args.models:
        wanted = set(args.models.split(","))
        index = [m for m in index if m["name"] in wanted]
    server, url = start_server(args.limn)
    results = []
    try:
        for model in index:
            obj = open(os.path.join(models_dir, model["name"] + ".obj")).read()
            centre, radius = bounds(obj)
            rng = random.Random("%s-%d" % (model["name"], args.seed))
            for k in range(args.views):
                camera = random_view(rng, centre, radius, args.size)
                view = measure(url, model, obj, camera, args.max_level)
                view.update({"model": model["name"], "faces": model["faces"], "scheme": model["scheme"],
                             "heldOut": model["heldOut"], "view": k, "camera": camera})
                results.append(view)
                rows = view.get("rows", {})
                print("%-13s view %d  adaptive %s  silhouette %s  patches %s  (%.1f s)" % (
                    model["name"], k, rows.get("adaptive:1", {}).get("px"), rows.get("silhouette", {}).get("px"),
                    rows.get("patches:1", {}).get("px"), view["seconds"]), file=sys.stderr)
    finally:
        server.terminate()
        server.wait()
    return results


def report(args, results):
    tuned = [v for v in results if not v["heldOut"]]
    held = [v for v in results if v["heldOut"]]
    models = len({v["model"] for v in results})
    # A saved run's own settings are not in its file: name the file instead.
    command = ("--from-json %s" % args.from_json if args.from_json else
               "--size %d --views %d --seed %d --max-level %d" % (args.size, args.views, args.seed,
                                                                  args.max_level))
    out = ["`python3 bench/fidelity_views.py %s`: %d models, %d views." % (command, models, len(results)), ""]
    out += summarise(results, "All models") + [""]
    if tuned and held:
        out += summarise(tuned, "Models used while tuning") + [""]
        out += summarise(held, "Held-out models") + [""]
    out += ["### Every view", ""] + per_model(results) + [""]
    out += ["Cameras of the views over target (for /v1/render):", ""]
    for v in results:
        over = [m for m, t in TARGETS.items() if (v.get("rows", {}).get(m, {}).get("px") or 0) > t]
        if over:
            out.append("- %s view %d (%s): `%s`" % (v["model"], v["view"], ", ".join(over),
                                                   json.dumps(v["camera"], separators=(",", ":"))))
    return out


def main():
    global MAX_LEVEL
    args = parse_args()
    MAX_LEVEL = args.max_level
    if args.from_json:
        results = json.load(open(args.from_json))
    else:
        results = measure_all(args)
        if args.json:
            json.dump(results, open(args.json, "w"), indent=1)
    print("\n".join(report(args, results)))


if __name__ == "__main__":
    main()
