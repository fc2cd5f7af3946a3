// The compare view's metrics table: what each number means (a one-line explanation) and whether
// it looks good or suspicious, from an answer of POST /v1/render with "reference": true.

export function formatNumber(x) {
  if (x === undefined || x === null) return "–";
  if (Number.isInteger(x)) return x.toLocaleString("en");
  const a = Math.abs(x);
  return a !== 0 && (a < 1e-3 || a >= 1e6) ? x.toExponential(2) : x.toPrecision(4);
}

// [good, suspicious]: a value on the good side of the first is coloured good, one past the
// second suspicious (for "higher is better" rows the bounds decrease). Rough guides for a
// picture of a few hundred pixels, not verdicts.
const below = (good, suspicious) => (x) => (x <= good ? "good" : x > suspicious ? "suspicious" : "");
const above = (good, suspicious) => (x) => (x >= good ? "good" : x < suspicious ? "suspicious" : "");

// The answer's metrics, stats and timings as small tables (one per group), each row with its
// explanation as a tooltip and, for the error metrics, a class "good" or "suspicious".
export function metricsTables(answer) {
  const m = answer.metrics, s = answer.stats, t = answer.timings;
  // [name, value, one-line explanation, judge]; a row with value null starts a table.
  const rows = [
    ["silhouette", null],
    ["outline Hausdorff (px)", m.silhouette?.outlineHausdorffPx,
     "The farthest any point of the approximation's outline lies from the reference's outline " +
     "(continuous curves, in pixels). Under 1 px the outlines look the same.", below(1, 2)],
    ["outline mean (px)", m.silhouette?.outlineMeanPx,
     "The average distance between the two outlines, in pixels.", below(0.5, 1)],
    ["mask Hausdorff (px)", m.silhouette?.hausdorffPx,
     "The same farthest distance measured on the covered-pixel masks (supersampled).", below(1, 2)],
    ["IoU", m.silhouette?.iou,
     "Covered pixels in both divided by covered pixels in either: 1 is the same coverage.",
     above(0.995, 0.98)],
    ["mismatched pixels", m.silhouette?.mismatchPx,
     "Pixels covered by one of the two pictures but not the other."],
    ["image, depth, normals", null],
    ["colour RMSE", m.image?.rmse,
     "Root-mean-square colour difference (0..1 per channel) over the covered pixels.",
     below(0.01, 0.04)],
    ["PSNR (dB)", m.image?.psnr,
     "Peak signal-to-noise ratio of the colour: above 40 dB differences are hard to see.",
     above(40, 30)],
    ["diff scale (top of ramp)", m.image?.diffScale,
     "The largest colour difference of one pixel: the top (pale yellow) of the difference image."],
    ["depth max (rel.)", m.depth?.maxRel,
     "The largest depth difference at a pixel covered by both, relative to the depth.",
     below(0.01, 0.05)],
    ["normal mean (deg)", m.normal?.meanDeg,
     "The average angle between the approximation's and the limit's normals over the pixels " +
     "both cover: what shading errors come from.", below(1, 5)],
    ["normal max (deg)", m.normal?.maxDeg,
     "The largest normal angle at one pixel; large at a few pixels along the outline is common " +
     "(one picture sees the front, the other the back), so read it with the mean."],
    ["geometry max dist (rel.)", m.geometry?.relMaxDist,
     "The largest distance from the approximation's vertices to the limit surface, relative to " +
     "the bounding-box diagonal.", below(0.001, 0.01)],
    ["size", null],
    ["triangles", s.triangles, "Triangles of the approximation."],
    ["reference triangles", s.referenceTriangles, "Triangles of the reference's mesh, if any."],
    ["times (ms)", null],
    ["surface", t.surfaceMs, "Building the limit surface (topology, patch tables)."],
    ["approximation", t.approxMs, "Making the approximation's triangles."],
    ["raster", t.rasterMs, "Drawing the pictures."],
    ["reference", t.referenceMs, "Ray casting the exact limit surface."],
    ["metrics", t.metricsMs, "Comparing the two."],
    ["encode", t.encodeMs, "Writing the PNG images."],
    ["total", t.totalMs, "The server's whole time for the request."],
  ];
  // One small table per group, side by side.
  const tables = [];
  for (const [name, value, explanation, judge] of rows) {
    if (value === null) {
      const table = document.createElement("table");
      table.createCaption().textContent = name;
      tables.push(table);
      continue;
    }
    const tr = tables.at(-1).insertRow();
    const label = tr.insertCell();
    label.textContent = name;
    label.title = explanation;
    const cell = tr.insertCell();
    cell.textContent = formatNumber(value);
    cell.title = explanation;
    const verdict = judge && typeof value === "number" ? judge(value) : "";
    if (verdict) cell.className = verdict;
  }
  return tables;
}
