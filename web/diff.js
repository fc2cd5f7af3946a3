// The server's difference image is linear from 0 (black) to its top, the largest difference of
// any pixel (metrics.image.diffScale, pale yellow): one bad pixel leaves the rest dark. The page
// can redraw it with another top — a percentile of the covered pixels' differences (brighter
// ones clamped) — or on a logarithmic scale, reading each pixel's difference back from the
// ramp's colour (the ramp of render/metrics/image_metrics.cpp, written as bytes without sRGB).
export const LOG_FLOOR = 1 / 255;  // one step of an 8-bit colour

const HEAT_STOPS = [[0.00, 0.00, 0.02], [0.34, 0.06, 0.43], [0.73, 0.21, 0.33], [0.98, 0.55, 0.04],
                    [0.99, 1.00, 0.64]];

export function heatRamp(t) {
  const x = Math.min(1, Math.max(0, t)) * 4, i = Math.min(Math.floor(x), 3), f = x - i;
  return HEAT_STOPS[i].map((c, k) => c + f * (HEAT_STOPS[i + 1][k] - c));
}

const HEAT_TABLE = Array.from({ length: 1021 }, (_, k) => heatRamp(k / 1020).map((c) => c * 255));

// The ramp position (0..1) of an 8-bit colour: the nearest of the table's colours.
function rampPosition(r, g, b, cache) {
  const key = (r << 16) | (g << 8) | b;
  let t = cache.get(key);
  if (t !== undefined) return t;
  let best = Infinity;
  HEAT_TABLE.forEach(([R, G, B], k) => {
    const d = (R - r) ** 2 + (G - g) ** 2 + (B - b) ** 2;
    if (d < best) { best = d; t = k / 1020; }
  });
  cache.set(key, t);
  return t;
}

const loadImage = (src) => new Promise((resolve, reject) => {
  const img = new Image();
  img.onload = () => resolve(img);
  img.onerror = reject;
  img.src = src;
});

// The server's difference image (a PNG data URL whose ramp tops at `scale`) redrawn with the
// top at a percentile of the covered pixels' differences (`mode` "99", "90", ...: brighter
// pixels clamped) or on a logarithmic scale ("log", from one 8-bit step to `scale`). Resolves
// to {url: a PNG data URL, top: the difference at the new top, or null for the logarithmic}.
export async function rescaleDiff(dataUrl, scale, mode) {
  const img = await loadImage(dataUrl);
  const canvas = document.createElement("canvas");
  canvas.width = img.naturalWidth;
  canvas.height = img.naturalHeight;
  const ctx = canvas.getContext("2d");
  ctx.drawImage(img, 0, 0);
  const pixels = ctx.getImageData(0, 0, canvas.width, canvas.height);
  const data = pixels.data, cache = new Map();
  const values = new Float32Array(data.length / 4).fill(-1);
  for (let i = 0; i < data.length; i += 4) {
    if (data[i + 3] > 0) values[i / 4] = rampPosition(data[i], data[i + 1], data[i + 2], cache) * scale;
  }
  let map, top = null;
  if (mode === "log") {
    map = (v) => Math.log1p(v / LOG_FLOOR) / Math.log1p(scale / LOG_FLOOR);
  } else {
    const covered = values.filter((v) => v >= 0).sort();
    const k = Math.min(covered.length - 1, Math.floor((Number(mode) / 100) * covered.length));
    top = Math.max(covered[k] || 0, LOG_FLOOR);
    map = (v) => v / top;
  }
  values.forEach((v, k) => {
    if (v < 0) return;
    const rgb = heatRamp(map(v));
    for (let c = 0; c < 3; c++) data[4 * k + c] = Math.round(rgb[c] * 255);
  });
  ctx.putImageData(pixels, 0, 0);
  return { url: canvas.toDataURL("image/png"), top };
}
