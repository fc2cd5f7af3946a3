#!/usr/bin/python3
"""The plots of a `limn batch` report, from DIR/results.csv (docs/batch.md).

Usage: batch_plots.py DIR
Writes DIR/plots/NAME.svg and NAME.png for
  error_vs_triangles  the outline error of every row against its triangles, one colour per
                      method, each method label's median as a labelled point, and the Pareto
                      front of those medians (no other label has both fewer triangles and a
                      smaller error);
  time_vs_triangles   the method's own time (approximation + raster) against its triangles;
  error_by_shape      per shape: each label's median error over the views, with a bar from its
                      best to its worst view.
Prints "wrote plots/NAME.svg" for each file. limn batch runs it with Debian's /usr/bin/python3
(python3-matplotlib); it exits 3 when matplotlib is missing."""
import csv
import os
import statistics
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed (Debian: apt-get install python3-matplotlib)")
    sys.exit(3)

ERROR = "silhouette.outlineHausdorffPx"
# Log axes cannot show 0: errors this small are drawn at this floor (a thousandth of a pixel,
# the precision the outline is located to).
ERROR_FLOOR = 1e-3
FAMILIES = ["coarse", "uniform", "adaptive", "silhouette"]
COLOURS = {"coarse": "#7f7f7f", "uniform": "#1f77b4", "adaptive": "#2ca02c",
           "silhouette": "#d62728"}
MARKERS = {"coarse": "s", "uniform": "o", "adaptive": "^", "silhouette": "D"}


def number(text):
    try:
        return float(text)
    except ValueError:
        return None


def read_rows(folder):
    rows = []
    with open(os.path.join(folder, "results.csv"), newline="", encoding="utf-8") as f:
        for r in csv.DictReader(f):
            if r["errorCode"]:
                continue
            error, triangles = number(r[ERROR]), number(r["triangles"])
            if error is None or triangles is None:
                continue
            rows.append({
                "mesh": r["mesh"], "view": r["view"], "label": r["label"], "method": r["method"],
                "error": max(error, ERROR_FLOOR), "triangles": max(triangles, 1.0),
                "ms": (number(r["approxMs"]) or 0.0) + (number(r["rasterMs"]) or 0.0),
            })
    return rows


def family_rank(method):
    return FAMILIES.index(method) if method in FAMILIES else len(FAMILIES)


def labels_in_order(rows):
    medians = {}
    for label in {r["label"] for r in rows}:
        mine = [r for r in rows if r["label"] == label]
        medians[label] = (family_rank(mine[0]["method"]),
                          statistics.median(r["triangles"] for r in mine), label)
    return sorted(medians, key=lambda label: medians[label])


def save(figure, folder, name):
    os.makedirs(os.path.join(folder, "plots"), exist_ok=True)
    for ext in ("svg", "png"):
        path = os.path.join("plots", f"{name}.{ext}")
        # No date in the files: the same results make the same plots.
        figure.savefig(os.path.join(folder, path), dpi=120, bbox_inches="tight",
                       metadata={"Date": None} if ext == "svg" else {"Software": None})
        print(f"wrote {path}")
    plt.close(figure)


def pareto_front(points):
    """The points no other point beats in both coordinates (fewer triangles, smaller error)."""
    front, best = [], float("inf")
    for p in sorted(points):
        if p[1] < best:
            front.append(p)
            best = p[1]
    return front


def error_vs_triangles(rows, folder):
    figure, axes = plt.subplots(figsize=(9, 6))
    medians = []
    for label in labels_in_order(rows):
        mine = [r for r in rows if r["label"] == label]
        method = mine[0]["method"]
        colour = COLOURS.get(method, "#9467bd")
        axes.scatter([r["triangles"] for r in mine], [r["error"] for r in mine], s=9,
                     color=colour, alpha=0.25, marker=MARKERS.get(method, "o"), linewidths=0)
        point = (statistics.median(r["triangles"] for r in mine),
                 statistics.median(r["error"] for r in mine))
        medians.append(point)
        axes.scatter(*point, s=60, color=colour, edgecolors="black", linewidths=0.6,
                     marker=MARKERS.get(method, "o"), zorder=3)
        axes.annotate(label, point, textcoords="offset points", xytext=(6, 4), fontsize=8)
    front = pareto_front(medians)
    axes.plot([p[0] for p in front], [p[1] for p in front], "k--", linewidth=1,
              label="Pareto front of the medians", zorder=2)
    for method in FAMILIES:
        if any(r["method"] == method for r in rows):
            axes.scatter([], [], color=COLOURS[method], marker=MARKERS[method], label=method)
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_xlabel("triangles")
    axes.set_ylabel("outline Hausdorff error (px)")
    axes.set_title("Outline error against triangles (faint: every row; large: each label's median)")
    axes.grid(True, which="both", alpha=0.25)
    axes.legend(fontsize=8)
    save(figure, folder, "error_vs_triangles")


def time_vs_triangles(rows, folder):
    figure, axes = plt.subplots(figsize=(9, 6))
    for method in sorted({r["method"] for r in rows}, key=family_rank):
        mine = [r for r in rows if r["method"] == method]
        axes.scatter([r["triangles"] for r in mine], [max(r["ms"], 0.01) for r in mine], s=12,
                     alpha=0.6, color=COLOURS.get(method, "#9467bd"),
                     marker=MARKERS.get(method, "o"), label=method, linewidths=0)
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_xlabel("triangles")
    axes.set_ylabel("approximation + raster (ms)")
    axes.set_title("Method time against triangles (one point per row)")
    axes.grid(True, which="both", alpha=0.25)
    axes.legend(fontsize=8)
    save(figure, folder, "time_vs_triangles")


def error_by_shape(rows, folder):
    labels = labels_in_order(rows)
    meshes = sorted({r["mesh"] for r in rows})
    figure, axes = plt.subplots(figsize=(10, max(3.0, 0.32 * len(meshes) + 1.5)))
    colours = plt.get_cmap("tab10" if len(labels) <= 10 else "tab20")
    spread = 0.7 / max(len(labels), 1)
    for k, label in enumerate(labels):
        ys, medians, low, high = [], [], [], []
        for i, mesh in enumerate(meshes):
            errors = [r["error"] for r in rows if r["mesh"] == mesh and r["label"] == label]
            if not errors:
                continue
            m = statistics.median(errors)
            ys.append(i + (k - (len(labels) - 1) / 2) * spread)
            medians.append(m)
            low.append(m - min(errors))
            high.append(max(errors) - m)
        axes.errorbar(medians, ys, xerr=[low, high], fmt="o", markersize=3.5, capsize=1.5,
                      elinewidth=0.8, color=colours(k % colours.N), label=label)
    axes.set_yticks(range(len(meshes)))
    axes.set_yticklabels(meshes, fontsize=8)
    axes.invert_yaxis()
    axes.set_xscale("log")
    axes.set_xlabel("outline Hausdorff error (px): median over the views, bar from best to worst")
    axes.set_title("Outline error per shape and method")
    axes.grid(True, axis="x", which="both", alpha=0.25)
    axes.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    save(figure, folder, "error_by_shape")


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        sys.exit(2)
    folder = sys.argv[1]
    matplotlib.rcParams["svg.hashsalt"] = "limn"  # stable ids inside the SVG files
    rows = read_rows(folder)
    if not rows:
        print("no row with an outline error in results.csv: nothing to plot")
        sys.exit(1)
    error_vs_triangles(rows, folder)
    time_vs_triangles(rows, folder)
    error_by_shape(rows, folder)


main()
